// Shared by the libFuzzer targets: the readers take paths, so each input goes through a
// per-process temporary file (in $TMPDIR, or /dev/shm when available: no disk traffic).
#pragma once
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace lodrefine::fuzz {

inline std::string temp_file(const char* name) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path dir = std::getenv("TMPDIR") ? fs::path(std::getenv("TMPDIR")) : fs::path("/dev/shm");
  if (!fs::is_directory(dir, ec)) dir = fs::temp_directory_path();
  return (dir / ("lodrefine_fuzz_" + std::to_string(::getpid()) + "_" + name)).string();
}

inline void write_bytes(const std::string& path, const std::uint8_t* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  if (!out) {
    std::fprintf(stderr, "fuzz harness: cannot write %s\n", path.c_str());
    std::abort();
  }
}

// A broken invariant is a finding: abort so libFuzzer saves the input.
#define FUZZ_CHECK(cond, ...)                                 \
  do {                                                        \
    if (!(cond)) {                                            \
      std::fprintf(stderr, "FUZZ_CHECK failed: %s: ", #cond); \
      std::fprintf(stderr, __VA_ARGS__);                      \
      std::fprintf(stderr, "\n");                             \
      std::abort();                                           \
    }                                                         \
  } while (0)

// InputError messages must be one line and name the file (apps/main.cpp prints them as is).
inline void check_message(const char* what, const std::string& path) {
  const std::string msg = what;
  FUZZ_CHECK(msg.find('\n') == std::string::npos && msg.find('\r') == std::string::npos, "multi-line InputError: %s",
             what);
  FUZZ_CHECK(msg.rfind(path, 0) == 0, "InputError does not start with the path: %s", what);
  FUZZ_CHECK(msg.size() < 1024, "InputError longer than 1 KiB (%zu chars)", msg.size());
}

}  // namespace lodrefine::fuzz
