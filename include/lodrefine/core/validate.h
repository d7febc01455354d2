// Stage 7, validation: the project's own validator; every model is checked before it is written as refined.
#pragma once
#include <string>
#include <vector>

#include "lodrefine/base/types.h"

namespace lodrefine {

// The defects this validator finds, numbered and named as val3dity 2.6 (src/definitions.h,
// docs/errors.rst) numbers the ISO 19107 / CityGML QIE catalogue: 1xx ring, 2xx polygon, 3xx shell,
// 4xx solid. val3dity 2.x folds the non-manifold vertex and edge (its 1.x 303 and 304) into 303.
// Unknown is our own catch-all for what no code names (a vertex not finite, a model beyond
// size_problem's bounds), numbered as val3dity's 999 UNKNOWN_ERROR.
enum class ValidityCode {
  TooFewPoints = 101,                   // a face of fewer than 3 vertices
  ConsecutivePointsSame = 102,          // a face runs through one point twice in a row
  RingSelfIntersection = 104,           // a face revisits a point, or has no area (collapsed to a line)
  NonPlanarPolygonDistancePlane = 203,  // a vertex farther than the planarity tolerance from its face's plane
  TooFewPolygons = 301,                 // fewer than 4 faces
  ShellNotClosed = 302,                 // edges of one face only
  NonManifoldCase = 303,                // edges of more than two faces, or faces meeting only at a vertex
  MultipleConnectedComponents = 305,    // faces in more than one edge-connected part
  ShellSelfIntersection = 306,          // faces cross or touch away from shared edges, or the shell is flat
  PolygonWrongOrientation = 307,        // two faces run their shared edge the same way
  WrongOrientationShell = 405,          // the (consistent) shell points inward
  Unknown = 999,
};
// val3dity's name of the code ("SHELL_NOT_CLOSED"), its `description` in a val3dity report.
const char* code_name(ValidityCode code);
inline int code_number(ValidityCode code) { return int(code); }

// One defect: its code, the faces it concerns (indices into the mesh validated; empty for the
// shell as a whole) and what was found, one line.
struct ValidityError {
  ValidityCode code = ValidityCode::Unknown;
  std::vector<int> faces;
  std::string info;
};

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
  // Every defect found, by code (ascending); empty exactly when `problem` is. A face that is
  // malformed (1xx) ends the checks: the shell's topology and geometry are not looked at.
  std::vector<ValidityError> errors;

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

// val3dity's default tolerances (its --snap_tol and --planarity_d2p_tol): coordinates within a
// millimetre are one point, a vertex within a centimetre of its face's plane is on it.
struct ValidityTolerances {
  double snap = 0.001;      // m, > 0
  double planarity = 0.01;  // m
};

// A polygon soup as a city file holds it (each face its own vertices, any frame) validated as
// one solid: vertices within `snap` welded, in a frame near the soup (georeferenced coordinates
// lose no precision), then validate_mesh at `planarity`, one component expected. The errors'
// face indices are the soup's.
Validation validate_soup(const Mesh& soup, const ValidityTolerances& tolerances = {});

// The codes of `errors` (sorted by code, as Validation::errors is), once each, ascending.
std::vector<int> error_codes(const std::vector<ValidityError>& errors);
inline std::vector<int> error_codes(const Validation& v) { return error_codes(v.errors); }

// Enclosed volume of `faces` (all indices valid), positive when they point outward; exact for
// closed meshes of planar faces.
double signed_volume(const std::vector<Vec3>& vertices, const std::vector<Face>& faces);

}  // namespace lodrefine
