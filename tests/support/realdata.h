// The GPL-3.0 real data sets beside the checkout (../shared/realdata); tests that need them skip
// when they are absent.
#pragma once
#include <gtest/gtest.h>

#include <filesystem>
#include "support/test_paths.h"

namespace lodrefine::fixtures {

inline std::filesystem::path realdata_dir() {
  return std::filesystem::path(test_paths::source_dir()) / ".." / "shared" / "realdata";
}

}  // namespace lodrefine::fixtures

// Declares `data_path` = realdata_dir() / rel, or skips the test when it does not exist.
#define REQUIRE_REALDATA(rel)                                                          \
  const std::filesystem::path data_path = lodrefine::fixtures::realdata_dir() / (rel); \
  if (!std::filesystem::exists(data_path)) GTEST_SKIP() << "real data not found: " << data_path.string()
