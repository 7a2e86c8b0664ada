# The API reference: target `doc` (not part of ALL) runs Doxygen on the public
# headers, with the README as main page, docs/*.md as related pages and the
# tutorials as examples; HTML in <build>/doc/html/index.html. A public symbol
# without documentation fails the target (cmake/Doxyfile.in). Without
# doxygen the target does not exist.
find_package(Doxygen)
if(NOT DOXYGEN_FOUND)
  message(STATUS "Doxygen not found: no target `doc` (API reference; apt-get install doxygen)")
  return()
endif()

set(OFV_DOC_OUTPUT_DIR ${PROJECT_BINARY_DIR}/doc)
configure_file(${PROJECT_SOURCE_DIR}/cmake/Doxyfile.in ${PROJECT_BINARY_DIR}/Doxyfile @ONLY)
add_custom_target(doc
  COMMAND ${CMAKE_COMMAND} -E make_directory ${OFV_DOC_OUTPUT_DIR}
  COMMAND Doxygen::doxygen ${PROJECT_BINARY_DIR}/Doxyfile
  WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
  COMMENT "API reference (Doxygen): ${OFV_DOC_OUTPUT_DIR}/html/index.html"
  VERBATIM)
