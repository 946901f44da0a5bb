# Install empm from BUILD_DIR into a fresh prefix and build hosts against the installed tree
# with pkg-config only: the C host (cc) and the Fortran 77 and modern Fortran hosts (gfortran),
# each linked shared (`pkg-config --libs empm`) and static (`pkg-config --libs --static
# empm-static`), then run. The static executables must not need libempm.so. Invoked by CTest
# (test capi_installed).
set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix}
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(rc)
  message(FATAL_ERROR "cmake --install failed")
endif()
foreach(f include/empm/empm.h lib/libempm.a lib/libempm.so lib/pkgconfig/empm.pc
          lib/pkgconfig/empm-static.pc)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "installed tree lacks ${f}")
  endif()
endforeach()

set(pcenv PKG_CONFIG_PATH=${prefix}/lib/pkgconfig)
function(pc out)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env ${pcenv} pkg-config ${ARGN}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE flags)
  if(rc)
    message(FATAL_ERROR "pkg-config ${ARGN} failed")
  endif()
  string(STRIP "${flags}" flags)
  separate_arguments(flags UNIX_COMMAND "${flags}")
  set(${out} ${flags} PARENT_SCOPE)
endfunction()

# --static of the shared package: HDF5 where CMake found it, OpenMP and the Fortran runtime.
pc(static_libs --libs --static empm)
string(REPLACE ";" " " s "${static_libs}")
if(NOT s MATCHES "hdf5" OR NOT s MATCHES "gomp|fopenmp" OR NOT s MATCHES "gfortran")
  message(FATAL_ERROR "pkg-config --libs --static empm lacks HDF5, OpenMP or gfortran: ${s}")
endif()

pc(cflags --cflags empm)
pc(libs_shared --libs empm)
pc(libs_static --libs --static empm-static)
foreach(kind shared static)
  foreach(host c f77 f90)
    if(host STREQUAL "c")
      set(cmd ${C_COMPILER} -std=c99 ${C_HOST} ${cflags} ${libs_${kind}} -lm)
    elseif(host STREQUAL "f77")
      # no module folder for the legacy host: the libraries only
      set(cmd ${Fortran_COMPILER} -std=legacy ${F77_HOST} ${libs_${kind}})
    else()
      set(cmd ${Fortran_COMPILER} ${F90_HOST} ${cflags} ${libs_${kind}})
    endif()
    set(exe ${WORK_DIR}/${host}_${kind})
    execute_process(COMMAND ${cmd} -o ${exe} WORKING_DIRECTORY ${WORK_DIR}
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
    if(rc)
      string(REPLACE ";" " " c "${cmd}")
      message(FATAL_ERROR "building the ${host} host (${kind}) failed:\n${c}\n${out}")
    endif()
    execute_process(COMMAND ${CMAKE_COMMAND} -E env LD_LIBRARY_PATH=${prefix}/lib ${exe}
                    WORKING_DIRECTORY ${WORK_DIR} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                    ERROR_VARIABLE out)
    if(rc)
      message(FATAL_ERROR "the ${host} host (${kind}) failed:\n${out}")
    endif()
    execute_process(COMMAND readelf -d ${exe} OUTPUT_VARIABLE dyn)
    if(kind STREQUAL "static" AND dyn MATCHES "libempm")
      message(FATAL_ERROR "the static ${host} host needs a shared libempm:\n${dyn}")
    elseif(kind STREQUAL "shared" AND NOT dyn MATCHES "libempm")
      message(FATAL_ERROR "the shared ${host} host does not use libempm.so:\n${dyn}")
    endif()
    message(STATUS "${host} host, ${kind}: ok")
  endforeach()
endforeach()
