// A run folder evaluated building by building (`lodrefine eval --dir`): its buildings found, each
// read into a local frame and measured (eval.h), and what refine recorded of it (its report.json
// or FAILED) read beside the figures.
#pragma once
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lodrefine/base/types.h"
#include "lodrefine/city/progress.h"
#include "lodrefine/core/outcome.h"
#include "lodrefine/core/params.h"
#include "lodrefine/eval/eval.h"
#include "lodrefine/formats/cloud.h"

namespace lodrefine {

// The files of one building; empty strings for absent optional ones. Its cloud may be several
// files, read as one (io/cloud.h); a run folder's is its cloud.ply.
struct BuildingFiles {
  std::string id, original, refined;
  std::vector<std::string> clouds;
  std::string truth, meta, report, failed;
};

// The buildings of a run folder: every RUN_DIR/<id>/ holding a coarse.obj, sorted by id, with
// refined.obj and cloud.ply (whether present or not) and truth.obj, meta.json, report.json and
// FAILED when present. Throws InputError when `dir` is not a folder or holds no building.
std::vector<BuildingFiles> discover_run(const std::string& dir);

// A facade the refinement moved: its input faces as the report lists them, and its largest move
// (m, >= 0).
struct MovedFacade {
  nlohmann::json surface;
  double displacement = 0.0;
};

// One evaluated building with what the outputs need besides the metrics.
struct RunRow {
  BuildingFiles files;
  BuildingEval eval;
  Vec3 origin = Vec3::Zero();      // local frame origin (added back to centroids in the JSON)
  std::string truth_faces_source;  // "meta.json", "detected" or empty (no truth)
  std::string refine_outcome;      // the refine report's "outcome" as written, if any (echoed; parse_outcome reads it)
  std::string selection;           // the report's selection.status (empty when none ran)
  // What the refine step recorded (report.json or FAILED).
  // The outcome refine decided (its report's "outcome"; kept for text no refine writes, or without
  // a report), or failed (no model to measure); none without a refine record (one building's
  // eval: written as "").
  std::optional<Outcome> outcome;
  std::string reason;              // why kept / why failed
  std::vector<MovedFacade> moved;  // facades replaced in the written model
  double refine_seconds = std::numeric_limits<double>::quiet_NaN();
};

// Inputs and refined model of one building in a local frame (georeferenced inputs): `origin`
// when given, else local_origin() of the original model. A refined model that is missing or
// unreadable is left empty with the reason in `refined_error`; unreadable inputs throw InputError.
struct LocalBuilding {
  Mesh original, refined;
  PointCloud cloud;
  Vec3 origin = Vec3::Zero();
};
LocalBuilding read_local(const BuildingFiles& files, const std::optional<Vec3>& origin, std::string& refined_error,
                         const CloudOptions& cloud_options = {});

// The cloud points `e` measured as facade points (its facade_index).
std::vector<Vec3> facade_points(const BuildingEval& e, const PointCloud& cloud);
// The top view of a building (svg_footprint): original vs refined over at most `max_points` of
// its facade points.
std::string building_footprint_svg(const BuildingEval& e, const LocalBuilding& b, std::size_t max_points);

// Reads and evaluates one building (truth distances when files.truth is set, on the scanned
// faces meta.json lists when it lists walls of the truth). Writes its footprint SVG into
// `svg_dir` unless that is empty. The row's refine record is left empty (add_refine_record).
// Throws InputError when the original model or the cloud cannot be read.
RunRow evaluate_building_files(const BuildingFiles& files, const RefineConfig& params, const std::string& svg_dir,
                               const CloudOptions& cloud_options = {});

// Fills the refine record of `row` (evaluated already) from what refine left: `failed_line`, the
// first line of a FAILED file (it replaces any evaluation error), or the `report` (JSON; null when
// there is none). Reads the current report (city/refine_report.h) only: its "outcome" as refine
// decided it (text no refine writes: kept), its "reason", its "facades" (input_faces, max_move) when
// refined, seconds.total and selection.status. A report without `report_version` is read as
// version 1 (reports before the field carry the same keys); one of a newer version throws
// InputError naming `source`. A key of the wrong type keeps the row, with the reason
// "unreadable report.json: ...".
void add_refine_record(RunRow& row, const nlohmann::json& report, const std::string& failed_line,
                       const std::string& source);

// The row of a building whose inputs cannot be read: failed, with `error`.
RunRow failure_row(const std::string& id, const std::string& error);

// An OBJ model to evaluate (read_obj), refused with InputError beyond validation's size bounds
// (size_problem): the distances' AABB tree degrades on faces of thousands of collinear vertices
// as validation does (minutes for one building).
Mesh read_eval_model(const std::string& path);

// Evaluates every building of `dir` (discover_run), `jobs` at once, rows in id order, each with
// its refine record. A building with unreadable inputs is a failed row; any other error stops
// the run and is rethrown. Each building's per-point series go into `series` in the run's order
// (the same bytes whatever `jobs`) and are then dropped: memory holds the bins and at most
// kInOrderItemsPerJob x jobs buildings' series (in_order_pool.h), not the run's. A progress line
// counts the buildings (`progress_mode`). Each building's cloud is read with `cloud_options`
// (max_points).
std::vector<RunRow> evaluate_run(const std::string& dir, const RefineConfig& params, const std::string& svg_dir,
                                 int jobs, PooledSeries& series, Progress::Mode progress_mode,
                                 const CloudOptions& cloud_options = {});

}  // namespace lodrefine
