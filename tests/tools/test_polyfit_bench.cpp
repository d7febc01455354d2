// The PolyFit bench (src/tools/polyfit_bench.cpp): both methods measured on the truth of one
// building; the summary counts PolyFit's failures and pools the truth RMSE over the buildings it
// closed; rows print ids and reasons escaped.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "lodrefine/core/params.h"
#include "lodrefine/tools/polyfit_bench.h"
#include "support/polyfit_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

TEST(PolyfitBench, CompareMeasuresBothMethodsOnTheTruth) {
  BenchBuilding b;
  b.id = "box";
  b.truth = truth_box();
  b.coarse = coarse_box();
  b.cloud = full_scan(b.truth);
  const PolyfitComparisonRow row = compare_with_polyfit(b, RefineConfig{}, {});
  EXPECT_EQ(row.id, "box");
  ASSERT_TRUE(row.coarse_facade && row.lodrefine.truth_facade && row.polyfit.truth_facade);
  EXPECT_GT(row.coarse_facade->rmse, 0.1);
  EXPECT_LT(row.polyfit.truth_facade->rmse, 0.02);
  EXPECT_LT(row.lodrefine.truth_facade->rmse, 0.02);
  EXPECT_TRUE(row.polyfit.produced && row.polyfit.watertight && row.lodrefine.watertight);
  EXPECT_GT(row.lodrefine.seconds, 0.0);
  EXPECT_GT(row.polyfit.seconds, 0.0);
  EXPECT_TRUE(row.baseline.mesh.faces.empty());  // dropped: rows hold figures only
}

TEST(PolyfitBench, SummaryCountsFailuresAndPoolsOverClosedBuildings) {
  auto stats = [](double rmse, std::size_t count) {
    DistanceStats s;
    s.rmse = rmse, s.count = count;
    return s;
  };
  PolyfitComparisonRow closed, failed;
  closed.lodrefine = {1.0, 1.0, true, true, stats(0.01, 100), stats(0.02, 100)};
  closed.polyfit = {10.0, 9.0, true, true, stats(0.03, 100), stats(0.04, 100)};
  closed.coarse_facade = stats(0.5, 100);
  closed.baseline.status = PolyfitStatus::Closed;
  failed.lodrefine = {3.0, 2.0, true, true, stats(0.05, 300), stats(0.02, 100)};
  failed.polyfit = {60.0, 60.0, false, false, std::nullopt, std::nullopt};
  failed.coarse_facade = stats(0.5, 300);
  failed.baseline.status = PolyfitStatus::TimeLimit;
  const PolyfitComparison s = summarize_comparison({closed, failed});
  EXPECT_EQ(s.buildings, 2);
  EXPECT_EQ(s.polyfit_closed, 1);
  ASSERT_EQ(s.failures.size(), 1u);
  EXPECT_EQ(s.failures[0], std::make_pair(std::string("time-limit"), 1));
  EXPECT_DOUBLE_EQ(s.lodrefine_median, 2.0);
  EXPECT_DOUBLE_EQ(s.polyfit_max, 60.0);
  EXPECT_DOUBLE_EQ(s.ratio_min, 10.0);
  EXPECT_DOUBLE_EQ(s.cpu_ratio_of_medians, 34.5 / 1.5);
  EXPECT_NEAR(s.facade_lodrefine, std::sqrt((0.01 * 0.01 * 100 + 0.05 * 0.05 * 300) / 400), 1e-12);
  EXPECT_NEAR(s.facade_lodrefine_closed, 0.01, 1e-12);
  EXPECT_NEAR(s.facade_polyfit_closed, 0.03, 1e-12);
  EXPECT_NEAR(s.roof_polyfit_closed, 0.04, 1e-12);
}

// A tile's building id (a model's file name) and PolyFit's reason are printed escaped: a CR in a
// file name printed "ALL GOOD" over the row.
TEST(PolyfitBench, RowsEscapeIdsAndReasons) {
  PolyfitComparisonRow row;
  row.id = "B\r\x1b[2KALL GOOD";
  row.outcome = Outcome::Kept;
  row.baseline.status = PolyfitStatus::TooFewPlanes;
  row.baseline.reason = "few\rplanes";
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  print_comparison_row(row, f);
  std::rewind(f);
  std::string text;
  for (int c; (c = std::fgetc(f)) != EOF;) text += char(c);
  std::fclose(f);
  EXPECT_EQ(text.find_first_of("\r\x1b"), std::string::npos) << text;
  EXPECT_NE(text.find("B\\r\\x1b[2KALL GOOD"), std::string::npos) << text;
  EXPECT_NE(text.find("few\\rplanes"), std::string::npos) << text;
}
