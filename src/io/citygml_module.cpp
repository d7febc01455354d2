// Loading the CityGML module (see citygml_module.h).
#include "citygml_module.h"

#include <dlfcn.h>

#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "lodrefine/core/types.h"

#ifndef LODREFINE_CITYGML_MODULE_RELDIR
#error \
    "LODREFINE_CITYGML_MODULE_RELDIR (the module's folder relative to the installed executable's) is set by CMakeLists.txt"
#endif

namespace lodrefine::io_citygml {
namespace {

namespace fs = std::filesystem;

// dlerror's text on one line.
std::string one_line(const char* text) {
  std::string s = text ? text : "unknown error";
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

// The places the module may be, in order: beside the executable, then the installed layout.
std::vector<fs::path> candidates() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec || !exe.is_absolute()) return {};
  const fs::path dir = exe.parent_path();
  return {dir / kModuleName, (dir / LODREFINE_CITYGML_MODULE_RELDIR / kModuleName).lexically_normal()};
}

// The loaded entry point, or why there is none.
struct Module {
  decltype(&lodrefine_citygml_to_cityjson) convert = nullptr;
  std::string error;
};

Module load() {
  const std::vector<fs::path> paths = candidates();
  if (paths.empty()) return {nullptr, "the running executable's path (/proc/self/exe) is unknown"};
  for (const fs::path& p : paths) {
    std::error_code ec;
    if (!fs::exists(p, ec)) continue;
    void* handle = dlopen(p.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) return {nullptr, "cannot load " + p.string() + ": " + one_line(dlerror())};
    const auto abi = reinterpret_cast<decltype(&lodrefine_citygml_abi)>(dlsym(handle, "lodrefine_citygml_abi"));
    const auto convert =
        reinterpret_cast<decltype(&lodrefine_citygml_to_cityjson)>(dlsym(handle, "lodrefine_citygml_to_cityjson"));
    if (!abi || !convert || std::string(abi()) != kAbiTag)
      return {nullptr, p.string() + " is not the module of this build (" + kAbiTag + ")"};
    return {convert, ""};  // never closed: libcitygml and Xerces stay for the process
  }
  return {nullptr, "the module " + paths.front().string() + " (or " + paths.back().string() + ") is missing"};
}

}  // namespace

void to_cityjson(const std::string& path, std::string& text, const std::string& crs_url, nlohmann::ordered_json& doc,
                 RenamedIds& renamed) {
  static const Module module = load();
  if (!module.convert) throw InputError(path + ": CityGML input is unavailable: " + module.error);
  std::string error;
  const int status = module.convert(path.c_str(), &text, crs_url.c_str(), &doc, &renamed, &error);
  if (status == kInputError) throw InputError(error);
  if (status != kOk) throw std::runtime_error(error);
}

}  // namespace lodrefine::io_citygml
