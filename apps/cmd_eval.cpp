// `lodrefine eval`: the paper's evaluation (C2M, ΔD, watertight rate) of one building or of a
// whole run directory, plus truth-based distances when a truth model is available. The work is
// eval/run_eval.h's run_eval(); this file declares the options.
#include <cstdio>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "lodrefine/city/refine_report.h"
#include "lodrefine/tools/run_eval.h"
#include "options.h"

namespace lodrefine::app {
namespace {

using nlohmann::json;

void add_gate_options(CLI::App* cmd, EvalOptions& a, CLI::Option* dir) {
  cmd->add_option("--write-baseline", a.baseline_out,
                  "With --dir: write the run's figures per building and pooled "
                  "(outcome, C2M, watertight, truth distances, facades moved) as a "
                  "baseline for --baseline")
      ->needs(dir);
  cmd->add_option("--baseline", a.baseline_in,
                  "With --dir: compare with this baseline; exit 1 when a building got "
                  "worse, changed outcome for the worse or went missing (one line each)")
      ->check(CLI::ExistingFile)
      ->needs(dir);
  add_ranged_option(cmd, "--tolerance", a.tolerance, "With --baseline: a distance may grow by this much (m)", 0.0,
                    100.0);
  cmd->add_option("--gates", a.gates,
                  "With --dir: absolute limits (JSON: max_c2m_rmse_refined, min_watertight_rate, "
                  "max_failed_buildings, max_building_truth_facade_rmse_refined, ...); exit 1 "
                  "on a breach")
      ->check(CLI::ExistingFile)
      ->needs(dir);
  cmd->add_option("--junit", a.junit_out,
                  "With --dir: write the verdict as JUnit XML (one test case per building and "
                  "per pooled check)")
      ->needs(dir);
}

}  // namespace

void add_eval_command(CLI::App& app) {
  static EvalOptions a;
  a.jobs = default_jobs();
  auto* cmd = app.add_subcommand("eval",
                                 "Evaluate refined models as in the paper: C2M of the facade points, centroid "
                                 "offset reduction, watertight rate (+ truth distances)");
  auto* dir = cmd->add_option("--dir", a.dir,
                              "Run directory: <id>/{coarse.obj,cloud.ply,refined.obj[,truth.obj,"
                              "meta.json,report.json]}, pooled over all buildings");
  auto* orig = cmd->add_option("--original", a.original, "Coarse model (OBJ)")->check(CLI::ExistingFile);
  cmd->add_option("--refined", a.refined, "Refined model (OBJ); a missing file is reported as a failure");
  cmd->add_option("--cloud", a.clouds,
                  "MLS crop (" + formats_text(kCloudFormatNames) +
                      "); a folder gives its cloud files by name; repeat for several: read "
                      "one after another as one cloud")
      ->check(CLI::ExistingPath);
  cmd->add_option("--truth", a.truth, "Truth model (OBJ): adds truth_facade_* / truth_roof_* distances")
      ->check(CLI::ExistingFile);
  cmd->add_option("--meta", a.meta, "Generator meta.json listing the scanned truth faces (else detected)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--json", a.json_out, "Write every figure as JSON");
  cmd->add_option("--csv", a.csv_out, "Write one row per building as CSV");
  cmd->add_option("--svg-dir", a.svg_dir, "Write C2M histogram + boxplot and a footprint per building (SVG)");
  auto* html = cmd->add_option("--html", a.html_out,
                               "With --dir: write one self-contained HTML report page (tables, "
                               "plots, footprints and 3D views; three.js embedded)");
  add_ranged_option(cmd, "--html-views", a.html_views, "Buildings shown in 3D in the HTML report, worst first", 0,
                    100000);
  html->needs(dir);
  cmd->add_option("--jobs", a.jobs, "With --dir: buildings evaluated at once (default: all cores)")
      ->check(CLI::Range(1, 1024));
  cmd->add_flag("--quiet", a.quiet, "With --dir: no progress line on stderr");
  dir->excludes(orig);
  add_gate_options(cmd, a, dir);
  add_cloud_options(cmd, a.cloud_options);
  add_param_options(cmd, a.params);
  cmd->callback([] {
    a.params_json = params_json(a.params);
    exit_code() = run_eval(a, stdout);
  });
}

}  // namespace lodrefine::app
