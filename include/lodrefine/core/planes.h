// Stage 1: planar primitives of the MLS cloud (CGAL Efficient RANSAC, the paper's, or region
// growing on CGAL's Region_growing; refitted by PCA).
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

// Detects planes in `cloud` (local frame). Deterministic for a given PlaneConfig::seed. Reads its
// ransac, ransac_*, normal_neighbors, detect_voxel, min_plane_area, facade_max_tilt_deg and
// vertical_snap_deg parameters. Returns planes of at least ransac_min_points inliers and
// min_plane_area hull, largest first; a point is the inlier of one plane at most. Detection runs
// on one point per voxel (detect_voxel; by default, negative, sqrt(min_plane_area /
// (normal_neighbors + 1)), 0.28 m), with normals from the k nearest points of the full cloud, and
// each point of the cloud goes back to the plane that took its voxel's point, if within
// ransac_epsilon of it; detect_voxel = 0 runs it on every point. The detector is Efficient RANSAC
// (ransac = 1) or region growing (ransac = 0): seeds from the most planar neighbourhood down, a
// point joining a region when within ransac_epsilon of its least-squares plane, its normal within
// ransac_normal_deg, and within the detection's cluster epsilon of a member (a point of the voxels
// around or of its normal's neighbourhood). Too few, repeated or nearly coincident points give no
// plane.
std::vector<ScanPlane> detect_planes(const PointCloud& cloud, const PlaneConfig& config);

}  // namespace lodrefine
