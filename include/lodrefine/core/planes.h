// Stage 1: planar primitives of the MLS cloud (CGAL Efficient RANSAC, refitted by PCA).
#pragma once
#include <vector>

#include "lodrefine/core/geometry.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/types.h"

namespace lodrefine {

struct ScanPlane {
  Plane plane;               // PCA refit on the inliers, normal oriented away from the model if known
  std::vector<int> inliers;  // indices into the cloud
  Vec3 centroid = Vec3::Zero();
  double rms = 0.0;        // inlier distance RMS (m)
  double hull_area = 0.0;  // area of the inliers' 2D convex hull in the plane (m^2)
  bool facade = false;     // near-vertical
};

// Detects planes in `cloud` (local frame). Deterministic for a given PlaneConfig::seed.
std::vector<ScanPlane> detect_planes(const PointCloud& cloud, const PlaneConfig& config);

}  // namespace lodrefine
