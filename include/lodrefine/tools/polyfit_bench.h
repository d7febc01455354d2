// lodrefine beside CGAL's PolyFit (polyfit_baseline.h) on the same buildings, in the same
// process (`lodrefine bench --polyfit`): per building the wall-clock time of each and their
// truth distances as eval.h measures them, then medians, ratios, pooled RMSEs and PolyFit's
// failures. Speed is printed, never asserted.
#pragma once
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "lodrefine/base/types.h"
#include "lodrefine/core/params.h"
#include "lodrefine/eval/eval.h"
#include "lodrefine/tools/polyfit_baseline.h"
#include "lodrefine/tools/run.h"

namespace lodrefine {

// One building in its input frame: coarse model, cloud, truth (no faces: no truth figures) and,
// when known, the truth faces the scan saw (else eval detects them).
struct BenchBuilding {
  std::string id;
  Mesh coarse, truth;
  PointCloud cloud;
  std::optional<std::vector<int>> scanned_truth_faces;
};

// The buildings of `dir`, sorted by id: a dev tile (models/<id>.obj, clouds/<id>.ply,
// truth/<id>.obj) when it has a models/ folder, else a run folder (run.h's discover_run:
// <id>/coarse.obj, cloud.ply, truth.obj). Throws InputError when there is none.
std::vector<BuildingFiles> discover_bench(const std::string& dir);
// Reads one building (truth when its file is set). Throws InputError on unreadable input.
BenchBuilding read_bench_building(const BuildingFiles& files);
// A method's output for `b` (input frame) against its coarse model and truth, measured in the
// coarse model's local frame: evaluate_building with the scan, the truth when it has faces and
// the scanned truth faces when known.
BuildingEval evaluate_against_truth(const BenchBuilding& b, const Mesh& output, const RefineConfig& params);

// What one method gave for a building.
struct MethodRun {
  double seconds = 0.0;      // wall clock of the call
  double cpu_seconds = 0.0;  // its CPU time (the machine's load does not inflate it)
  bool produced = false;     // a mesh to measure (lodrefine: always; PolyFit: when closed)
  bool watertight = false;
  std::optional<DistanceStats> truth_facade, truth_roof;
};

struct PolyfitComparisonRow {
  std::string id;
  std::size_t points = 0;             // of the cloud
  Outcome outcome = Outcome::Failed;  // lodrefine's
  std::optional<DistanceStats> coarse_facade, coarse_roof;
  MethodRun lodrefine, polyfit;
  PolyfitResult baseline;  // the mesh dropped; status, reason, planes, candidates, times
};

// Refines `b` with refine_building and reconstructs it with polyfit_baseline_isolated (same params, one
// after the other), and measures the coarse model and both outputs against its truth in its
// local frame (evaluate_building: truth facade and roof distances, watertightness).
PolyfitComparisonRow compare_with_polyfit(const BenchBuilding& b, const RefineConfig& params,
                                          const PolyfitOptions& options);

struct PolyfitComparison {
  int buildings = 0, polyfit_closed = 0, lodrefine_watertight = 0, polyfit_watertight = 0;
  std::vector<std::pair<std::string, int>> failures;  // PolyFit status name -> buildings
  double lodrefine_median = 0, lodrefine_max = 0, polyfit_median = 0, polyfit_max = 0;  // s, wall clock
  double lodrefine_cpu_median = 0, lodrefine_cpu_max = 0, polyfit_cpu_median = 0, polyfit_cpu_max = 0;
  double ratio_of_medians = 0, cpu_ratio_of_medians = 0;  // PolyFit's median / lodrefine's
  double ratio_median = 0, ratio_min = 0;                 // per building PolyFit / lodrefine
  // Truth RMSE pooled over the samples (m; NaN when none): over every building, and over those
  // PolyFit closed (the same buildings for the three columns).
  double facade_coarse = 0, facade_lodrefine = 0;
  double facade_coarse_closed = 0, facade_lodrefine_closed = 0, facade_polyfit_closed = 0;
  double roof_coarse = 0, roof_lodrefine = 0;
  double roof_coarse_closed = 0, roof_lodrefine_closed = 0, roof_polyfit_closed = 0;
};
PolyfitComparison summarize_comparison(const std::vector<PolyfitComparisonRow>& rows);

// The table: a header, one line per row (print_comparison_row as each building finishes), then
// the summary.
void print_comparison_header(std::FILE* out);
void print_comparison_row(const PolyfitComparisonRow& row, std::FILE* out);
void print_comparison_summary(const PolyfitComparison& s, const PolyfitOptions& options, std::FILE* out);

}  // namespace lodrefine
