// Stage 3, matching: model-to-surface matching. Groups the model's faces into planar surfaces, matches
// scan planes to wall surfaces and scores the model by Q_model (sum of S_match).
#pragma once
#include <string>
#include <vector>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/types.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/planes.h"

namespace lodrefine {

// Edge-connected coplanar faces: one supporting plane of the model; its semantic is the one
// covering most of its area.
struct ModelSurface {
  Plane plane;             // PCA plane of all its vertices, oriented outward
  std::vector<int> faces;  // indices into Mesh::faces
  Semantic sem = Semantic::Other;
  double area = 0.0;
  Vec3 centroid = Vec3::Zero();
};

// A face joins a surface when its normal is within kSurfaceAngleDeg of the surface's first face
// and all its vertices lie within kSurfaceDistance of that face's plane. Twice the default
// planarity tolerance: faces that pass validation each (1 cm off their own plane) still join
// their coplanar neighbours, while a real step or kink between walls (decimetres) does not.
constexpr double kSurfaceAngleDeg = 1.0;
constexpr double kSurfaceDistance = 0.02;  // m
std::vector<ModelSurface> model_surfaces(const Mesh& mesh, double angle_deg = kSurfaceAngleDeg,
                                         double distance = kSurfaceDistance);

// Largest distance of a surface's vertices from `plane` (how far the wall moves onto it).
double surface_deviation(const Mesh& mesh, const ModelSurface& surface, const Plane& plane);
// Mean distance of a surface's vertices from `plane` (0 for a surface without vertices).
double surface_mean_deviation(const Mesh& mesh, const ModelSurface& surface, const Plane& plane);

struct Match {
  int scan_plane = -1;  // index into the scan planes
  int surface = -1;     // index into the model surfaces
  double s_normal = 0, d_centroid = 0, c_bbox = 0, s_match = 0;
  std::vector<int> owned;  // the scan points in front of the wall that belong to it
};

struct MatchResult {
  std::vector<Match> matches;  // the accepted one-to-one matches (one scan plane per surface)
  double q_model = 0.0;        // sum of S_match
  // One line per match turned down after a wall was found in reach of the plane (coverage,
  // facing, a corner conflict), and why; a plane no wall is near (match_distance,
  // match_angle_deg) has no candidate and no line.
  std::vector<std::string> rejected;
};

// A facade plane and a wall surface match when (hard filters) their normals are within
// match_angle_deg, at least 150 of the plane's inliers belong to the wall (each point goes to the
// nearest wall within match_distance of it whose outline, grown by match_margin, it lies in
// front of), and those points cover match_min_overlap of the wall (the largest of the in-plane
// boxes' IoU and the share of either box inside the other). Of the matches, each wall keeps the
// plane with most points, walls facing away from the one the plane fits best are dropped, and
// so are matches whose corner with an adjacent matched facade lies over corner_gap beyond both
// that facade's points and its wall's end in the model (a scan that stops short of the corner is
// no conflict). S_match = w_normal |S_normal| + w_coverage IoU.
MatchResult match_surfaces(const Mesh& mesh, const std::vector<ModelSurface>& surfaces, const PointCloud& cloud,
                           const std::vector<ScanPlane>& planes, const MatchConfig& config);

// The inliers of each matched scan plane that lie in front of its wall, grown by `margin` (a
// plane may run on along a flush neighbouring facade, whose points are not this building's);
// indices into `cloud`, ascending.
std::vector<int> points_in_front(const Mesh& mesh, const std::vector<ModelSurface>& surfaces,
                                 const std::vector<ScanPlane>& planes, const MatchResult& matched,
                                 const PointCloud& cloud, double margin);

}  // namespace lodrefine
