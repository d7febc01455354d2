// `lodrefine bench`: refines test buildings (generated in memory, or a dev tile's or run
// folder's with --tile) and prints the seconds of every pipeline stage per building, their
// median and maximum, and the accuracy against the known truth. With --polyfit, CGAL's PolyFit
// runs beside lodrefine on each building and the table compares their time and accuracy
// (eval/polyfit_bench.h). Speed and memory are measured here, never in timed tests.
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "commands.h"
#include "lodrefine/base/files.h"
#include "lodrefine/eval/eval.h"
#include "lodrefine/refine/refine.h"
#include "lodrefine/synth/synth.h"
#include "lodrefine/tools/polyfit_bench.h"
#include "options.h"

namespace lodrefine::app {
namespace {

struct BenchArgs {
  std::vector<std::string> types{"all"};
  int count = 3;
  int seed = 1;
  int points = 30000;
  int facades = 0;
  bool polyfit = false;
  int repeat = 1;    // refinements per building; each stage's least seconds count
  std::string tile;  // a dev tile or run folder instead of generated buildings
  std::string polyfit_planes = "model+scan";
  PolyfitOptions polyfit_options;
  RefineConfig params;
};

std::vector<BuildingType> bench_types(const BenchArgs& a) {
  std::vector<BuildingType> types;
  for (const auto& t : a.types) {
    if (t == "all") {
      const auto all = all_building_types();
      types.insert(types.end(), all.begin(), all.end());
    } else {
      types.push_back(building_type_from_name(t));
    }
  }
  return types;
}

SynthOptions synth_options(const BenchArgs& a) {
  SynthOptions opt;
  opt.target_points = a.points;
  opt.scanned_facades = a.facades;
  return opt;
}

// Hands each building of the run to `each`: read from --tile, or generated; `start` is called
// with the longest id (0 for generated ones) once the buildings are known (an unknown type or an
// empty tile is refused before any output). A building whose files cannot be read is reported
// and skipped; returns how many were.
template <class Start, class Each>
int for_each_building(const BenchArgs& a, Start start, Each each) {
  if (!a.tile.empty()) {
    const std::vector<BuildingFiles> files = discover_bench(a.tile);
    std::size_t longest = 0;
    for (const auto& f : files) longest = std::max(longest, f.id.size());
    start(longest);
    int skipped = 0;
    for (const BuildingFiles& f : files) {
      std::optional<BenchBuilding> b;
      try {
        b = read_bench_building(f);
      } catch (const InputError& e) {
        std::printf("  %s: skipped: %s\n", escaped_line(f.id).c_str(), escaped_line(e.what()).c_str());
        ++skipped;
        continue;
      }
      each(*b);
    }
    return skipped;
  }
  const std::vector<BuildingType> types = bench_types(a);
  start(std::size_t(0));
  for (BuildingType type : types)
    for (int k = 0; k < a.count; ++k) {
      SynthBuilding s = make_building(type, std::uint64_t(a.seed + k), synth_options(a));
      each(BenchBuilding{s.id, std::move(s.coarse), std::move(s.truth), std::move(s.cloud), s.scanned_truth_faces});
    }
  return 0;
}

// lodrefine and PolyFit on each building, a row as each finishes, then the summary; PolyFit's
// failures are rows. Exit code 1 when a building could not be read.
void run_polyfit(const BenchArgs& a) {
  PolyfitOptions options = a.polyfit_options;
  options.planes = a.polyfit_planes == "scan" ? PolyfitPlanes::Scan : PolyfitPlanes::ModelAndScan;
  std::vector<PolyfitComparisonRow> rows;
  const int skipped = for_each_building(
      a, [](std::size_t) { print_comparison_header(stdout); },
      [&](const BenchBuilding& b) {
        rows.push_back(compare_with_polyfit(b, a.params, options));
        print_comparison_row(rows.back(), stdout);
      });
  print_comparison_summary(summarize_comparison(rows), options, stdout);
  if (skipped) exit_code() = 1;
}

const double kNotReached = std::numeric_limits<double>::quiet_NaN();

// Seconds per stage (kRefineStageNames, then "total") of one refinement; kNotReached for a stage
// it did not reach (a building kept early), which no median or maximum counts.
std::vector<double> stage_times(const RefineTrace& t) {
  std::vector<double> s;
  for (const char* name : kRefineStageNames) s.push_back(t.stage_seconds(name).value_or(kNotReached));
  s.push_back(t.stage_seconds("total").value_or(kNotReached));
  return s;
}

// The building refined `repeat` times: the result (the same each time) and each stage's least
// seconds, since a loaded machine only ever adds time.
std::pair<RefineResult, std::vector<double>> refine_best_of(const BenchBuilding& b, const RefineConfig& params,
                                                            int repeat) {
  RefineResult r = refine_building(b.coarse, b.cloud, params);
  std::vector<double> best = stage_times(r.trace);
  for (int k = 1; k < repeat; ++k) {
    const std::vector<double> again = stage_times(refine_building(b.coarse, b.cloud, params).trace);
    for (std::size_t i = 0; i < best.size(); ++i) best[i] = std::fmin(best[i], again[i]);
  }
  return {std::move(r), std::move(best)};
}

// The table of stage times: the id column as wide as the longest id (at least 24), each stage's
// as its name (at least 7); "-" for a stage not reached.
struct StageTable {
  int id_width = 24;

  int lead() const { return id_width + 28; }  // building, points, planes, cand, mipvar
  static int width(std::size_t column) {
    return column < kRefineStageNames.size() ? std::max(7, int(std::strlen(kRefineStageNames[column]))) : 7;
  }
  static void stage_names() {
    for (std::size_t i = 0; i < kRefineStageNames.size(); ++i) std::printf(" %*s", width(i), kRefineStageNames[i]);
    std::printf(" %*s", width(kRefineStageNames.size()), "total");
  }
  static void cells(const std::vector<double>& seconds) {
    for (std::size_t i = 0; i < seconds.size(); ++i)
      if (std::isnan(seconds[i])) std::printf(" %*s", width(i), "-");
      else std::printf(" %*.3f", width(i), seconds[i]);
  }
  void header() const {
    std::printf("%-*s %7s %6s %5s %6s |", id_width, "building", "points", "planes", "cand", "mipvar");
    stage_names();
    std::printf(" | %8s %8s | %s\n", "facade0", "facade1", "outcome");
  }
  // The stages' median and maximum over the buildings that reached them, under their columns.
  void summary(const std::vector<std::vector<double>>& times, int repeat) const {
    const std::string title = "seconds per building, best of " + std::to_string(repeat);
    std::printf("\n%-*s |", lead(), title.c_str());
    stage_names();
    std::printf("\n");
    for (const bool max : {false, true}) {
      std::vector<double> row;
      for (std::size_t i = 0; i < times.front().size(); ++i) {
        std::vector<double> col;
        for (const auto& t : times)
          if (!std::isnan(t[i])) col.push_back(t[i]);
        std::sort(col.begin(), col.end());
        row.push_back(col.empty() ? kNotReached : max ? col.back() : percentile_sorted(col, 0.5));
      }
      std::printf("%-*s |", lead(), max ? "  max" : "  median");
      cells(row);
      std::printf("\n");
    }
  }
};

// Each building refined (--repeat times), a row as each finishes: its stage times and the truth
// facade RMSE before and after; then the stages' median and max over the buildings. Exit code 1
// when a building could not be read.
void run(const BenchArgs& a) {
  if (a.polyfit) return run_polyfit(a);
  double sum_sq_after = 0.0, sum_sq_before = 0.0;
  std::size_t n_after = 0;
  int refined = 0, valid = 0;
  std::vector<std::vector<double>> times;
  StageTable table;
  auto start = [&](std::size_t longest_id) {
    table.id_width = std::max(table.id_width, int(longest_id));
    table.header();
  };
  const int skipped = for_each_building(a, start, [&](const BenchBuilding& b) {
    const auto [r, best] = refine_best_of(b, a.params, a.repeat);
    const RefineTrace& t = r.trace;
    const BuildingEval ev = evaluate_against_truth(b, r.mesh, a.params);
    const double f0 = ev.truth_facade_before ? ev.truth_facade_before->rmse : -1;
    const double f1 = ev.truth_facade_after ? ev.truth_facade_after->rmse : -1;
    if (ev.truth_facade_after && ev.truth_facade_before) {
      sum_sq_after += f1 * f1 * double(ev.truth_facade_after->count);
      sum_sq_before += f0 * f0 * double(ev.truth_facade_before->count);
      n_after += ev.truth_facade_after->count;
    }
    std::printf("%-*s %7zu %6zu %5d %6d |", table.id_width, escaped_line(b.id).c_str(), b.cloud.points.size(),
                t.planes ? t.planes->size() : std::size_t(0), t.selection ? t.selection->candidates : 0,
                t.selection ? t.selection->selection.variables : 0);
    StageTable::cells(best);
    std::printf(" | %8.4f %8.4f | %s\n", f0, f1, outcome_name(r.outcome));
    std::fflush(stdout);
    times.push_back(best);
    refined += r.refined();
    valid += r.valid && ev.watertight_after;
  });
  if (skipped) exit_code() = 1;
  if (times.empty()) {
    std::printf("\n0 buildings benched, %d skipped\n", skipped);
    return;
  }
  table.summary(times, a.repeat);
  struct rusage ru {};
  getrusage(RUSAGE_SELF, &ru);
  std::printf("\n%zu buildings, %d refined, %d valid+watertight, %d skipped; peak RSS %.0f MB\n", times.size(), refined,
              valid, skipped, ru.ru_maxrss / 1024.0);
  if (n_after)
    std::printf("truth scanned-facade RMSE: before %.4f m, after %.4f m (%zu samples)\n",
                std::sqrt(sum_sq_before / double(n_after)), std::sqrt(sum_sq_after / double(n_after)), n_after);
}

}  // namespace

void add_bench_command(CLI::App& app) {
  static BenchArgs args;
  auto* cmd = app.add_subcommand(
      "bench", "Benchmark: refine generated buildings or a tile's, print seconds per stage (median, max) and accuracy");
  // What generates the buildings; none of it applies to --tile's.
  const std::vector<CLI::Option*> generated = {
      cmd->add_option("--type", args.types, "Building types (or all)")->capture_default_str(),
      add_ranged_option(cmd, "--count", args.count, "Buildings per type", 1, 100000),
      cmd->add_option("--first-seed", args.seed, "First building seed (the RANSAC seed is --seed)")
          ->capture_default_str(),
      add_ranged_option(cmd, "--points", args.points, "Target facade points per building", 100, 10000000),
      add_ranged_option(cmd, "--facades", args.facades,
                        "Scanned facades per building (0: random 1..3, as in the generator)", 0, 20)};
  auto* polyfit = cmd->add_flag("--polyfit", args.polyfit,
                                "Run CGAL's PolyFit beside lodrefine on each building; print both methods' "
                                "time and truth accuracy and PolyFit's failures");
  auto* tile =
      cmd->add_option("--tile", args.tile,
                      "The buildings of a dev tile (models/, clouds/, truth/) or a run folder (<id>/coarse.obj, "
                      "cloud.ply, truth.obj) instead of generated ones")
          ->check(CLI::ExistingDirectory);
  for (CLI::Option* o : generated) tile->excludes(o);
  add_ranged_option(cmd, "--repeat", args.repeat,
                    "Refinements per building; each stage's least seconds count (a loaded machine only adds time)", 1,
                    100)
      ->excludes(polyfit);
  cmd->add_option("--polyfit-planes", args.polyfit_planes,
                  "PolyFit's planes: the scan's (lodrefine's plane stage), or those and the coarse model's")
      ->check(CLI::IsMember({"scan", "model+scan"}))
      ->capture_default_str()
      ->needs(polyfit);
  add_ranged_option(cmd, "--polyfit-cpu-limit", args.polyfit_options.cpu_limit,
                    "CPU seconds PolyFit may take per building (it runs in a child process; beyond: time-limit)", 1.0,
                    86400.0)
      ->needs(polyfit);
  add_param_options(cmd, args.params);
  cmd->callback([] { run(args); });
}

}  // namespace lodrefine::app
