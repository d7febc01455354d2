// The project's own validator: every model is checked before it is written as refined.
#pragma once
#include <string>
#include <vector>

#include "lodrefine/base/types.h"

namespace lodrefine {

struct Validation {
  int boundary_edges = 0;     // edges with one incident face
  int nonmanifold_edges = 0;  // edges with > 2 incident faces
  int nonmanifold_vertices = 0;
  int inconsistent_edges = 0;  // both faces traverse the edge the same way
  bool outward = false;        // signed volume > 0
  double volume = 0.0;
  double max_planarity_error = 0.0;  // max vertex distance from its face's plane (m)
  bool self_intersecting = false;
  int components = 0;
  std::string problem;  // first problem found, one line; empty when valid

  bool watertight() const { return boundary_edges == 0 && nonmanifold_edges == 0 && nonmanifold_vertices == 0; }
  bool valid() const { return problem.empty(); }
};

// The largest building model validated and refined: faces of at most kMaxFaceVertices
// vertices, at most kMaxFaceCorners face corners in all. The self-intersection test's time grows
// with the square of a face's vertices where they lie on one line (8 faces of 6,000 collinear
// vertices took minutes); Delfshaven's largest LoD2 face has 251 vertices, its largest building
// 1,916 face corners.
inline constexpr std::size_t kMaxFaceVertices = 1000;
inline constexpr std::size_t kMaxFaceCorners = 20000;

// Why `mesh` exceeds those bounds, one line ("face 3 has 6000 vertices, more than 1000 ..."), or
// empty when it does not.
std::string size_problem(const Mesh& mesh);

// Checks closed, 2-manifold (edges and vertices), consistently and outward oriented, planar
// faces within `planarity_tolerance` (RepairConfig::planarity_tolerance; no default here, the
// parameter table holds it), one component, no self-intersections (CGAL PMP on the triangulated
// faces). Expects shared vertices. A mesh beyond size_problem's bounds is invalid unchecked.
// `single_component` false accepts a building of several closed shells (a multi-part export).
Validation validate_mesh(const Mesh& mesh, double planarity_tolerance, bool check_self_intersections = true,
                         bool single_component = true);

// The vertices where `mesh` (shared vertices) is no 2-manifold: its faces there form more than
// one fan (they meet only at the point), or it ends an edge of more than two faces. Sorted.
std::vector<int> pinched_vertices(const Mesh& mesh);

// Enclosed volume of `faces` (all indices valid), positive when they point outward; exact for
// closed meshes of planar faces.
double signed_volume(const std::vector<Vec3>& vertices, const std::vector<Face>& faces);

}  // namespace lodrefine
