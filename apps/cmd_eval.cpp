// `lodrefine eval`: the paper's evaluation (C2M, ΔD, watertight rate) of one building or of a
// whole run directory, plus truth-based distances when a truth model is available.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <map>
#include <optional>
#include <thread>
#include <tuple>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "lodrefine/eval/eval.h"
#include "lodrefine/eval/gate.h"
#include "lodrefine/core/geometry.h"
#include "lodrefine/io/obj.h"
#include "lodrefine/io/files.h"
#include "lodrefine/io/progress.h"
#include "lodrefine/io/refine_report.h"
#include "lodrefine/eval/plots.h"
#include "lodrefine/core/refine.h"
#include "lodrefine/eval/report.h"
#include "options.h"

namespace lodrefine::app {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct EvalArgs {
  std::string original, refined, cloud, truth, meta, dir, json_out, csv_out, svg_dir, html_out;
  int html_views = 20;
  std::string baseline_in, baseline_out, gates, junit_out;  // the regression gate (--dir)
  double tolerance = 0.005;
  int jobs = default_jobs();
  bool quiet = false;
  Params params;
  CloudOptions cloud_options;  // single-building mode (a run folder holds cropped PLYs)
};

// The files of one building; empty strings for absent optional ones.
struct BuildingFiles {
  std::string id, original, refined, cloud, truth, meta, report, failed;
};

// A facade the refinement moved: its surface (as the report names it) and by how much (m).
struct MovedFacade {
  json surface;
  double displacement = 0.0;
};

// One evaluated building with what the outputs need besides the metrics.
struct Row {
  BuildingFiles files;
  BuildingEval eval;
  Vec3 origin = Vec3::Zero();      // local frame origin (added back to centroids in the JSON)
  std::string truth_faces_source;  // "meta.json", "detected" or empty
  std::string refine_outcome;      // the refine report's "outcome" as written, if any
  std::string selection;           // the report's selection.status (empty: older report, or none ran)
  // What the refine step recorded (report.json or FAILED).
  std::string outcome;             // "refined", "kept" (anything else written) or "failed"
  std::string reason;              // why kept / why failed
  std::vector<MovedFacade> moved;  // facades replaced in the written model
  double refine_seconds = std::nan("");
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

std::vector<Vec3> facade_points(const BuildingEval& e, const PointCloud& cloud) {
  std::vector<Vec3> pts;
  for (int i : e.facade_index) pts.push_back(cloud.points[std::size_t(i)]);
  return pts;
}

std::string footprint_svg(const BuildingEval& e, const Mesh& original, const Mesh& refined, const PointCloud& cloud,
                          std::size_t max_points) {
  return svg_footprint(original, refined, facade_points(e, cloud), e.id + ": original vs refined, facade points (XY)",
                       max_points);
}

// Points drawn in a footprint file (svg_footprint's default): dense enough to see each facade.
constexpr std::size_t kFootprintFilePoints = 5000;

void write_footprint(const std::string& svg_dir, const BuildingEval& e, const Mesh& original, const Mesh& refined,
                     const PointCloud& cloud) {
  write_file_atomic((fs::path(svg_dir) / ("footprint_" + safe_name(e.id) + ".svg")).string(),
                    footprint_svg(e, original, refined, cloud, kFootprintFilePoints));
}

// Inputs and refined model of one building in a local frame (georeferenced inputs): the given
// origin, else local_origin() of the original model.
struct LocalBuilding {
  Mesh original, refined;
  PointCloud cloud;
  Vec3 origin;
};

LocalBuilding read_local(const BuildingFiles& f, std::optional<Vec3> origin, std::string& refined_error,
                         const CloudOptions& cloud_options = {}) {
  LocalBuilding b;
  b.original = read_obj(f.original);
  b.origin = origin ? *origin : local_origin(b.original);
  b.original = translated(std::move(b.original), -b.origin);
  b.cloud = read_cloud(f.cloud, cloud_options);
  for (auto& p : b.cloud.points) p -= b.origin;
  b.refined = translated(read_refined(f.refined, refined_error), -b.origin);
  return b;
}

// Reads, moves to a local frame (georeferenced inputs) and evaluates one building.
Row evaluate_files(const BuildingFiles& f, const Params& params, const std::string& svg_dir,
                   const CloudOptions& cloud_options = {}) {
  Row row;
  row.files = f;
  std::string refined_error;
  const auto [original, refined, cloud, origin] = read_local(f, std::nullopt, refined_error, cloud_options);
  row.origin = origin;
  std::optional<Mesh> truth;
  std::optional<std::vector<int>> scanned;
  if (!f.truth.empty()) {
    truth = translated(read_obj(f.truth), -row.origin);
    scanned = meta_scanned_faces(f.meta, *truth);
    row.truth_faces_source = scanned ? "meta.json" : "detected";
  }
  row.eval = evaluate_building(original, refined, cloud, truth ? &*truth : nullptr, params, scanned ? &*scanned : nullptr);
  if (!f.id.empty()) row.eval.id = f.id;
  if (!refined_error.empty()) row.eval.error = refined_error;
  if (!svg_dir.empty()) write_footprint(svg_dir, row.eval, original, refined, cloud);
  return row;
}

// The moved facades of a refine report: its "facades" list when present (a facade is named by
// "surface" or its "input_faces"; it moved by "displacement", else its largest move "max_move"),
// else the successful "replacements" (scan plane, moved_by) mapped to the matched surface.
std::vector<MovedFacade> moved_facades(const json& report) {
  std::vector<MovedFacade> out;
  const json facades = report.value("facades", json());
  if (facades.is_array()) {
    for (const auto& f : facades) {
      if (!f.is_object()) continue;
      json d = f.value("displacement", json());
      if (!d.is_number()) d = f.value("max_move", json());
      if (!d.is_number()) d = f.value("moved_by", json());
      const json surface = f.contains("surface") ? f["surface"] : f.value("input_faces", json());
      if (d.is_number()) out.push_back({surface, std::abs(d.get<double>())});
    }
    return out;
  }
  std::map<int, json> surface_of_plane;
  for (const auto& m : report.value("matches", json::array()))
    if (m.is_object() && m.value("scan_plane", json()).is_number_integer())
      surface_of_plane[m["scan_plane"].get<int>()] = m.value("surface", json());
  for (const auto& r : report.value("replacements", json::array())) {
    if (!r.is_object() || !r.value("ok", false) || !r.value("moved_by", json()).is_number()) continue;
    const json plane = r.value("scan_plane", json());
    const auto it = plane.is_number_integer() ? surface_of_plane.find(plane.get<int>()) : surface_of_plane.end();
    out.push_back({it == surface_of_plane.end() ? json() : it->second, std::abs(r["moved_by"].get<double>())});
  }
  return out;
}

std::string first_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line.empty() ? "failed (no reason recorded)" : line;
}

// Outcome, reason, moved facades and time from what refine left: FAILED (its reason replaces
// any evaluation error, e.g. "refined model missing") or report.json. Anything written that is
// not "refined" counts as kept; the report's "reason", else the outcome's "(...)" says why.
void add_refine_record(Row& row, const BuildingFiles& f) {
  // Only what the table needs is kept: a city's reports in full would weigh hundreds of MB.
  const json rep = read_json_or_null(f.report);
  const json outcome_value = rep.is_object() ? rep.value("outcome", json()) : json();
  if (outcome_value.is_string()) row.refine_outcome = outcome_value.get<std::string>();
  if (rep.is_object() && rep.contains("selection") && rep["selection"].is_object()) {
    const json status = rep["selection"].value("status", json());
    if (status.is_string()) row.selection = status.get<std::string>();
  }
  if (!f.failed.empty()) row.eval.error = first_line(f.failed);
  if (!row.eval.ok()) {
    row.outcome = "failed";
    row.reason = row.eval.error;
    return;
  }
  if (!rep.is_object()) {
    row.outcome = "kept";
    row.reason = "no report.json";
    return;
  }
  try {
    const std::string& outcome = row.refine_outcome;
    row.outcome = outcome.rfind("refined", 0) == 0 ? "refined" : "kept";
    row.reason = rep.value("reason", std::string());
    const auto open = outcome.find('('), close = outcome.rfind(')');
    if (row.reason.empty() && open != std::string::npos && close > open) row.reason = outcome.substr(open + 1, close - open - 1);
    if (row.reason.empty() && row.outcome == "kept") row.reason = outcome;
    if (row.outcome == "refined") row.moved = moved_facades(rep);  // a kept building's model moved nothing
    const json total = rep.value("seconds", json::object()).value("total", json());
    if (total.is_number()) row.refine_seconds = total.get<double>();
  } catch (const json::exception& e) {  // a hand-edited or foreign report: keep the row
    row.reason = std::string("unreadable report.json: ") + e.what();
  }
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
                   optional_file("report.json"), optional_file("FAILED")});
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

// Buildings are independent: `jobs` threads take the next one; rows stay in id order and the
// first unexpected error (not a building's bad input) is rethrown here. Each building's
// per-point series go into `series` as it finishes and are dropped (memory: the bins, not the
// run's points); a progress line counts the buildings (`progress_mode`).
std::vector<Row> evaluate_run(const std::string& dir, const Params& params, const std::string& svg_dir, int jobs,
                              PooledSeries& series, Progress::Mode progress_mode) {
  const auto buildings = discover(dir);
  std::vector<Row> rows(buildings.size());
  std::atomic<std::size_t> next{0};
  std::size_t finished = 0, failed = 0;
  std::mutex mutex;
  std::exception_ptr error;
  Progress progress("eval", "buildings", buildings.size(), progress_mode);
  auto work = [&] {
    for (std::size_t k; (k = next++) < buildings.size();) {
      Row& row = rows[k];
      try {
        try {
          row = evaluate_files(buildings[k], params, svg_dir);
        } catch (const InputError& e) {
          row = failure_row(buildings[k].id, e.what());
        }
        row.files = buildings[k];
        add_refine_record(row, buildings[k]);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(mutex);
        if (!error) error = std::current_exception();
        next = buildings.size();
        return;
      }
      const std::lock_guard<std::mutex> lock(mutex);
      series.add(row.eval);
      drop_series(row.eval);
      failed += !row.eval.ok();
      progress.update(++finished, std::to_string(failed) + " failed");
    }
  };
  std::vector<std::thread> threads;
  for (int t = 1; t < std::max(1, jobs); ++t) threads.emplace_back(work);
  work();
  for (auto& t : threads) t.join();
  progress.finish();
  if (error) std::rethrow_exception(error);
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

// Count, largest and mean displacement of the moved facades (NaN when none moved).
struct MovedSummary {
  std::size_t count = 0;
  double max = std::nan(""), mean = std::nan("");
};

MovedSummary summarize_moved(const std::vector<MovedFacade>& moved) {
  MovedSummary m;
  m.count = moved.size();
  if (moved.empty()) return m;
  m.max = m.mean = 0.0;
  for (const auto& f : moved) m.max = std::max(m.max, f.displacement), m.mean += f.displacement;
  m.mean /= double(moved.size());
  return m;
}

json moved_json(const Row& r) {
  const MovedSummary m = summarize_moved(r.moved);
  json list = json::array();
  for (const auto& f : r.moved) list.push_back({{"surface", f.surface}, {"displacement", f.displacement}});
  return {{"count", m.count}, {"max", number_or_null(m.max)}, {"mean", number_or_null(m.mean)}, {"facades", list}};
}

json row_json(const Row& r) {
  const BuildingEval& e = r.eval;
  json j = {{"id", e.id},
            {"status", e.ok() ? "ok" : "failed"},
            {"error", e.error},
            {"outcome", r.outcome},
            {"reason", r.reason},
            {"facades_moved", moved_json(r)},
            {"refine_seconds", number_or_null(r.refine_seconds)},
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
  if (!r.refine_outcome.empty()) j["refine_outcome"] = r.refine_outcome;
  if (!r.selection.empty()) j["selection"] = r.selection;
  return j;
}

// Outcome counts and moved facades over the whole run.
struct RunTotals {
  std::map<std::string, std::size_t> outcomes{{"refined", 0}, {"kept", 0}, {"failed", 0}};
  MovedSummary moved;
  double refine_seconds = 0.0;
};

RunTotals run_totals(const std::vector<Row>& rows) {
  RunTotals t;
  std::vector<MovedFacade> all;
  for (const Row& r : rows) {
    ++t.outcomes[r.outcome];
    all.insert(all.end(), r.moved.begin(), r.moved.end());
    if (std::isfinite(r.refine_seconds)) t.refine_seconds += r.refine_seconds;
  }
  t.moved = summarize_moved(all);
  return t;
}

json totals_json(const RunTotals& t) {
  return {{"outcomes", t.outcomes},
          {"facades_moved", {{"count", t.moved.count}, {"max", number_or_null(t.moved.max)}, {"mean", number_or_null(t.moved.mean)}}},
          {"refine_seconds_total", t.refine_seconds}};
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

std::string csv_text(const std::vector<const Row*>& rows) {
  std::string out =
      "id,outcome,reason,facades_moved,displacement_max,displacement_mean,watertight_original,watertight_refined,"
      "refine_seconds,facade_points,"
      "c2m_rmse_original,c2m_mae_original,c2m_mean_original,c2m_std_original,c2m_median_original,c2m_p95_original,"
      "c2m_rmse_refined,c2m_mae_refined,c2m_mean_refined,c2m_std_refined,c2m_median_refined,c2m_p95_refined,"
      "delta_d,truth_facade_rmse_original,truth_facade_rmse_refined,truth_roof_rmse_original,truth_roof_rmse_refined,"
      "refine_outcome,selection\n";
  auto opt = [](double v) { return std::isfinite(v) ? fmt(v, 4) : std::string(); };
  for (const Row* r : rows) {
    const BuildingEval& e = r->eval;
    const bool measured = e.facade_points > 0;
    const MovedSummary m = summarize_moved(r->moved);
    out += csv_field(e.id) + ',' + r->outcome + ',' + csv_field(r->reason) + ',' + std::to_string(m.count) + ',' +
           opt(m.max) + ',' + opt(m.mean) + ',' + (e.watertight_before ? "1" : "0") + ',' +
           (e.ok() && e.watertight_after ? "1" : "0") + ',' + opt(r->refine_seconds) + ',' +
           std::to_string(e.facade_points) + ',' + csv_stats(measured ? std::optional(e.before) : std::nullopt) + ',' +
           csv_stats(measured && e.ok() ? std::optional(e.after) : std::nullopt) + ',' + opt(e.delta_d) + ',' +
           csv_rmse(e.truth_facade_before) + ',' + csv_rmse(e.truth_facade_after) + ',' + csv_rmse(e.truth_roof_before) +
           ',' + csv_rmse(e.truth_roof_after) + ',' +
           csv_field(r->refine_outcome) + ',' + csv_field(r->selection) + '\n';
  }
  return out;
}

// Worst first: failed, then not watertight after refinement, then by refined C2M RMSE (largest
// first, unmeasured last), then by id.
std::vector<const Row*> worst_first(const std::vector<Row>& rows) {
  std::vector<const Row*> order;
  for (const Row& r : rows) order.push_back(&r);
  auto key = [](const Row* r) {
    const BuildingEval& e = r->eval;
    const int rank = !e.ok() ? 0 : !e.watertight_after ? 1 : 2;
    const double rmse = e.ok() && e.facade_points > 0 ? e.after.rmse : -1.0;
    return std::make_tuple(rank, -rmse, e.id);
  };
  std::stable_sort(order.begin(), order.end(), [&](const Row* a, const Row* b) { return key(a) < key(b); });
  return order;
}

// The paper's Table 1, pooled over points; batch runs add the mean of per-building values.
void print_table(std::FILE* out, const PooledEval& p, bool batch) {
  std::fprintf(out, "buildings: %zu (evaluated %zu, failed %zu), facade points: %zu\n\n", p.buildings, p.evaluated, p.failed,
              p.before.count);
  std::fprintf(out, "%-28s %10s %10s", "", "Original", "Refined");
  if (batch) std::fprintf(out, "   %12s %12s", "Orig (mean)", "Ref (mean)");
  std::fprintf(out, "\n");
  auto line = [&](const char* name, double a, double b, double ma, double mb) {
    std::fprintf(out, "%-28s %10s %10s", name, fmt(a).c_str(), fmt(b).c_str());
    if (batch) std::fprintf(out, "   %12s %12s", fmt(ma).c_str(), fmt(mb).c_str());
    std::fprintf(out, "\n");
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
  std::fprintf(out, "%-28s %10.0f %10.0f\n", "Watertight rate (%)", 100 * p.watertight_rate_before,
              100 * p.watertight_rate_after);
  auto rmse = [&](const std::optional<DistanceStats>& s) { return s ? s->rmse : nan; };
  line("Truth facade RMSE (m)", rmse(p.truth_facade_before), rmse(p.truth_facade_after), nan, nan);
  line("Truth roof RMSE (m)", rmse(p.truth_roof_before), rmse(p.truth_roof_after), nan, nan);
}

void print_totals(std::FILE* out, const RunTotals& t) {
  std::fprintf(out, "\noutcomes: refined %zu, kept %zu, failed %zu; facades moved %zu (max %s m, mean %s m); refine %.1f s in all\n",
              t.outcomes.at("refined"), t.outcomes.at("kept"), t.outcomes.at("failed"), t.moved.count,
              fmt(t.moved.max).c_str(), fmt(t.moved.mean).c_str(), t.refine_seconds);
}

// C2M histogram and boxplot over every evaluated building's facade points (their pooled bins).
std::pair<std::string, std::string> c2m_plots(const PooledSeries& series) {
  const char* title = "C2M signed distance of the facade points";
  return {svg_histogram(series.c2m_before, series.c2m_after, title),
          svg_boxplot(series.c2m_before, series.c2m_after, title)};
}

void write_plots(const std::string& svg_dir, const std::string& histogram, const std::string& boxplot) {
  write_file_atomic((fs::path(svg_dir) / "c2m_histogram.svg").string(), histogram);
  write_file_atomic((fs::path(svg_dir) / "c2m_boxplot.svg").string(), boxplot);
}

// The per-building table of the HTML report: what a person scans first.
const json kHtmlColumns = json::array({{"id", "building"},
                                       {"outcome", "outcome"},
                                       {"reason", "reason"},
                                       {"selection", "selection"},
                                       {"moved", "facades moved"},
                                       {"moved_max", "max move (m)"},
                                       {"moved_mean", "mean move (m)"},
                                       {"c2m_before", "C2M RMSE before (m)"},
                                       {"c2m_after", "C2M RMSE after (m)"},
                                       {"watertight", "watertight"},
                                       {"seconds", "refine (s)"}});

json html_row(const Row& r) {
  const BuildingEval& e = r.eval;
  const MovedSummary m = summarize_moved(r.moved);
  const bool measured = e.facade_points > 0;
  return {{"id", e.id},
          {"outcome", r.outcome},
          {"reason", r.reason},
          {"selection", r.selection},
          {"moved", m.count},
          {"moved_max", number_or_null(m.max)},
          {"moved_mean", number_or_null(m.mean)},
          {"c2m_before", measured ? json(e.before.rmse) : json()},
          {"c2m_after", measured && e.ok() ? json(e.after.rmse) : json()},
          {"watertight", e.ok() && e.watertight_after},
          {"seconds", number_or_null(r.refine_seconds)}};
}

// The 3D + footprint view of one building, read again from its files (only the shown ones).
BuildingView html_view(const Row& r, const Params& params) {
  std::string refined_error;
  const LocalBuilding b = read_local(r.files, r.origin, refined_error);
  // A run drops each building's per-point series once pooled: the few shown are measured again
  // (the same points and distances: the evaluation is deterministic).
  const BuildingEval e = r.eval.facade_points > 0 && r.eval.facade_index.empty()
                             ? evaluate_building(b.original, b.refined, b.cloud, nullptr, params)
                             : r.eval;
  const std::vector<double>& c2m = e.ok() ? e.c2m_after : e.c2m_before;
  constexpr std::size_t kViewPoints = 4000;       // per building: enough to see the facades, keeps the page small
  constexpr std::size_t kFootprintPoints = 1500;  // idem for the top view
  BuildingView v = make_building_view(e.id, b.original, b.refined, facade_points(e, b.cloud), c2m, kViewPoints);
  v.footprint_svg = footprint_svg(e, b.original, b.refined, b.cloud, kFootprintPoints);
  v.caption = r.outcome + (r.reason.empty() ? "" : " (" + r.reason + ")") + ", " + std::to_string(r.moved.size()) +
              " facade(s) moved" +
              (e.facade_points ? ", C2M RMSE " + fmt(e.before.rmse) + " -> " + (e.ok() ? fmt(e.after.rmse) : "-") + " m" : "");
  return v;
}

std::string captured(const std::function<void(std::FILE*)>& print) {
  char* buf = nullptr;
  std::size_t len = 0;
  std::FILE* f = open_memstream(&buf, &len);
  if (!f) throw std::runtime_error("open_memstream failed");
  print(f);
  std::fclose(f);
  std::string s(buf, len);
  std::free(buf);
  return s;
}

// The self-contained page: Table 1, plots, the table worst first, and the worst buildings in 3D.
void write_html(const EvalArgs& a, const std::vector<Row>& rows, const PooledEval& pooled,
                const std::pair<std::string, std::string>& plots) {
  HtmlReport h;
  h.title = "lodrefine run " + fs::path(a.dir).filename().string() + ": " + std::to_string(rows.size()) + " buildings";
  h.table1 = captured([&](std::FILE* out) {
    print_table(out, pooled, true);
    print_totals(out, run_totals(rows));
  });
  std::tie(h.histogram_svg, h.boxplot_svg) = plots;
  h.columns = kHtmlColumns;
  h.rows = json::array();
  for (const Row* r : worst_first(rows)) {
    h.rows.push_back(html_row(*r));
    if (int(h.views.size()) >= a.html_views) continue;
    try {
      h.views.push_back(html_view(*r, a.params));
    } catch (const InputError&) {  // unreadable inputs: the table row says so, no view
    }
  }
  write_file_atomic(a.html_out, html_report(h));
}

void write_outputs(const EvalArgs& a, const std::vector<Row>& rows, const PooledEval& pooled,
                   const PooledSeries& series) {
  const auto order = worst_first(rows);
  if (!a.json_out.empty()) {
    json j = {{"pooled", pooled_json(pooled)}, {"buildings", json::array()}, {"params", params_json(a.params)}};
    j["pooled"].update(totals_json(run_totals(rows)));
    for (const Row* r : order) j["buildings"].push_back(row_json(*r));
    if (!a.dir.empty()) j["run_dir"] = a.dir;
    write_file_atomic(a.json_out, j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  }
  if (!a.csv_out.empty()) write_file_atomic(a.csv_out, csv_text(order));
  if (a.svg_dir.empty() && a.html_out.empty()) return;
  const auto plots = c2m_plots(series);
  if (!a.svg_dir.empty()) write_plots(a.svg_dir, plots.first, plots.second);
  if (!a.html_out.empty()) write_html(a, rows, pooled, plots);
}

// --- the regression gate ------------------------------------------------------------------

// A row's figures for the gate: its outcome in refine's words (kept-invalid kept apart).
BuildingFigures building_figures(const Row& r) {
  const BuildingEval& e = r.eval;
  BuildingFigures b;
  b.id = e.id;
  b.outcome = r.outcome == "kept" && r.refine_outcome.rfind("kept-invalid", 0) == 0 ? "kept-invalid" : r.outcome;
  b.reason = r.reason;
  if (e.ok() && e.facade_points > 0) b.c2m_rmse = e.after.rmse, b.c2m_mae = e.after.mae;
  if (e.ok() && e.truth_facade_after) b.truth_facade_rmse = e.truth_facade_after->rmse;
  if (e.ok() && e.truth_roof_after) b.truth_roof_rmse = e.truth_roof_after->rmse;
  b.watertight = e.ok() && e.watertight_after;
  const MovedSummary m = summarize_moved(r.moved);
  b.facades_moved = m.count;
  if (std::isfinite(m.max)) b.moved_max = m.max;
  return b;
}

RunFigures run_figures(const std::vector<Row>& rows, const PooledEval& p) {
  RunFigures run;
  for (const Row& r : rows) run.buildings.push_back(building_figures(r));
  run.failed = p.failed;
  run.refined = std::size_t(std::count_if(rows.begin(), rows.end(), [](const Row& r) { return r.outcome == "refined"; }));
  run.watertight_rate = p.watertight_rate_after;
  if (p.before.count) run.c2m_rmse_original = p.before.rmse;
  if (p.after.count) run.c2m_rmse = p.after.rmse, run.c2m_mae = p.after.mae;
  if (p.truth_facade_after) run.truth_facade_rmse = p.truth_facade_after->rmse;
  if (p.truth_roof_after) run.truth_roof_rmse = p.truth_roof_after->rmse;
  return run;
}

// Reads the gate's inputs before any work, so a bad file costs no evaluation.
struct GateInputs {
  std::optional<RunFigures> baseline;
  std::optional<Gates> gates;
};

GateInputs read_gate_inputs(const EvalArgs& a) {
  for (const std::string& out : {a.baseline_out, a.junit_out})
    if (!out.empty() && !fs::is_directory(fs::absolute(out).parent_path()))
      throw InputError(out + ": output directory " + fs::absolute(out).parent_path().string() + " does not exist");
  GateInputs in;
  if (!a.baseline_in.empty()) in.baseline = read_baseline(read_file(a.baseline_in), a.baseline_in);
  if (!a.gates.empty()) in.gates = read_gates(read_file(a.gates), a.gates);
  return in;
}

// Writes the baseline, compares and gates; one line per regression or breach on stdout and exit
// code 1 when there is any.
void apply_gate(const EvalArgs& a, const GateInputs& in, const RunFigures& run) {
  if (!a.baseline_out.empty()) write_file_atomic(a.baseline_out, baseline_json(run));
  if (!in.baseline && !in.gates && a.junit_out.empty()) return;
  const GateVerdict v = check_run(run, in.baseline ? &*in.baseline : nullptr, in.gates ? &*in.gates : nullptr, a.tolerance);
  if (!a.junit_out.empty()) write_file_atomic(a.junit_out, junit_xml(v, "lodrefine eval " + a.dir));
  std::printf("\ngate: %zu building(s), %zu new, %zu pooled check(s): %s\n", v.buildings.size(), v.new_buildings.size(),
              v.pooled_checks.size(), v.failed() ? "FAILED" : "passed");
  for (const std::string& id : v.new_buildings) std::printf("new: %s (not in the baseline)\n", id.c_str());
  for (const GateLine& l : v.failures) std::printf("%s: %s\n", l.check == "baseline" ? "regression" : "breach", l.text.c_str());
  if (v.failed()) exit_code() = 1;
}

void run(const EvalArgs& a) {
  a.params.validate();
  const GateInputs gate_inputs = read_gate_inputs(a);
  if (!a.dir.empty() && !a.cloud_options.classes.empty())
    throw InputError(a.dir + ": --classes applies to --cloud; a run folder holds cropped PLY clouds");
  const bool batch = !a.dir.empty();
  if (!batch && (a.original.empty() || a.refined.empty() || a.cloud.empty()))
    throw InputError("eval: give --dir RUN_DIR, or --original, --refined and --cloud");
  if (!a.svg_dir.empty()) fs::create_directories(a.svg_dir);
  std::vector<Row> rows;
  PooledSeries series;
  if (batch) {
    rows = evaluate_run(a.dir, a.params, a.svg_dir, a.jobs, series, Progress::mode_for_stderr(a.quiet));
  } else {
    rows.push_back(evaluate_files({"", a.original, a.refined, a.cloud, a.truth, a.meta, "", ""}, a.params, a.svg_dir,
                                  a.cloud_options));
    if (!rows.back().eval.ok()) std::fprintf(stderr, "lodrefine: warning: %s\n", rows.back().eval.error.c_str());
    series.add(rows.back().eval);
  }
  std::vector<BuildingEval> evals;
  for (const Row& r : rows) evals.push_back(r.eval);
  const PooledEval pooled = pool_evaluations(evals, series);
  print_table(stdout, pooled, batch);
  if (batch) print_totals(stdout, run_totals(rows));
  write_outputs(a, rows, pooled, series);
  if (batch) apply_gate(a, gate_inputs, run_figures(rows, pooled));
}

void add_gate_options(CLI::App* cmd, EvalArgs& a, CLI::Option* dir) {
  cmd->add_option("--write-baseline", a.baseline_out, "With --dir: write the run's figures per building and pooled "
                                                       "(outcome, C2M, watertight, truth distances, facades moved) as a "
                                                       "baseline for --baseline")->needs(dir);
  cmd->add_option("--baseline", a.baseline_in, "With --dir: compare with this baseline; exit 1 when a building got "
                                                "worse, changed outcome for the worse or went missing (one line each)")
      ->check(CLI::ExistingFile)->needs(dir);
  add_ranged_option(cmd, "--tolerance", a.tolerance, "With --baseline: a distance may grow by this much (m)", 0.0, 100.0);
  cmd->add_option("--gates", a.gates, "With --dir: absolute limits (JSON: max_c2m_rmse_refined, min_watertight_rate, "
                                       "max_failed_buildings, max_building_truth_facade_rmse_refined, ...); exit 1 "
                                       "on a breach")->check(CLI::ExistingFile)->needs(dir);
  cmd->add_option("--junit", a.junit_out, "With --dir: write the verdict as JUnit XML (one test case per building and "
                                           "per pooled check)")->needs(dir);
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
  auto* html = cmd->add_option("--html", a.html_out, "With --dir: write one self-contained HTML report page (tables, "
                                                     "plots, footprints and 3D views; three.js embedded)");
  add_ranged_option(cmd, "--html-views", a.html_views, "Buildings shown in 3D in the HTML report, worst first", 0, 100000);
  html->needs(dir);
  cmd->add_option("--jobs", a.jobs, "With --dir: buildings evaluated at once (default: all cores)")
      ->check(CLI::Range(1, 1024));
  cmd->add_flag("--quiet", a.quiet, "With --dir: no progress line on stderr");
  dir->excludes(orig);
  add_gate_options(cmd, a, dir);
  add_cloud_options(cmd, a.cloud_options);
  add_param_options(cmd, a.params);
  cmd->callback([] { run(a); });
}

}  // namespace lodrefine::app
