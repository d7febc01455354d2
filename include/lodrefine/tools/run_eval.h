// `lodrefine eval` as one call: one building (original, refined, cloud) or a run folder, Table 1
// on stdout, the requested files, and for a run folder the regression gate (gate.h).
#pragma once
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "lodrefine/core/params.h"
#include "lodrefine/formats/cloud.h"

namespace lodrefine {

struct EvalOptions {
  // One building (original, refined and cloud required; truth and meta optional) or, with `dir`,
  // a run folder (run.h's discover_run). The cloud: --cloud's values, files or folders
  // (io/cloud.h's cloud_files), read as one cloud.
  std::string original, refined;
  std::vector<std::string> clouds;
  std::string truth, meta, dir;
  // Outputs, each skipped when empty: --json, --csv, --svg-dir (created), --html (run folder only).
  std::string json_out, csv_out, svg_dir, html_out;
  int html_views = 20;  // buildings shown in 3D on the HTML page, worst first
  // The regression gate (run folder only): baseline to compare with / to write, gates, JUnit out.
  std::string baseline_in, baseline_out, gates, junit_out;
  double tolerance = 0.005;  // m a distance may grow by against the baseline
  int jobs = 1;              // buildings evaluated at once
  bool quiet = false;        // no progress line on stderr
  RefineConfig params;
  nlohmann::json params_json;  // the parameters as --json records them ("params")
  CloudOptions cloud_options;  // one building only (a run folder holds cropped PLYs)
};

// Validates the options and the gate's inputs before any work, evaluates, prints Table 1 (and
// for a run folder the outcome totals and the gate's verdict, one line per regression or breach)
// on `out`, then writes the requested files. Returns the exit code: 1 when the gate failed, else
// 0. Throws InputError on bad options or input (nothing written).
int run_eval(const EvalOptions& options, std::FILE* out);

}  // namespace lodrefine
