# ctest layers.check: cmake/check_layers.cmake (the configure-time layer rule) run standalone
#  - on tests/layers/fixture: fails, naming exactly the four forbidden includes (MuJoCo and sim/ in
#    controller/, model/ in core/, diagnosis/ in formats/) and none of the allowed ones;
#  - on the source tree: passes.
# Args: -DSOURCE=<source tree>.
set(_check ${SOURCE}/cmake/check_layers.cmake)
set(_fixture ${SOURCE}/tests/layers/fixture)

execute_process(COMMAND ${CMAKE_COMMAND} -DROOT=${_fixture} -P ${_check}
                RESULT_VARIABLE _rc OUTPUT_VARIABLE _out ERROR_VARIABLE _err)
set(_all "${_out}${_err}")
if(_rc EQUAL 0)
  message(FATAL_ERROR "the check passed a tree with forbidden includes:\n${_all}")
endif()
foreach(_expected "controller/forbidden.cc: #include <mujoco/mujoco.h>"
                  "controller/forbidden.cc: #  include \"sim/plant.h\""
                  "core/forbidden.h: #include \"model/lumped_params.h\""
                  "formats/forbidden.h: #include \"diagnosis/diagnose.h\"")
  string(FIND "${_all}" "${_expected}" _at)
  if(_at EQUAL -1)
    message(FATAL_ERROR "the check did not name '${_expected}':\n${_all}")
  endif()
endforeach()
string(REGEX MATCHALL "[a-z]+/[a-z_]+\\.(h|cc): #" _named "${_all}")
list(LENGTH _named _n)
if(NOT _n EQUAL 4)
  message(FATAL_ERROR "expected 4 forbidden includes, the check named ${_n}:\n${_all}")
endif()

execute_process(COMMAND ${CMAKE_COMMAND} -DROOT=${SOURCE} -P ${_check}
                RESULT_VARIABLE _rc OUTPUT_VARIABLE _out ERROR_VARIABLE _err)
if(NOT _rc EQUAL 0)
  message(FATAL_ERROR "the source tree breaks the layer rule:\n${_out}${_err}")
endif()
message(STATUS "layer check: fixture refused (4 forbidden includes named), source tree accepted")
