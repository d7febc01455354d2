// `lodrefine synth`: writes synthetic test buildings (truth, coarse model, MLS crop, meta).
#include <cstdio>
#include <string>

#include "commands.h"
#include "lodrefine/base/files.h"
#include "lodrefine/city/progress.h"
#include "lodrefine/synth/synth.h"
#include "options.h"

namespace lodrefine::app {

namespace {

struct SynthArgs {
  std::string type = "all";
  std::uint64_t seed = 1;
  int count = 1;
  std::string out, tile, rescan, city;
  double grid = 80.0;
  std::string scanner = "even";
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
  a.opt.scanner = a.scanner == "van" ? Scanner::Van : Scanner::Even;
  check_synth_options(a.opt);  // before anything is made: a van that would cast too many rays, say
  if (!a.rescan.empty()) {
    if (a.opt.scanner != Scanner::Van) throw InputError("synth --rescan: give --scanner van");
    rescan_tile(a.rescan, a.city, a.out, a.opt, a.seed, [&](const std::string& id, std::size_t points) {
      if (!a.quiet) std::printf("%s  crop=%zu points\n", id.c_str(), points);  // ids are safe names
    });
    std::printf("%s rescanned by the van -> %s/{meta.json,tile.ply,clouds,models,truth}\n",
                escaped_line(a.rescan).c_str(), escaped_line(a.out).c_str());
    return;
  }
  OutputTree out(a.out);  // what a run refused or failed half-way made is removed again
  out.folder();
  if (!a.tile.empty()) {
    std::uint64_t done = 0;
    Progress progress("synth", "buildings", std::uint64_t(a.count), Progress::mode_for_stderr(a.quiet));
    const std::uint64_t points = write_synth_tile(out, a.tile, a.count, a.seed, a.grid, a.opt,
                                                  [&](const SynthBuilding&) { progress.update(++done); });
    progress.finish();
    out.keep();
    std::printf("%d buildings -> %s/<id>/{coarse,truth}.obj, %llu points -> %s\n", a.count, escaped_line(a.out).c_str(),
                static_cast<unsigned long long>(points), escaped_line(a.tile).c_str());
    return;
  }
  const auto types =
      a.type == "all" ? all_building_types() : std::vector<BuildingType>{building_type_from_name(a.type)};
  std::vector<std::string> ids;  // every building's folder checked before the first is made
  for (auto t : types)
    for (int i = 0; i < a.count; ++i) ids.push_back(synth_building_id(t, a.seed + std::uint64_t(i)));
  check_synth_outputs(out, ids);
  for (auto t : types)
    for (int i = 0; i < a.count; ++i) {
      const auto b = make_building(t, a.seed + std::uint64_t(i), a.opt);
      write_synth_building(out, b);
      std::printf("%s  faces=%zu points=%zu scanned=[%s] moved=[%s] -> %s/%s\n", b.id.c_str(), b.truth.faces.size(),
                  b.cloud.points.size(), scanned_summary(b).c_str(), moved_summary(b).c_str(),
                  escaped_line(a.out).c_str(), b.id.c_str());
    }
  out.keep();
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
  cmd->add_option("--rescan", a.rescan,
                  "with --scanner van: a dev tile folder (meta.json, truth/, models/; ../shared/devtiles "
                  "layout) whose buildings the van scans again: --out gets the same truths and models and "
                  "the van's clouds (seed: --seed)")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--city", a.city,
                  "with --rescan: the CityJSON file the tile's buildings come from; its buildings within 40 m "
                  "stand in the street as neighbours (without it, boxes stand in for them)")
      ->check(CLI::ExistingFile);
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
  cmd->add_option("--scanner", a.scanner,
                  "even: the facades sampled evenly (--points); van: a mapping van's profile scanners, ray cast "
                  "first hit from its drives past the street facades (--van-*), with facade relief (window "
                  "reveals, glass with no return or the room behind it, doors, shop fronts, cornices, ledges, "
                  "balconies) and street clutter (parked cars, people, lamp posts, trees with porous crowns)")
      ->check(CLI::IsMember({"even", "van"}))
      ->capture_default_str();
  auto& v = o.van;
  add_ranged_option(cmd, "--van-speed", v.speed, "van: speed (m/s)", 0.5, 40.0);
  add_ranged_option(cmd, "--van-rate", v.profile_rate, "van: profiles per second, per profiler (Hz)", 1.0, 1000.0);
  add_ranged_option(cmd, "--van-step", v.angle_step_deg, "van: angle between rays of a profile (deg)", 0.01, 10.0);
  add_ranged_option(cmd, "--van-height", v.height, "van: scanner height above the road (m)", 0.5, 6.0);
  add_ranged_option(cmd, "--van-yaw", v.yaw_deg, "van: the two profilers turned +- this from across the street (deg)",
                    0.0, 80.0);
  add_ranged_option(cmd, "--van-range", v.max_range, "van: maximum range (m)", 2.0, 1000.0);
  add_ranged_option(cmd, "--van-drives", v.drives, "van: drives past each street (the second back in the far lane)", 1,
                    8);
  add_ranged_option(cmd, "--van-offset", v.offset,
                    "van: misregistration of the later drives: horizontal offset up to this (m)", 0.0, 5.0);
  add_ranged_option(cmd, "--van-heading", v.heading_deg, "van: and heading error up to this (deg)", 0.0, 5.0);
  cmd->add_flag("--no-defects", a.no_defects, "coarse model without export defects");
  cmd->add_flag("--no-nuisances", a.no_nuisances, "cloud without windows, clutter, ground and neighbours");
  cmd->add_flag("--quiet", a.quiet, "with --tile: no progress line on stderr");
  cmd->callback([] { run(a); });
}

}  // namespace lodrefine::app
