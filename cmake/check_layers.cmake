# The libraries' dependency rule (ARCHITECTURE.md), checked on the includes: each library
# includes only its own headers and those of the libraries beneath it; base, laz and formats
# include no CGAL or GLPK header (reading a file needs neither), and GLPK is refine's (the
# selection) and tools' (the PolyFit baseline) alone, so eval and core link without it. Run by
# CTest as `layering`.
#   cmake -DROOT=<source dir> -P cmake/check_layers.cmake
set(allowed_base "base")
set(allowed_laz "base|laz")
set(allowed_formats "base|laz|formats")
set(allowed_core "base|core")
set(allowed_refine "base|core|refine")
set(allowed_city "base|laz|formats|core|refine|city")
set(allowed_eval "base|core|eval")
set(allowed_synth "base|laz|formats|core|refine|city|synth")
set(allowed_tools "base|laz|formats|core|refine|city|eval|tools")
set(no_cgal "^(base|laz|formats)$")
set(no_glpk "^(base|laz|formats|core|city|eval|synth)$")
set(problems "")
# Each line of file `f` (library `lib`, path `rel`) matching `regex` is a problem: `what` it does.
function(refuse_lines regex what)
  file(STRINGS ${f} matched REGEX "${regex}")
  foreach(line ${matched})
    string(STRIP "${line}" line)
    string(APPEND problems "  ${rel}: the ${lib} library ${what} (${line})\n")
  endforeach()
  set(problems "${problems}" PARENT_SCOPE)
endfunction()
foreach(lib base laz formats core refine city eval synth tools)
  file(GLOB_RECURSE files ${ROOT}/src/${lib}/*.cpp ${ROOT}/src/${lib}/*.h ${ROOT}/include/lodrefine/${lib}/*.h)
  if(NOT files)
    string(APPEND problems "  the ${lib} library has no files (src/${lib}/, include/lodrefine/${lib}/)\n")
  endif()
  foreach(f ${files})
    file(RELATIVE_PATH rel ${ROOT} ${f})
    file(STRINGS ${f} includes REGEX "#include \"lodrefine/[a-z]+/")
    foreach(line ${includes})
      string(REGEX REPLACE ".*#include \"lodrefine/([a-z]+)/.*" "\\1" dep "${line}")
      if(NOT dep MATCHES "^(${allowed_${lib}})$")
        string(APPEND problems "  ${rel}: the ${lib} library includes ${dep}\n")
      endif()
    endforeach()
    if(lib MATCHES "${no_cgal}")
      refuse_lines("#[ \t]*include[ \t]*[<\"]CGAL/" "includes a CGAL header")  # GLPK: no_glpk below
    endif()
    if(lib MATCHES "${no_glpk}")
      refuse_lines("#[ \t]*include[ \t]*[<\"](glpk\\.h|CGAL/GLPK)|glp_[a-z_]+[ \t]*\\("
                   "uses GLPK, which only refine and tools link")
    endif()
  endforeach()
endforeach()
if(problems)
  message(FATAL_ERROR "layering broken:\n${problems}")
endif()
message(STATUS "layering: base <- laz <- formats; base <- core <- refine; refine + formats <- city; core <- eval; "
               "city <- synth; eval + city <- tools; all <- apps; no CGAL or GLPK in base, laz, formats; "
               "GLPK in refine and tools only")
