#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <map>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/topology.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/validate.h"
#include "support/mesh_fixtures.h"

using namespace lodrefine;

// Validation at the parameter table's planarity tolerance.
const double kPlanarity = RefineConfig{}.repair.planarity_tolerance;

namespace {

// A closed prism with shared vertices over a counter-clockwise footprint, faces outward:
// walls 0..n-1 (wall i along footprint edge i), then roof n, then ground n+1.
Mesh prism(const std::vector<Vec2>& foot, double z0, double z1) {
  Mesh m;
  const int n = int(foot.size());
  for (const Vec2& p : foot) m.vertices.emplace_back(p.x(), p.y(), z0);
  for (const Vec2& p : foot) m.vertices.emplace_back(p.x(), p.y(), z1);
  Face roof{{}, Semantic::Roof, n}, ground{{}, Semantic::Ground, n + 1};
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    m.faces.push_back({{i, j, n + j, n + i}, Semantic::Wall, i});
    roof.v.push_back(n + i);
    ground.v.insert(ground.v.begin(), i);
  }
  m.faces.push_back(roof);
  m.faces.push_back(ground);
  return m;
}

Mesh unit_cube() { return prism({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, 0, 1); }

void reverse_face(Face& f) { std::reverse(f.v.begin(), f.v.end()); }

// Appends `b` to `a`, sharing vertices at identical coordinates.
Mesh combined(const Mesh& a, const Mesh& b) {
  Mesh m = a;
  std::vector<int> map;
  for (const Vec3& p : b.vertices) {
    const auto it = std::find(m.vertices.begin(), m.vertices.end(), p);
    map.push_back(int(it - m.vertices.begin()));
    if (it == m.vertices.end()) m.vertices.push_back(p);
  }
  for (Face f : b.faces) {
    for (int& i : f.v) i = map[i];
    m.faces.push_back(f);
  }
  return m;
}

bool mentions(const Validation& v, const std::string& what) { return v.problem.find(what) != std::string::npos; }

}  // namespace

TEST(Validate, ClosedCubeIsValid) {
  const Validation v = validate_mesh(unit_cube(), kPlanarity);
  EXPECT_TRUE(v.valid()) << v.problem;
  EXPECT_TRUE(v.watertight());
  EXPECT_EQ(v.boundary_edges, 0);
  EXPECT_EQ(v.nonmanifold_edges, 0);
  EXPECT_EQ(v.nonmanifold_vertices, 0);
  EXPECT_EQ(v.inconsistent_edges, 0);
  EXPECT_EQ(v.components, 1);
  EXPECT_TRUE(v.outward);
  EXPECT_NEAR(v.volume, 1.0, 1e-12);
  EXPECT_NEAR(v.max_planarity_error, 0.0, 1e-12);
  EXPECT_FALSE(v.self_intersecting);  // triangles sharing vertices and edges do not count
}

TEST(Validate, GeoreferencedNonConvexPrismIsValid) {
  const Mesh l =
      translated(prism({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}}, 0, 3), {85123.4567, 447987.6543, 2});
  const Validation v = validate_mesh(l, kPlanarity);
  EXPECT_TRUE(v.valid()) << v.problem;
  EXPECT_NEAR(v.volume, 9.0, 1e-6);
  EXPECT_FALSE(v.self_intersecting);
}

TEST(Validate, MissingFaceGivesFourBoundaryEdges) {
  Mesh m = unit_cube();
  m.faces.pop_back();
  const Validation v = validate_mesh(m, kPlanarity);
  EXPECT_EQ(v.boundary_edges, 4);
  EXPECT_FALSE(v.watertight());
  EXPECT_EQ(v.problem, "4 boundary edges (mesh not closed)");
}

TEST(Validate, FlippedFaceGivesInconsistentEdges) {
  Mesh m = unit_cube();
  reverse_face(m.faces[2]);
  const Validation v = validate_mesh(m, kPlanarity);
  EXPECT_TRUE(v.watertight());
  EXPECT_EQ(v.inconsistent_edges, 4);
  EXPECT_TRUE(mentions(v, "4 inconsistently oriented edges")) << v.problem;
}

TEST(Validate, InvertedCubeIsNotOutward) {
  Mesh m = unit_cube();
  for (Face& f : m.faces) reverse_face(f);
  const Validation v = validate_mesh(m, kPlanarity);
  EXPECT_EQ(v.inconsistent_edges, 0);
  EXPECT_FALSE(v.outward);
  EXPECT_NEAR(v.volume, -1.0, 1e-12);
  EXPECT_TRUE(mentions(v, "inward")) << v.problem;
}

TEST(Validate, NonPlanarQuadIsReported) {
  Mesh m = unit_cube();
  m.vertices[6].z() += 0.05;  // a roof corner: the roof twists, its two walls stay planar
  const Validation v = validate_mesh(m, 0.01);
  EXPECT_NEAR(v.max_planarity_error, 0.05 / 4, 1e-4);
  EXPECT_TRUE(mentions(v, "planarity error 0.0125 m exceeds 0.01 m")) << v.problem;
  EXPECT_TRUE(validate_mesh(m, 0.02).valid());
}

TEST(Validate, CubesSharingAnEdgeAreNonManifold) {
  const Validation v = validate_mesh(combined(unit_cube(), translated(unit_cube(), {1, 1, 0})), kPlanarity);
  EXPECT_EQ(v.nonmanifold_edges, 1);
  EXPECT_EQ(v.boundary_edges, 0);
  EXPECT_FALSE(v.watertight());
  EXPECT_TRUE(mentions(v, "1 non-manifold edges")) << v.problem;
}

TEST(Validate, CubesSharingAVertexHaveANonManifoldVertexAndTwoComponents) {
  const Validation v = validate_mesh(combined(unit_cube(), translated(unit_cube(), {1, 1, 1})), kPlanarity);
  EXPECT_EQ(v.nonmanifold_edges, 0);
  EXPECT_EQ(v.nonmanifold_vertices, 1);
  EXPECT_EQ(v.components, 2);
  EXPECT_NEAR(v.volume, 2.0, 1e-12);
  EXPECT_FALSE(v.self_intersecting);  // touching at the shared vertex only
  EXPECT_TRUE(mentions(v, "1 non-manifold vertices")) << v.problem;
}

// The points where a mesh is no 2-manifold: the shared vertex of two cubes touching at a corner,
// the two ends of the edge two cubes share; none on one cube.
TEST(Validate, PinchedVerticesAreWhereTheFacesMeetOnlyAtAPointOrFourAtAnEdge) {
  const Mesh at_vertex = combined(unit_cube(), translated(unit_cube(), {1, 1, 1}));
  const std::vector<int> v = pinched_vertices(at_vertex);
  ASSERT_EQ(v.size(), 1u);
  EXPECT_LT((at_vertex.vertices[std::size_t(v[0])] - Vec3(1, 1, 1)).norm(), 1e-12);
  const Mesh at_edge = combined(unit_cube(), translated(unit_cube(), {1, 1, 0}));
  std::vector<Vec3> ends;
  for (int i : pinched_vertices(at_edge)) ends.push_back(at_edge.vertices[std::size_t(i)]);
  ASSERT_EQ(ends.size(), 2u);
  for (const Vec3& p : ends) EXPECT_LT((p - Vec3(1, 1, p.z())).norm(), 1e-12);
  EXPECT_NE(ends[0].z(), ends[1].z());
  EXPECT_TRUE(pinched_vertices(unit_cube()).empty());
}

TEST(Validate, SeparateCubesAreTwoComponents) {
  const Validation v = validate_mesh(combined(unit_cube(), translated(unit_cube(), {3, 0, 0})), kPlanarity);
  EXPECT_TRUE(v.watertight());
  EXPECT_EQ(v.components, 2);
  EXPECT_EQ(v.problem, "2 connected components (expected one)");
}

TEST(Validate, VertexPushedThroughTheOppositeFaceSelfIntersects) {
  Mesh m = unit_cube();
  m.vertices[6] = Vec3(0.8, 0.8, -0.5);  // roof corner (1,1,1) pushed out through the ground
  const Validation v = validate_mesh(m, 10.0);
  EXPECT_TRUE(v.watertight());
  EXPECT_TRUE(v.self_intersecting);
  EXPECT_EQ(v.problem, "faces intersect each other");
  EXPECT_FALSE(validate_mesh(m, 10.0, false).self_intersecting);  // the check can be skipped
}

TEST(Validate, MalformedFacesAreReportedNotCrashed) {
  Mesh m = unit_cube();
  m.faces[0].v.push_back(42);
  EXPECT_EQ(validate_mesh(m, kPlanarity).problem, "face 0 references missing vertex 42");
  m = unit_cube();
  m.faces[1].v = {0, 1};
  EXPECT_EQ(validate_mesh(m, kPlanarity).problem, "face 1 has fewer than 3 vertices");
  EXPECT_EQ(validate_mesh(Mesh{}, kPlanarity).problem, "no faces");
}

// Issue 15, item 9: a building lowered to the ground crashed CGAL's face triangulation (a
// face of no area has no normal). Degenerate faces and flat shells are reported, not crashed.
TEST(Validate, FlatBuildingsAreReportedNotCrashed) {
  const std::vector<Vec2> l_shape = {{0, 0}, {10, 0}, {10, 4}, {4, 4}, {4, 8}, {0, 8}};
  Mesh flat = prism(l_shape, 2.5, 2.5);  // roof on the ground: every wall a line
  const Validation v = validate_mesh(flat, kPlanarity);
  EXPECT_FALSE(v.valid());
  EXPECT_EQ(v.problem, "face 0 is degenerate (no area: its vertices are on one line or it folds onto itself)");
  // A gable lowered to its eaves: walls of zero height around a real roof.
  Mesh gable = prism({{0, 0}, {10, 0}, {10, 8}, {0, 8}}, 0, 0);
  gable.vertices.push_back({0, 4, 3});
  gable.vertices.push_back({10, 4, 3});
  gable.faces[4] = {{4, 5, 9, 8}, Semantic::Roof, 4};
  gable.faces.push_back({{6, 7, 8, 9}, Semantic::Roof, 6});
  gable.faces[1].v = {1, 2, 6, 9, 5};
  gable.faces[3].v = {3, 0, 4, 8, 7};
  EXPECT_NE(validate_mesh(gable, kPlanarity).problem.find("is degenerate"), std::string::npos);
  // Closed, non-degenerate faces, but no volume: two coincident triangles back to back.
  Mesh sheet;
  sheet.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  sheet.faces = {{{0, 1, 2}, Semantic::Roof, 0}, {{0, 2, 1}, Semantic::Ground, 1}};
  EXPECT_EQ(validate_mesh(sheet, kPlanarity).problem.rfind("the shell encloses no volume", 0), 0u)
      << validate_mesh(sheet, kPlanarity).problem;
}

// A face through two vertices at one point (distinct indices, as a weld can leave) crashed
// CGAL's constrained triangulation inside validation; it is reported instead.
TEST(Validate, TwoVerticesAtOnePointAreReportedNotCrashed) {
  Mesh m = prism({{0, 0}, {10, 0}, {10, 8}, {0, 8}}, 0, 6);
  m.vertices.push_back(m.vertices[m.faces[0].v[1]]);  // a copy of the bottom face's second vertex
  m.faces[0].v.insert(m.faces[0].v.begin() + 2, int(m.vertices.size()) - 1);
  const Validation v = validate_mesh(m, kPlanarity);
  EXPECT_FALSE(v.valid());
  EXPECT_EQ(v.problem, "face 0 has two vertices at one point");
}

TEST(Validate, EdgeUsesRecordDirection) {
  const EdgeUses uses = edge_uses(unit_cube().faces);
  EXPECT_EQ(uses.size(), 12u);
  for (const auto& [e, u] : uses) {
    ASSERT_EQ(u.size(), 2u);
    EXPECT_NE(u[0].forward, u[1].forward) << e.first << "-" << e.second;
  }
}

// A shell the selection once proposed for a Delfshaven building (region-grown planes): its ground
// face has a vertex on its own closing edge, where CGAL's face triangulation never returned.
// Validation ends, in a child process so that a hang fails the test, and finds the shell invalid.
TEST(Validate, AFaceTouchingItselfIsTriangulatedWithoutHanging) {
  Mesh shell;
  shell.vertices = {{59.429000000003725, 79.798999999999069, 0},
                    {59.429000000003725, 79.798999999999069, 12.929},
                    {47.456000000005588, 80.76500000001397, 12.929},
                    {47.456000000005588, 80.76500000001397, 3.548},
                    {43.307000000000698, 81.097999999998137, 3.548},
                    {43.307000000000698, 81.097999999998137, 0},
                    {47.957999999998719, 85.961000000010245, 3.548},
                    {47.957999999998719, 85.961000000010245, 12.907999999999999},
                    {59.679000000003725, 85.020000000018626, 12.904},
                    {59.677973582579988, 85.020096972624657, 3.5480000000000005},
                    {59.679000000003725, 85.020000000018626, 0},
                    {43.369000000006054, 86.35899999999674, 0},
                    {43.369000000006054, 86.35899999999674, 3.548},
                    {59.680051398728416, 85.960988345818208, 0},
                    {59.724053206978645, 85.960891174486491, 0},
                    {59.724053206978645, 85.960891174486491, 3.5480000000000005},
                    {59.677923731856168, 84.997523216024931, 3.5480000000000005},
                    {47.706000000005588, 83.353999999992084, 16.173999999999999},
                    {56.320000000006985, 82.661000000021886, 16.173999999999999},
                    {59.680051398728416, 85.960988345818208, 3.5480000000000005}};
  for (const std::vector<int>& f : std::vector<std::vector<int>>{{0, 1, 2, 3, 4, 5},
                                                                 {6, 7, 8, 9, 10, 11, 12},
                                                                 {0, 5, 11, 10, 13, 14},
                                                                 {0, 14, 15, 16, 8, 1},
                                                                 {3, 2, 17, 7, 6},
                                                                 {1, 18, 17, 2},
                                                                 {7, 17, 18, 8},
                                                                 {9, 16, 15, 19},
                                                                 {3, 6, 12, 4},
                                                                 {4, 12, 11, 5},
                                                                 {1, 8, 18},
                                                                 {16, 9, 8},
                                                                 {9, 19, 13, 10},
                                                                 {14, 13, 19, 15}})
    shell.faces.push_back({f, Semantic::Wall});
  EXPECT_EXIT(
      {
        ::alarm(20);
        std::exit(validate_mesh(shell, kPlanarity).valid() ? 1 : 0);
      },
      testing::ExitedWithCode(0), "");
}

// Issue 50: every defect under val3dity's code (src/definitions.h of val3dity 2.6), each on a
// crafted solid; the problem text stays the first defect's.
namespace {
std::vector<int> codes(const Validation& v) { return error_codes(v); }
}  // namespace

TEST(ValidityCodes, AValidCubeHasNone) {
  const Validation v = validate_mesh(unit_cube(), kPlanarity);
  EXPECT_TRUE(v.errors.empty());
  EXPECT_TRUE(codes(v).empty());
}

TEST(ValidityCodes, AMissingFaceIs302ShellNotClosed) {
  Mesh m = unit_cube();
  m.faces.pop_back();
  const Validation v = validate_mesh(m, kPlanarity);
  EXPECT_EQ(codes(v), std::vector<int>({302}));
  EXPECT_STREQ(code_name(v.errors[0].code), "SHELL_NOT_CLOSED");
  EXPECT_EQ(v.errors[0].info, v.problem);
}

TEST(ValidityCodes, NonManifoldEdgesAndVerticesAre303) {
  const Validation edge = validate_mesh(combined(unit_cube(), translated(unit_cube(), {1, 1, 0})), kPlanarity);
  EXPECT_EQ(codes(edge), std::vector<int>({303}));
  EXPECT_STREQ(code_name(edge.errors[0].code), "NON_MANIFOLD_CASE");
  // Two cubes touching at a corner: a non-manifold vertex, and two parts.
  const Validation vertex = validate_mesh(combined(unit_cube(), translated(unit_cube(), {1, 1, 1})), kPlanarity);
  EXPECT_EQ(codes(vertex), std::vector<int>({303, 305}));
  EXPECT_EQ(vertex.problem, "1 non-manifold vertices (faces meet only at a point)");
}

TEST(ValidityCodes, SeparateCubesAre305UnlessSeveralPartsAreAllowed) {
  const Mesh two = combined(unit_cube(), translated(unit_cube(), {3, 0, 0}));
  const Validation v = validate_mesh(two, kPlanarity);
  EXPECT_EQ(codes(v), std::vector<int>({305}));
  EXPECT_STREQ(code_name(v.errors[0].code), "MULTIPLE_CONNECTED_COMPONENTS");
  EXPECT_TRUE(validate_mesh(two, kPlanarity, true, false).errors.empty());
}

TEST(ValidityCodes, FacesCrossingEachOtherAre306AndAFlatShellToo) {
  Mesh m = unit_cube();
  m.vertices[6] = Vec3(0.8, 0.8, -0.5);
  const Validation v = validate_mesh(m, 10.0);
  EXPECT_EQ(codes(v), std::vector<int>({306}));
  EXPECT_STREQ(code_name(v.errors[0].code), "SHELL_SELF_INTERSECTION");
  Mesh sheet;  // two triangles back to back: closed, no volume, and too few faces for a solid
  sheet.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  sheet.faces = {{{0, 1, 2}, Semantic::Roof, 0}, {{0, 2, 1}, Semantic::Ground, 1}};
  EXPECT_EQ(codes(validate_mesh(sheet, kPlanarity)), std::vector<int>({301, 306}));
}

TEST(ValidityCodes, AFlippedFaceIs307AndAnInvertedShell405) {
  Mesh m = unit_cube();
  reverse_face(m.faces[2]);
  const Validation flipped = validate_mesh(m, kPlanarity);
  EXPECT_EQ(codes(flipped), std::vector<int>({307}));
  EXPECT_STREQ(code_name(flipped.errors[0].code), "POLYGON_WRONG_ORIENTATION");
  for (Face& f : m.faces) reverse_face(f);
  reverse_face(m.faces[2]);  // now every face is reversed: consistent, inward
  const Validation inward = validate_mesh(m, kPlanarity);
  EXPECT_EQ(codes(inward), std::vector<int>({405}));
  EXPECT_STREQ(code_name(inward.errors[0].code), "WRONG_ORIENTATION_SHELL");
}

TEST(ValidityCodes, AWarpedFaceIs203WithItsFace) {
  Mesh m = unit_cube();
  m.vertices[6].z() += 0.05;
  const Validation v = validate_mesh(m, 0.01);
  EXPECT_EQ(codes(v), std::vector<int>({203}));
  EXPECT_STREQ(code_name(v.errors[0].code), "NON_PLANAR_POLYGON_DISTANCE_PLANE");
  EXPECT_EQ(v.errors[0].faces, std::vector<int>({4}));  // the roof; its walls stay planar
}

TEST(ValidityCodes, RingDefectsAre101And102And104PerFace) {
  Mesh m = unit_cube();
  m.faces[1].v = {0, 1};
  m.faces[3].v = {3, 3, 7, 4, 0};  // a vertex twice in a row
  const Validation v = validate_mesh(m, kPlanarity);
  EXPECT_EQ(codes(v), std::vector<int>({101, 102}));
  EXPECT_EQ(v.errors[0].faces, std::vector<int>({1}));
  EXPECT_EQ(v.errors[1].faces, std::vector<int>({3}));
  EXPECT_EQ(v.problem, "face 1 has fewer than 3 vertices");
  m = unit_cube();
  m.faces[0].v = {0, 1, 5, 0, 4};  // a vertex again, not in a row
  EXPECT_EQ(codes(validate_mesh(m, kPlanarity)), std::vector<int>({104}));
  Mesh flat = prism({{0, 0}, {10, 0}, {10, 4}, {0, 4}}, 2.5, 2.5);  // walls collapsed to lines
  const Validation collapsed = validate_mesh(flat, kPlanarity);
  EXPECT_EQ(codes(collapsed), std::vector<int>({104}));
  ASSERT_EQ(collapsed.errors.size(), 4u);  // one per face
  EXPECT_EQ(collapsed.errors[3].faces, std::vector<int>({3}));
  EXPECT_STREQ(code_name(collapsed.errors[0].code), "RING_SELF_INTERSECTION");
}

// A city file's soup: each face its own vertices, georeferenced. Snapped at val3dity's 1 mm, a
// corner 0.4 mm apart is one point; 3 mm apart it leaves the shell open.
TEST(ValidityCodes, ASoupIsWeldedAtTheSnapToleranceInALocalFrame) {
  const Mesh cube = translated(prism({{0, 0}, {10, 0}, {10, 8}, {0, 8}}, 0, 6), {92345.678, 437654.321, 1.5});
  Mesh soup = lodrefine::fixtures::as_soup(cube);
  EXPECT_TRUE(validate_soup(soup).errors.empty()) << validate_soup(soup).problem;
  soup.vertices[0].x() += 0.0004;
  EXPECT_TRUE(validate_soup(soup).valid()) << validate_soup(soup).problem;
  soup.vertices[0].x() += 0.003;
  EXPECT_EQ(codes(validate_soup(soup)), std::vector<int>({302}));
  EXPECT_TRUE(validate_soup(soup, {0.01, 0.01}).valid());
}
