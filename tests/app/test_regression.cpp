// CI regression gate: the shipped batch Makefile over the shipped sample buildings, pooled by
// `lodrefine eval --dir`, must stay within tests/regression_thresholds.json.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>
#include "support/test_paths.h"

namespace fs = std::filesystem;
using nlohmann::json;

TEST(Regression, SampleBatchStaysWithinThresholds) {
  const fs::path src = test_paths::source_dir();
  const fs::path run = fs::temp_directory_path() / ("lodrefine_regression_" + std::to_string(::getpid()));
  fs::remove_all(run);
  fs::create_directories(run);
  int samples = 0;
  for (const auto& e : fs::directory_iterator(src / "data" / "samples")) {
    if (!fs::exists(e.path() / "coarse.obj")) continue;
    fs::copy(e.path(), run / e.path().filename(), fs::copy_options::recursive);
    ++samples;
  }
  ASSERT_GE(samples, 3);
  const std::string cmd = "make -s -f '" + (src / "scripts" / "batch.mk").string() + "' RUN='" + run.string() +
                          "' LODREFINE='" + test_paths::lodrefine_binary() + "' -j2 > '" +
                          (run / "batch.log").string() + "' 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << "batch failed, see " << run / "batch.log";

  std::ifstream tf(src / "tests" / "regression_thresholds.json"), sf(run / "summary.json");
  ASSERT_TRUE(tf && sf);
  const json t = json::parse(tf), pooled = json::parse(sf).at("pooled");
  const json& points = pooled.at("pooled_over_points");
  const double watertight = pooled.at("watertight_rate").at("refined").get<double>();
  const double c2m = points.at("c2m").at("refined").at("rmse").get<double>();
  const double c2m_before = points.at("c2m").at("original").at("rmse").get<double>();
  const double facade = points.at("truth_facade").at("refined").at("rmse").get<double>();
  const double roof = points.at("truth_roof").at("refined").at("rmse").get<double>();
  std::printf(
      "samples %d: watertight %.0f %%, C2M RMSE %.4f -> %.4f m, truth facade RMSE %.4f m, truth roof RMSE %.4f m\n",
      samples, 100 * watertight, c2m_before, c2m, facade, roof);
  EXPECT_LE(pooled.at("failed").get<int>(), t.at("max_failed_buildings").get<int>());
  EXPECT_GE(watertight, t.at("min_watertight_rate").get<double>());
  EXPECT_LE(c2m, t.at("max_c2m_rmse_refined").get<double>());
  EXPECT_LT(c2m, c2m_before);
  EXPECT_LE(facade, t.at("max_truth_facade_rmse_refined").get<double>());
  EXPECT_LE(roof, t.at("max_truth_roof_rmse_refined").get<double>());
  if (!HasFailure()) fs::remove_all(run);
}
