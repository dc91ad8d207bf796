# The package test (ctest -R package; tests/package/CMakeLists.txt runs it in three steps):
#   STEP=install      cmake --install the build tree into PREFIX (emptied first), write the tone
#                     files and an HDF5 copy of one (made by the installed geardiag command)
#   STEP=find_package configure and build tests/package/consumer against PREFIX with
#                     find_package(geardiag) and run it on every tone file
#   STEP=pkg_config   compile the same main.cpp with `pkg-config --cflags --libs geardiag` alone
#   STEP=cleanup      remove all of it (the installed tree is some 400 MB with debug information)
# The consumer prints the PSD's bin count and the frequency of its largest bin: 129 bins
# (nperseg 256) and the tone's frequency, which make_tones.py puts exactly on a bin.
cmake_minimum_required(VERSION 3.22)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    string(REPLACE ";" " " cmd "${ARGN}")
    message(FATAL_ERROR "failed (${rc}): ${cmd}\n${out}\n${err}")
  endif()
  set(run_output "${out}" PARENT_SCOPE)
endfunction()

# Runs a consumer program on each tone file and checks what it prints.
function(check_consumer exe)
  foreach(case "tone_125hz.csv=125" "tone_1000hz.wav=1000" "tone_125hz.h5=125")
    string(REPLACE "=" ";" case "${case}")
    list(GET case 0 file)
    list(GET case 1 peak_hz)
    run(${exe} ${WORK}/data/${file})
    message(STATUS "${file}:\n${run_output}")
    if(NOT run_output MATCHES "psd: 129 bins, [0-9]+ segments, peak at ${peak_hz} Hz")
      message(FATAL_ERROR "${file}: expected 129 bins and the peak at ${peak_hz} Hz, got:\n"
                          "${run_output}")
    endif()
  endforeach()
endfunction()

set(PREFIX ${WORK}/prefix)
if(STEP STREQUAL "install")
  file(REMOVE_RECURSE ${WORK})
  run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${PREFIX})
  foreach(installed bin/geardiag include/geardiag/geardiag.hpp include/diag/io/recording.hpp
                    include/detect/spectral/welch.hpp include/sim/dynamics/simulate.hpp)
    if(NOT EXISTS ${PREFIX}/${installed})
      message(FATAL_ERROR "cmake --install: no ${installed} under ${PREFIX}")
    endif()
  endforeach()
  run(${PYTHON} ${SOURCE_DIR}/make_tones.py ${WORK}/data)
  run(${PREFIX}/bin/geardiag import ${WORK}/data/tone_125hz.csv -o ${WORK}/data/tone_125hz.h5)
elseif(STEP STREQUAL "find_package")
  run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/consumer -B ${WORK}/consumer -G ${GENERATOR}
      -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER}
      -DCMAKE_PREFIX_PATH=${PREFIX})
  run(${CMAKE_COMMAND} --build ${WORK}/consumer)
  check_consumer(${WORK}/consumer/consumer)
  # detect::analyze_file and report::to_json from the installed package: the report of the
  # 125 Hz tone has its findings list and a spectral peak at 125 Hz (on a bin: 2048 samples).
  run(${WORK}/consumer/analyze ${WORK}/data/tone_125hz.h5)
  if(NOT run_output MATCHES "\"findings\": \\[" OR
     NOT run_output MATCHES "\"frequency_hz\": 125\\.0")
    message(FATAL_ERROR "analyze: no findings list or no peak at 125 Hz in:\n${run_output}")
  endif()
elseif(STEP STREQUAL "pkg_config")
  set(ENV{PKG_CONFIG_PATH} ${PREFIX}/${LIBDIR}/pkgconfig)
  run(${PKG_CONFIG} --cflags --libs geardiag)
  separate_arguments(flags UNIX_COMMAND "${run_output}")
  if(LAUNCHER)
    set(compiler ${LAUNCHER} ${CXX})
  else()
    set(compiler ${CXX})
  endif()
  run(${compiler} -Wall -Wextra -Werror ${SOURCE_DIR}/consumer/main.cpp -o ${WORK}/consumer_pc
      ${flags})
  check_consumer(${WORK}/consumer_pc)
elseif(STEP STREQUAL "cleanup")
  file(REMOVE_RECURSE ${WORK})
else()
  message(FATAL_ERROR
          "check_package.cmake: STEP=${STEP}: not install, find_package, pkg_config or cleanup")
endif()
