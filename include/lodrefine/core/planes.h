// Stage 2, planes: planar primitives of the MLS cloud (CGAL Efficient RANSAC, the paper's, or region
// growing on CGAL's Region_growing; refitted by PCA).
#pragma once
#include <vector>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/types.h"
#include "lodrefine/core/params.h"

namespace lodrefine {

struct ScanPlane {
  Plane plane;               // PCA refit on the inliers, normal oriented away from the model if known
  std::vector<int> inliers;  // indices into the cloud
  Vec3 centroid = Vec3::Zero();
  double rms = 0.0;        // inlier distance RMS (m)
  double hull_area = 0.0;  // area of the inliers' 2D convex hull in the plane (m^2)
  bool facade = false;     // near-vertical
  // m: the distance between the two copies of a facade seen by two drives registered apart
  // (0: one copy). The plane then lies midway between them and holds both copies' points.
  double doubled = 0.0;
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
// plane. A facade seen twice (two drives registered a few centimetres apart: the points within
// kMaxDoubledWall of its plane and inside its extent fall in two layers, each holding a fifth of
// them or more, as wide and tall as each other) is one plane midway between the layers, with
// `doubled` their distance; the pieces RANSAC cut from the second layer are gone.
std::vector<ScanPlane> detect_planes(const PointCloud& cloud, const PlaneConfig& config);

// m: the farthest apart two copies of one facade are taken for a misregistration, not two walls.
constexpr double kMaxDoubledWall = 0.12;

// Lays the two copies of each doubled facade (ScanPlane::doubled) onto its plane: each inlier
// moves by half their distance towards the plane, from the side it lies on. Later stages then see
// one wall with one drive's noise. `planes` index into `cloud`.
void collapse_doubled_walls(PointCloud& cloud, const std::vector<ScanPlane>& planes);

// The scan's facade planes that are relief, not walls: balconies, cornices, ledges, shop fronts,
// cars. A wall stands from its foot to its eave, however sparse its points (a return seen at a
// grazing angle); relief stands over a part of that. A facade plane is a wall when, beside some
// model wall parallel to it (within facade_max_tilt_deg and kReliefDepth of it: balconies stand
// 1-1.5 m proud, a recess's return stands metres from the side walls it parallels; its extent
// along the street), its inliers span kMinWallSpan of the wall's height bins (kHeightBin, the
// wall's foot to its eave: its lowest vertex to the highest at either end). Planes beside no
// such model wall (a wall the model lacks) are walls. Returns the walls; `relief` (optional)
// gets the others.
constexpr double kHeightBin = 0.5;    // m
constexpr double kReliefDepth = 1.6;  // m
constexpr double kMinWallSpan = 0.5;
std::vector<ScanPlane> without_relief(std::vector<ScanPlane> planes, const Mesh& model, const PointCloud& cloud,
                                      const PlaneConfig& config, std::vector<ScanPlane>* relief = nullptr);

}  // namespace lodrefine
