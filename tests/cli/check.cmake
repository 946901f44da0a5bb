# Run one empm command line and check its exit status, its output and the files it leaves.
# -DEXE=... -DARGS="a;b" -DEXPECT_RC=n [-DEXPECT_REGEX=re] [-DEXPECT_FILE=f] [-DNO_FILE=f]
# [-DWORK_DIR=d]
if(WORK_DIR)
  file(MAKE_DIRECTORY ${WORK_DIR})
endif()
if(EXPECT_FILE)
  file(REMOVE ${EXPECT_FILE})
endif()
execute_process(COMMAND ${EXE} ${ARGS} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err WORKING_DIRECTORY ${WORK_DIR})
message(STATUS "exit status ${rc}\nstdout: ${out}\nstderr: ${err}")
if(NOT "${rc}" STREQUAL "${EXPECT_RC}")
  message(FATAL_ERROR "expected exit status ${EXPECT_RC}, got ${rc}")
endif()
if(EXPECT_REGEX AND NOT "${out}${err}" MATCHES "${EXPECT_REGEX}")
  message(FATAL_ERROR "output does not match '${EXPECT_REGEX}'")
endif()
if(EXPECT_FILE AND NOT EXISTS ${EXPECT_FILE})
  message(FATAL_ERROR "expected file ${EXPECT_FILE} is missing")
endif()
if(NO_FILE AND EXISTS ${NO_FILE})
  message(FATAL_ERROR "file ${NO_FILE} must not exist")
endif()
