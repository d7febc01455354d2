// The project's own validator: every model is checked before it is written as refined.
#pragma once
#include <string>
#include <vector>

#include "lodrefine/core/types.h"

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

// Checks closed, 2-manifold (edges and vertices), consistently and outward oriented, planar
// faces within `planarity_tolerance` (Params::planarity_tolerance; no default here, the
// parameter table holds it), one component, no self-intersections (CGAL PMP on the triangulated
// faces). Expects shared vertices. `single_component` false accepts a building of several closed
// shells (a multi-part export).
Validation validate_mesh(const Mesh& mesh, double planarity_tolerance, bool check_self_intersections = true,
                         bool single_component = true);

// Enclosed volume of `faces` (all indices valid), positive when they point outward; exact for
// closed meshes of planar faces.
double signed_volume(const std::vector<Vec3>& vertices, const std::vector<Face>& faces);

}  // namespace lodrefine
