# CTest ReadmeParams: the README's parameter tables (between the params:begin/end markers) are
# exactly what `lodrefine params --markdown` prints, so the docs follow the table in params.h.
# cmake -DBIN=path/to/lodrefine -DREADME=path/to/README.md -P check_readme_params.cmake
execute_process(COMMAND ${BIN} params --markdown OUTPUT_VARIABLE generated RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "lodrefine params --markdown failed (${rc})")
endif()
file(READ ${README} readme)
set(begin "<!-- params:begin (lodrefine params --markdown) -->\n")
set(end "<!-- params:end -->")
string(FIND "${readme}" "${begin}" b)
string(FIND "${readme}" "${end}" e)
if(b LESS 0 OR e LESS b)
  message(FATAL_ERROR "README.md has no params:begin/params:end markers")
endif()
string(LENGTH "${begin}" blen)
math(EXPR start "${b} + ${blen}")
math(EXPR len "${e} - ${start}")
string(SUBSTRING "${readme}" ${start} ${len} documented)
if(NOT documented STREQUAL generated)
  message(FATAL_ERROR "README.md's parameter table differs from `lodrefine params --markdown`; "
                      "paste its output between the markers.\n--- README:\n${documented}\n--- generated:\n${generated}")
endif()
