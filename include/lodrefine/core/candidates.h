// Stage 4 (README's numbering): PolyFit-style candidate faces, for the whole building's
// arrangement (shell_selection.h) and the local one (arrangement.h). Every supporting
// plane (the arrangement has already swept walls coplanar with the scan plane into it), cropped
// to a convex region, is split by every other plane; the convex pieces are the candidates, with
// their edge adjacency for the manifold constraint.
// Vertices are plane-triple meets (solved with pivoting) welded at 1e-6 m, so identity does
// not depend on coordinate magnitude (callers work in a local frame).
#pragma once
#include <array>
#include <vector>

#include "lodrefine/core/geometry.h"
#include "lodrefine/core/types.h"

namespace lodrefine {

struct SupportPlane {
  Plane plane;
  Semantic sem = Semantic::Other;
  bool from_scan = false;  // an MLS facade plane (else a kept model plane)
  int source = -1;         // model surface or scan plane index
};

// An oriented box: the region where candidates are generated.
struct Region {
  Vec3 center = Vec3::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // orthonormal columns
  Vec3 half = Vec3::Ones();
  std::array<Plane, 6> planes() const;  // outward normals; inside is distance <= 0
  bool contains(const Vec3& p, double tol = 0.0) const;
  // Axis-aligned box (in the current frame) of points, expanded.
  static Region around(const std::vector<Vec3>& pts, double relative, double absolute);
};

struct Candidate {
  int plane = -1;          // index into CandidateSet::planes
  std::vector<int> v;      // convex polygon, CCW around planes[plane].plane.n
  double area = 0.0;
  Vec3 centroid = Vec3::Zero();
};

struct CandidateEdge {
  int a = -1, b = -1;
  std::vector<int> faces;  // incident candidates (2, or more where 3+ planes share the line)
  int box_plane = -1;      // 0..5 when the edge lies on the region's boundary
  double length = 0.0;
};

struct CandidateSet {
  std::vector<SupportPlane> planes;
  Region region;
  std::vector<Vec3> vertices;
  std::vector<Candidate> faces;
  std::vector<CandidateEdge> edges;
  std::vector<Vec3> polygon(int f) const;
};

// The convex polygon where `plane` crosses `region` (empty if it misses it), CCW about plane.n.
std::vector<Vec3> region_section(const Plane& plane, const Region& region);

// Splits every plane (cropped to `region`) by every other plane. Pieces smaller than
// `min_area` (m^2) are dropped: by default those under a square millimetre, slivers between
// nearly coincident planes that no face of a building is.
constexpr double kMinCandidateArea = 1e-6;  // m^2
CandidateSet build_candidates(const std::vector<SupportPlane>& planes, const Region& region,
                              double min_area = kMinCandidateArea);

}  // namespace lodrefine
