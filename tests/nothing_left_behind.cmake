# The temp folder of the test run (tests/CMakeLists.txt sets TMPDIR=DIR for every test).
#   cmake -DDIR=<folder> -DMODE=clear -P nothing_left_behind.cmake   empties (creates) DIR
#   cmake -DDIR=<folder> -DMODE=check -P nothing_left_behind.cmake   fails, naming them, if DIR holds anything
if(NOT DIR OR NOT MODE MATCHES "^(clear|check)$")
  message(FATAL_ERROR "usage: cmake -DDIR=<folder> -DMODE=clear|check -P nothing_left_behind.cmake")
endif()
if(MODE STREQUAL "clear")
  file(REMOVE_RECURSE "${DIR}")
  file(MAKE_DIRECTORY "${DIR}")
  return()
endif()
file(GLOB _left LIST_DIRECTORIES true "${DIR}/*" "${DIR}/.*")
list(FILTER _left EXCLUDE REGEX "/\\.\\.?$")
if(_left)
  string(REPLACE ";" "\n  " _list "${_left}")
  message(FATAL_ERROR "the tests left these behind in their temp folder ${DIR}:\n  ${_list}")
endif()
message(STATUS "nothing left behind in ${DIR}")
