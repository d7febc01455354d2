// Files for the io tests: per-test temporary paths, and the check that a reader refuses a file
// with one line naming it and the fault.
#pragma once
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "lodrefine/core/types.h"

namespace lodrefine::fixtures {

// A fresh per-test path under the GoogleTest temp dir.
inline std::string temp_path(const std::string& name) {
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir =
      std::filesystem::path(testing::TempDir()) / ("lodrefine_io_" + std::to_string(::getpid())) / info->name();
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

inline std::string write_bytes(const std::string& name, const std::string& content) {
  const std::string path = temp_path(name);
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

// Expects InputError whose one-line message starts with the file's path and contains `fault`.
template <class F>
void expect_input_error(const std::string& path, const std::string& fault, F&& read) {
  try {
    read(path);
    ADD_FAILURE() << "no InputError for " << path << " (expected '" << fault << "')";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
    EXPECT_NE(msg.find(fault), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

// Writes `bytes` to the test's file `name` and expects `read` to refuse it (expect_input_error).
template <class F>
void expect_bytes_refused(const std::string& name, const std::string& bytes, const std::string& fault, F&& read) {
  expect_input_error(write_bytes(name, bytes), fault, std::forward<F>(read));
}

// Overwrites sizeof(T) bytes at `at` with `v` (the test machine is little-endian, as LAS is):
// header lies made to order.
template <class T>
void poke(std::string& bytes, std::size_t at, T v) {
  std::memcpy(&bytes[at], &v, sizeof v);
}

}  // namespace lodrefine::fixtures
