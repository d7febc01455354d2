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
#include <optional>
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

bool sorted_less(const Vec3& a, const Vec3& b) {
  return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
}

// What is wrong with face k's index list (empty when nothing): fewer than 3 vertices (101), a
// missing vertex (no code: the mesh is not one), a vertex twice in a row (102) or apart (104).
std::optional<ValidityError> malformed_indices(const Mesh& m, std::size_t k) {
  const auto& v = m.faces[k].v;
  const std::string face = "face " + std::to_string(k);
  const std::vector<int> which = {int(k)};
  if (v.size() < 3) return ValidityError{ValidityCode::TooFewPoints, which, face + " has fewer than 3 vertices"};
  for (int i : v)
    if (i < 0 || std::size_t(i) >= m.vertices.size())
      return ValidityError{ValidityCode::Unknown, which, face + " references missing vertex " + std::to_string(i)};
  if (std::set<int>(v.begin(), v.end()).size() == v.size()) return std::nullopt;
  bool in_a_row = false;
  for (std::size_t i = 0; i < v.size(); ++i) in_a_row |= v[i] == v[(i + 1) % v.size()];
  return ValidityError{in_a_row ? ValidityCode::ConsecutivePointsSame : ValidityCode::RingSelfIntersection, which,
                       face + " repeats a vertex"};
}

// What is wrong with face k's geometry: no area (104), two vertices at one point (102 when
// they follow each other, else 104).
std::optional<ValidityError> malformed_geometry(const Mesh& m, std::size_t k) {
  std::vector<Vec3> pts = face_points(m, m.faces[k]);
  const std::vector<int> which = {int(k)};
  if (degenerate(pts))
    return ValidityError{
        ValidityCode::RingSelfIntersection, which,
        "face " + std::to_string(k) + " is degenerate (no area: its vertices are on one line or it folds onto itself)"};
  bool in_a_row = false;
  for (std::size_t i = 0; i < pts.size(); ++i) in_a_row |= pts[i] == pts[(i + 1) % pts.size()];
  // Two vertices at one point make CGAL's constrained triangulation of the face crash.
  std::sort(pts.begin(), pts.end(), sorted_less);
  if (std::adjacent_find(pts.begin(), pts.end()) == pts.end()) return std::nullopt;
  return ValidityError{in_a_row ? ValidityCode::ConsecutivePointsSame : ValidityCode::RingSelfIntersection, which,
                       "face " + std::to_string(k) + " has two vertices at one point"};
}

// Index errors and degenerate polygons make every other check meaningless: every face's, in
// face order, the index lists' before the geometry's (the first is the validation's problem).
std::vector<ValidityError> malformed(const Mesh& m) {
  for (std::size_t i = 0; i < m.vertices.size(); ++i)
    if (!m.vertices[i].allFinite())
      return {{ValidityCode::Unknown, {}, "vertex " + std::to_string(i) + " is not finite"}};
  std::vector<ValidityError> out;
  for (std::size_t k = 0; k < m.faces.size(); ++k)
    if (auto e = malformed_indices(m, k)) out.push_back(std::move(*e));
  if (!out.empty()) return out;
  for (std::size_t k = 0; k < m.faces.size(); ++k)
    if (auto e = malformed_geometry(m, k)) out.push_back(std::move(*e));
  return out;
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

// Each face's largest vertex distance from its plane.
std::vector<double> planarity_errors(const Mesh& m) {
  std::vector<double> out;
  for (const Face& f : m.faces) {
    const auto pts = face_points(m, f);
    const Plane plane = polygon_plane(pts);
    double err = 0.0;
    for (const Vec3& p : pts) err = std::max(err, std::abs(plane.distance(p)));
    out.push_back(err);
  }
  return out;
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

// The shell's defects, in the order the first of them is its problem: its topology (302, 303,
// 307, and 305 when one component is expected); on a shell whose topology holds (val3dity checks
// the geometry only then) a flat (306) or inward (405) shell; its faces' planarity (203); then
// self-intersections (306, again on a sound topology only); 301 last (a solid of fewer than 4
// faces shows another defect first).
std::vector<ValidityError> shell_errors(const Validation& v, const std::vector<double>& planarity,
                                        double planarity_tolerance, bool single_component) {
  const auto n = [](int k) { return std::to_string(k); };
  std::vector<ValidityError> out;
  const auto add = [&](ValidityCode code, std::string info) { out.push_back({code, {}, std::move(info)}); };
  if (v.boundary_edges) add(ValidityCode::ShellNotClosed, n(v.boundary_edges) + " boundary edges (mesh not closed)");
  if (v.nonmanifold_edges)
    add(ValidityCode::NonManifoldCase, n(v.nonmanifold_edges) + " non-manifold edges (more than two faces)");
  if (v.nonmanifold_vertices)
    add(ValidityCode::NonManifoldCase,
        n(v.nonmanifold_vertices) + " non-manifold vertices (faces meet only at a point)");
  if (v.inconsistent_edges)
    add(ValidityCode::PolygonWrongOrientation, n(v.inconsistent_edges) + " inconsistently oriented edges");
  if (single_component && v.components != 1)
    add(ValidityCode::MultipleConnectedComponents, n(v.components) + " connected components (expected one)");
  const bool sound = out.empty();
  if (sound && std::abs(v.volume) < kFlatShellVolume)
    add(ValidityCode::ShellSelfIntersection,
        "the shell encloses no volume (signed volume " + format_number(v.volume) + " m^3)");
  else if (sound && !v.outward)
    add(ValidityCode::WrongOrientationShell, "faces point inward (signed volume " + format_number(v.volume) + " m^3)");
  ValidityError warped{ValidityCode::NonPlanarPolygonDistancePlane, {}, {}};
  for (std::size_t k = 0; k < planarity.size(); ++k)
    if (planarity[k] > planarity_tolerance) warped.faces.push_back(int(k));
  if (!warped.faces.empty()) {
    warped.info = "face planarity error " + format_number(v.max_planarity_error) + " m exceeds " +
                  format_number(planarity_tolerance) + " m";
    out.push_back(std::move(warped));
  }
  if (sound && v.self_intersecting) add(ValidityCode::ShellSelfIntersection, "faces intersect each other");
  if (planarity.size() < 4) add(ValidityCode::TooFewPolygons, n(int(planarity.size())) + " faces (a solid needs 4)");
  return out;
}

void sort_by_code(std::vector<ValidityError>& errors) {
  std::stable_sort(errors.begin(), errors.end(),
                   [](const ValidityError& a, const ValidityError& b) { return a.code < b.code; });
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
  if (mesh.faces.empty()) {
    v.errors = {{ValidityCode::TooFewPolygons, {}, "no faces"}};
  } else if (std::string why = size_problem(mesh); !why.empty()) {
    v.errors = {{ValidityCode::Unknown, {}, std::move(why)}};
  } else {
    v.errors = malformed(mesh);
  }
  if (!v.errors.empty()) {
    v.problem = v.errors.front().info;
    sort_by_code(v.errors);
    return v;
  }
  const EdgeUses uses = edge_uses(mesh.faces);
  count_edge_defects(uses, v);
  v.nonmanifold_vertices = int(fanned_vertices(mesh, uses).size());
  v.components = count_components(mesh.faces.size(), uses);
  v.volume = signed_volume(mesh.vertices, mesh.faces);
  v.outward = v.volume > 0;
  const std::vector<double> planarity = planarity_errors(mesh);
  v.max_planarity_error = planarity.empty() ? 0.0 : *std::max_element(planarity.begin(), planarity.end());
  if (check_self_intersections) v.self_intersecting = self_intersects(mesh);
  v.errors = shell_errors(v, planarity, planarity_tolerance, single_component);
  if (!v.errors.empty()) v.problem = v.errors.front().info;
  sort_by_code(v.errors);
  return v;
}

const char* code_name(ValidityCode code) {
  switch (code) {
    case ValidityCode::TooFewPoints: return "TOO_FEW_POINTS";
    case ValidityCode::ConsecutivePointsSame: return "CONSECUTIVE_POINTS_SAME";
    case ValidityCode::RingSelfIntersection: return "RING_SELF_INTERSECTION";
    case ValidityCode::NonPlanarPolygonDistancePlane: return "NON_PLANAR_POLYGON_DISTANCE_PLANE";
    case ValidityCode::TooFewPolygons: return "TOO_FEW_POLYGONS";
    case ValidityCode::ShellNotClosed: return "SHELL_NOT_CLOSED";
    case ValidityCode::NonManifoldCase: return "NON_MANIFOLD_CASE";
    case ValidityCode::MultipleConnectedComponents: return "MULTIPLE_CONNECTED_COMPONENTS";
    case ValidityCode::ShellSelfIntersection: return "SHELL_SELF_INTERSECTION";
    case ValidityCode::PolygonWrongOrientation: return "POLYGON_WRONG_ORIENTATION";
    case ValidityCode::WrongOrientationShell: return "WRONG_ORIENTATION_SHELL";
    case ValidityCode::Unknown: break;
  }
  return "UNKNOWN_ERROR";
}

std::vector<int> error_codes(const std::vector<ValidityError>& errors) {
  std::vector<int> out;
  for (const ValidityError& e : errors)
    if (out.empty() || out.back() != code_number(e.code)) out.push_back(code_number(e.code));
  return out;
}

Validation validate_soup(const Mesh& soup, const ValidityTolerances& tolerances) {
  Eigen::AlignedBox3d box;
  for (const Vec3& p : soup.vertices)
    if (p.allFinite()) box.extend(p);
  const Vec3 origin = box.isEmpty() ? Vec3::Zero() : Vec3((box.min() / 100.0).array().floor() * 100.0);
  Mesh welded;
  welded.id = soup.id;
  PointWelder welder(tolerances.snap);
  std::vector<int> index(soup.vertices.size());
  for (std::size_t i = 0; i < soup.vertices.size(); ++i)
    index[i] = soup.vertices[i].allFinite() ? welder.add(soup.vertices[i] - origin) : -1;
  welded.vertices = welder.points();
  for (Face f : soup.faces) {
    for (int& i : f.v) i = i >= 0 && std::size_t(i) < index.size() ? index[std::size_t(i)] : -1;
    welded.faces.push_back(std::move(f));
  }
  return validate_mesh(welded, tolerances.planarity);
}

}  // namespace lodrefine
