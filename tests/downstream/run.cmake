# Install empm from BUILD_DIR into a fresh prefix, then build and run two downstream projects
# against it: core/ (find_package(empm), empm::empm) with FFTW and LAPACK made unfindable, so
# that the core package is shown to need neither, and full/ (COMPONENTS analysis verify).
# Also checks the pkg-config files. Invoked by CTest (test install_downstream).
set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix}
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(rc)
  message(FATAL_ERROR "cmake --install failed")
endif()
foreach(f lib/cmake/empm/empmConfig.cmake lib/cmake/empm/empmConfigVersion.cmake
          lib/cmake/empm/empmTargets.cmake lib/cmake/empm/empmAnalysisTargets.cmake
          lib/cmake/empm/empmVerifyTargets.cmake lib/pkgconfig/empm.pc
          lib/pkgconfig/empm-analysis.pc lib/pkgconfig/empm-verify.pc include/empm/empm.mod
          include/empm/empm_analysis.mod bin/empm)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "installed package lacks ${f}")
  endif()
endforeach()

function(build_and_run name)
  cmake_parse_arguments(B "" "" "CONFIGURE_ENV;CONFIGURE_ARGS" ${ARGN})
  set(bdir ${WORK_DIR}/${name})
  execute_process(COMMAND ${CMAKE_COMMAND} -E env ${B_CONFIGURE_ENV}
                  ${CMAKE_COMMAND} -S ${SOURCE_DIR}/${name} -B ${bdir} -G Ninja
                  -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_Fortran_COMPILER=${Fortran_COMPILER}
                  ${B_CONFIGURE_ARGS}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(rc)
    message(FATAL_ERROR "configuring the downstream project ${name} failed:\n${out}")
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} --build ${bdir} RESULT_VARIABLE rc
                  OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(rc)
    message(FATAL_ERROR "building the downstream project ${name} failed:\n${out}")
  endif()
  execute_process(COMMAND ${bdir}/downstream RESULT_VARIABLE rc OUTPUT_VARIABLE out)
  message(STATUS "${out}")
  if(rc)
    message(FATAL_ERROR "the downstream program ${name} failed")
  endif()
  # The link line, for the callers' checks.
  execute_process(COMMAND ninja -C ${bdir} -t commands downstream OUTPUT_VARIABLE cmds)
  set(LINK_COMMANDS "${cmds}" PARENT_SCOPE)
endfunction()

# Core only: LAPACK disabled and no system pkg-config files (fftw3.pc) visible.
file(MAKE_DIRECTORY ${WORK_DIR}/no-pc)
build_and_run(core CONFIGURE_ENV PKG_CONFIG_LIBDIR=${WORK_DIR}/no-pc
              CONFIGURE_ARGS -DCMAKE_DISABLE_FIND_PACKAGE_LAPACK=ON)
string(TOLOWER "${LINK_COMMANDS}" cmds)
if(cmds MATCHES "fftw|lapack|blas|empm_analysis|empm_verify")
  message(FATAL_ERROR "the core-only consumer links more than the core:\n${LINK_COMMANDS}")
endif()
build_and_run(full)

# pkg-config files resolve relative to their own location (relocatable prefix) and give the
# module folder; the core file names neither FFTW nor LAPACK.
foreach(pc empm empm-analysis empm-verify)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env PKG_CONFIG_PATH=${prefix}/lib/pkgconfig
                  pkg-config --cflags ${pc} RESULT_VARIABLE rc OUTPUT_VARIABLE out)
  string(STRIP "${out}" out)
  string(REGEX REPLACE "^-I([^ ]*).*" "\\1" incdir "${out}")
  if(rc OR NOT EXISTS "${incdir}/empm.mod")
    message(FATAL_ERROR "pkg-config --cflags ${pc} gave '${out}', which lacks empm.mod")
  endif()
endforeach()
execute_process(COMMAND ${CMAKE_COMMAND} -E env PKG_CONFIG_PATH=${prefix}/lib/pkgconfig
                pkg-config --libs --static empm RESULT_VARIABLE rc OUTPUT_VARIABLE out)
string(TOLOWER "${out}" out)
if(rc OR out MATCHES "fftw|lapack" OR NOT out MATCHES "hdf5")
  message(FATAL_ERROR "pkg-config --libs --static empm gave '${out}'")
endif()
