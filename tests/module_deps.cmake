# Objects of a higher layer depend on the module files of the layers below (Ninja dyndep), so
# that an incremental build recompiles them when a module there changes. `ninja -t query` lists
# an object's inputs once its dyndep file is loaded; each object named here must list a module
# of the core library.
# -DNINJA=... -DBUILD_DIR=... -DOBJECTS="a.o;b.o"
foreach(obj IN LISTS OBJECTS)
  execute_process(COMMAND ${NINJA} -C ${BUILD_DIR} -t query ${obj}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "ninja -t query ${obj} failed (${rc}): ${err}")
  endif()
  if(NOT out MATCHES "\\| mod/empm/empm_[a-z_]+\\.mod")
    message(FATAL_ERROR "${obj} does not depend on any module of the core library "
                        "(mod/empm/*.mod):\n${out}")
  endif()
  message(STATUS "${obj}: depends on core modules")
endforeach()
