// Stage 5, selection (paper Sec. 3.2): PolyFit-style candidate faces on a CGAL::Surface_mesh. Every
// supporting plane, cropped to a convex region, is split by every other plane; the convex pieces
// are the candidates. As in CGAL's Polygonal_surface_reconstruction (its hypothesis), each plane
// is one component of the mesh (its pieces share halfedges), a property map gives each face its
// supporting plane, and the edges of the manifold constraint are the fans of halfedges of all
// components that run along one segment (where 2, 3 or more planes meet on a line).
// Vertices are plane-triple meets (solved with pivoting) welded at 1e-6 m, so identity does
// not depend on coordinate magnitude (callers work in a local frame).
#pragma once
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <utility>
#include <vector>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/types.h"

namespace lodrefine {

struct SupportPlane {
  Plane plane;
  Semantic sem = Semantic::Other;
  bool from_scan = false;  // an MLS facade plane (else a kept model plane)
  int source = -1;         // model surface or scan plane index
  // What a face on it is (Face::provenance): the model's plane, the scan's (a facade, or a
  // start plane a wall was moved onto), or a hypothesis (a step wall, a wall across a hole).
  Provenance provenance = Provenance::Model;
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

using CandidateMesh = CGAL::Surface_mesh<CGAL::Simple_cartesian<double>::Point_3>;
using CandidateFace = CandidateMesh::Face_index;
template <class T>
using CandidateMap = CandidateMesh::Property_map<CandidateFace, T>;

using CandidateHalfedge = CandidateMesh::Halfedge_index;

// A property map of the candidate mesh: its name and its value where unset. Every map the code
// keeps on a candidate mesh is one in candidate_props below, so each name is written once.
template <class Key, class T>
struct CandidateProperty {
  using Map = CandidateMesh::Property_map<Key, T>;
  const char* name;
  T unset;
  // The map on `mesh`, added (every element `unset`) when it has none.
  Map add(CandidateMesh& mesh) const { return mesh.add_property_map<Key, T>(name, unset).first; }
  // The map on `mesh` and whether it has one.
  std::pair<Map, bool> find(const CandidateMesh& mesh) const { return mesh.property_map<Key, T>(name); }
  // The map on `mesh`, which must have it.
  Map get(const CandidateMesh& mesh) const { return find(mesh).first; }
};
template <class T>
using CandidateFaceProperty = CandidateProperty<CandidateFace, T>;

// The candidate mesh's property maps, by what sets them:
// - build_candidates / kept_candidates: `support` (int: a face's plane, an index into `planes`),
//   `area` (double, m^2), `centroid` (Vec3), and per vertex `point` (its index in `vertices`,
//   the same point in every component);
// - select_faces (selection.h): `variable` (int: a face's GLPK column, 1-based; 0 when fixed)
//   and `selected` (bool: chosen);
// - select_shell / rebuild_shell (shell_describe.h's FaceProps): `in_start`, `source` (read
//   by traced_shell, shell_trace.h), `confidence`, `in_zone`, `fit`.
namespace candidate_props {
inline const CandidateFaceProperty<int> support{"f:support", -1};
inline const CandidateFaceProperty<double> area{"f:area", 0.0};
inline const CandidateFaceProperty<Vec3> centroid{"f:centroid", Vec3::Zero()};
inline const CandidateProperty<CandidateMesh::Vertex_index, int> point{"v:point", -1};
inline const CandidateFaceProperty<int> variable{"f:variable", 0};
inline const CandidateFaceProperty<bool> selected{"f:selected", false};
inline const CandidateFaceProperty<bool> in_start{"f:in_start", false};
inline const CandidateFaceProperty<int> source{"f:source", -1};
inline const CandidateFaceProperty<double> confidence{"f:confidence", 0.0};
inline const CandidateFaceProperty<bool> in_zone{"f:in_zone", false};
inline const CandidateFaceProperty<double> fit{"f:fit", 0.0};
}  // namespace candidate_props

// One segment of the arrangement and the candidates along it, as CGAL's hypothesis has it (its
// Intersection): the halfedges of the faces along the segment, one per face (a face along it
// twice, twice), in face order, each running as its face does. 2 in a plane's interior (a
// halfedge and its opposite), more where 3+ planes share the line, 1 on the region's boundary.
using CandidateEdge = std::vector<CandidateHalfedge>;

// The candidates. `mesh` holds them: face f is candidate f, CCW about its plane's normal, with
// the property maps candidate_props::support, area, centroid and point. Adjacency is the halfedge structure's: `edges`
// are the fans (CandidateEdge) in order of first appearance (faces in order, each from its first corner), the
// constraints of the selection (selection.h).
struct CandidateSet {
  std::vector<SupportPlane> planes;
  Region region;
  std::vector<Vec3> vertices;
  CandidateMesh mesh;
  std::vector<CandidateEdge> edges;
  bool capped = false;  // build_candidates stopped at its cap: no candidates
  int size() const { return int(mesh.number_of_faces()); }
  int face(CandidateHalfedge h) const { return int(mesh.face(h)); }
  // The face maps above (present on every set build_candidates or kept_candidates returns).
  CandidateMap<int> supports() const;
  CandidateMap<double> areas() const;
  CandidateMap<Vec3> centroids() const;
  std::vector<int> corners(int f) const;  // indices into `vertices`, CCW
  std::vector<Vec3> polygon(int f) const;
  std::pair<int, int> ends(const CandidateEdge& e) const;  // its ends in `vertices`, smaller first
  double length(const CandidateEdge& e) const;             // m
};

// The convex polygon where `plane` crosses `region` (empty if it misses it), CCW about plane.n.
std::vector<Vec3> region_section(const Plane& plane, const Region& region);

// Splits every plane (cropped to `region`) by every other plane. Pieces smaller than
// `min_area` (m^2) are dropped: by default those under a square millimetre, slivers between
// nearly coincident planes that no face of a building is.
constexpr double kMinCandidateArea = 1e-6;  // m^2
CandidateSet build_candidates(const std::vector<SupportPlane>& planes, const Region& region,
                              double min_area = kMinCandidateArea);

// Local sections: plane i is cropped to `reach[i]` (a box with region's axes; it is intersected
// with `region`) instead of the whole region, and split only by the planes whose boxes meet its
// box. A large building's roof planes then split each other only where they are near, not all
// with all (the cube of the planes); a plane along the whole building (a long facade, the
// ground) is still cut by every plane along it. A face of plane i that
// reaches its box's boundary has an edge no other face shares there: the selection leaves it
// out, so each box must hold every face of plane i a shell may need (callers grow it by the
// farthest a wall can move). reach.size() == planes.size().
// At most `max_candidates` pieces are made: beyond, the set comes back empty with `capped` set
// (bounded time and memory for untrusted input).
constexpr int kMaxCandidates = 40000;
CandidateSet build_candidates(const std::vector<SupportPlane>& planes, const Region& region,
                              const std::vector<Region>& reach, int max_candidates = kMaxCandidates,
                              double min_area = kMinCandidateArea);

// The candidates where keep[f], renumbered in order, on a mesh of their own (the face maps
// above; not those callers added); the edges in their order, on the new mesh's halfedges,
// without the dropped faces (an edge left with none goes). Pruning candidates a program
// fixes unselected leaves the program over the others the same.
CandidateSet kept_candidates(const CandidateSet& cs, const std::vector<char>& keep);

}  // namespace lodrefine
