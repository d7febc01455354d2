// `lodrefine bench`: generates a tile of test buildings in memory, refines each one and
// prints time per stage and per building, with accuracy against the known truth. With
// --polyfit, CGAL's PolyFit runs beside lodrefine on each building (generated or read from
// --tile) and the table compares their time and accuracy (eval/polyfit_bench.h). Speed and
// memory are measured here, never in timed tests.
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <optional>

#include "commands.h"
#include "lodrefine/core/geometry.h"
#include "lodrefine/core/refine.h"
#include "lodrefine/eval/eval.h"
#include "lodrefine/eval/polyfit_bench.h"
#include "lodrefine/synth/synth.h"
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
  std::string tile;  // a dev tile or run folder instead of generated buildings (with --polyfit)
  std::string polyfit_planes = "model+scan";
  PolyfitOptions polyfit_options;
  Params params;
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

// lodrefine and PolyFit on each building, a row as each finishes, then the summary. A building
// whose files cannot be read is reported and skipped; PolyFit's failures are rows.
void run_polyfit(const BenchArgs& a) {
  PolyfitOptions options = a.polyfit_options;
  options.planes = a.polyfit_planes == "scan" ? PolyfitPlanes::Scan : PolyfitPlanes::ModelAndScan;
  const std::vector<BuildingFiles> files = a.tile.empty() ? std::vector<BuildingFiles>{} : discover_bench(a.tile);
  std::vector<PolyfitComparisonRow> rows;
  print_comparison_header(stdout);
  auto compare = [&](const BenchBuilding& b) {
    rows.push_back(compare_with_polyfit(b, a.params, options));
    print_comparison_row(rows.back(), stdout);
  };
  if (!a.tile.empty()) {
    for (const BuildingFiles& f : files) {
      std::optional<BenchBuilding> b;
      try {
        b = read_bench_building(f);
      } catch (const InputError& e) {
        std::printf("  %s: skipped: %s\n", f.id.c_str(), e.what());
        continue;
      }
      compare(*b);
    }
  } else {
    for (BuildingType type : bench_types(a))
      for (int k = 0; k < a.count; ++k) {
        SynthBuilding s = make_building(type, std::uint64_t(a.seed + k), synth_options(a));
        compare({s.id, std::move(s.coarse), std::move(s.truth), std::move(s.cloud), s.scanned_truth_faces});
      }
  }
  print_comparison_summary(summarize_comparison(rows), options, stdout);
}

void run(const BenchArgs& a) {
  if (a.polyfit) return run_polyfit(a);
  const std::vector<BuildingType> types = bench_types(a);
  const SynthOptions opt = synth_options(a);
  std::printf("%-24s %7s %6s %5s %6s %6s | %7s %7s %7s %7s %7s | %8s %8s | %s\n", "building", "points", "planes",
              "cand", "mipvar", "mip_s", "repair", "planes", "match", "replace", "total", "facade0", "facade1",
              "outcome");
  double total_time = 0.0, sum_sq_after = 0.0, sum_sq_before = 0.0;
  std::size_t n_after = 0;
  int n = 0, refined = 0, valid = 0;
  for (BuildingType type : types)
    for (int k = 0; k < a.count; ++k) {
      const SynthBuilding b = make_building(type, std::uint64_t(a.seed + k), opt);
      const RefineResult r = refine_building(b.coarse, b.cloud, a.params);
      const RefineTrace& t = r.trace;
      int cand = 0, vars = 0;
      double mip = 0.0;
      if (t.selection) {
        cand = t.selection->candidates;
        vars = t.selection->selection.variables;
        mip = t.selection->selection.seconds;
      }
      // Accuracy in a local frame: points on the truth's scanned walls to each model.
      const Vec3 o = local_origin(b.truth);
      PointCloud local_cloud = b.cloud;
      for (auto& p : local_cloud.points) p -= o;
      const Mesh truth = translated(b.truth, -o);
      const BuildingEval ev = evaluate_building(translated(b.coarse, -o), translated(r.mesh, -o), local_cloud, &truth,
                                                a.params, &b.scanned_truth_faces);
      const double f0 = ev.truth_facade_before ? ev.truth_facade_before->rmse : -1;
      const double f1 = ev.truth_facade_after ? ev.truth_facade_after->rmse : -1;
      if (ev.truth_facade_after) {
        sum_sq_after += f1 * f1 * double(ev.truth_facade_after->count);
        sum_sq_before += f0 * f0 * double(ev.truth_facade_before->count);
        n_after += ev.truth_facade_after->count;
      }
      std::printf("%-24s %7zu %6zu %5d %6d %6.3f | %7.3f %7.3f %7.3f %7.3f %7.3f | %8.4f %8.4f | %s\n", b.id.c_str(),
                  b.cloud.points.size(), t.planes ? t.planes->size() : std::size_t(0), cand, vars, mip,
                  t.stage_seconds("repair"), t.stage_seconds("planes"), t.stage_seconds("matching"),
                  t.stage_seconds("replacement"), t.stage_seconds("total"), f0, f1, outcome_name(r.outcome));
      std::fflush(stdout);
      total_time += t.stage_seconds("total");
      ++n;
      refined += r.refined();
      valid += r.valid && ev.watertight_after;
    }
  struct rusage ru {};
  getrusage(RUSAGE_SELF, &ru);
  std::printf("\n%d buildings, %d refined, %d valid+watertight; mean %.3f s per building; peak RSS %.0f MB\n", n,
              refined, valid, n ? total_time / n : 0.0, ru.ru_maxrss / 1024.0);
  if (n_after)
    std::printf("truth scanned-facade RMSE: before %.4f m, after %.4f m (%zu samples)\n",
                std::sqrt(sum_sq_before / n_after), std::sqrt(sum_sq_after / n_after), n_after);
}

}  // namespace

void add_bench_command(CLI::App& app) {
  static BenchArgs args;
  auto* cmd = app.add_subcommand("bench", "Benchmark: refine a generated tile, print time per stage and accuracy");
  cmd->add_option("--type", args.types, "Building types (or all)")->capture_default_str();
  add_ranged_option(cmd, "--count", args.count, "Buildings per type", 1, 100000);
  cmd->add_option("--first-seed", args.seed, "First building seed (the RANSAC seed is --seed)")->capture_default_str();
  add_ranged_option(cmd, "--points", args.points, "Target facade points per building", 100, 10000000);
  add_ranged_option(cmd, "--facades", args.facades,
                    "Scanned facades per building (0: random 1..3, as in the generator)", 0, 20);
  auto* polyfit = cmd->add_flag("--polyfit", args.polyfit,
                                "Run CGAL's PolyFit beside lodrefine on each building; print both methods' "
                                "time and truth accuracy and PolyFit's failures");
  cmd->add_option("--tile", args.tile,
                  "With --polyfit: the buildings of a dev tile (models/, clouds/, truth/) or a run "
                  "folder (<id>/coarse.obj, cloud.ply, truth.obj) instead of generated ones")
      ->check(CLI::ExistingDirectory)
      ->needs(polyfit);
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
