// Fixed-bin distance histogram (see histogram.h).
#include "lodrefine/eval/histogram.h"

#include "lodrefine/eval/eval.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace lodrefine {
namespace {

constexpr double kLinearWidth = 1e-4;  // m: 0.1 mm, well below any scanner's noise
constexpr double kLinearEnd = 10.0;    // m: |d| beyond this is a gross outlier, binned relatively
constexpr double kRelativeWidth = 1e-3;
constexpr double kLargest = 1e9;  // m: kMaxCoordinate; larger |d| share the last bin
const std::size_t kLinearBins = std::size_t(std::llround(kLinearEnd / kLinearWidth));
const double kLogStep = std::log1p(kRelativeWidth);
const std::size_t kBins = kLinearBins + std::size_t(std::ceil(std::log(kLargest / kLinearEnd) / kLogStep)) + 1;

}  // namespace

DistanceHistogram::Bin DistanceHistogram::bin_of(double d) {
  const double u = std::abs(d);
  std::size_t j;
  if (u < kLinearEnd) j = std::min(kLinearBins - 1, std::size_t(u / kLinearWidth));
  else j = std::min(kBins - 1, kLinearBins + std::size_t(std::log(u / kLinearEnd) / kLogStep));
  return {d < 0 ? -1 : 1, j};
}

double DistanceHistogram::lower_edge(std::size_t j) {
  if (j <= kLinearBins) return double(j) * kLinearWidth;
  return kLinearEnd * std::exp(double(j - kLinearBins) * kLogStep);
}

double DistanceHistogram::bin_width(double d) {
  const std::size_t j = bin_of(d).j;
  return lower_edge(j + 1) - lower_edge(j);
}

void DistanceHistogram::add(double d) {
  if (!std::isfinite(d)) return;
  if (pos_.empty()) neg_.assign(kBins, 0), pos_.assign(kBins, 0);
  const Bin b = bin_of(d);
  ++(b.side < 0 ? neg_ : pos_)[b.j];
  min_ = count_ ? std::min(min_, d) : d;
  max_ = count_ ? std::max(max_, d) : d;
  ++count_;
  sum_ += d, sum_abs_ += std::abs(d), sum_sq_ += d * d;
}

void DistanceHistogram::merge(const DistanceHistogram& o) {
  if (o.count_ == 0) return;
  if (pos_.empty()) neg_.assign(kBins, 0), pos_.assign(kBins, 0);
  for (std::size_t j = 0; j < kBins; ++j) neg_[j] += o.neg_[j], pos_[j] += o.pos_[j];
  min_ = count_ ? std::min(min_, o.min_) : o.min_;
  max_ = count_ ? std::max(max_, o.max_) : o.max_;
  count_ += o.count_;
  sum_ += o.sum_, sum_abs_ += o.sum_abs_, sum_sq_ += o.sum_sq_;
}

double DistanceHistogram::upper_edge(std::size_t j) const {
  return j + 1 < kBins ? lower_edge(j + 1) : std::max(lower_edge(j + 1), max_abs());  // the last bin: all beyond
}

template <class F>
void DistanceHistogram::for_each_ascending(F&& f) const {
  // f(count, lowest value, highest value) of each non-empty bin; stops when f returns true.
  for (std::size_t j = neg_.size(); j-- > 0;)
    if (neg_[j] && f(neg_[j], -upper_edge(j), -lower_edge(j))) return;
  for (std::size_t j = 0; j < pos_.size(); ++j)
    if (pos_[j] && f(pos_[j], lower_edge(j), upper_edge(j))) return;
}

double DistanceHistogram::kth(std::uint64_t k) const {
  if (k == 0) return min_;  // the extremes are exact
  if (k + 1 >= count_) return max_;
  double v = max_;
  std::uint64_t below = 0;
  for_each_ascending([&](std::uint64_t c, double lo, double hi) {
    if (k >= below + c) {
      below += c;
      return false;
    }
    v = lo + (double(k - below) + 0.5) / double(c) * (hi - lo);  // spread evenly in the bin
    return true;
  });
  return std::clamp(v, min_, max_);
}

double DistanceHistogram::quantile(double q) const {
  if (count_ == 0) return 0.0;
  const double pos = std::clamp(q, 0.0, 1.0) * double(count_ - 1);
  const std::uint64_t lo = std::uint64_t(std::floor(pos));
  const double a = kth(lo), b = lo + 1 < count_ ? kth(lo + 1) : a;
  return a + (pos - double(lo)) * (b - a);
}

double DistanceHistogram::abs_quantile(double q) const {
  if (count_ == 0) return 0.0;
  const double pos = std::clamp(q, 0.0, 1.0) * double(count_ - 1);
  const std::uint64_t lo = std::uint64_t(std::floor(pos));
  auto kth_abs = [&](std::uint64_t k) {
    if (k + 1 >= count_) return max_abs();
    std::uint64_t below = 0;
    for (std::size_t j = 0; j < kBins; ++j) {
      const std::uint64_t c = neg_[j] + pos_[j];
      if (k < below + c)
        return std::min(max_abs(),
                        lower_edge(j) + (double(k - below) + 0.5) / double(c) * (upper_edge(j) - lower_edge(j)));
      below += c;
    }
    return max_abs();
  };
  const double a = kth_abs(lo), b = lo + 1 < count_ ? kth_abs(lo + 1) : a;
  return a + (pos - double(lo)) * (b - a);
}

std::uint64_t DistanceHistogram::count_between(double lo, double hi) const {
  std::uint64_t n = 0;
  for_each_ascending([&](std::uint64_t c, double a, double b) {
    const double mid = 0.5 * (a + b);
    if (mid >= hi) return true;
    if (mid >= lo) n += c;
    return false;
  });
  return n;
}

double DistanceHistogram::lowest_in(double lo, double hi) const {
  double v = std::numeric_limits<double>::quiet_NaN();
  for_each_ascending([&](std::uint64_t, double a, double b) {
    const double mid = 0.5 * (a + b);
    if (mid > hi) return true;
    if (mid < lo) return false;
    v = std::max(a, min_);
    return true;
  });
  return v;
}

double DistanceHistogram::highest_in(double lo, double hi) const {
  double v = std::numeric_limits<double>::quiet_NaN();
  for_each_ascending([&](std::uint64_t, double a, double b) {
    const double mid = 0.5 * (a + b);
    if (mid > hi) return true;
    if (mid >= lo) v = std::min(b, max_);
    return false;
  });
  return v;
}

DistanceStats DistanceHistogram::stats() const {
  DistanceStats s;
  s.count = count_;
  if (count_ == 0) return s;
  const double n = double(count_);
  s.mean = sum_ / n, s.mae = sum_abs_ / n, s.rmse = std::sqrt(sum_sq_ / n);
  s.std = std::sqrt(std::max(0.0, sum_sq_ / n - s.mean * s.mean));
  s.max_abs = max_abs();
  s.median = quantile(0.5);
  s.p95 = abs_quantile(0.95);
  return s;
}

DistanceStats pooled_stats(const std::vector<const DistanceStats*>& parts, const DistanceHistogram& pooled) {
  DistanceStats s;
  double sum = 0, sum_abs = 0, sum_sq = 0;
  for (const DistanceStats* p : parts) {
    const double n = double(p->count);
    s.count += p->count;
    sum += p->mean * n, sum_abs += p->mae * n, sum_sq += p->rmse * p->rmse * n;
    s.max_abs = std::max(s.max_abs, p->max_abs);
  }
  if (s.count == 0) return s;
  const double n = double(s.count);
  s.mean = sum / n, s.mae = sum_abs / n, s.rmse = std::sqrt(sum_sq / n);
  // The spread about the pooled mean from each part's own spread and mean (exact; no
  // cancellation of the squares' sum).
  double var = 0;
  for (const DistanceStats* p : parts)
    var += double(p->count) * (p->std * p->std + (p->mean - s.mean) * (p->mean - s.mean));
  s.std = std::sqrt(var / n);
  s.median = pooled.quantile(0.5);
  s.p95 = pooled.abs_quantile(0.95);
  return s;
}

}  // namespace lodrefine
