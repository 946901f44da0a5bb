# funit-lite: runs pFUnit .pf test files without pFUnit (see docs/testing.md).
#
# Included by tests/CMakeLists.txt when find_package(PFUNIT) fails. Defines
#
#   add_pfunit_ctest(<name> TEST_SOURCES <pf>... [OTHER_SOURCES <src>...]
#                    [LINK_LIBRARIES <lib>...] [MAX_PES <n>] [EXTRA_USE <module>]
#                    [EXTRA_INITIALIZE <subroutine>] [EXTRA_FINALIZE <subroutine>]
#                    [WORKING_DIRECTORY <dir>] [REGISTRY <file>])
#
# with the signature of pFUnit 4's function: each .pf is turned into plain Fortran by
# tests/funit_lite/funitproc_lite.py, a driver program runs every @test, and the executable
# <name> (linked with LINK_LIBRARIES and the support library empm_funit_lite, which provides
# the `funit` module) is registered as the CTest test <name>. Generated sources are compiled
# with the project's flags (empm_set_flags). Tests run serially: MAX_PES is accepted and
# ignored, as is REGISTRY (the suites are always <basename>_suite, as with pFUnit's default).
#
# Also defines empm_funit_lite_selftest(), which registers the runner's own failure-reporting
# checks and checks that the preprocessor rejects what pFUnit 4.x cannot build, and calls it
# when EMPM_BUILD_TESTS is on.

include_guard(GLOBAL)

find_package(Python3 COMPONENTS Interpreter REQUIRED)

# The support library (module `funit`), created once.
function(_empm_funit_lite_support_library)
  if(NOT TARGET empm_funit_lite)
    set(src_dir ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/../tests/funit_lite)
    set(mod_dir ${CMAKE_BINARY_DIR}/mod_funit_lite)
    add_library(empm_funit_lite STATIC ${src_dir}/funit.f90)
    set_target_properties(empm_funit_lite PROPERTIES Fortran_MODULE_DIRECTORY ${mod_dir})
    target_include_directories(empm_funit_lite PUBLIC $<BUILD_INTERFACE:${mod_dir}>)
    if(COMMAND empm_set_flags)
      empm_set_flags(empm_funit_lite)
    endif()
  endif()
endfunction()

function(add_pfunit_ctest test_package_name)
  set(options)
  set(one_value_args REGISTRY MAX_PES EXTRA_USE EXTRA_INITIALIZE EXTRA_FINALIZE
      WORKING_DIRECTORY)
  set(multi_value_args TEST_SOURCES OTHER_SOURCES LINK_LIBRARIES)
  cmake_parse_arguments(PF_TEST "${options}" "${one_value_args}" "${multi_value_args}"
                        ${ARGN})
  if(PF_TEST_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR
      "add_pfunit_ctest(${test_package_name}): unknown arguments ${PF_TEST_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT PF_TEST_TEST_SOURCES)
    message(FATAL_ERROR "add_pfunit_ctest(${test_package_name}): TEST_SOURCES is required")
  endif()
  if(PF_TEST_REGISTRY)
    message(WARNING "add_pfunit_ctest(${test_package_name}): funit-lite ignores REGISTRY")
  endif()

  _empm_funit_lite_support_library()
  set(script ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/../tests/funit_lite/funitproc_lite.py)
  get_filename_component(script ${script} ABSOLUTE)
  set(gen_dir ${CMAKE_CURRENT_BINARY_DIR}/funit_lite/${test_package_name})

  set(generated)
  set(modules)
  foreach(pf IN LISTS PF_TEST_TEST_SOURCES)
    get_filename_component(pf_abs ${pf} ABSOLUTE BASE_DIR ${CMAKE_CURRENT_SOURCE_DIR})
    get_filename_component(base ${pf} NAME_WE)
    set(f90 ${gen_dir}/${base}.F90)
    add_custom_command(
      OUTPUT ${f90}
      COMMAND ${Python3_EXECUTABLE} ${script} process ${pf_abs} ${f90}
      DEPENDS ${pf_abs} ${script}
      COMMENT "funit-lite: preprocessing ${base}.pf"
      VERBATIM)
    list(APPEND generated ${f90})
    list(APPEND modules ${base})
  endforeach()

  set(driver_args)
  if(PF_TEST_EXTRA_USE)
    list(APPEND driver_args --extra-use ${PF_TEST_EXTRA_USE})
  endif()
  if(PF_TEST_EXTRA_INITIALIZE)
    list(APPEND driver_args --extra-initialize ${PF_TEST_EXTRA_INITIALIZE})
  endif()
  if(PF_TEST_EXTRA_FINALIZE)
    list(APPEND driver_args --extra-finalize ${PF_TEST_EXTRA_FINALIZE})
  endif()
  set(driver ${gen_dir}/${test_package_name}_driver.f90)
  add_custom_command(
    OUTPUT ${driver}
    COMMAND ${Python3_EXECUTABLE} ${script} driver --output ${driver} ${driver_args}
            ${modules}
    DEPENDS ${script}
    COMMENT "funit-lite: writing the driver of ${test_package_name}"
    VERBATIM)

  add_executable(${test_package_name} ${generated} ${PF_TEST_OTHER_SOURCES} ${driver})
  set_target_properties(${test_package_name} PROPERTIES
    Fortran_MODULE_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/mod/${test_package_name})
  target_link_libraries(${test_package_name} PRIVATE ${PF_TEST_LINK_LIBRARIES} empm_funit_lite)
  if(COMMAND empm_set_flags)
    empm_set_flags(${test_package_name})
  endif()

  if(PF_TEST_WORKING_DIRECTORY)
    set(workdir ${PF_TEST_WORKING_DIRECTORY})
  else()
    set(workdir ${CMAKE_CURRENT_BINARY_DIR})
  endif()
  add_test(NAME ${test_package_name} COMMAND ${test_package_name}
           WORKING_DIRECTORY ${workdir})
endfunction()

# funit_lite_rejects_<case>: preprocessing tests/funit_lite/selftest/rejected_<case>.pf fails;
# funit_lite_rejects_<case>_message: its error message matches <regex>.
function(_empm_funit_lite_rejects case regex)
  set(script ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/../tests/funit_lite/funitproc_lite.py)
  get_filename_component(script ${script} ABSOLUTE)
  set(pf ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/../tests/funit_lite/selftest/rejected_${case}.pf)
  get_filename_component(pf ${pf} ABSOLUTE)
  set(out ${CMAKE_CURRENT_BINARY_DIR}/funit_lite/rejected/rejected_${case}.F90)
  foreach(test IN ITEMS funit_lite_rejects_${case} funit_lite_rejects_${case}_message)
    add_test(NAME ${test} COMMAND ${Python3_EXECUTABLE} ${script} process ${pf} ${out})
  endforeach()
  set_tests_properties(funit_lite_rejects_${case} PROPERTIES WILL_FAIL TRUE LABELS funit-lite)
  set_tests_properties(funit_lite_rejects_${case}_message PROPERTIES
    PASS_REGULAR_EXPRESSION "${regex}" LABELS funit-lite)
endfunction()

# The runner's own checks, funit-lite mode only: tests/funit_lite/selftest/failing_example.pf
# must fail (non-zero exit) and must report file, line, test, expected and actual values.
function(empm_funit_lite_selftest)
  set(pf ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/../tests/funit_lite/selftest/failing_example.pf)
  get_filename_component(pf ${pf} ABSOLUTE)
  add_pfunit_ctest(funit_lite_selftest TEST_SOURCES ${pf})
  set_tests_properties(funit_lite_selftest PROPERTIES WILL_FAIL TRUE LABELS funit-lite)

  # The exit code is ignored when PASS_REGULAR_EXPRESSION is set; '.' also matches newlines.
  # No ';' in the pattern (it would split it into a list of alternatives).
  string(CONCAT expected_output
    "failing_example\\.pf:12: test_integer_mismatch: expected 3 but found 4\n"
    "failing_example\\.pf:17: test_real_mismatch: expected 1\\.0000000000000000E\\+00 "
    "but found 1\\.5000000000000000E\\+00. difference 5\\.0000000000000000E-01 "
    "> tolerance 1\\.2500000000000000E-01\n"
    "failing_example\\.pf:25: test_array_mismatch: at index \\(3\\) of shape \\(4\\): "
    "expected 2\\.0000000000000000E\\+00 but found 2\\.5000000000000000E\\+00[^\n]*\n"
    "failing_example\\.pf:30: test_message: nodes: expected 7 but found 8\n"
    "failing_example\\.pf:36: test_stops_at_first_failure: expected \\.true\\. but found "
    "\\.false\\.\n"
    "1 passed, 5 failed\n")
  add_test(NAME funit_lite_selftest_output COMMAND funit_lite_selftest)
  # A failed assertion ends its test: the second assertion of a test must never report.
  set_tests_properties(funit_lite_selftest_output PROPERTIES
    PASS_REGULAR_EXPRESSION "${expected_output}"
    FAIL_REGULAR_EXPRESSION "failing_example\\.pf:37:|not reached"
    LABELS funit-lite)

  # Constructs pFUnit 4.x cannot build must be rejected by the preprocessor (non-zero exit),
  # with a message naming the file and line: rejected_<case>.pf, see docs/testing.md.
  _empm_funit_lite_rejects(continuation
    "rejected_continuation\\.pf:10: pFUnit 4\\.x requires @assertEqual on one line \\(no '&' continuation\\)")
  _empm_funit_lite_rejects(long_line
    "rejected_long_line\\.pf:11: directive line is 129 columns long, the limit is 128")
  _empm_funit_lite_rejects(module_comment
    "rejected_module_comment\\.pf:1: comment on the 'module' line")
endfunction()

if(EMPM_BUILD_TESTS)
  empm_funit_lite_selftest()
endif()
