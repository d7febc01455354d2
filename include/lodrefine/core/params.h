// Every method parameter, declared once with its default, bounds and description.
// The table drives the CLI options, `lodrefine params` (docs) and validation.
#pragma once
#include <string>
#include <vector>

namespace lodrefine {

// X(type, name, default, min, max, description)
#define LODREFINE_PARAMS(X)                                                                              \
  X(int, seed, 42, 0, 2147483647, "RANSAC random seed (runs are reproducible)")                          \
  X(double, ransac_epsilon, 0.03, 0.001, 1.0, "RANSAC: max point-to-plane distance of an inlier (m)")    \
  X(double, ransac_cluster_epsilon, 0.25, 0.01, 10.0, "RANSAC: max gap between connected inliers (m)")   \
  X(double, ransac_normal_deg, 25.0, 1.0, 90.0, "RANSAC: max angle between point normal and plane (deg)") \
  X(int, ransac_min_points, 150, 3, 100000000, "RANSAC: min inliers of a plane")                         \
  X(double, ransac_probability, 0.01, 1e-6, 1.0, "RANSAC: probability to miss the largest shape")        \
  X(double, detect_voxel, 0.1, 0.0, 1.0, "plane detection runs on one point per voxel of this size, then takes back the points of its voxels near its planes (m; 0: all points)") \
  X(int, normal_neighbors, 12, 3, 200, "neighbours for PCA normal estimation")                           \
  X(double, min_plane_area, 1.0, 0.0, 1e6, "scan planes whose inlier hull is smaller are ignored (m^2)") \
  X(double, facade_max_tilt_deg, 10.0, 0.0, 45.0, "scan plane counts as facade if its normal is within this of horizontal (deg)") \
  X(double, vertical_snap_deg, 1.5, 0.0, 10.0, "facade planes tilted less than this are refitted exactly vertical (deg)") \
  X(double, change_tolerance, 0.02, 0.0, 1.0, "a matched wall within this of its scan plane everywhere is kept as is (m)") \
  X(double, match_angle_deg, 10.0, 0.0, 90.0, "matching hard filter: max angle between normals (deg)")    \
  X(double, match_distance, 1.25, 0.0, 100.0, "matching hard filter: max distance of a wall to its scan points (m); airborne facades are decimetres to a metre off")  \
  X(double, match_min_overlap, 0.2, 0.0, 1.0, "matching: min OBB overlap (share of the scan box inside the face box)") \
  X(double, match_margin, 0.5, 0.0, 10.0, "matching: scan points up to this far beyond a wall's outline (in its plane) still belong to it (m)") \
  X(double, corner_gap, 0.6, 0.0, 100.0, "a wall match is rejected if the new corner lies farther than this beyond the adjacent scanned facade's points (m)") \
  X(double, w_normal, 0.5, 0.0, 1.0, "matching score weight of |S_normal|")                              \
  X(double, w_coverage, 0.5, 0.0, 1.0, "matching score weight of the OBB IoU C_bbox")                    \
  X(double, bbox_expand, 0.1, 0.0, 2.0, "relative expansion of the bounding box on each side")           \
  X(double, bbox_margin, 1.0, 0.0, 100.0, "absolute expansion of the bounding box on each side (m)")     \
  X(double, merge_angle_deg, 5.0, 0.0, 30.0, "planes within this angle (and merge_distance) are merged (deg)") \
  X(double, merge_distance, 0.05, 0.0, 5.0, "planes closer than this (and within merge_angle_deg) are merged (m)") \
  X(double, conf_angle_deg, 5.0, 0.0, 90.0, "confidence: angle filter theta_filter (deg)")                \
  X(double, conf_model_distance, 0.5, 0.0, 10.0, "confidence: max corner distance to a model reference (m)") \
  X(double, conf_cloud_distance, 0.2, 0.0, 10.0, "confidence: max mean/std point distance to a cloud reference (m)") \
  X(double, conf_bbox_iou, 0.3, 0.0, 1.0, "confidence: min bbox IoU or coverage ratio to a model reference") \
  X(double, tau_cov, 0.3, 0.0, 1.0, "coverage threshold tau_cov: inflection of the sigmoid coverage cost") \
  X(double, lambda_coverage, 1.0, 0.0, 1e6, "weight of the coverage term")                               \
  X(double, lambda_complexity, 0.2, 0.0, 1e6, "weight of the complexity (sharp edge) term")               \
  X(double, mip_time_limit, 2.0, 0.001, 86400.0, "GLPK time limit of a building's face selection (s); at the limit the best selection found, at least the starting shell, is taken") \
  X(double, mip_gap, 1e-4, 0.0, 1.0, "GLPK relative MIP gap")                                            \
  X(double, weld_tolerance, 0.01, 0.0, 1.0, "model repair: vertices closer than this are welded (m)")    \
  X(double, planarity_tolerance, 0.01, 0.0, 1.0, "validation: max vertex distance from its face plane (m)")

struct Params {
#define LODREFINE_PARAM_FIELD(type, name, def, lo, hi, help) type name = def;
  LODREFINE_PARAMS(LODREFINE_PARAM_FIELD)
#undef LODREFINE_PARAM_FIELD
  // Throws InputError naming the first parameter outside its bounds.
  void validate() const;
};

// Read-only description of one parameter, for CLI and docs.
struct ParamInfo {
  std::string name;         // snake_case field name; the CLI option is --kebab-case
  std::string type;         // "int" or "double"
  double default_value;
  double min, max;
  std::string description;
};
const std::vector<ParamInfo>& param_table();

}  // namespace lodrefine
