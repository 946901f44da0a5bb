# docs/embedding.md shows the tested host programs verbatim (CTest capi_docs_examples): each
# file in FILES must appear in DOC as a whole.
file(READ ${DOC} doc)
foreach(f IN LISTS FILES)
  file(READ ${f} text)
  string(FIND "${doc}" "${text}" at)
  if(at LESS 0)
    message(FATAL_ERROR "${DOC} does not show ${f} as it is: copy it into the page again")
  endif()
endforeach()
