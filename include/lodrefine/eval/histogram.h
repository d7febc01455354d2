// Signed distances pooled in fixed bins, so that a run's percentiles and plots need memory that
// does not grow with its points (a city tile has hundreds of millions of C2M values).
//
// Bins: 0.1 mm wide below 10 m of |d|, then 0.1 % wide (relative) up to 1e9 m, on each side of
// zero; about 2 x 118,000 counters (1.9 MB), allocated on the first value. Count, sums, minimum,
// maximum and max |d| are exact; a quantile is exact to within the width of the bin it falls in
// (values spread evenly inside a bin), and never outside [min, max].
#pragma once
#include <algorithm>
#include <cstdint>
#include <vector>

namespace lodrefine {

struct DistanceStats;  // eval.h

class DistanceHistogram {
 public:
  void add(double d);  // finite values only (a NaN is not counted)
  void add(const std::vector<double>& d) {
    for (double x : d) add(x);
  }
  void merge(const DistanceHistogram& other);

  std::uint64_t count() const { return count_; }
  double min() const { return min_; }  // 0 when empty, as max() and max_abs()
  double max() const { return max_; }
  double max_abs() const { return std::max(-min_, max_); }
  double mean() const { return count_ ? sum_ / double(count_) : 0.0; }
  // Quantile q (0..1) of the signed values / of |d|, interpolated between order statistics as
  // percentile() does; 0 when empty.
  double quantile(double q) const;
  double abs_quantile(double q) const;
  // Values in [lo, hi) to within the bins straddling lo and hi (counted whole when their centre
  // is inside).
  std::uint64_t count_between(double lo, double hi) const;
  // The width of the bin that holds d (the error bound of a quantile there).
  static double bin_width(double d);
  // As summarize_distances(), median and p95 from the bins (the sums are exact, but a pool
  // built in another order can differ in the last bits: see pooled_stats()).
  DistanceStats stats() const;
  // The value of the k-th smallest signed value (0-based), k < count().
  double kth(std::uint64_t k) const;
  // The lowest / highest value of non-empty bins inside [lo, hi] (to within a bin), NaN if none.
  double lowest_in(double lo, double hi) const;
  double highest_in(double lo, double hi) const;

 private:
  struct Bin {
    int side;       // -1: negative values, +1: zero and positive
    std::size_t j;  // index by |d|
  };
  static Bin bin_of(double d);
  static double lower_edge(std::size_t j);  // of |d|
  double upper_edge(std::size_t j) const;   // of |d|; the last bin reaches max |d|
  // The bins in ascending order of value: negative side from the top index down, then positive.
  template <class F>
  void for_each_ascending(F&& f) const;
  std::vector<std::uint64_t> neg_, pos_;
  std::uint64_t count_ = 0;
  double sum_ = 0, sum_abs_ = 0, sum_sq_ = 0, min_ = 0, max_ = 0;
};

// The pooled figures of several parts (buildings) and their pooled histogram: count, mean,
// RMSE, MAE, std and max |d| from the parts' exact figures in their order (the same bits
// whatever order the histogram was filled in), median and p95 from the histogram.
DistanceStats pooled_stats(const std::vector<const DistanceStats*>& parts, const DistanceHistogram& pooled);

}  // namespace lodrefine
