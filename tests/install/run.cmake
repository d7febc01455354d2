# CTest `install`: installs the build tree into a fresh prefix, then configures, builds and runs
# tests/install/consumer against it with find_package(lodrefine), and reads CityGML with the
# installed app. Catches a package that no longer installs a header, exports a target, finds a
# dependency or installs the CityGML module where the app looks for it.
# The consumer asks for the version built (VERSION, project(VERSION)): the package's version file
# accepts the same minor version only (SameMinorVersion: before 1.0 a minor release may break).
#   cmake -DBUILD=<build dir> -DSOURCE=<source dir> -DWORK=<scratch dir> -DVERSION=<x.y.z> -P tests/install/run.cmake
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "install test: ${what} failed (${rc}):\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

run("install" ${CMAKE_COMMAND} --install ${BUILD} --prefix ${WORK}/prefix)
foreach(f include/lodrefine/version.h include/lodrefine/base/types.h include/lodrefine/laz/laz_write.h
          include/lodrefine/formats/obj.h include/lodrefine/core/validate.h include/lodrefine/refine/refine.h
          include/lodrefine/city/cityfile.h
          include/lodrefine/eval/eval.h include/lodrefine/tools/report.h lib/cmake/lodrefine/lodrefineConfig.cmake
          bin/lodrefine)
  if(NOT EXISTS ${WORK}/prefix/${f})
    message(FATAL_ERROR "install test: ${f} not installed")
  endif()
endforeach()
if(EXISTS ${WORK}/prefix/include/lodrefine/synth)
  message(FATAL_ERROR "install test: the synth headers are installed, their library is not")
endif()
run("configure the consumer" ${CMAKE_COMMAND} -S ${SOURCE}/tests/install/consumer -B ${WORK}/build
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${WORK}/prefix -DLODREFINE_WANTED=${VERSION})
run("build the consumer" ${CMAKE_COMMAND} --build ${WORK}/build)
run("run the consumer" ${WORK}/build/consumer ${WORK}/box.obj)
# formats, core and eval link no GLPK: only the selection (refine) and tools do.
file(GET_RUNTIME_DEPENDENCIES EXECUTABLES ${WORK}/build/consumer RESOLVED_DEPENDENCIES_VAR resolved
     UNRESOLVED_DEPENDENCIES_VAR unresolved)
foreach(dep ${resolved} ${unresolved})
  if(dep MATCHES "glpk")
    message(FATAL_ERROR "install test: a program linking formats, core and eval loads GLPK (${dep})")
  endif()
endforeach()
message(STATUS "${last_output}")
if(NOT last_output MATCHES "^lodrefine ${VERSION}:")
  message(FATAL_ERROR "install test: the installed version.h does not say ${VERSION}:\n${last_output}")
endif()
# The installed app finds its CityGML module (<libdir>/lodrefine/, relative to bin/).
run("convert CityGML with the installed app" ${WORK}/prefix/bin/lodrefine convert
    --citygml ${SOURCE}/tests/fuzz/corpus/fuzz_citygml/thematic.gml --out-dir ${WORK}/citygml)
if(NOT EXISTS ${WORK}/citygml/t.obj)
  message(FATAL_ERROR "install test: the installed app did not convert CityGML:\n${last_output}")
endif()
