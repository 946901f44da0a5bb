# docs/input.md holds the key tables that `empm keys` generates from the declarations (between
# the markers "<!-- BEGIN empm keys -->" and "<!-- END empm keys -->"). Regenerate them with
# scripts/update-docs. Invoked by CTest (test docs_keys).
execute_process(COMMAND ${EXE} keys RESULT_VARIABLE rc OUTPUT_VARIABLE generated)
if(rc)
  message(FATAL_ERROR "empm keys failed (${rc})")
endif()
file(READ ${DOC} doc)
string(FIND "${doc}" "<!-- BEGIN empm keys -->\n" b)
string(FIND "${doc}" "<!-- END empm keys -->" e)
if(b LESS 0 OR e LESS 0)
  message(FATAL_ERROR "${DOC} lacks the markers of the generated key tables")
endif()
string(LENGTH "<!-- BEGIN empm keys -->\n" lb)
math(EXPR start "${b} + ${lb}")
math(EXPR len "${e} - ${start}")
string(SUBSTRING "${doc}" ${start} ${len} held)
if(NOT held STREQUAL generated)
  file(WRITE ${WORK}/keys.md "${generated}")
  message(FATAL_ERROR "the key tables in ${DOC} differ from the declarations: run "
          "scripts/update-docs (the generated text is in ${WORK}/keys.md)")
endif()
message(STATUS "docs/input.md key tables match the declarations")
