# API documentation from the public headers (Doxygen, Debian `doxygen`): `cmake --build build
# --target docs` writes build/docs/api/html/index.html, with a page per module (docs/api/*.md).
# Only when doxygen is found; the test `api_docs` builds it into a scratch folder.
include_guard(GLOBAL)
find_package(Doxygen QUIET)
if(NOT DOXYGEN_FOUND)
  message(STATUS "doxygen not found: no 'docs' target (Debian package 'doxygen')")
  return()
endif()
set(IMPACTDECK_DOC_INPUTS "${PROJECT_SOURCE_DIR}/docs/api")
foreach(_m common collision geometry contact fem_export plot scene study)
  string(APPEND IMPACTDECK_DOC_INPUTS " ${PROJECT_SOURCE_DIR}/${_m}/include")
endforeach()
set(IMPACTDECK_DOC_OUTPUT "${PROJECT_BINARY_DIR}/docs/api")
configure_file(${PROJECT_SOURCE_DIR}/docs/api/Doxyfile.in ${PROJECT_BINARY_DIR}/docs/Doxyfile @ONLY)
add_custom_target(docs
  COMMAND ${CMAKE_COMMAND} -E make_directory ${IMPACTDECK_DOC_OUTPUT}
  COMMAND ${DOXYGEN_EXECUTABLE} ${PROJECT_BINARY_DIR}/docs/Doxyfile
  WORKING_DIRECTORY ${PROJECT_BINARY_DIR}
  COMMENT "API documentation (doxygen) -> ${IMPACTDECK_DOC_OUTPUT}/html/index.html"
  VERBATIM)
