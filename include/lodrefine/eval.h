// The paper's metrics (Sec. 4.2) and truth-based ones: C2M signed distances on an AABB tree,
// centroid offset reduction, watertightness.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "lodrefine/params.h"
#include "lodrefine/types.h"

namespace lodrefine {

struct DistanceStats {
  std::size_t count = 0;
  double rmse = 0, mae = 0, mean = 0, std = 0, median = 0, p95 = 0, max_abs = 0;
};
DistanceStats summarize_distances(const std::vector<double>& d);

// Signed distance from each point to the nearest point of the mesh surface (positive on the
// side the nearest face's outward normal points to). CGAL AABB tree on the triangulated faces.
std::vector<double> cloud_to_mesh(const Mesh& mesh, const std::vector<Vec3>& points);

// Volume centroid of a closed mesh (falls back to the area centroid of an open one).
Vec3 mesh_centroid(const Mesh& mesh);

struct BuildingEval {
  std::string id;
  std::size_t facade_points = 0;
  DistanceStats before, after;          // C2M of the facade points to original / refined
  double delta_d = 0.0;                 // centroid offset reduction (m)
  bool watertight_before = false, watertight_after = false;
  // With a truth model: points sampled on the truth's scanned walls / roofs vs each model.
  std::optional<DistanceStats> truth_facade_before, truth_facade_after;
  std::optional<DistanceStats> truth_roof_before, truth_roof_after;
};

// All inputs in the same frame (use a local one for georeferenced data).
BuildingEval evaluate_building(const Mesh& original, const Mesh& refined, const PointCloud& cloud,
                               const Mesh* truth, const Params& params);

}  // namespace lodrefine
