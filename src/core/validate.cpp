// Mesh validation. The only translation unit of io/repair/validate that pulls in CGAL's
// self-intersection machinery (slow to compile).
#include "lodrefine/core/validate.h"

// Self-overlapping face outlines reach CDT_2 (and fall back, see face_triangles): no warning spam.
#define CGAL_NO_CDT_2_WARNING
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/Euler_operations.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <numeric>
#include <set>
#include <sstream>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/topology.h"

namespace lodrefine {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using SmVertex = SurfaceMesh::Vertex_index;
using SmFace = SurfaceMesh::Face_index;

// A face whose area is below this fraction of its longest edge squared is a line or a point:
// it has no plane (CGAL's face triangulation crashes on its null normal), so the mesh is
// reported invalid before any triangulation. Far below any real sliver (a 10 m edge with a
// 1 nm wide face is 1e-10), far above rounding noise of local-frame coordinates.
constexpr double kDegenerateFaceRatio = 1e-12;

// A shell enclosing less than this (m^3) is flat: a building lowered to the ground.
constexpr double kFlatShellVolume = 1e-9;

std::string format_number(double x) {
  std::ostringstream s;
  s.precision(3);
  s << x;
  return s.str();
}

bool degenerate(const std::vector<Vec3>& pts) {
  double longest = 0.0;
  for (std::size_t i = 0; i < pts.size(); ++i)
    longest = std::max(longest, (pts[(i + 1) % pts.size()] - pts[i]).squaredNorm());
  return newell_normal(pts).norm() <= kDegenerateFaceRatio * longest;
}

// Index errors and degenerate polygons make every other check meaningless.
std::string malformed(const Mesh& m) {
  for (std::size_t i = 0; i < m.vertices.size(); ++i)
    if (!m.vertices[i].allFinite()) return "vertex " + std::to_string(i) + " is not finite";
  for (std::size_t k = 0; k < m.faces.size(); ++k) {
    const auto& v = m.faces[k].v;
    const std::string face = "face " + std::to_string(k);
    if (v.size() < 3) return face + " has fewer than 3 vertices";
    for (int i : v)
      if (i < 0 || std::size_t(i) >= m.vertices.size()) return face + " references missing vertex " + std::to_string(i);
    if (std::set<int>(v.begin(), v.end()).size() != v.size()) return face + " repeats a vertex";
  }
  for (std::size_t k = 0; k < m.faces.size(); ++k) {
    std::vector<Vec3> pts = face_points(m, m.faces[k]);
    if (degenerate(pts))
      return "face " + std::to_string(k) +
             " is degenerate (no area: its vertices are on one line or it folds onto itself)";
    // Two vertices at one point make CGAL's constrained triangulation of the face crash.
    std::sort(pts.begin(), pts.end(), [](const Vec3& a, const Vec3& b) {
      return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
    });
    if (std::adjacent_find(pts.begin(), pts.end()) != pts.end())
      return "face " + std::to_string(k) + " has two vertices at one point";
  }
  return {};
}

void count_edge_defects(const EdgeUses& uses, Validation& v) {
  for (const auto& entry : uses) {
    const auto& u = entry.second;
    if (u.size() == 1) ++v.boundary_edges;
    else if (u.size() > 2) ++v.nonmanifold_edges;
    else if (u[0].forward == u[1].forward) ++v.inconsistent_edges;
  }
}

// The vertices whose faces form more than one edge-connected fan.
std::vector<int> fanned_vertices(const Mesh& m, const EdgeUses& uses) {
  std::map<std::pair<int, int>, int> corner;  // (vertex, face) -> id
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    for (int v : m.faces[f].v) {
      const int id = int(corner.size());
      corner.emplace(std::make_pair(v, int(f)), id);
    }
  DisjointSets fans(corner.size());
  for (const auto& [e, u] : uses)
    for (int v : {e.first, e.second})
      for (std::size_t k = 1; k < u.size(); ++k) fans.unite(corner.at({v, u[0].face}), corner.at({v, u[k].face}));
  std::map<int, std::set<int>> fans_of;
  for (const auto& [vf, id] : corner) fans_of[vf.first].insert(fans.find(id));
  std::vector<int> out;
  for (const auto& [v, f] : fans_of)
    if (f.size() > 1) out.push_back(v);
  return out;
}

double max_planarity_error(const Mesh& m) {
  double err = 0.0;
  for (const Face& f : m.faces) {
    const auto pts = face_points(m, f);
    const Plane plane = polygon_plane(pts);
    for (const Vec3& p : pts) err = std::max(err, std::abs(plane.distance(p)));
  }
  return err;
}

// Whether two edges of the outline that share no vertex touch or cross, or come within a
// billionth of its size of each other, in the plane of the two coordinates its normal leaves
// (dropping one is exact, and the segment test is CGAL's exact predicate). Edges are swept by
// their boxes' x: only pairs whose boxes come within that tolerance are tested, so an outline of
// many vertices costs about a sort, not a test per pair.
bool touches_itself(const std::vector<Vec3>& pts) {
  const Vec3 n = newell_normal(pts).cwiseAbs();
  const int drop = n.x() >= n.y() && n.x() >= n.z() ? 0 : n.y() >= n.z() ? 1 : 2;
  const int a = drop == 0 ? 1 : 0, b = drop == 2 ? 1 : 2;
  Eigen::AlignedBox3d box;
  for (const Vec3& p : pts) box.extend(p);
  const double tol = 1e-9 * box.diagonal().norm();
  const std::size_t m = pts.size();
  std::vector<Kernel::Segment_2> edge;
  for (std::size_t i = 0; i < m; ++i) {
    const Vec3 &p = pts[i], &q = pts[(i + 1) % m];
    edge.emplace_back(Kernel::Point_2(p[a], p[b]), Kernel::Point_2(q[a], q[b]));
  }
  std::vector<std::size_t> by_x(m);
  std::iota(by_x.begin(), by_x.end(), 0);
  std::sort(by_x.begin(), by_x.end(),
            [&](std::size_t i, std::size_t j) { return edge[i].bbox().xmin() < edge[j].bbox().xmin(); });
  auto adjacent = [&](std::size_t i, std::size_t j) { return (i + 1) % m == j || (j + 1) % m == i; };
  for (std::size_t k = 0; k < m; ++k) {
    const std::size_t i = by_x[k];
    const CGAL::Bbox_2 bi = edge[i].bbox();
    for (std::size_t l = k + 1; l < m && edge[by_x[l]].bbox().xmin() - bi.xmax() <= tol; ++l) {
      const std::size_t j = by_x[l];
      const CGAL::Bbox_2 bj = edge[j].bbox();
      if (adjacent(i, j) || bi.ymin() - bj.ymax() > tol || bj.ymin() - bi.ymax() > tol) continue;
      if (CGAL::do_intersect(edge[i], edge[j]) || CGAL::squared_distance(edge[i], edge[j]) <= tol * tol) return true;
    }
  }
  return false;
}

// Triangles of one face as indices into it. CGAL's constrained Delaunay triangulation in the
// face's plane is used first: geometry.h's ear clipper accepts ears whose diagonal runs through
// a reflex vertex (an L-shaped roof then gets overlapping triangles that would read as a
// self-intersection). Outlines that touch or cross themselves go to the clipper: CGAL rejects
// some, and on one (a ground face with a vertex on its closing edge, a Delfshaven building with
// region-grown planes) its triangulation never returned.
std::vector<std::array<int, 3>> face_triangles(const std::vector<Vec3>& pts) {
  if (pts.size() == 3) return {{0, 1, 2}};
  if (touches_itself(pts)) return triangulate_polygon(pts);
  SurfaceMesh one;
  std::vector<SmVertex> loop;
  for (const Vec3& p : pts) loop.push_back(one.add_vertex(Kernel::Point_3(p.x(), p.y(), p.z())));
  const SmFace f = one.add_face(loop);
  if (f == SurfaceMesh::null_face() || !CGAL::Polygon_mesh_processing::triangulate_face(f, one))
    return triangulate_polygon(pts);
  std::vector<std::array<int, 3>> tris;
  for (SmFace t : one.faces()) {
    std::array<int, 3> tri{};
    int k = 0;
    for (SmVertex v : CGAL::vertices_around_face(one.halfedge(t), one)) tri[k++] = int(v);
    tris.push_back(tri);
  }
  return tris;
}

// Triangulated faces as a Surface_mesh for CGAL's self-intersection test. A triangle that cannot
// join the mesh topologically (at a non-manifold or inconsistent spot) gets its own vertex
// copies; `original` maps every mesh vertex back to the input vertex it stands for.
SurfaceMesh triangle_mesh(const Mesh& m, std::vector<int>& original) {
  SurfaceMesh sm;
  std::vector<SmVertex> vid;
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    const Vec3& p = m.vertices[i];
    vid.push_back(sm.add_vertex(Kernel::Point_3(p.x(), p.y(), p.z())));
    original.push_back(int(i));
  }
  for (const Face& f : m.faces)
    for (const auto& t : face_triangles(face_points(m, f))) {
      std::array<SmVertex, 3> tri = {vid[f.v[t[0]]], vid[f.v[t[1]]], vid[f.v[t[2]]]};
      if (CGAL::Euler::can_add_face(tri, sm) && sm.add_face(tri) != SurfaceMesh::null_face()) continue;
      for (int k = 0; k < 3; ++k) {
        const Kernel::Point_3 p = sm.point(tri[k]);  // a copy: add_vertex may reallocate the points
        tri[k] = sm.add_vertex(p);
        original.push_back(f.v[t[k]]);
      }
      sm.add_face(tri);
    }
  return sm;
}

std::set<int> face_vertices(const SurfaceMesh& sm, SmFace f) {
  std::set<int> out;
  for (SmVertex v : CGAL::vertices_around_face(sm.halfedge(f), sm)) out.insert(int(v));
  return out;
}

// CGAL reports triangles touching at a point unless they share that vertex in the mesh, so
// pairs that share an input vertex only through copies are skipped (they meet there by
// construction; a deeper crossing of such a pair goes unnoticed, but such a mesh already fails
// the manifold checks). Degenerate triangles come back as (f, f) and are no intersection.
bool self_intersects(const Mesh& m) {
  std::vector<int> original;
  const SurfaceMesh sm = triangle_mesh(m, original);
  std::vector<std::pair<SmFace, SmFace>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(sm, std::back_inserter(pairs));
  for (const auto& [f, g] : pairs) {
    if (f == g) continue;
    const auto a = face_vertices(sm, f), b = face_vertices(sm, g);
    std::set<int> oa, ob;
    for (int v : a) oa.insert(original[v]);
    for (int v : b) ob.insert(original[v]);
    const bool shared_in_mesh = std::any_of(a.begin(), a.end(), [&](int v) { return b.count(v) > 0; });
    const bool shared_by_copy = std::any_of(oa.begin(), oa.end(), [&](int v) { return ob.count(v) > 0; });
    if (shared_in_mesh || !shared_by_copy) return true;
  }
  return false;
}

std::string first_problem(const Validation& v, double planarity_tolerance, bool single_component) {
  const auto n = [](int k) { return std::to_string(k); };
  if (v.boundary_edges) return n(v.boundary_edges) + " boundary edges (mesh not closed)";
  if (v.nonmanifold_edges) return n(v.nonmanifold_edges) + " non-manifold edges (more than two faces)";
  if (v.nonmanifold_vertices) return n(v.nonmanifold_vertices) + " non-manifold vertices (faces meet only at a point)";
  if (v.inconsistent_edges) return n(v.inconsistent_edges) + " inconsistently oriented edges";
  if (single_component && v.components != 1) return n(v.components) + " connected components (expected one)";
  if (std::abs(v.volume) < kFlatShellVolume)
    return "the shell encloses no volume (signed volume " + format_number(v.volume) + " m^3)";
  if (!v.outward) return "faces point inward (signed volume " + format_number(v.volume) + " m^3)";
  if (v.max_planarity_error > planarity_tolerance)
    return "face planarity error " + format_number(v.max_planarity_error) + " m exceeds " +
           format_number(planarity_tolerance) + " m";
  if (v.self_intersecting) return "faces intersect each other";
  return {};
}

}  // namespace

double signed_volume(const std::vector<Vec3>& vertices, const std::vector<Face>& faces) {
  // Pyramids from a reference point near the mesh: small lever arms keep georeferenced
  // coordinates precise.
  Vec3 ref = Vec3::Zero();
  std::size_t n = 0;
  for (const Face& f : faces)
    for (int i : f.v) ref += vertices[i], ++n;
  if (n == 0) return 0.0;
  ref /= double(n);
  double volume = 0.0;
  for (const Face& f : faces) {
    std::vector<Vec3> pts;
    Vec3 mean = Vec3::Zero();
    for (int i : f.v) pts.push_back(vertices[i] - ref), mean += pts.back();
    volume += newell_normal(pts).dot(mean / double(pts.size())) / 6.0;
  }
  return volume;
}

std::string size_problem(const Mesh& mesh) {
  std::size_t corners = 0;
  for (std::size_t k = 0; k < mesh.faces.size(); ++k) {
    const std::size_t n = mesh.faces[k].v.size();
    if (n > kMaxFaceVertices)
      return "face " + std::to_string(k) + " has " + std::to_string(n) + " vertices, more than " +
             std::to_string(kMaxFaceVertices) + " (LoD2 faces have tens)";
    corners += n;
  }
  if (corners > kMaxFaceCorners)
    return "the faces have " + std::to_string(corners) + " corners in all, more than " +
           std::to_string(kMaxFaceCorners) + " (LoD2 buildings have hundreds)";
  return {};
}

std::vector<int> pinched_vertices(const Mesh& mesh) {
  const EdgeUses uses = edge_uses(mesh.faces);
  std::vector<int> out = fanned_vertices(mesh, uses);
  for (const auto& [e, u] : uses)
    if (u.size() > 2) out.insert(out.end(), {e.first, e.second});
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

Validation validate_mesh(const Mesh& mesh, double planarity_tolerance, bool check_self_intersections,
                         bool single_component) {
  Validation v;
  v.problem = mesh.faces.empty() ? "no faces" : size_problem(mesh);
  if (v.problem.empty()) v.problem = malformed(mesh);
  if (!v.problem.empty()) return v;
  const EdgeUses uses = edge_uses(mesh.faces);
  count_edge_defects(uses, v);
  v.nonmanifold_vertices = int(fanned_vertices(mesh, uses).size());
  v.components = count_components(mesh.faces.size(), uses);
  v.volume = signed_volume(mesh.vertices, mesh.faces);
  v.outward = v.volume > 0;
  v.max_planarity_error = max_planarity_error(mesh);
  if (check_self_intersections) v.self_intersecting = self_intersects(mesh);
  v.problem = first_problem(v, planarity_tolerance, single_component);
  return v;
}

}  // namespace lodrefine
