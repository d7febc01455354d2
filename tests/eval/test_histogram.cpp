// The binned distance pool: its percentiles against the exact ones on generated distances
// (within one bin), its exact sums, and a pooled run's figures against the held series.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "lodrefine/eval/eval.h"
#include "lodrefine/eval/histogram.h"
#include "lodrefine/eval/plots.h"

using namespace lodrefine;

namespace {

// C2M-like signed distances: most within a few cm, a tail of outliers up to tens of metres.
std::vector<double> generated(std::size_t n, unsigned seed, double shift = 0.0) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(shift, 0.03);
  std::exponential_distribution<double> tail(0.2);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> d;
  for (std::size_t i = 0; i < n; ++i) d.push_back(u(rng) < 0.02 ? (u(rng) < 0.5 ? -1 : 1) * tail(rng) : noise(rng));
  return d;
}

}  // namespace

TEST(DistanceHistogram, PercentilesWithinOneBinOfTheExactOnes) {
  const std::vector<double> d = generated(200000, 7, 0.05);
  DistanceHistogram h;
  h.add(d);
  ASSERT_EQ(h.count(), d.size());
  std::vector<double> abs_d;
  for (double x : d) abs_d.push_back(std::abs(x));
  for (double q : {0.0, 0.01, 0.25, 0.5, 0.75, 0.95, 0.99, 0.999, 1.0}) {
    std::vector<double> v = d;
    const double exact = percentile(v, q);
    EXPECT_NEAR(h.quantile(q), exact, DistanceHistogram::bin_width(exact)) << "q " << q;
    std::vector<double> a = abs_d;
    const double exact_abs = percentile(a, q);
    EXPECT_NEAR(h.abs_quantile(q), exact_abs, DistanceHistogram::bin_width(exact_abs)) << "|d| q " << q;
  }
  // The bins: 0.1 mm near zero, relative beyond 10 m.
  EXPECT_NEAR(DistanceHistogram::bin_width(0.02), 1e-4, 1e-12);
  EXPECT_NEAR(DistanceHistogram::bin_width(-25.0) / 25.0, 1e-3, 2e-5);
}

TEST(DistanceHistogram, SumsAreExactAndMergeEqualsOnePool) {
  const std::vector<double> a = generated(5000, 1), b = generated(7000, 2, -0.1);
  DistanceHistogram ha, hb, all;
  ha.add(a), hb.add(b), all.add(a), all.add(b);
  ha.merge(hb);
  std::vector<double> both = a;
  both.insert(both.end(), b.begin(), b.end());
  const DistanceStats exact = summarize_distances(both), s = ha.stats();
  EXPECT_EQ(s.count, exact.count);
  EXPECT_NEAR(s.rmse, exact.rmse, 1e-12);
  EXPECT_NEAR(s.mae, exact.mae, 1e-12);
  EXPECT_NEAR(s.mean, exact.mean, 1e-12);
  EXPECT_NEAR(s.std, exact.std, 1e-9);
  EXPECT_EQ(s.max_abs, exact.max_abs);
  EXPECT_EQ(ha.quantile(0.5), all.quantile(0.5));  // counts: the same whatever the order
  EXPECT_EQ(ha.min(), *std::min_element(both.begin(), both.end()));
  // Odd values: a NaN is not counted, huge values share the last bin yet max |d| stays exact.
  DistanceHistogram odd;
  odd.add(std::nan(""));
  odd.add(5e12);
  odd.add(-1.0);
  EXPECT_EQ(odd.count(), 2u);
  EXPECT_EQ(odd.max_abs(), 5e12);
  EXPECT_EQ(odd.quantile(1.0), 5e12);
  EXPECT_NEAR(odd.quantile(0.0), -1.0, DistanceHistogram::bin_width(-1.0));
  EXPECT_EQ(DistanceHistogram().quantile(0.5), 0.0);
}

// A run pooled building by building with the series dropped gives the figures of the series
// held: RMSE/MAE/mean/std to 1e-12, median and p95 within one bin.
TEST(DistanceHistogram, PooledRunMatchesTheHeldSeries) {
  std::vector<BuildingEval> run;
  for (unsigned k = 0; k < 12; ++k) {
    BuildingEval b;
    b.id = "b" + std::to_string(k);
    b.c2m_before = generated(3000 + 500 * k, k, 0.2);
    b.c2m_after = generated(3000 + 500 * k, 100 + k);
    b.facade_points = b.c2m_before.size();
    b.before = summarize_distances(b.c2m_before), b.after = summarize_distances(b.c2m_after);
    b.truth_facade_d_before = generated(400, 200 + k, 0.3);
    b.truth_facade_before = summarize_distances(b.truth_facade_d_before);
    run.push_back(std::move(b));
  }
  run[3].error = "refined.obj missing";  // failed: not pooled
  const PooledEval held = pool_evaluations(run);
  std::vector<double> before;
  for (const auto& b : run)
    if (b.ok()) before.insert(before.end(), b.c2m_before.begin(), b.c2m_before.end());
  const DistanceStats exact = summarize_distances(before);
  PooledSeries series;
  for (auto& b : run) {
    series.add(b);
    drop_series(b);
    EXPECT_TRUE(b.c2m_before.empty() && b.truth_facade_d_before.empty());
  }
  const PooledEval p = pool_evaluations(run, series);
  EXPECT_EQ(p.before.count, exact.count);
  EXPECT_NEAR(p.before.rmse, exact.rmse, 1e-12);
  EXPECT_NEAR(p.before.mae, exact.mae, 1e-12);
  EXPECT_NEAR(p.before.mean, exact.mean, 1e-12);
  EXPECT_NEAR(p.before.std, exact.std, 1e-12);
  EXPECT_EQ(p.before.max_abs, exact.max_abs);
  EXPECT_NEAR(p.before.median, exact.median, DistanceHistogram::bin_width(exact.median));
  EXPECT_NEAR(p.before.p95, exact.p95, DistanceHistogram::bin_width(exact.p95));
  EXPECT_EQ(p.before.rmse, held.before.rmse);
  EXPECT_EQ(p.after.median, held.after.median);
  ASSERT_TRUE(p.truth_facade_before);
  EXPECT_EQ(p.truth_facade_before->count, 11u * 400u);
  EXPECT_FALSE(p.truth_roof_before);
  EXPECT_EQ(p.evaluated, 11u);
  // The plots from the bins: the same legend counts as from the values.
  const std::string svg = svg_histogram(series.c2m_before, series.c2m_after, "C2M");
  EXPECT_NE(svg.find("n=" + std::to_string(exact.count)), std::string::npos);
  EXPECT_NE(svg_boxplot(series.c2m_before, series.c2m_after, "C2M").find("beyond whiskers"), std::string::npos);
}

// The boxplot from bins agrees with the one from the values: same outlier count to within the
// values in the fences' bins.
TEST(DistanceHistogram, BoxplotFromBinsMatchesTheValues) {
  const std::vector<double> a = generated(20000, 3, 0.1), b = generated(20000, 4);
  DistanceHistogram ha, hb;
  ha.add(a), hb.add(b);
  auto outliers = [](const std::string& svg) {
    const auto e = svg.find(" of 20000 beyond whiskers");
    const auto s = svg.rfind('>', e);
    return std::stol(svg.substr(s + 1, e - s - 1));
  };
  const std::string exact = svg_boxplot(a, b, "C2M"), binned = svg_boxplot(ha, hb, "C2M");
  EXPECT_NEAR(outliers(binned), outliers(exact), 20);
  EXPECT_GT(outliers(exact), 300);  // the generated 2 % tail, and the normal's own beyond 2.7 sigma
  EXPECT_LT(outliers(exact), 800);
}
