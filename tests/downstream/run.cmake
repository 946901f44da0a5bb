# Install empm from BUILD_DIR into a fresh prefix, then configure, build and run the downstream
# project against it. Invoked by CTest (test install_downstream).
set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix}
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "cmake --install failed")
endif()
foreach(f lib/cmake/empm/empmConfig.cmake lib/cmake/empm/empmConfigVersion.cmake
          lib/pkgconfig/empm.pc include/empm/empm.mod bin/empm)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "installed package lacks ${f}")
  endif()
endforeach()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build -G Ninja
                -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_Fortran_COMPILER=${Fortran_COMPILER}
                RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring the downstream project failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building the downstream project failed")
endif()
execute_process(COMMAND ${WORK_DIR}/build/downstream RESULT_VARIABLE rc OUTPUT_VARIABLE out)
message(STATUS "${out}")
if(rc)
  message(FATAL_ERROR "the downstream program failed")
endif()
# The pkg-config file must resolve relative to its own location (relocatable prefix).
execute_process(COMMAND ${CMAKE_COMMAND} -E env PKG_CONFIG_PATH=${prefix}/lib/pkgconfig
                pkg-config --cflags empm RESULT_VARIABLE rc OUTPUT_VARIABLE pc)
string(STRIP "${pc}" pc)
string(REGEX REPLACE "^-I" "" incdir "${pc}")
if(rc OR NOT EXISTS "${incdir}/empm.mod")
  message(FATAL_ERROR "pkg-config --cflags empm gave '${pc}', which lacks empm.mod")
endif()
