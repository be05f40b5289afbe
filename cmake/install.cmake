# Installation, the Debian package and the build tree's data folder (included by the top-level
# CMakeLists.txt before the layers, so that the RPATH below applies to every target).
#
# Layout (P = the install prefix; the .deb uses P = /usr):
#   P/bin/                 the programs                 exotwin_install_programs(<target>...)
#   P/lib/exotwin/         private shared libraries and plugins (found through RPATH $ORIGIN/../lib/exotwin)
#                                                       exotwin_install_libraries(<target>...)
#   P/share/exotwin/       the data folder: mjcf/, data/, scenarios/ (+ baselines), examples/
# A program finds the data folder as <its folder>/../share/exotwin, or EXOTWIN_DATA_DIR
# (core/data_dir.h). The build tree has the same layout: build/share/exotwin/<folder> are symbolic
# links to the source folders, and every program of the build tree lives one folder below build/
# (build/app/exotwin, build/tests/tests_core, build/bench/...), so build/<x>/../share/exotwin is that
# folder and no program carries the source path.
include(GNUInstallDirs)

set(EXOTWIN_DATA_FOLDERS mjcf data scenarios examples)
set(EXOTWIN_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/exotwin)
set(EXOTWIN_INSTALL_PRIVATE_LIBDIR lib/exotwin)
set(CMAKE_INSTALL_RPATH "$ORIGIN/../${EXOTWIN_INSTALL_PRIVATE_LIBDIR}")
# cmake --install and cpack install the build tree as it is (build first): cpack then builds nothing.
set(CMAKE_SKIP_INSTALL_ALL_DEPENDENCY TRUE)

# The build tree's data folder: links, so edits of the source data are seen without reconfiguring.
file(MAKE_DIRECTORY ${CMAKE_BINARY_DIR}/share/exotwin)
foreach(folder ${EXOTWIN_DATA_FOLDERS})
  file(CREATE_LINK ${CMAKE_SOURCE_DIR}/${folder} ${CMAKE_BINARY_DIR}/share/exotwin/${folder} SYMBOLIC)
endforeach()

# One line per program or library: exotwin_install_programs(exotwin) in app/CMakeLists.txt.
function(exotwin_install_programs)
  install(TARGETS ${ARGN} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endfunction()
function(exotwin_install_libraries)
  install(TARGETS ${ARGN} LIBRARY DESTINATION ${EXOTWIN_INSTALL_PRIVATE_LIBDIR})
endfunction()

install(DIRECTORY ${EXOTWIN_DATA_FOLDERS} DESTINATION ${EXOTWIN_INSTALL_DATADIR})

# cpack -G DEB (run in the build folder, or cpack --config build/CPackConfig.cmake -B DIR).
# Dependencies: computed by dpkg-shlibdeps from the installed ELF files (the Debian packages of
# MuJoCo, yaml-cpp, OpenCV, OSMesa, libstdc++, ...), so the list follows what the programs link.
set(CPACK_PACKAGE_NAME exotwin)
set(CPACK_PACKAGE_VERSION 0.1.0)
set(CPACK_PACKAGE_CONTACT "exotwin maintainers <exotwin@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Digital twin of a leg wearing a rehabilitation exoskeleton (MuJoCo)")
set(CPACK_PACKAGE_DESCRIPTION
    "Headless scenarios with pass/fail checks, the controller against virtual CAN hardware, off-screen videos, identification and diagnosis against measured data.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# The Python module (P/lib/python3/dist-packages/exotwin, python/CMakeLists.txt) needs Debian's python3
# and numpy, which dpkg-shlibdeps does not see; the programs do not: recommended, not required.
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "python3, python3-numpy")
include(CPack)
