// Shared by the suites that drive the lodrefine binary or need a per-test scratch folder.
#pragma once
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include "support/test_paths.h"

namespace cli_fixtures {

// A fresh folder for the running test: <tmp>/<prefix>_<pid>/<test name>.
inline std::string test_dir(const std::string& prefix) {
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir =
      std::filesystem::path(testing::TempDir()) / (prefix + "_" + std::to_string(::getpid())) / info->name();
  std::filesystem::create_directories(dir);
  return dir.string();
}

inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

struct Cli {
  int exit = -1;
  std::string out, err;
  double seconds = 0;
};

// Runs `lodrefine ARGS` with stdout/stderr captured in files under `dir`.
inline Cli run_cli(const std::string& args, const std::string& dir) {
  const std::string out = dir + "/.out", err = dir + "/.err";
  const auto t0 = std::chrono::steady_clock::now();
  const int st = std::system((test_paths::lodrefine_binary() + " " + args + " >" + out + " 2>" + err).c_str());
  Cli r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.exit = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

}  // namespace cli_fixtures
