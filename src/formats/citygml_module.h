// Internal to the formats library: the CityGML reader's libcitygml part lives in a module,
// lodrefine_citygml.so (src/formats/citygml_module/), loaded with dlopen only when a CityGML file is
// read. libcitygml brings Xerces-C, GDAL and ~110 shared libraries whose symbol relocations cost
// every process start ~0.1 s, CityGML or not; lodrefine runs once per building over districts.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "lodrefine/version.h"

#define LODREFINE_CITYGML_STR2(x) #x
#define LODREFINE_CITYGML_STR(x) LODREFINE_CITYGML_STR2(x)

namespace lodrefine::io_citygml {

// The module's file name. It is looked for only beside the running executable (/proc/self/exe:
// the build tree) and in <that folder>/LODREFINE_CITYGML_MODULE_RELDIR (installed: ../lib/lodrefine),
// by absolute path: never through LD_LIBRARY_PATH, the current folder or a path a user gives.
inline constexpr const char* kModuleName = "lodrefine_citygml.so";

// The entry point passes C++ objects, so the loader takes only a module built from the same
// version against the same nlohmann_json and C++ library ABI.
inline constexpr const char* kAbiTag =
    "lodrefine " LODREFINE_VERSION " nlohmann_json " LODREFINE_CITYGML_STR(NLOHMANN_JSON_VERSION_MAJOR) "." LODREFINE_CITYGML_STR(
        NLOHMANN_JSON_VERSION_MINOR) "." LODREFINE_CITYGML_STR(NLOHMANN_JSON_VERSION_PATCH) " cxx11abi " LODREFINE_CITYGML_STR(_GLIBCXX_USE_CXX11_ABI);

enum Status : int { kOk = 0, kInputError = 1, kFailure = 2, kOutOfMemory = 3 };

// Buildings whose gml:id was given before: (the gml:id, the id written instead).
using RenamedIds = std::vector<std::pair<std::string, std::string>>;

}  // namespace lodrefine::io_citygml

// The module's entry points, with C linkage so that dlsym finds them by these names.
extern "C" {
// The module's lodrefine::io_citygml::kAbiTag.
const char* lodrefine_citygml_abi();
// The buildings of the CityGML document `text` (read from `path`, already passed through
// io_xml::safe_citygml_text; emptied on return) as a CityJSON 2.0 document in `doc` (what
// citygml_to_cityjson documents; `crs_url` becomes metadata.referenceSystem unless empty),
// with the renamed ids in `renamed`. Returns kOk, or kInputError (the file's fault),
// kOutOfMemory (also when libcitygml or Xerces swallowed it) or kFailure (anything else) with a
// one-line message in `error`. Throws nothing.
int lodrefine_citygml_to_cityjson(const char* path, std::string* text, const char* crs_url, nlohmann::ordered_json* doc,
                                  lodrefine::io_citygml::RenamedIds* renamed, std::string* error);
}

namespace lodrefine::io_citygml {

// lodrefine_citygml_to_cityjson through the module, loaded on the first call (thread-safe; it
// stays loaded). Throws InputError "<path>: CityGML input is unavailable: ..." (one line, with
// the module's path) when the module is missing or does not load, and InputError / runtime_error
// with the module's message when the conversion fails (out of memory: a runtime_error naming
// the file). Memory running out while the module's libraries initialise (inside dlopen, where an
// exception ends in std::terminate) ends the process with one line naming the file, exit 3.
void to_cityjson(const std::string& path, std::string& text, const std::string& crs_url, nlohmann::ordered_json& doc,
                 RenamedIds& renamed);

}  // namespace lodrefine::io_citygml
