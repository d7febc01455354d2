// Loading the CityGML module (see citygml_module.h).
#include "citygml_module.h"

#include <dlfcn.h>
#include <fcntl.h>
#include <unistd.h>

#include <cstdlib>
#include <exception>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <system_error>

#include "lodrefine/base/types.h"

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

// Around the module's foreign code: libraries whose constructors run inside dlopen, where an
// exception (memory running out under a ulimit) can only end in std::terminate, some printing
// their own failures (GnuTLS); and Xerces-C, whose panic (its initialisation out of memory)
// prints a word and calls exit(-1). For that time stderr is silenced, and a terminate or an
// exit prints one line naming the file instead and ends the process with exit 3 (main's
// out-of-memory code). Only one guard is active at a time (the module is entered on one
// thread at a time: `module_mutex`).
class ModuleGuard {
 public:
  ModuleGuard(const std::string& path, const char* what) {
    line_ = "lodrefine: error: " + path + ": " + what + "\n";
    saved_stderr_ = ::dup(2);
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_stderr_ >= 0 && null >= 0) ::dup2(null, 2);
    if (null >= 0) ::close(null);
    static const bool hooked = std::atexit(ended) == 0;
    (void)hooked;
    active_ = this;
    before_ = std::set_terminate(ended);
  }
  ~ModuleGuard() {
    std::set_terminate(before_);
    active_ = nullptr;
    restore_stderr();
  }
  ModuleGuard(const ModuleGuard&) = delete;
  ModuleGuard& operator=(const ModuleGuard&) = delete;

 private:
  void restore_stderr() {
    if (saved_stderr_ < 0) return;
    ::dup2(saved_stderr_, 2);
    ::close(saved_stderr_);
    saved_stderr_ = -1;
  }
  static void ended() {
    if (!active_) return;  // an ordinary exit
    active_->restore_stderr();
    const ssize_t n = ::write(2, active_->line_.data(), active_->line_.size());
    (void)n;
    ::_exit(3);
  }

  static inline ModuleGuard* active_ = nullptr;
  std::string line_;
  int saved_stderr_ = -1;
  std::terminate_handler before_ = nullptr;
};

Module load(const std::string& path) {
  const std::vector<fs::path> paths = candidates();
  if (paths.empty()) return {nullptr, "the running executable's path (/proc/self/exe) is unknown"};
  for (const fs::path& p : paths) {
    std::error_code ec;
    if (!fs::exists(p, ec)) continue;
    void* handle = nullptr;
    {
      const ModuleGuard guard(path, "out of memory loading the CityGML module");
      handle = dlopen(p.c_str(), RTLD_NOW | RTLD_LOCAL);
    }
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
  static const Module module = load(path);
  if (!module.convert) throw InputError(path + ": CityGML input is unavailable: " + module.error);
  std::string error;
  int status = kFailure;
  {
    static std::mutex module_mutex;
    const std::lock_guard<std::mutex> lock(module_mutex);
    const ModuleGuard guard(path, "Xerces-C ended the process while reading the CityGML file (out of memory?)");
    status = module.convert(path.c_str(), &text, crs_url.c_str(), &doc, &renamed, &error);
  }
  if (status == kInputError) throw InputError(error);
  if (status == kOutOfMemory)
    throw OutOfMemory(error.empty() ? path + ": out of memory reading the CityGML file" : error);
  if (status != kOk) throw std::runtime_error(error);
}

}  // namespace lodrefine::io_citygml
