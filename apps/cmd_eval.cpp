// `lodrefine eval`: the paper's evaluation (C2M, ΔD, watertight rate) of one building or of a
// whole run directory, plus truth-based distances when a truth model is available.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "lodrefine/eval.h"
#include "lodrefine/geometry.h"
#include "lodrefine/io.h"
#include "lodrefine/plots.h"
#include "lodrefine/refine.h"
#include "options.h"

namespace lodrefine::app {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct EvalArgs {
  std::string original, refined, cloud, truth, meta, dir, json_out, csv_out, svg_dir;
  Params params;
  CloudOptions cloud_options;  // single-building mode (a run folder holds cropped PLYs)
};

// The files of one building; empty strings for absent optional ones.
struct BuildingFiles {
  std::string id, original, refined, cloud, truth, meta, report;
};

// One evaluated building with what the outputs need besides the metrics.
struct Row {
  BuildingEval eval;
  Vec3 origin = Vec3::Zero();      // local frame origin (added back to centroids in the JSON)
  std::string truth_faces_source;  // "meta.json", "detected" or empty
  json report;                     // the refine report.json, if any
};

json read_json_or_null(const std::string& path) {
  if (path.empty() || !fs::exists(path)) return nullptr;
  std::ifstream in(path);
  return json::parse(in, nullptr, false);  // discarded (null-like) on a parse error
}

// Scanned truth faces listed by the generator, if present and plausible (walls of this truth).
std::optional<std::vector<int>> meta_scanned_faces(const std::string& meta_path, const Mesh& truth) {
  const json meta = read_json_or_null(meta_path);
  if (!meta.is_object() || !meta.contains("scanned_truth_faces")) return std::nullopt;
  std::vector<int> faces;
  for (const auto& f : meta["scanned_truth_faces"]) {
    const int i = f.get<int>();
    if (i < 0 || std::size_t(i) >= truth.faces.size() || truth.faces[std::size_t(i)].sem != Semantic::Wall) {
      std::fprintf(stderr, "lodrefine: warning: %s: scanned face %d is not a wall of the truth; detecting instead\n",
                   meta_path.c_str(), i);
      return std::nullopt;
    }
    faces.push_back(i);
  }
  return faces;
}

// A missing or unreadable refined model is a failure row, never an abort.
Mesh read_refined(const std::string& path, std::string& error) {
  if (path.empty() || !fs::exists(path)) {
    error = "refined model missing (" + (path.empty() ? std::string("no path") : path) + ")";
    return {};
  }
  try {
    return read_obj(path);
  } catch (const InputError& e) {
    error = e.what();
    return {};
  }
}

std::string file_safe(std::string s) {
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  return s.empty() ? "building" : s;
}

void write_footprint(const std::string& svg_dir, const BuildingEval& e, const Mesh& original, const Mesh& refined,
                     const PointCloud& cloud) {
  std::vector<Vec3> pts;
  for (int i : e.facade_index) pts.push_back(cloud.points[std::size_t(i)]);
  const std::string title = e.id + ": original vs refined, facade points (XY)";
  write_file_atomic((fs::path(svg_dir) / ("footprint_" + file_safe(e.id) + ".svg")).string(),
                    svg_footprint(original, refined, pts, title));
}

// Reads, moves to a local frame (georeferenced inputs) and evaluates one building.
Row evaluate_files(const BuildingFiles& f, const Params& params, const std::string& svg_dir,
                   const CloudOptions& cloud_options = {}) {
  Row row;
  const Mesh original_geo = read_obj(f.original);
  row.origin = local_origin(original_geo);
  const Vec3 to_local = -row.origin;
  const Mesh original = translated(original_geo, to_local);
  PointCloud cloud = read_cloud(f.cloud, cloud_options);
  for (auto& p : cloud.points) p += to_local;
  std::string refined_error;
  const Mesh refined = translated(read_refined(f.refined, refined_error), to_local);
  std::optional<Mesh> truth;
  std::optional<std::vector<int>> scanned;
  if (!f.truth.empty()) {
    truth = translated(read_obj(f.truth), to_local);
    scanned = meta_scanned_faces(f.meta, *truth);
    row.truth_faces_source = scanned ? "meta.json" : "detected";
  }
  row.eval = evaluate_building(original, refined, cloud, truth ? &*truth : nullptr, params, scanned ? &*scanned : nullptr);
  if (!f.id.empty()) row.eval.id = f.id;
  if (!refined_error.empty()) row.eval.error = refined_error;
  row.report = read_json_or_null(f.report);
  if (!svg_dir.empty()) write_footprint(svg_dir, row.eval, original, refined, cloud);
  return row;
}

// A building whose inputs cannot even be read still gets its row.
Row failure_row(const std::string& id, const std::string& error) {
  Row row;
  row.eval.id = id;
  row.eval.error = error;
  row.eval.delta_d = std::nan("");
  return row;
}

// RUN_DIR/<id>/ with a coarse.obj, sorted by id.
std::vector<BuildingFiles> discover(const std::string& dir) {
  if (!fs::is_directory(dir)) throw InputError(dir + ": not a directory");
  std::vector<BuildingFiles> out;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const fs::path d = entry.path();
    if (!entry.is_directory() || !fs::exists(d / "coarse.obj")) continue;
    auto optional_file = [&](const char* name) { return fs::exists(d / name) ? (d / name).string() : std::string(); };
    out.push_back({d.filename().string(), (d / "coarse.obj").string(), (d / "refined.obj").string(),
                   (d / "cloud.ply").string(), optional_file("truth.obj"), optional_file("meta.json"),
                   optional_file("report.json")});
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  if (out.empty()) throw InputError(dir + ": no building directories (<id>/coarse.obj) found");
  return out;
}

std::string fmt(double v, int decimals = 3) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

void progress(std::size_t k, std::size_t n, const Row& r, double seconds) {
  const BuildingEval& e = r.eval;
  if (!e.ok()) {
    std::fprintf(stderr, "[%zu/%zu] %s: FAILED: %s\n", k, n, e.id.c_str(), e.error.c_str());
    return;
  }
  if (e.facade_points == 0) {
    std::fprintf(stderr, "[%zu/%zu] %s: no facade points selected, watertight %s -> %s (%.1f s)\n", k, n, e.id.c_str(),
                 e.watertight_before ? "yes" : "no", e.watertight_after ? "yes" : "no", seconds);
    return;
  }
  std::fprintf(stderr, "[%zu/%zu] %s: %zu facade points, C2M RMSE %s -> %s m, dD %s m, watertight %s -> %s (%.1f s)\n",
               k, n, e.id.c_str(), e.facade_points, fmt(e.before.rmse).c_str(), fmt(e.after.rmse).c_str(),
               fmt(e.delta_d).c_str(), e.watertight_before ? "yes" : "no", e.watertight_after ? "yes" : "no", seconds);
}

std::vector<Row> evaluate_run(const std::string& dir, const Params& params, const std::string& svg_dir) {
  const auto buildings = discover(dir);
  std::vector<Row> rows;
  for (std::size_t k = 0; k < buildings.size(); ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    try {
      rows.push_back(evaluate_files(buildings[k], params, svg_dir));
    } catch (const InputError& e) {
      rows.push_back(failure_row(buildings[k].id, e.what()));
    }
    progress(k + 1, buildings.size(), rows.back(),
             std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return rows;
}

// --- outputs -----------------------------------------------------------------------------

json stats_json(const std::optional<DistanceStats>& s) {
  if (!s) return nullptr;
  return {{"count", s->count}, {"rmse", s->rmse},     {"mae", s->mae}, {"mean", s->mean},
          {"std", s->std},     {"median", s->median}, {"p95", s->p95}, {"max_abs", s->max_abs}};
}

json number_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json point_json(const Vec3& p) { return {p.x(), p.y(), p.z()}; }

json row_json(const Row& r) {
  const BuildingEval& e = r.eval;
  json j = {{"id", e.id},
            {"status", e.ok() ? "ok" : "failed"},
            {"error", e.error},
            {"facade_points", e.facade_points},
            {"c2m", {{"original", stats_json(e.before)}, {"refined", stats_json(e.ok() ? std::optional(e.after) : std::nullopt)}}},
            {"delta_d", number_or_null(e.delta_d)},
            {"watertight", {{"original", e.watertight_before}, {"refined", e.watertight_after}}},
            {"centroids",
             {{"mls", point_json(e.c_mls + r.origin)},
              {"original", point_json(e.c_init + r.origin)},
              {"refined", e.ok() ? point_json(e.c_ref + r.origin) : json(nullptr)}}}};
  if (!r.truth_faces_source.empty())
    j["truth"] = {{"scanned_faces", e.scanned_truth_faces},
                  {"scanned_faces_from", r.truth_faces_source},
                  {"facade", {{"original", stats_json(e.truth_facade_before)}, {"refined", stats_json(e.truth_facade_after)}}},
                  {"roof", {{"original", stats_json(e.truth_roof_before)}, {"refined", stats_json(e.truth_roof_after)}}}};
  if (r.report.is_object()) j["refine_outcome"] = r.report.value("outcome", std::string());
  return j;
}

json pooled_json(const PooledEval& p) {
  return {{"buildings", p.buildings},
          {"failed", p.failed},
          {"evaluated", p.evaluated},
          {"pooled_over_points",
           {{"c2m", {{"original", stats_json(p.before)}, {"refined", stats_json(p.after)}}},
            {"truth_facade", {{"original", stats_json(p.truth_facade_before)}, {"refined", stats_json(p.truth_facade_after)}}},
            {"truth_roof", {{"original", stats_json(p.truth_roof_before)}, {"refined", stats_json(p.truth_roof_after)}}}}},
          {"mean_of_buildings", {{"c2m", {{"original", stats_json(p.mean_before)}, {"refined", stats_json(p.mean_after)}}}}},
          {"delta_d", {{"mean", p.delta_d_mean}, {"median", p.delta_d_median}}},
          {"watertight_rate", {{"original", p.watertight_rate_before}, {"refined", p.watertight_rate_after}}},
          {"truth_buildings", p.truth_buildings}};
}

json params_json(const Params& p) {
  json j;
#define LODREFINE_PARAM_JSON(type, name, def, lo, hi, help) j[#name] = p.name;
  LODREFINE_PARAMS(LODREFINE_PARAM_JSON)
#undef LODREFINE_PARAM_JSON
  return j;
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string csv_stats(const std::optional<DistanceStats>& s) {
  if (!s) return ",,,,,";
  return fmt(s->rmse, 4) + ',' + fmt(s->mae, 4) + ',' + fmt(s->mean, 4) + ',' + fmt(s->std, 4) + ',' +
         fmt(s->median, 4) + ',' + fmt(s->p95, 4);
}

std::string csv_rmse(const std::optional<DistanceStats>& s) { return s ? fmt(s->rmse, 4) : std::string(); }

std::string csv_text(const std::vector<Row>& rows) {
  std::string out =
      "id,status,facade_points,"
      "c2m_rmse_original,c2m_mae_original,c2m_mean_original,c2m_std_original,c2m_median_original,c2m_p95_original,"
      "c2m_rmse_refined,c2m_mae_refined,c2m_mean_refined,c2m_std_refined,c2m_median_refined,c2m_p95_refined,"
      "delta_d,watertight_original,watertight_refined,truth_facade_rmse_original,truth_facade_rmse_refined,"
      "truth_roof_rmse_original,truth_roof_rmse_refined,refine_outcome,error\n";
  for (const Row& r : rows) {
    const BuildingEval& e = r.eval;
    const bool measured = e.facade_points > 0;
    out += csv_field(e.id) + ',' + (e.ok() ? "ok" : "failed") + ',' + std::to_string(e.facade_points) + ',' +
           csv_stats(measured ? std::optional(e.before) : std::nullopt) + ',' +
           csv_stats(measured && e.ok() ? std::optional(e.after) : std::nullopt) + ',' +
           (std::isfinite(e.delta_d) ? fmt(e.delta_d, 4) : "") + ',' + (e.watertight_before ? "1" : "0") + ',' +
           (e.watertight_after ? "1" : "0") + ',' + csv_rmse(e.truth_facade_before) + ',' +
           csv_rmse(e.truth_facade_after) + ',' + csv_rmse(e.truth_roof_before) + ',' + csv_rmse(e.truth_roof_after) +
           ',' + csv_field(r.report.is_object() ? r.report.value("outcome", std::string()) : std::string()) + ',' +
           csv_field(e.error) + '\n';
  }
  return out;
}

// The paper's Table 1, pooled over points; batch runs add the mean of per-building values.
void print_table(const PooledEval& p, bool batch) {
  std::printf("buildings: %zu (evaluated %zu, failed %zu), facade points: %zu\n\n", p.buildings, p.evaluated, p.failed,
              p.before.count);
  std::printf("%-28s %10s %10s", "", "Original", "Refined");
  if (batch) std::printf("   %12s %12s", "Orig (mean)", "Ref (mean)");
  std::printf("\n");
  auto line = [&](const char* name, double a, double b, double ma, double mb) {
    std::printf("%-28s %10s %10s", name, fmt(a).c_str(), fmt(b).c_str());
    if (batch) std::printf("   %12s %12s", fmt(ma).c_str(), fmt(mb).c_str());
    std::printf("\n");
  };
  const double nan = std::nan("");
  using Field = double DistanceStats::*;
  const std::pair<const char*, Field> c2m_rows[] = {
      {"C2M RMSE (m)", &DistanceStats::rmse},     {"C2M MAE (m)", &DistanceStats::mae},
      {"C2M Mean (m)", &DistanceStats::mean},     {"C2M Std (m)", &DistanceStats::std},
      {"C2M median (m)", &DistanceStats::median}, {"C2M p95 |d| (m)", &DistanceStats::p95}};
  auto get = [&](const DistanceStats& s, Field f) { return s.count ? s.*f : nan; };  // "-" when nothing measured
  for (const auto& [name, f] : c2m_rows)
    line(name, get(p.before, f), get(p.after, f), get(p.mean_before, f), get(p.mean_after, f));
  line("Centroid offset red. (m)", nan, p.evaluated ? p.delta_d_mean : nan, nan, nan);
  std::printf("%-28s %10.0f %10.0f\n", "Watertight rate (%)", 100 * p.watertight_rate_before,
              100 * p.watertight_rate_after);
  auto rmse = [&](const std::optional<DistanceStats>& s) { return s ? s->rmse : nan; };
  line("Truth facade RMSE (m)", rmse(p.truth_facade_before), rmse(p.truth_facade_after), nan, nan);
  line("Truth roof RMSE (m)", rmse(p.truth_roof_before), rmse(p.truth_roof_after), nan, nan);
}

void write_plots(const std::string& svg_dir, const std::vector<Row>& rows) {
  std::vector<double> before, after;
  for (const Row& r : rows)
    if (r.eval.ok()) {
      before.insert(before.end(), r.eval.c2m_before.begin(), r.eval.c2m_before.end());
      after.insert(after.end(), r.eval.c2m_after.begin(), r.eval.c2m_after.end());
    }
  write_file_atomic((fs::path(svg_dir) / "c2m_histogram.svg").string(),
                    svg_histogram(before, after, "C2M signed distance of the facade points"));
  write_file_atomic((fs::path(svg_dir) / "c2m_boxplot.svg").string(),
                    svg_boxplot(before, after, "C2M signed distance of the facade points"));
}

void write_outputs(const EvalArgs& a, const std::vector<Row>& rows, const PooledEval& pooled) {
  if (!a.json_out.empty()) {
    json j = {{"pooled", pooled_json(pooled)}, {"buildings", json::array()}, {"params", params_json(a.params)}};
    for (const Row& r : rows) j["buildings"].push_back(row_json(r));
    if (!a.dir.empty()) j["run_dir"] = a.dir;
    write_file_atomic(a.json_out, j.dump(2) + "\n");
  }
  if (!a.csv_out.empty()) write_file_atomic(a.csv_out, csv_text(rows));
  if (!a.svg_dir.empty()) write_plots(a.svg_dir, rows);
}

void run(const EvalArgs& a) {
  a.params.validate();
  if (!a.dir.empty() && !a.cloud_options.classes.empty())
    throw InputError(a.dir + ": --classes applies to --cloud; a run folder holds cropped PLY clouds");
  const bool batch = !a.dir.empty();
  if (!batch && (a.original.empty() || a.refined.empty() || a.cloud.empty()))
    throw InputError("eval: give --dir RUN_DIR, or --original, --refined and --cloud");
  if (!a.svg_dir.empty()) fs::create_directories(a.svg_dir);
  std::vector<Row> rows;
  if (batch) {
    rows = evaluate_run(a.dir, a.params, a.svg_dir);
  } else {
    rows.push_back(evaluate_files({"", a.original, a.refined, a.cloud, a.truth, a.meta, ""}, a.params, a.svg_dir, a.cloud_options));
    if (!rows.back().eval.ok()) std::fprintf(stderr, "lodrefine: warning: %s\n", rows.back().eval.error.c_str());
  }
  std::vector<BuildingEval> evals;
  for (const Row& r : rows) evals.push_back(r.eval);
  const PooledEval pooled = pool_evaluations(evals);
  print_table(pooled, batch);
  write_outputs(a, rows, pooled);
}

}  // namespace

void add_eval_command(CLI::App& app) {
  static EvalArgs a;
  auto* cmd = app.add_subcommand("eval", "Evaluate refined models as in the paper: C2M of the facade points, centroid "
                                         "offset reduction, watertight rate (+ truth distances)");
  auto* dir = cmd->add_option("--dir", a.dir, "Run directory: <id>/{coarse.obj,cloud.ply,refined.obj[,truth.obj,"
                                              "meta.json,report.json]}, pooled over all buildings");
  auto* orig = cmd->add_option("--original", a.original, "Coarse model (OBJ)")->check(CLI::ExistingFile);
  cmd->add_option("--refined", a.refined, "Refined model (OBJ); a missing file is reported as a failure");
  cmd->add_option("--cloud", a.cloud, "MLS crop (PLY or LAS)")->check(CLI::ExistingFile);
  cmd->add_option("--truth", a.truth, "Truth model (OBJ): adds truth_facade_* / truth_roof_* distances")
      ->check(CLI::ExistingFile);
  cmd->add_option("--meta", a.meta, "Generator meta.json listing the scanned truth faces (else detected)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--json", a.json_out, "Write every figure as JSON");
  cmd->add_option("--csv", a.csv_out, "Write one row per building as CSV");
  cmd->add_option("--svg-dir", a.svg_dir, "Write C2M histogram + boxplot and a footprint per building (SVG)");
  dir->excludes(orig);
  add_cloud_options(cmd, a.cloud_options);
  add_param_options(cmd, a.params);
  cmd->callback([] { run(a); });
}

}  // namespace lodrefine::app
