// A run folder evaluated building by building: discovery, reading into a local frame, the refine
// record of each building, and the buildings on a TBB pool.
#include "lodrefine/tools/run.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include "lodrefine/base/files.h"
#include "lodrefine/base/geometry.h"
#include "lodrefine/city/in_order_pool.h"
#include "lodrefine/city/refine_report.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/eval/plots.h"
#include "lodrefine/formats/cityjson.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/refine/refine.h"

namespace lodrefine {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Points drawn in a footprint file (svg_footprint's default): dense enough to see each facade.
constexpr std::size_t kFootprintFilePoints = 5000;

// A run folder's JSON file, or null when absent or unreadable. Read as every untrusted file: a
// FIFO or device is not read (it hung eval), the nesting is bounded.
json read_json_or_null(const std::string& path) {
  if (path.empty() || !fs::exists(path)) return nullptr;
  try {
    return parse_json(read_file(path), path);
  } catch (const InputError&) {
    return nullptr;
  }
}

// Scanned truth faces listed by the generator, if present and plausible (walls of this truth).
std::optional<std::vector<int>> meta_scanned_faces(const std::string& meta_path, const Mesh& truth) {
  const json meta = read_json_or_null(meta_path);
  if (!meta.is_object() || !meta.contains("scanned_truth_faces") || !meta["scanned_truth_faces"].is_array())
    return std::nullopt;
  std::vector<int> faces;
  for (const auto& f : meta["scanned_truth_faces"]) {
    if (!f.is_number_integer() || f.get<long long>() < INT_MIN || f.get<long long>() > INT_MAX) {
      std::fprintf(stderr, "lodrefine: warning: %s: a scanned face is not a face index; detecting instead\n",
                   escaped_line(meta_path).c_str());
      return std::nullopt;
    }
    const int i = f.get<int>();
    if (i < 0 || std::size_t(i) >= truth.faces.size() || truth.faces[std::size_t(i)].sem != Semantic::Wall) {
      std::fprintf(stderr, "lodrefine: warning: %s: scanned face %d is not a wall of the truth; detecting instead\n",
                   escaped_line(meta_path).c_str(), i);
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
    return read_eval_model(path);
  } catch (const InputError& e) {
    error = e.what();
    return {};
  }
}

// The reason a FAILED marker records: its first line, at most kMaxReason bytes, control
// characters escaped (escaped_line); a FIFO or device is not read.
std::string first_line(const std::string& path) {
  constexpr std::size_t kMaxReason = 500;
  if (!fs::is_regular_file(path)) return "failed (the FAILED marker is not a regular file)";
  std::ifstream in(path, std::ios::binary);
  std::string line(kMaxReason, '\0');
  in.read(line.data(), std::streamsize(line.size()));
  line.resize(std::size_t(in.gcount()));
  line = line.substr(0, line.find_first_of("\r\n"));
  return line.empty() ? "failed (no reason recorded)" : escaped_line(line);
}

// Refuses a report written by a newer refine than this eval reads (absent: version 1).
void check_report_version(const json& report, const std::string& source) {
  const json version = report.value("report_version", json(1));
  if (!version.is_number_integer() || version.get<long long>() < 1 || version.get<long long>() > kRefineReportVersion)
    throw InputError(source + ": report_version " + shown_json(version) + " is not one this lodrefine reads (1.." +
                     std::to_string(kRefineReportVersion) + ")");
}

// The moved facades of a refined building's report: its "facades", each named by its
// "input_faces" and moved by its "max_move".
std::vector<MovedFacade> moved_facades(const json& report) {
  std::vector<MovedFacade> out;
  const json facades = report.value("facades", json());
  if (!facades.is_array()) return out;
  for (const auto& f : facades) {
    if (!f.is_object() || !f.value("max_move", json()).is_number()) continue;
    out.push_back({f.value("input_faces", json()), std::abs(f["max_move"].get<double>())});
  }
  return out;
}

// Outcome, reason, moved facades and time of a report that is a JSON object.
void read_report(RunRow& row, const json& report) {
  // The outcome refine decided, as its report states it; text no refine writes: the model is there,
  // so it was at least kept.
  row.outcome = parse_outcome(row.refine_outcome).value_or(Outcome::Kept);
  const json reason = report.value("reason", json());
  row.reason = reason.is_string() ? escaped_line(reason.get<std::string>())
               : reason.is_null() ? std::string()
                                  : "report.json: \"reason\" is no text";
  if (row.outcome == Outcome::Refined) row.moved = moved_facades(report);  // a kept building's model moved nothing
  const json total = report.value("seconds", json::object()).value("total", json());
  if (total.is_number()) row.refine_seconds = total.get<double>();
}

}  // namespace

std::vector<BuildingFiles> discover_run(const std::string& dir) {
  if (!fs::is_directory(dir)) throw InputError(dir + ": not a directory");
  std::vector<BuildingFiles> out;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const fs::path d = entry.path();
    if (!entry.is_directory() || !fs::exists(d / "coarse.obj")) continue;
    auto optional_file = [&](const char* name) { return fs::exists(d / name) ? (d / name).string() : std::string(); };
    out.push_back({d.filename().string(),
                   (d / "coarse.obj").string(),
                   (d / "refined.obj").string(),
                   {(d / "cloud.ply").string()},
                   optional_file("truth.obj"),
                   optional_file("meta.json"),
                   optional_file("report.json"),
                   optional_file("FAILED")});
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  if (out.empty()) throw InputError(dir + ": no building directories (<id>/coarse.obj) found");
  return out;
}

std::vector<Vec3> facade_points(const BuildingEval& e, const PointCloud& cloud) {
  std::vector<Vec3> pts;
  for (int i : e.facade_index) pts.push_back(cloud.points[std::size_t(i)]);
  return pts;
}

std::string building_footprint_svg(const BuildingEval& e, const LocalBuilding& b, std::size_t max_points) {
  return svg_footprint(b.original, b.refined, facade_points(e, b.cloud),
                       e.id + ": original vs refined, facade points (XY)", max_points);
}

// A model as eval judges it: its solid, without the faces of its fins group (a repaired
// building's fins stand beside the solid: they are no part of its watertightness or centroid).
Mesh read_eval_model(const std::string& path) {
  Mesh m = read_obj_model(path).solid;
  if (m.faces.empty()) throw InputError(path + ": every face is in the fins group (no solid to evaluate)");
  if (const std::string too_large = size_problem(m); !too_large.empty()) throw InputError(path + ": " + too_large);
  return m;
}

LocalBuilding read_local(const BuildingFiles& f, const std::optional<Vec3>& origin, std::string& refined_error,
                         const CloudOptions& cloud_options) {
  LocalBuilding b;
  b.original = read_eval_model(f.original);
  b.origin = origin ? *origin : local_origin(b.original);
  b.original = translated(std::move(b.original), -b.origin);
  b.cloud = read_cloud(f.clouds, cloud_options);
  for (auto& p : b.cloud.points) p -= b.origin;
  b.refined = translated(read_refined(f.refined, refined_error), -b.origin);
  return b;
}

RunRow evaluate_building_files(const BuildingFiles& f, const RefineConfig& params, const std::string& svg_dir,
                               const CloudOptions& cloud_options) {
  RunRow row;
  row.files = f;
  std::string refined_error;
  const LocalBuilding b = read_local(f, std::nullopt, refined_error, cloud_options);
  row.origin = b.origin;
  std::optional<Mesh> truth;
  std::optional<std::vector<int>> scanned;
  if (!f.truth.empty()) {
    truth = translated(read_eval_model(f.truth), -row.origin);
    scanned = meta_scanned_faces(f.meta, *truth);
    row.truth_faces_source = scanned ? "meta.json" : "detected";
  }
  row.eval = evaluate_building(b.original, b.refined, b.cloud, truth ? &*truth : nullptr, params,
                               scanned ? &*scanned : nullptr);
  if (!f.id.empty()) row.eval.id = f.id;
  if (!refined_error.empty()) row.eval.error = refined_error;
  if (!svg_dir.empty()) {
    const std::string svg = (fs::path(svg_dir) / ("footprint_" + safe_name(row.eval.id) + ".svg")).string();
    std::vector<FileOption> inputs = {
        {"--original", f.original}, {"--refined", f.refined}, {"--truth", f.truth}, {"--meta", f.meta}};
    for (const std::string& cloud : f.clouds) inputs.push_back({"--cloud", cloud});
    refuse_overwrites(inputs, {{"--svg-dir", svg}});
    write_file_atomic(svg, building_footprint_svg(row.eval, b, kFootprintFilePoints));
  }
  return row;
}

void add_refine_record(RunRow& row, const json& report, const std::string& failed_line, const std::string& source) {
  if (report.is_object()) check_report_version(report, source);
  const json outcome = report.is_object() ? report.value("outcome", json()) : json();
  if (outcome.is_string()) row.refine_outcome = escaped_line(outcome.get<std::string>());
  if (report.is_object() && report.contains("selection") && report["selection"].is_object()) {
    const json status = report["selection"].value("status", json());
    if (status.is_string()) row.selection = escaped_line(status.get<std::string>());
  }
  if (!failed_line.empty()) row.eval.error = failed_line;
  if (!row.eval.ok()) {
    row.outcome = decide_outcome({Ending::NoModel});
    row.reason = row.eval.error;
    return;
  }
  row.outcome = Outcome::Kept;
  if (!report.is_object()) {
    row.reason = "no report.json";
    return;
  }
  try {
    read_report(row, report);
  } catch (const json::exception&) {  // a hand-edited or foreign report: keep the row
    row.reason = "unreadable report.json (a value of the wrong kind)";
  }
}

RunRow failure_row(const std::string& id, const std::string& error) {
  RunRow row;
  row.eval.id = id;
  row.eval.error = error;
  row.eval.delta_d = std::nan("");
  return row;
}

std::vector<RunRow> evaluate_run(const std::string& dir, const RefineConfig& params, const std::string& svg_dir,
                                 int jobs, PooledSeries& series, Progress::Mode progress_mode,
                                 const CloudOptions& cloud_options) {
  const auto buildings = discover_run(dir);
  std::vector<RunRow> rows(buildings.size());
  std::size_t next = 0, finished = 0, failed = 0;
  Progress progress("eval", "buildings", buildings.size(), progress_mode);
  // Each building's series go into `series` in the run's order, whatever finished first: the
  // pooled sums (floating point) are then the same bytes for any --jobs. The pool hands them
  // back in that order and holds only its items in flight (in_order_pool), so the per-point
  // series waiting for an earlier building are bounded by --jobs, not by the run.
  in_order_pool<std::size_t>(
      jobs,
      [&]() -> std::shared_ptr<std::size_t> {
        return next == buildings.size() ? nullptr : std::make_shared<std::size_t>(next++);
      },
      [&](std::size_t& k) {
        const BuildingFiles& f = buildings[k];
        RunRow& row = rows[k];
        try {
          row = evaluate_building_files(f, params, svg_dir, cloud_options);
        } catch (const InputError& e) {
          row = failure_row(f.id, e.what());
        }
        row.files = f;
        // Only what the table needs is kept: a city's reports in full would weigh hundreds of MB.
        add_refine_record(row, read_json_or_null(f.report), f.failed.empty() ? "" : first_line(f.failed), f.report);
      },
      [&](std::size_t& k) {
        RunRow& row = rows[k];
        PooledSeries own;  // pooled as one part, then merged: the same sums as before the pool
        own.add(row.eval);
        series.merge(own);
        drop_series(row.eval);
        failed += !row.eval.ok();
        progress.update(++finished, std::to_string(failed) + " failed");
      });
  progress.finish();
  return rows;
}

}  // namespace lodrefine
