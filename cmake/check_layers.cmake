# The layer rule (docs/ARCHITECTURE.md, DESIGN.md "Layout and dependency rules"), checked on the
# sources: a layer's files include only the layers (and the guarded third-party libraries MuJoCo and
# OpenCV) its row below allows. No layer includes one above it; core/ includes no project layer and
# every layer may include core/; controller/ never includes MuJoCo, OpenCV, sim/, hwsim/, render/ or
# runner/. Each row is the closure of the layer's target_link_libraries (*/CMakeLists.txt), core
# added; exotwin_check_layer_links() checks that the CMake links need nothing beyond it.
#
# Included from the top-level CMakeLists.txt: checks CMAKE_SOURCE_DIR at configure time (fails the
# configuration on a forbidden include). Standalone: cmake -DROOT=<source tree> -P check_layers.cmake
# (exit code non-zero and a message naming file, line and include on a forbidden include).
# Only "#include <dir/...>" / "#include \"dir/...\"" lines whose dir is a layer, mujoco or opencv2
# are judged; headers of other libraries (Eigen, yaml-cpp, system) are not.

if(CMAKE_SCRIPT_MODE_FILE)
  cmake_minimum_required(VERSION 3.16)  # policies of the project (IN_LIST) in script mode too
endif()

set(EXOTWIN_LAYERS core model dsp protocol controller deploy sim hwsim formats identification diagnosis emg render
                   runner batch app python)
set(EXOTWIN_GUARDED_LIBS mujoco opencv2)

# What each layer's sources may include besides the layer itself.
set(EXOTWIN_ALLOWED_core)
set(EXOTWIN_ALLOWED_model core)
set(EXOTWIN_ALLOWED_dsp core)
set(EXOTWIN_ALLOWED_protocol core)
set(EXOTWIN_ALLOWED_controller core model dsp protocol)
set(EXOTWIN_ALLOWED_deploy core model dsp protocol controller)
set(EXOTWIN_ALLOWED_sim core model dsp mujoco)
set(EXOTWIN_ALLOWED_hwsim core model dsp protocol)
set(EXOTWIN_ALLOWED_formats core model dsp)
set(EXOTWIN_ALLOWED_identification core model dsp sim formats mujoco)
set(EXOTWIN_ALLOWED_diagnosis core model dsp sim formats mujoco)
set(EXOTWIN_ALLOWED_emg core model dsp sim formats diagnosis mujoco)
set(EXOTWIN_ALLOWED_render core mujoco opencv2)
set(EXOTWIN_ALLOWED_runner core model dsp protocol controller sim hwsim formats identification diagnosis emg
                           render mujoco)
set(EXOTWIN_ALLOWED_batch core model dsp protocol controller sim hwsim formats identification diagnosis emg render
                          runner mujoco)
set(EXOTWIN_ALLOWED_app core model dsp protocol controller sim hwsim formats identification diagnosis emg render
                        runner batch mujoco)
set(EXOTWIN_ALLOWED_python core model dsp protocol controller sim hwsim formats identification diagnosis emg render
                           runner batch app mujoco)

# Fails (FATAL_ERROR) listing every forbidden include in the layer folders under `root`.
function(exotwin_check_layer_includes root)
  set(_judged ${EXOTWIN_LAYERS} ${EXOTWIN_GUARDED_LIBS})
  set(_bad "")
  foreach(layer ${EXOTWIN_LAYERS})
    if(NOT IS_DIRECTORY ${root}/${layer})
      continue()
    endif()
    file(GLOB_RECURSE _files ${root}/${layer}/*.h ${root}/${layer}/*.hpp ${root}/${layer}/*.cc
         ${root}/${layer}/*.cpp)
    foreach(f ${_files})
      file(STRINGS ${f} _lines REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"][A-Za-z0-9_]+/")
      foreach(line ${_lines})
        string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*[<\"]([A-Za-z0-9_]+)/.*" "\\1" _dir "${line}")
        if(NOT _dir IN_LIST _judged OR _dir STREQUAL layer OR _dir IN_LIST EXOTWIN_ALLOWED_${layer})
          continue()
        endif()
        file(RELATIVE_PATH _rel ${root} ${f})
        string(STRIP "${line}" line)
        string(REPLACE ";" " " _may "${EXOTWIN_ALLOWED_${layer}}")
        if(_may STREQUAL "")
          set(_may "no other layer")
        endif()
        string(APPEND _bad "\n  ${_rel}: ${line}  (${layer}/ may include ${_may})")
      endforeach()
    endforeach()
  endforeach()
  if(_bad)
    message(FATAL_ERROR "layer rule broken (cmake/check_layers.cmake, docs/ARCHITECTURE.md):${_bad}")
  endif()
endfunction()

# Targets of a layer, and the layer (or guarded library) of a link item ("" for anything else).
# render/ has three: the loader the others link, the renderer, and the plugin module that holds it
# (render/CMakeLists.txt); OpenCV is allowed in render/ only, so no other layer maps it.
function(_exotwin_layer_targets layer out)
  if(layer STREQUAL "app")
    set(${out} exotwin_cli PARENT_SCOPE)
  elseif(layer STREQUAL "python")
    set(${out} exotwin_python PARENT_SCOPE)
  elseif(layer STREQUAL "render")
    set(${out} exotwin_render exotwin_render_gl exotwin_render_plugin PARENT_SCOPE)
  else()
    set(${out} exotwin_${layer} PARENT_SCOPE)
  endif()
endfunction()
function(_exotwin_link_family item out)
  string(REGEX REPLACE "^\\$<LINK_ONLY:(.*)>$" "\\1" item "${item}")
  set(_f "")
  if(item STREQUAL "exotwin_cli")
    set(_f app)
  elseif(item MATCHES "^exotwin_([a-z]+)(_gl|_plugin)?$")
    if(CMAKE_MATCH_1 IN_LIST EXOTWIN_LAYERS)
      set(_f ${CMAKE_MATCH_1})
    endif()
  elseif(item MATCHES "^mujoco")
    set(_f mujoco)
  elseif(item MATCHES "^opencv_")
    set(_f opencv2)
  endif()
  set(${out} "${_f}" PARENT_SCOPE)
endfunction()

# After every layer's add_subdirectory: fails if a layer's target links (directly or through its
# dependencies' public links) a layer or guarded library its row above does not allow.
function(exotwin_check_layer_links)
  set(_bad "")
  foreach(layer ${EXOTWIN_LAYERS})
    _exotwin_layer_targets(${layer} _targets)
    foreach(_target ${_targets})
      if(NOT TARGET ${_target})
        continue()
      endif()
      get_target_property(_todo ${_target} LINK_LIBRARIES)
      set(_seen "")
      set(_families "")
      while(_todo)
        list(POP_FRONT _todo _item)
        string(REGEX REPLACE "^\\$<LINK_ONLY:(.*)>$" "\\1" _item "${_item}")
        if(_item IN_LIST _seen)
          continue()
        endif()
        list(APPEND _seen ${_item})
        _exotwin_link_family("${_item}" _f)
        if(_f AND NOT _f STREQUAL layer)
          list(APPEND _families ${_f})
        endif()
        if(TARGET ${_item})
          get_target_property(_imported ${_item} IMPORTED)
          get_target_property(_next ${_item} INTERFACE_LINK_LIBRARIES)
          if(_next AND NOT _imported)
            list(APPEND _todo ${_next})
          endif()
        endif()
      endwhile()
      list(REMOVE_DUPLICATES _families)
      foreach(f ${_families})
        if(NOT f IN_LIST EXOTWIN_ALLOWED_${layer})
          string(APPEND _bad "\n  ${_target} links ${f}, which ${layer}/ may not include")
        endif()
      endforeach()
    endforeach()
  endforeach()
  if(_bad)
    message(FATAL_ERROR "layer links and cmake/check_layers.cmake's table disagree:${_bad}")
  endif()
endfunction()

if(CMAKE_SCRIPT_MODE_FILE STREQUAL CMAKE_CURRENT_LIST_FILE)
  if(NOT ROOT)
    message(FATAL_ERROR "usage: cmake -DROOT=<source tree> -P check_layers.cmake")
  endif()
  get_filename_component(ROOT ${ROOT} ABSOLUTE)
  exotwin_check_layer_includes(${ROOT})
  message(STATUS "layer rule holds in ${ROOT}")
else()
  exotwin_check_layer_includes(${CMAKE_SOURCE_DIR})
endif()
