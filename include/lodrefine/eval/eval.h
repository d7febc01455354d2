// The paper's metrics (Sec. 4.2) and truth-based ones: C2M signed distances on an AABB tree,
// centroid offset reduction, watertightness.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "lodrefine/base/types.h"
#include "lodrefine/core/distance.h"  // cloud_to_mesh, sample_faces: the measures used here
#include "lodrefine/core/params.h"
#include "lodrefine/eval/histogram.h"

namespace lodrefine {

// rmse = sqrt(mean d²), mae = mean |d|, mean = mean d, std = population standard deviation
// (so rmse² = mean² + std², as in the paper's Table 1), median = median of the signed values
// (the boxplot's red line), p95 = 95th percentile of |d|, max_abs = max |d|. Percentiles
// interpolate linearly between order statistics. All zero for an empty input.
struct DistanceStats {
  std::size_t count = 0;
  double rmse = 0, mae = 0, mean = 0, std = 0, median = 0, p95 = 0, max_abs = 0;
};
DistanceStats summarize_distances(const std::vector<double>& d);
// Linearly interpolated quantile q (0..1) of an ascending vector; 0 when empty.
double percentile_sorted(const std::vector<double>& sorted, double q);
// The same value from unsorted values in O(n) (selection, not a sort; a city's tens of millions
// of distances): reorders `values`.
double percentile(std::vector<double>& values, double q);

// Volume centroid of a closed mesh (falls back to the area centroid of an open one).
Vec3 mesh_centroid(const Mesh& mesh);

// The paper's watertightness: closed, edge- and vertex-manifold and consistently oriented.
// Vertices with identical coordinates are welded first (exported soups repeat them per face);
// nothing else is repaired, so mm gaps, holes and flipped faces count against the model.
bool is_watertight(const Mesh& mesh);

// The facade points of a cloud for evaluation: inliers of scan planes matched to the model's
// walls (no ground, clutter or neighbours), in front of their wall. The model is repaired first
// (matching needs the walls' adjacency, which a soup lacks); one no weld closes is matched as
// read. Mesh and cloud in the same (local) frame.
std::vector<int> select_facade_points(const Mesh& mesh, const PointCloud& cloud, const RefineConfig& params);

// Wall faces of `truth` with at least `min_points` of `points` within `distance` of them
// (nearest face) — the walls the scanner saw.
std::vector<int> scanned_walls(const Mesh& truth, const std::vector<Vec3>& points, double distance = 0.05,
                               int min_points = 10);

struct BuildingEval {
  std::string id;
  std::size_t facade_points = 0;
  DistanceStats before, after;  // C2M of the facade points to original / refined
  double delta_d = 0.0;         // centroid offset reduction (m); NaN without facade points
  bool watertight_before = false, watertight_after = false;
  // With a truth model: points sampled on the truth's scanned walls / roofs vs each model.
  std::optional<DistanceStats> truth_facade_before, truth_facade_after;
  std::optional<DistanceStats> truth_roof_before, truth_roof_after;

  // Non-empty when the refined model is missing or unusable: the after-side is left empty and
  // the building counts as not watertight after refinement.
  std::string error;
  // Raw data for pooling and plots.
  std::vector<int> facade_index;                                    // indices into the cloud
  std::vector<double> c2m_before, c2m_after;                        // per facade point, same order
  std::vector<double> truth_facade_d_before, truth_facade_d_after;  // unsigned, per sample
  std::vector<double> truth_roof_d_before, truth_roof_d_after;
  std::vector<int> scanned_truth_faces;  // the truth walls sampled
  Vec3 c_mls = Vec3::Zero(), c_init = Vec3::Zero(), c_ref = Vec3::Zero();
  bool ok() const { return error.empty(); }
};

// All inputs in the same frame (use a local one for georeferenced data). The facade points are
// select_facade_points() of the ORIGINAL model, so both models are measured on the same points.
// A refined mesh without faces marks the building failed (see BuildingEval::error).
BuildingEval evaluate_building(const Mesh& original, const Mesh& refined, const PointCloud& cloud, const Mesh* truth,
                               const RefineConfig& params);
// As above; `scanned_truth_faces` (indices into truth->faces, e.g. from the generator's
// meta.json) replaces the detection of scanned walls when given.
BuildingEval evaluate_building(const Mesh& original, const Mesh& refined, const PointCloud& cloud, const Mesh* truth,
                               const RefineConfig& params, const std::vector<int>* scanned_truth_faces);

// Figures over a whole run.
struct PooledEval {
  std::size_t buildings = 0, failed = 0, evaluated = 0;  // evaluated: ok and with facade points
  DistanceStats before, after;                           // over all facade points of all evaluated buildings
  DistanceStats mean_before, mean_after;                 // each field averaged over evaluated buildings
  double delta_d_mean = 0.0, delta_d_median = 0.0;
  double watertight_rate_before = 0.0, watertight_rate_after = 0.0;  // over all buildings (0..1)
  std::size_t truth_buildings = 0;
  std::optional<DistanceStats> truth_facade_before, truth_facade_after;  // over all samples
  std::optional<DistanceStats> truth_roof_before, truth_roof_after;
};
// The per-point series of a run pooled in bins, one building at a time (memory does not grow
// with the run): add() each building's evaluation, then drop_series() it.
struct PooledSeries {
  DistanceHistogram c2m_before, c2m_after;  // buildings measured with both models
  DistanceHistogram truth_facade_before, truth_facade_after, truth_roof_before, truth_roof_after;
  void add(const BuildingEval& b);
  void merge(const PooledSeries& other);
};
// Frees a building's per-point series (c2m_*, truth_*_d_*, facade_index); its figures stay.
void drop_series(BuildingEval& b);

// Failed buildings count in the watertight rates only (as not watertight after refinement):
// C2M and ΔD pool the buildings measured with both models, so the columns stay comparable.
// Count, RMSE, MAE, mean, std and max |d| come from the buildings' own figures (exact, in
// their order); median and p95 from `series` (to one bin, see histogram.h).
PooledEval pool_evaluations(const std::vector<BuildingEval>& buildings, const PooledSeries& series);
// The same, pooling the buildings' own series (they must not have been dropped).
PooledEval pool_evaluations(const std::vector<BuildingEval>& buildings);

}  // namespace lodrefine
