# `cmake --install`: the geardiag command, the static libraries, their headers, an umbrella
# header <geardiag/geardiag.hpp>, a CMake package (find_package(geardiag) -> geardiag::<library>)
# and a pkg-config file geardiag.pc. Included at the end of the top-level CMakeLists.txt, after
# every target exists. docs/install.md is the user's side of this file.
#
# Which libraries are exported: GEARDIAG_EXPORTED_LIBRARIES below. A library added to it needs
# nothing else here: its public include folders are installed as they are (so that
# "diag/io/recording.hpp" stays "diag/io/recording.hpp"), its headers join the umbrella header,
# and its link dependencies are recreated by the package config (cmake/geardiagConfig.cmake.in;
# a new external dependency is added there and to geardiag.pc.in).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(GEARDIAG_EXPORTED_LIBRARIES diag sim detect)
# The report writers, when the tree has them as a library of their own.
if(TARGET report)
  list(APPEND GEARDIAG_EXPORTED_LIBRARIES report)
endif()

set(GEARDIAG_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/geardiag)
set(GEARDIAG_UMBRELLA_DIR ${CMAKE_BINARY_DIR}/generated/include)

# Every exported library's public include folders. The targets name them by absolute source
# paths, which only the build tree may see: they are wrapped in $<BUILD_INTERFACE:...> here, and
# the installed targets see ${prefix}/include instead (install(TARGETS ... INCLUDES DESTINATION)).
set(GEARDIAG_PUBLIC_INCLUDE_DIRS)
foreach(lib IN LISTS GEARDIAG_EXPORTED_LIBRARIES)
  get_target_property(dirs ${lib} INTERFACE_INCLUDE_DIRECTORIES)
  set(wrapped)
  foreach(dir IN LISTS dirs)
    if(dir MATCHES "^\\$<" OR NOT IS_ABSOLUTE "${dir}")
      list(APPEND wrapped "${dir}")  # already a generator expression, or relative
    else()
      list(APPEND wrapped "$<BUILD_INTERFACE:${dir}>")
      list(APPEND GEARDIAG_PUBLIC_INCLUDE_DIRS "${dir}")
    endif()
  endforeach()
  set_target_properties(${lib} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${wrapped}"
                                          # libgeardiag_diag.a, not a bare libdiag.a in lib/
                                          OUTPUT_NAME geardiag_${lib}
                                          EXPORT_NAME ${lib})
endforeach()
list(REMOVE_DUPLICATES GEARDIAG_PUBLIC_INCLUDE_DIRS)

# The umbrella header: every public header, in a stable (sorted) order. Written at configure
# time from the header folders; CONFIGURE_DEPENDS re-runs the glob when a header is added.
set(GEARDIAG_PUBLIC_HEADERS)
foreach(dir IN LISTS GEARDIAG_PUBLIC_INCLUDE_DIRS)
  file(GLOB_RECURSE headers CONFIGURE_DEPENDS RELATIVE ${dir} ${dir}/*.hpp ${dir}/*.h)
  list(APPEND GEARDIAG_PUBLIC_HEADERS ${headers})
  install(DIRECTORY ${dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
          FILES_MATCHING PATTERN "*.hpp" PATTERN "*.h")
endforeach()
list(SORT GEARDIAG_PUBLIC_HEADERS)
set(GEARDIAG_UMBRELLA_INCLUDES "")
foreach(header IN LISTS GEARDIAG_PUBLIC_HEADERS)
  string(APPEND GEARDIAG_UMBRELLA_INCLUDES "#include \"${header}\"\n")
endforeach()
configure_file(${CMAKE_SOURCE_DIR}/cmake/geardiag.hpp.in
               ${GEARDIAG_UMBRELLA_DIR}/geardiag/geardiag.hpp @ONLY)
install(FILES ${GEARDIAG_UMBRELLA_DIR}/geardiag/geardiag.hpp
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/geardiag)

# The installed command keeps the run paths of shared libraries found outside the system's
# folders (a dependency built under /opt, say); the system's need none.
set_target_properties(geardiag PROPERTIES INSTALL_RPATH_USE_LINK_PATH ON)
install(TARGETS geardiag RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS ${GEARDIAG_EXPORTED_LIBRARIES}
        EXPORT geardiagTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT geardiagTargets NAMESPACE geardiag:: DESTINATION ${GEARDIAG_INSTALL_CMAKEDIR})

# The package config: the dependencies the build found, found again for the user.
if(LIBDEFLATE_FOUND)
  set(GEARDIAG_PACKAGE_LIBDEFLATE ON)
else()
  set(GEARDIAG_PACKAGE_LIBDEFLATE OFF)
endif()
configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/geardiagConfig.cmake.in
                              ${CMAKE_BINARY_DIR}/generated/geardiagConfig.cmake
                              INSTALL_DESTINATION ${GEARDIAG_INSTALL_CMAKEDIR})
# 0.x: a new minor version may change the API.
write_basic_package_version_file(${CMAKE_BINARY_DIR}/generated/geardiagConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/generated/geardiagConfig.cmake
              ${CMAKE_BINARY_DIR}/generated/geardiagConfigVersion.cmake
        DESTINATION ${GEARDIAG_INSTALL_CMAKEDIR})

# geardiag.pc. The libraries are static only, so their dependencies go into Requires (not
# Requires.private): a plain `pkg-config --libs geardiag` links. The prefix is found from the
# file's own place (${pcfiledir}), so that `cmake --install --prefix ANY` gives a working file.
set(GEARDIAG_PC_REQUIRES "nlohmann_json >= 3, eigen3 >= 3.3, gsl, fftw3, sndfile, matio, zlib")
pkg_check_modules(GEARDIAG_PC_HDF5 QUIET hdf5)
if(GEARDIAG_PC_HDF5_FOUND)
  string(APPEND GEARDIAG_PC_REQUIRES ", hdf5")
  set(GEARDIAG_PC_EXTRA_LIBS "")
else()
  # No hdf5.pc: the libraries FindHDF5 found, by path.
  list(JOIN HDF5_C_LIBRARIES " " GEARDIAG_PC_EXTRA_LIBS)
endif()
if(LIBDEFLATE_FOUND)
  string(APPEND GEARDIAG_PC_REQUIRES ", libdeflate")
endif()
# Link order: a library before the ones it uses (report and detect use diag, as sim does).
set(GEARDIAG_PC_LIBS "")
foreach(lib IN ITEMS report detect sim diag)
  if(lib IN_LIST GEARDIAG_EXPORTED_LIBRARIES)
    string(APPEND GEARDIAG_PC_LIBS " -lgeardiag_${lib}")
  endif()
endforeach()
foreach(lib IN LISTS GEARDIAG_EXPORTED_LIBRARIES)
  if(NOT lib MATCHES "^(report|detect|sim|diag)$")
    message(FATAL_ERROR "cmake/GeardiagInstall.cmake: give ${lib} its place in the link order "
                        "of geardiag.pc (GEARDIAG_PC_LIBS)")
  endif()
endforeach()
file(RELATIVE_PATH GEARDIAG_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
string(REGEX REPLACE "/$" "" GEARDIAG_PC_TO_PREFIX "${GEARDIAG_PC_TO_PREFIX}")
configure_file(${CMAKE_SOURCE_DIR}/cmake/geardiag.pc.in ${CMAKE_BINARY_DIR}/generated/geardiag.pc
               @ONLY)
install(FILES ${CMAKE_BINARY_DIR}/generated/geardiag.pc
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# Everything `cmake --install` copies, built by one target (`make install` builds this one).
add_custom_target(install_targets DEPENDS geardiag ${GEARDIAG_EXPORTED_LIBRARIES})
