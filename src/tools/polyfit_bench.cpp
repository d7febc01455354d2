// lodrefine and CGAL's PolyFit on the same buildings (polyfit_bench.h).
#include "lodrefine/tools/polyfit_bench.h"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>

#include "lodrefine/base/files.h"
#include "lodrefine/base/geometry.h"
#include "lodrefine/formats/cloud.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/refine/refine.h"
#include "lodrefine/tools/run.h"

namespace lodrefine {
namespace {

namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

std::vector<BuildingFiles> discover_tile(const fs::path& dir) {
  std::vector<BuildingFiles> out;
  for (const auto& e : fs::directory_iterator(dir / "models")) {
    if (e.path().extension() != ".obj") continue;
    const std::string id = e.path().stem().string();
    const fs::path truth = dir / "truth" / (id + ".obj");
    BuildingFiles f;
    f.id = id, f.original = e.path().string(), f.clouds = {(dir / "clouds" / (id + ".ply")).string()};
    if (fs::exists(truth)) f.truth = truth.string();
    out.push_back(std::move(f));
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  if (out.empty()) throw InputError(dir.string() + ": no models/<id>.obj");
  return out;
}

// A method's output measured against the truth: evaluate_building's "after" side.
void measure(MethodRun& m, const BuildingEval& e) {
  m.watertight = e.watertight_after;
  m.truth_facade = e.truth_facade_after;
  m.truth_roof = e.truth_roof_after;
}

double median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  return percentile_sorted(v, 0.5);
}

double max_of(const std::vector<double>& v) { return v.empty() ? kNaN : *std::max_element(v.begin(), v.end()); }

// Pooled RMSE over the samples of several buildings: sqrt(sum count·rmse² / sum count).
struct Pool {
  double sum_sq = 0;
  std::size_t n = 0;
  void add(const std::optional<DistanceStats>& s) {
    if (s) sum_sq += s->rmse * s->rmse * double(s->count), n += s->count;
  }
  double rmse() const { return n ? std::sqrt(sum_sq / double(n)) : kNaN; }
};

// Over `rows` (those `keep` accepts): the pooled RMSE of what `pick` selects of each.
template <class Keep, class Pick>
double pooled(const std::vector<PolyfitComparisonRow>& rows, Keep keep, Pick pick) {
  Pool p;
  for (const auto& r : rows)
    if (keep(r)) p.add(pick(r));
  return p.rmse();
}

std::string metres(const std::optional<DistanceStats>& s) {
  char buf[32];
  if (!s) return "-";
  std::snprintf(buf, sizeof buf, "%.3f", s->rmse);
  return buf;
}

}  // namespace

std::vector<BuildingFiles> discover_bench(const std::string& dir) {
  if (fs::is_directory(fs::path(dir) / "models")) return discover_tile(dir);
  return discover_run(dir);
}

BenchBuilding read_bench_building(const BuildingFiles& f) {
  BenchBuilding b;
  b.id = f.id;
  b.coarse = read_eval_model(f.original);
  b.cloud = read_cloud(f.clouds);
  if (!f.truth.empty()) b.truth = read_eval_model(f.truth);
  return b;
}

BuildingEval evaluate_against_truth(const BenchBuilding& b, const Mesh& output, const RefineConfig& params) {
  const Vec3 o = local_origin(b.coarse);
  PointCloud cloud = b.cloud;
  for (auto& p : cloud.points) p -= o;
  const Mesh truth = translated(b.truth, -o);
  return evaluate_building(translated(b.coarse, -o), translated(output, -o), cloud,
                           truth.faces.empty() ? nullptr : &truth, params,
                           b.scanned_truth_faces ? &*b.scanned_truth_faces : nullptr);
}

PolyfitComparisonRow compare_with_polyfit(const BenchBuilding& b, const RefineConfig& params,
                                          const PolyfitOptions& options) {
  PolyfitComparisonRow row;
  row.id = b.id, row.points = b.cloud.points.size();
  const Clock::time_point t0 = Clock::now();
  const double cpu0 = thread_cpu_seconds();
  const RefineResult refined = refine_building(b.coarse, b.cloud, params);
  row.lodrefine.cpu_seconds = thread_cpu_seconds() - cpu0;
  row.lodrefine.seconds = seconds_since(t0);
  row.lodrefine.produced = true;
  row.outcome = refined.outcome;
  row.baseline = polyfit_baseline_isolated(b.coarse, b.cloud, params, options);
  row.polyfit.seconds = row.baseline.seconds;
  row.polyfit.cpu_seconds = row.baseline.cpu_seconds;
  row.polyfit.produced = row.baseline.closed();

  // Both measured the same way, on the same facade points and truth samples.
  const BuildingEval ev = evaluate_against_truth(b, refined.mesh, params);
  row.coarse_facade = ev.truth_facade_before, row.coarse_roof = ev.truth_roof_before;
  measure(row.lodrefine, ev);
  if (row.polyfit.produced) measure(row.polyfit, evaluate_against_truth(b, row.baseline.mesh, params));
  row.baseline.mesh = Mesh{};
  return row;
}

PolyfitComparison summarize_comparison(const std::vector<PolyfitComparisonRow>& rows) {
  PolyfitComparison s;
  std::vector<double> lod, pf, lod_cpu, pf_cpu, ratio;
  std::map<std::string, int> failures;
  for (const auto& r : rows) {
    ++s.buildings;
    s.polyfit_closed += r.polyfit.produced;
    s.lodrefine_watertight += r.lodrefine.watertight;
    s.polyfit_watertight += r.polyfit.produced && r.polyfit.watertight;
    if (!r.polyfit.produced) ++failures[polyfit_status_name(r.baseline.status)];
    lod.push_back(r.lodrefine.seconds), pf.push_back(r.polyfit.seconds);
    lod_cpu.push_back(r.lodrefine.cpu_seconds), pf_cpu.push_back(r.polyfit.cpu_seconds);
    if (r.lodrefine.seconds > 0) ratio.push_back(r.polyfit.seconds / r.lodrefine.seconds);
  }
  s.failures.assign(failures.begin(), failures.end());
  s.lodrefine_median = median(lod), s.lodrefine_max = max_of(lod);
  s.polyfit_median = median(pf), s.polyfit_max = max_of(pf);
  s.lodrefine_cpu_median = median(lod_cpu), s.lodrefine_cpu_max = max_of(lod_cpu);
  s.polyfit_cpu_median = median(pf_cpu), s.polyfit_cpu_max = max_of(pf_cpu);
  s.ratio_of_medians = s.polyfit_median / s.lodrefine_median;
  s.cpu_ratio_of_medians = s.polyfit_cpu_median / s.lodrefine_cpu_median;
  s.ratio_median = median(ratio);
  s.ratio_min = ratio.empty() ? kNaN : *std::min_element(ratio.begin(), ratio.end());

  const auto all = [](const PolyfitComparisonRow&) { return true; };
  const auto closed = [](const PolyfitComparisonRow& r) { return r.polyfit.produced; };
  const auto coarse_f = [](const PolyfitComparisonRow& r) { return r.coarse_facade; };
  const auto lod_f = [](const PolyfitComparisonRow& r) { return r.lodrefine.truth_facade; };
  const auto pf_f = [](const PolyfitComparisonRow& r) { return r.polyfit.truth_facade; };
  const auto coarse_r = [](const PolyfitComparisonRow& r) { return r.coarse_roof; };
  const auto lod_r = [](const PolyfitComparisonRow& r) { return r.lodrefine.truth_roof; };
  const auto pf_r = [](const PolyfitComparisonRow& r) { return r.polyfit.truth_roof; };
  s.facade_coarse = pooled(rows, all, coarse_f), s.facade_lodrefine = pooled(rows, all, lod_f);
  s.facade_coarse_closed = pooled(rows, closed, coarse_f), s.facade_lodrefine_closed = pooled(rows, closed, lod_f);
  s.facade_polyfit_closed = pooled(rows, closed, pf_f);
  s.roof_coarse = pooled(rows, all, coarse_r), s.roof_lodrefine = pooled(rows, all, lod_r);
  s.roof_coarse_closed = pooled(rows, closed, coarse_r), s.roof_lodrefine_closed = pooled(rows, closed, lod_r);
  s.roof_polyfit_closed = pooled(rows, closed, pf_r);
  return s;
}

void print_comparison_header(std::FILE* out) {
  std::fprintf(out, "%-22s %7s | %8s %-12s | %8s %6s %7s %6s %-14s | %7s | %-23s | %-23s\n", "building", "points",
               "lod_s", "lod_outcome", "pf_s", "planes", "cand", "cgal_s", "pf_status", "pf/lod",
               "facade coarse/lod/pf m", "roof coarse/lod/pf m");
}

void print_comparison_row(const PolyfitComparisonRow& r, std::FILE* out) {
  const PolyfitResult& p = r.baseline;
  std::fprintf(out, "%-22s %7zu | %8.3f %-12s | %8.3f %6d %7d %6.2f %-14s | %7.1f | %-7s %-7s %-7s | %-7s %-7s %-7s\n",
               escaped_line(r.id).c_str(), r.points, r.lodrefine.seconds, outcome_name(r.outcome), r.polyfit.seconds,
               p.planes, p.candidates, p.polyfit_seconds, polyfit_status_name(p.status),
               r.lodrefine.seconds > 0 ? r.polyfit.seconds / r.lodrefine.seconds : kNaN,
               metres(r.coarse_facade).c_str(), metres(r.lodrefine.truth_facade).c_str(),
               metres(r.polyfit.truth_facade).c_str(), metres(r.coarse_roof).c_str(),
               metres(r.lodrefine.truth_roof).c_str(), metres(r.polyfit.truth_roof).c_str());
  if (!p.closed())
    std::fprintf(out, "  %s: PolyFit %s: %s\n", escaped_line(r.id).c_str(), polyfit_status_name(p.status),
                 escaped_line(p.reason).c_str());
  std::fflush(out);
}

void print_comparison_summary(const PolyfitComparison& s, const PolyfitOptions& options, std::FILE* out) {
  std::fprintf(out,
               "\n%d buildings; PolyFit (%s planes, weights %.2f/%.2f/%.2f) closed %d, watertight %d; "
               "lodrefine watertight %d\n",
               s.buildings, polyfit_planes_name(options.planes), options.wt_fitting, options.wt_coverage,
               options.wt_complexity, s.polyfit_closed, s.polyfit_watertight, s.lodrefine_watertight);
  std::fprintf(out, "PolyFit failures:");
  if (s.failures.empty()) std::fprintf(out, " none");
  for (const auto& [status, n] : s.failures) std::fprintf(out, " %s %d", status.c_str(), n);
  std::fprintf(out, "\nseconds per building   wall median     max | CPU median     max\n");
  std::fprintf(out, "  lodrefine              %7.3f %7.3f |    %7.3f %7.3f\n", s.lodrefine_median, s.lodrefine_max,
               s.lodrefine_cpu_median, s.lodrefine_cpu_max);
  std::fprintf(out, "  PolyFit                %7.3f %7.3f |    %7.3f %7.3f\n", s.polyfit_median, s.polyfit_max,
               s.polyfit_cpu_median, s.polyfit_cpu_max);
  std::fprintf(out,
               "PolyFit / lodrefine: %.1fx wall, %.1fx CPU (medians); per building (wall) median %.1fx, min %.1fx\n",
               s.ratio_of_medians, s.cpu_ratio_of_medians, s.ratio_median, s.ratio_min);
  std::fprintf(out, "truth RMSE (m)                 coarse lodrefine PolyFit\n");
  std::fprintf(out, "  facade, all buildings       %7.3f %9.3f       -\n", s.facade_coarse, s.facade_lodrefine);
  std::fprintf(out, "  facade, PolyFit closed      %7.3f %9.3f %7.3f\n", s.facade_coarse_closed,
               s.facade_lodrefine_closed, s.facade_polyfit_closed);
  std::fprintf(out, "  roof, all buildings         %7.3f %9.3f       -\n", s.roof_coarse, s.roof_lodrefine);
  std::fprintf(out, "  roof, PolyFit closed        %7.3f %9.3f %7.3f\n", s.roof_coarse_closed, s.roof_lodrefine_closed,
               s.roof_polyfit_closed);
}

}  // namespace lodrefine
