// `lodrefine bench`: generates a tile of test buildings in memory, refines each one and
// prints time per stage and per building, with accuracy against the known truth. Speed and
// memory are measured here, never in timed tests.
#include <sys/resource.h>

#include <chrono>
#include <cstdio>

#include "commands.h"
#include "lodrefine/core/geometry.h"
#include "lodrefine/core/refine.h"
#include "lodrefine/eval/eval.h"
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
  Params params;
};

void run(const BenchArgs& a) {
  std::vector<BuildingType> types;
  for (const auto& t : a.types) {
    if (t == "all") {
      const auto all = all_building_types();
      types.insert(types.end(), all.begin(), all.end());
    } else {
      types.push_back(building_type_from_name(t));
    }
  }
  SynthOptions opt;
  opt.target_points = a.points;
  opt.scanned_facades = a.facades;
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
  add_param_options(cmd, args.params);
  cmd->callback([] { run(args); });
}

}  // namespace lodrefine::app
