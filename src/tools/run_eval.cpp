// `lodrefine eval` as one call: evaluate, print, write, gate.
#include "lodrefine/tools/run_eval.h"

#include <filesystem>
#include <optional>
#include <vector>

#include "lodrefine/base/files.h"
#include "lodrefine/eval/plots.h"
#include "lodrefine/tools/gate.h"
#include "lodrefine/tools/report.h"
#include "lodrefine/tools/run.h"
#include "lodrefine/tools/run_table.h"

namespace lodrefine {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// C2M histogram and boxplot over every evaluated building's facade points (their pooled bins).
struct C2mPlots {
  std::string histogram, boxplot;
};
C2mPlots c2m_plots(const PooledSeries& series) {
  const char* title = "C2M signed distance of the facade points";
  return {svg_histogram(series.c2m_before, series.c2m_after, title),
          svg_boxplot(series.c2m_before, series.c2m_after, title)};
}

// The self-contained page: Table 1, plots, the table worst first, and the worst buildings in 3D.
std::string run_html(const EvalOptions& a, const std::vector<RunRow>& rows, const PooledEval& pooled,
                     const C2mPlots& plots) {
  HtmlReport h;
  h.title = "lodrefine run " + fs::path(a.dir).filename().string() + ": " + std::to_string(rows.size()) + " buildings";
  h.table1 = table1_text(pooled, true) + totals_text(run_totals(rows));
  h.histogram_svg = plots.histogram;
  h.boxplot_svg = plots.boxplot;
  h.columns = html_columns();
  h.rows = json::array();
  for (const RunRow* r : worst_first(rows)) {
    h.rows.push_back(html_row(*r));
    if (int(h.views.size()) >= a.html_views) continue;
    try {
      h.views.push_back(html_view(*r, a.params));
    } catch (const InputError&) {  // unreadable inputs: the table row says so, no view
    }
  }
  return html_report(h);
}

void write_outputs(const EvalOptions& a, const std::vector<RunRow>& rows, const PooledEval& pooled,
                   const PooledSeries& series) {
  const auto order = worst_first(rows);
  if (!a.json_out.empty())
    write_file_atomic(a.json_out, run_json(order, pooled, run_totals(rows), a.params_json, a.dir)
                                          .dump(2, ' ', false, json::error_handler_t::replace) +
                                      "\n");
  if (!a.csv_out.empty()) write_file_atomic(a.csv_out, csv_text(order));
  if (a.svg_dir.empty() && a.html_out.empty()) return;
  const C2mPlots plots = c2m_plots(series);
  if (!a.svg_dir.empty()) {
    write_file_atomic((fs::path(a.svg_dir) / "c2m_histogram.svg").string(), plots.histogram);
    write_file_atomic((fs::path(a.svg_dir) / "c2m_boxplot.svg").string(), plots.boxplot);
  }
  if (!a.html_out.empty()) write_file_atomic(a.html_out, run_html(a, rows, pooled, plots));
}

// The gate's inputs, read before any work so that a bad file costs no evaluation.
struct GateInputs {
  std::optional<RunFigures> baseline;
  std::optional<Gates> gates;
};

GateInputs read_gate_inputs(const EvalOptions& a) {
  for (const std::string& out : {a.baseline_out, a.junit_out})
    if (!out.empty() && !fs::is_directory(fs::absolute(out).parent_path()))
      throw InputError(out + ": output directory " + fs::absolute(out).parent_path().string() + " does not exist");
  GateInputs in;
  if (!a.baseline_in.empty()) in.baseline = read_baseline(read_file(a.baseline_in), a.baseline_in);
  if (!a.gates.empty()) in.gates = read_gates(read_file(a.gates), a.gates);
  return in;
}

// Writes the baseline, compares and gates; one line per regression or breach on `out`. True
// when the gate failed.
bool apply_gate(const EvalOptions& a, const GateInputs& in, const RunFigures& run, std::FILE* out) {
  if (!a.baseline_out.empty()) write_file_atomic(a.baseline_out, baseline_json(run));
  if (!in.baseline && !in.gates && a.junit_out.empty()) return false;
  const GateVerdict v =
      check_run(run, in.baseline ? &*in.baseline : nullptr, in.gates ? &*in.gates : nullptr, a.tolerance);
  if (!a.junit_out.empty()) write_file_atomic(a.junit_out, junit_xml(v, "lodrefine eval " + a.dir));
  std::fprintf(out, "\ngate: %zu building(s), %zu new, %zu pooled check(s): %s\n", v.buildings.size(),
               v.new_buildings.size(), v.pooled_checks.size(), v.failed() ? "FAILED" : "passed");
  for (const std::string& id : v.new_buildings)
    std::fprintf(out, "new: %s (not in the baseline)\n", shown_id(id).c_str());
  for (const GateLine& l : v.failures)
    std::fprintf(out, "%s: %s\n", l.check == "baseline" ? "regression" : "breach", l.text.c_str());
  return v.failed();
}

// Every file the evaluation reads: the options' (`clouds`: --cloud's files) and, with --dir, each
// building's of the run.
std::vector<FileOption> eval_inputs(const EvalOptions& a, const std::vector<std::string>& clouds) {
  std::vector<FileOption> in = {{"--original", a.original}, {"--refined", a.refined},      {"--truth", a.truth},
                                {"--meta", a.meta},         {"--baseline", a.baseline_in}, {"--gates", a.gates}};
  for (const std::string& cloud : clouds) in.push_back({"--cloud", cloud});
  if (a.dir.empty() || !fs::is_directory(a.dir)) return in;
  for (const BuildingFiles& f : discover_run(a.dir)) {
    for (const std::string* path : {&f.original, &f.refined, &f.truth, &f.meta, &f.report, &f.failed})
      in.push_back({"run's", *path});
    for (const std::string& cloud : f.clouds) in.push_back({"run's", cloud});
  }
  return in;
}

void check_options(const EvalOptions& a, const std::vector<std::string>& clouds) {
  a.params.validate();
  // An output given as an input (--json r.obj --refined r.obj, or --json RUN/<id>/coarse.obj)
  // replaced it without a word.
  std::vector<FileOption> outputs = {{"--json", a.json_out},
                                     {"--csv", a.csv_out},
                                     {"--html", a.html_out},
                                     {"--write-baseline", a.baseline_out},
                                     {"--junit", a.junit_out}};
  if (!a.svg_dir.empty())
    for (const char* name : {"c2m_histogram.svg", "c2m_boxplot.svg"})
      outputs.push_back({"--svg-dir", (fs::path(a.svg_dir) / name).string()});
  refuse_overwrites(eval_inputs(a, clouds), outputs);
  if (!a.dir.empty() && !a.cloud_options.classes.empty())
    throw InputError(a.dir + ": --classes applies to --cloud; a run folder holds cropped PLY clouds");
  if (a.dir.empty() && (a.original.empty() || a.refined.empty() || clouds.empty()))
    throw InputError("eval: give --dir RUN_DIR, or --original, --refined and --cloud");
}

// The one building of --original/--refined/--cloud; a refined model that cannot be used is a
// warning (the row says failed).
RunRow evaluate_single(const EvalOptions& a, const std::vector<std::string>& clouds, PooledSeries& series) {
  RunRow row = evaluate_building_files({"", a.original, a.refined, clouds, a.truth, a.meta, "", ""}, a.params,
                                       a.svg_dir, a.cloud_options);
  if (!row.eval.ok()) std::fprintf(stderr, "lodrefine: warning: %s\n", escaped_line(row.eval.error).c_str());
  series.add(row.eval);
  return row;
}

}  // namespace

int run_eval(const EvalOptions& a, std::FILE* out) {
  std::vector<SkippedEntry> skipped;
  const std::vector<std::string> clouds =
      a.clouds.empty() ? std::vector<std::string>() : cloud_files(a.clouds, "--cloud", &skipped);
  check_options(a, clouds);
  const GateInputs gate_inputs = read_gate_inputs(a);
  const bool batch = !a.dir.empty();
  if (!a.svg_dir.empty()) fs::create_directories(a.svg_dir);
  std::vector<RunRow> rows;
  PooledSeries series;
  if (batch)
    rows =
        evaluate_run(a.dir, a.params, a.svg_dir, a.jobs, series, Progress::mode_for_stderr(a.quiet), a.cloud_options);
  else rows.push_back(evaluate_single(a, clouds, series));
  std::vector<BuildingEval> evals;
  for (const RunRow& r : rows) evals.push_back(r.eval);
  const PooledEval pooled = pool_evaluations(evals, series);
  if (!skipped.empty()) std::fprintf(out, "%s\n", skipped_entries_text(skipped).c_str());
  std::fputs(table1_text(pooled, batch).c_str(), out);
  if (batch) std::fputs(totals_text(run_totals(rows)).c_str(), out);
  write_outputs(a, rows, pooled, series);
  return batch && apply_gate(a, gate_inputs, run_figures(rows, pooled), out) ? 1 : 0;
}

}  // namespace lodrefine
