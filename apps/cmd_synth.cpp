// `lodrefine synth`: writes synthetic test buildings (truth, coarse model, MLS crop, meta).
#include <cstdio>
#include <string>

#include "commands.h"
#include "lodrefine/io/progress.h"
#include "lodrefine/synth/synth.h"
#include "options.h"

namespace lodrefine::app {

namespace {

struct SynthArgs {
  std::string type = "all";
  std::uint64_t seed = 1;
  int count = 1;
  std::string out, tile;
  double grid = 80.0;
  bool no_defects = false, no_nuisances = false, quiet = false;
  SynthOptions opt;
};

std::string moved_summary(const SynthBuilding& b) {
  std::string s;
  for (const auto& m : b.moved_walls) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s%d:%+.2fm/%+.1fdeg%s", s.empty() ? "" : ",", m.truth_faces.front(), m.offset,
                  m.rotation_deg, m.scanned ? "*" : "");
    s += buf;
  }
  return s;
}

std::string scanned_summary(const SynthBuilding& b) {
  std::string s;
  for (int f : b.scanned_truth_faces) s += (s.empty() ? "" : ",") + std::to_string(f);
  return s;
}

void run(SynthArgs& a) {
  a.opt.defects = !a.no_defects;
  a.opt.nuisances = !a.no_nuisances;
  if (!a.tile.empty()) {
    std::uint64_t done = 0;
    Progress progress("synth", "buildings", std::uint64_t(a.count), Progress::mode_for_stderr(a.quiet));
    const std::uint64_t points = write_synth_tile(a.out, a.tile, a.count, a.seed, a.grid, a.opt,
                                                  [&](const SynthBuilding&) { progress.update(++done); });
    progress.finish();
    std::printf("%d buildings -> %s/<id>/{coarse,truth}.obj, %llu points -> %s\n", a.count, a.out.c_str(),
                static_cast<unsigned long long>(points), a.tile.c_str());
    return;
  }
  const auto types =
      a.type == "all" ? all_building_types() : std::vector<BuildingType>{building_type_from_name(a.type)};
  for (auto t : types)
    for (int i = 0; i < a.count; ++i) {
      const auto b = make_building(t, a.seed + std::uint64_t(i), a.opt);
      write_synth_building(a.out, b);
      std::printf("%s  faces=%zu points=%zu scanned=[%s] moved=[%s] -> %s/%s\n", b.id.c_str(), b.truth.faces.size(),
                  b.cloud.points.size(), scanned_summary(b).c_str(), moved_summary(b).c_str(), a.out.c_str(),
                  b.id.c_str());
    }
}

}  // namespace

void add_synth_command(CLI::App& app) {
  static SynthArgs a;
  auto* cmd = app.add_subcommand("synth",
                                 "Generate synthetic buildings with known truth: truth.obj, coarse.obj, "
                                 "cloud.ply, meta.json per building");
  cmd->add_option("--type", a.type, "flat|gable|hip|shed|stepped|lshape|tshape|polygon|recess|bay|setback|all")
      ->capture_default_str();
  cmd->add_option("--seed", a.seed, "first seed (seeds seed..seed+count-1)")->capture_default_str();
  add_ranged_option(cmd, "--count", a.count, "buildings per type", 1, 100000);
  cmd->add_option("--out", a.out, "output directory (one subdirectory per building)")->required();
  cmd->add_option("--tile", a.tile,
                  "city tile: --count buildings in all (types cycling) on a grid, their clouds "
                  "streamed into this one PLY instead of <id>/cloud.ply (cut with `lodrefine crop`)");
  add_ranged_option(cmd, "--grid", a.grid, "with --tile: grid spacing between buildings (m)", 10.0, 10000.0);
  auto& o = a.opt;
  add_ranged_option(cmd, "--shift-min", o.min_shift, "min facade offset (m)", 0.0, 3.0);
  add_ranged_option(cmd, "--shift-max", o.max_shift, "max facade offset (m)", 0.0, 3.0);
  add_ranged_option(cmd, "--rotation-max", o.max_rotation_deg, "max facade rotation about a vertical axis (deg)", 0.0,
                    15.0);
  add_ranged_option(cmd, "--global-shift", o.global_shift, "max shift of the whole coarse model (m)", 0.0, 10.0);
  add_ranged_option(cmd, "--facades", o.scanned_facades,
                    "scanned facades (0: random 1..3; recess/bay/setback: the street walls)", 0, 20);
  add_ranged_option(cmd, "--noise", o.noise, "MLS range noise sigma (m)", 0.0, 0.5);
  add_ranged_option(cmd, "--points", o.target_points, "points on the scanned facades before nuisances", 100, 10000000);
  cmd->add_option("--origin-x", o.origin.x(), "georeferenced origin x")->capture_default_str();
  cmd->add_option("--origin-y", o.origin.y(), "georeferenced origin y")->capture_default_str();
  cmd->add_flag("--no-defects", a.no_defects, "coarse model without export defects");
  cmd->add_flag("--no-nuisances", a.no_nuisances, "cloud without windows, clutter, ground and neighbours");
  cmd->add_flag("--quiet", a.quiet, "with --tile: no progress line on stderr");
  cmd->callback([] { run(a); });
}

}  // namespace lodrefine::app
