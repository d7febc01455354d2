// Stage 5, selection: the output shell traced on the candidate mesh from the chosen faces.
#include <gtest/gtest.h>

#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>

#include <algorithm>
#include <set>

#include "lodrefine/base/topology.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/refine/candidates.h"
#include "lodrefine/refine/shell_trace.h"
#include "support/candidate_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

namespace {

using FaceIndex = CandidateMesh::Face_index;

// The box [0,10] x [0,6] x [0,5] with a recess [3,7] x [0,1] over its whole height in the front
// (y = 0) facade: the recess's back wall (y = 1) and its two returns (x = 3, x = 7) are faces the
// box lacks, on supporting planes of their own.
constexpr double kA = 10, kB = 6, kC = 5;
bool in_recess(const Vec3& p) { return p.x() > 3 && p.x() < 7 && p.y() < 1; }
bool in_solid(const Vec3& p) { return inside_box(p, kA, kB, kC) && !in_recess(p); }

std::vector<SupportPlane> recess_planes() {
  auto p = box_planes(kA, kB, kC);
  p.push_back({Plane(Vec3(0, -1, 0), 1), Semantic::Wall, true, 6});  // back wall y = 1
  p.push_back({Plane(Vec3(1, 0, 0), -3), Semantic::Wall, true, 7});  // return x = 3
  p.push_back({Plane(Vec3(-1, 0, 0), 7), Semantic::Wall, true, 8});  // return x = 7
  return p;
}

// Chooses the candidates on the boundary of `solid` (inside on one side, outside on the other,
// `eps` m off the centroid); each candidate's source is its plane's.
template <class Solid>
void choose_boundary(CandidateSet& cs, Solid solid, double eps) {
  auto chosen = candidate_props::selected.add(cs.mesh);
  auto source = candidate_props::source.add(cs.mesh);
  for (int f = 0; f < cs.size(); ++f) {
    const Vec3& c = centroid_of(cs, f);
    const Vec3 n = cs.planes[plane_of(cs, f)].plane.n;
    chosen[FaceIndex(f)] = solid(c - eps * n) != solid(c + eps * n);
    source[FaceIndex(f)] = plane_of(cs, f);
  }
}

CandidateSet recess_selection(bool inward_planes = false) {
  auto planes = recess_planes();
  if (inward_planes)
    for (auto& p : planes) p.plane = p.plane.flipped();
  CandidateSet cs = build_candidates(planes, box_region(kA, kB, kC));
  choose_boundary(cs, in_solid, 1e-3);
  return cs;
}

// A polygon as its corners from the lowest (lexicographic), in its direction.
using Polygon = std::vector<std::array<double, 3>>;
Polygon canonical(const Mesh& m, const Face& f) {
  Polygon p;
  for (int v : f.v) p.push_back({m.vertices[v].x(), m.vertices[v].y(), m.vertices[v].z()});
  std::rotate(p.begin(), std::min_element(p.begin(), p.end()), p.end());
  return p;
}
Polygon canonical(Polygon p) {
  std::rotate(p.begin(), std::min_element(p.begin(), p.end()), p.end());
  return p;
}

}  // namespace

// The recessed box's shell: 10 outward polygons on 16 corners. The ground and roof are each one
// U-shaped polygon (their pieces merged along shared mesh edges), the front facade two pieces,
// the corners where the recess's planes only cross the back and side walls are gone.
TEST(ShellTrace, RecessIsTheExpectedPolygonSet) {
  // Candidates run CCW about their planes' normals: given inward normals, every face turns.
  for (bool inward : {false, true}) {
    const Mesh m = traced_shell(recess_selection(inward));
    std::set<Polygon> got;
    for (const auto& f : m.faces) got.insert(canonical(m, f));
    const std::set<Polygon> expected{
        canonical(
            {{0, 0, 0}, {0, 6, 0}, {10, 6, 0}, {10, 0, 0}, {7, 0, 0}, {7, 1, 0}, {3, 1, 0}, {3, 0, 0}}),  // ground
        canonical({{0, 0, 5}, {3, 0, 5}, {3, 1, 5}, {7, 1, 5}, {7, 0, 5}, {10, 0, 5}, {10, 6, 5}, {0, 6, 5}}),  // roof
        canonical({{0, 0, 0}, {0, 0, 5}, {0, 6, 5}, {0, 6, 0}}),                                                // x = 0
        canonical({{10, 0, 0}, {10, 6, 0}, {10, 6, 5}, {10, 0, 5}}),  // x = 10
        canonical({{0, 6, 0}, {0, 6, 5}, {10, 6, 5}, {10, 6, 0}}),    // back
        canonical({{0, 0, 0}, {3, 0, 0}, {3, 0, 5}, {0, 0, 5}}),      // front, left of the recess
        canonical({{7, 0, 0}, {10, 0, 0}, {10, 0, 5}, {7, 0, 5}}),    // front, right of the recess
        canonical({{3, 1, 0}, {7, 1, 0}, {7, 1, 5}, {3, 1, 5}}),      // the recess's back wall
        canonical({{3, 0, 0}, {3, 1, 0}, {3, 1, 5}, {3, 0, 5}}),      // return x = 3 (faces +x)
        canonical({{7, 0, 0}, {7, 0, 5}, {7, 1, 5}, {7, 1, 0}}),      // return x = 7 (faces -x)
    };
    EXPECT_EQ(m.vertices.size(), 16u);
    EXPECT_EQ(got, expected) << (inward ? "inward" : "outward") << " planes";
  }
}

TEST(ShellTrace, RecessIsClosedManifoldOutward) {
  const Mesh m = traced_shell(recess_selection());
  // Every edge used by exactly two faces, in opposite directions.
  const EdgeUses uses = edge_uses(m.faces);
  for (const auto& [e, u] : uses) {
    ASSERT_EQ(u.size(), 2u) << e.first << "-" << e.second;
    EXPECT_NE(u[0].forward, u[1].forward) << e.first << "-" << e.second;
  }
  const Validation v = validate_mesh(m, 1e-6);
  EXPECT_TRUE(v.valid()) << v.problem;
  EXPECT_NEAR(v.volume, kA * kB * kC - 4 * 1 * kC, 1e-9);
  // CGAL's view of the same shell.
  CandidateMesh sm;
  std::vector<CandidateMesh::Vertex_index> vs;
  for (const auto& p : m.vertices) vs.push_back(sm.add_vertex({p.x(), p.y(), p.z()}));
  for (const auto& f : m.faces) {
    std::vector<CandidateMesh::Vertex_index> loop;
    for (int i : f.v) loop.push_back(vs[std::size_t(i)]);
    ASSERT_NE(sm.add_face(loop), CandidateMesh::null_face());
  }
  ASSERT_TRUE(CGAL::is_closed(sm));
  ASSERT_TRUE(CGAL::Polygon_mesh_processing::triangulate_faces(sm));
  EXPECT_TRUE(CGAL::Polygon_mesh_processing::is_outward_oriented(sm));
}

// Semantics from the supporting plane, sources from candidate_props::source (a merged polygon takes its
// largest piece's: here all pieces of a plane share it).
TEST(ShellTrace, FacesCarrySemanticAndSource) {
  const Mesh m = traced_shell(recess_selection());
  const auto planes = recess_planes();
  for (const auto& f : m.faces) {
    ASSERT_GE(f.source, 0);
    EXPECT_EQ(f.sem, planes[std::size_t(f.source)].sem);
    const Plane& pl = planes[std::size_t(f.source)].plane;
    for (int v : f.v) EXPECT_NEAR(pl.distance(m.vertices[v]), 0.0, 1e-9);
  }
}

// The box without its roof: the selection leaves edges used once, and the trace says so (it does
// not mend): the open edges are boundary edges of the output.
TEST(ShellTrace, OpenSelectionStaysOpen) {
  CandidateSet cs = recess_selection();
  auto chosen = candidate_props::selected.get(cs.mesh);
  for (int f = 0; f < cs.size(); ++f)
    if (plane_of(cs, f) == 5) chosen[FaceIndex(f)] = false;
  const Mesh m = traced_shell(cs);
  EXPECT_EQ(m.faces.size(), 9u);
  EXPECT_GT(validate_mesh(m, 1e-6).boundary_edges, 0);
}

// The east wall (x = 10) and a scan plane 0.4 mm beside it (x = 10.0004), the solid on the first
// for y < 3 and on the second for y > 3: the step between them (on y = 3) and the roof's and
// ground's strips are 0.4 mm wide. Their short edges collapse to points, the two walls are one
// polygon, and the box's 6 faces on 8 corners remain.
TEST(ShellTrace, SubMillimetreEdgesCollapse) {
  constexpr double kStep = 4e-4;
  auto planes = box_planes(kA, kB, kC);
  planes.push_back({Plane(Vec3(1, 0, 0), -(kA + kStep)), Semantic::Wall, true, 6});
  planes.push_back({Plane(Vec3(0, -1, 0), 3), Semantic::Wall, true, 7});
  CandidateSet cs = build_candidates(planes, box_region(kA, kB, kC));
  choose_boundary(
      cs, [&](const Vec3& p) { return inside_box(p, p.y() < 3 ? kA : kA + kStep, kB, kC); }, 1e-5);
  const Mesh m = traced_shell(cs);
  EXPECT_EQ(m.faces.size(), 6u);
  EXPECT_EQ(m.vertices.size(), 8u);
  const Validation v = validate_mesh(m, 1e-3);
  EXPECT_TRUE(v.valid()) << v.problem;
  EXPECT_NEAR(v.volume, kA * kB * kC, 0.01);
}
