// Where the tests find the source tree and the lodrefine binary, read at run time so that no
// absolute path is compiled into a test object (ccache then hits in any checkout, CI's fresh
// clone too). A test binary finds them from the build tree it sits in (CTest runs it there, and
// so does a hand): the lodrefine beside it, and the source folder that tree's CMakeCache.txt
// names (CMAKE_HOME_DIRECTORY). LODREFINE_BINARY and LODREFINE_SOURCE_DIR in the environment
// override them (another build's binary, a test binary copied elsewhere).
#pragma once
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace test_paths {
namespace detail {

// The folder of the running test binary (the build tree).
inline std::filesystem::path build_dir() { return std::filesystem::read_symlink("/proc/self/exe").parent_path(); }

inline std::string from_cmake_cache() {
  std::ifstream cache(build_dir() / "CMakeCache.txt");
  const std::string key = "CMAKE_HOME_DIRECTORY:INTERNAL=";
  for (std::string line; std::getline(cache, line);)
    if (line.rfind(key, 0) == 0) return line.substr(key.size());
  std::fprintf(stderr, "test_paths: set LODREFINE_SOURCE_DIR (no CMakeCache.txt beside the test binary)\n");
  std::abort();
}

inline std::string from_env(const char* name) {
  const char* value = std::getenv(name);
  return value ? std::string(value) : std::string();
}

}  // namespace detail

// The source folder (holds data/, scripts/, tests/; ../shared beside it).
inline const std::string& source_dir() {
  static const std::string dir = [] {
    const std::string env = detail::from_env("LODREFINE_SOURCE_DIR");
    return env.empty() ? detail::from_cmake_cache() : env;
  }();
  return dir;
}

// The lodrefine executable the command-line tests run.
inline const std::string& lodrefine_binary() {
  static const std::string path = [] {
    const std::string env = detail::from_env("LODREFINE_BINARY");
    return env.empty() ? (detail::build_dir() / "lodrefine").string() : env;
  }();
  return path;
}

}  // namespace test_paths
