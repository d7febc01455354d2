// End to end on hand-made buildings with known truth, and on two generated hips the starting
// shell's fallback is pinned by (the generator's richer cases are in test_end_to_end.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "lodrefine/base/geometry.h"
#include "lodrefine/core/distance.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/refine/candidates.h"
#include "lodrefine/refine/refine.h"
#include "lodrefine/synth/synth.h"
#include "support/mesh_fixtures.h"
#include "support/scan_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

// Validation at the parameter table's planarity tolerance.
const double kPlanarity = RefineConfig{}.repair.planarity_tolerance;

namespace {

const Vec3 kOrigin(85000.0, 447000.0, 0.0);

// The shared box [x0,x1]x[y0,y1]x[0,h] as an exported soup, georeferenced.
Mesh box_soup(double x0, double x1, double y0, double y1, double h) {
  Mesh m = as_soup(translated(box(Vec3(x0, y0, 0), Vec3(x1, y1, h)), kOrigin));
  m.id = "box";
  return m;
}

// MLS-like points on the wall y = y_wall (x in [xa,xb], z up to zmax), with a recessed window
// and street ground in front.
PointCloud scan_front(double y_wall, double xa, double xb, double zmax, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.01);
  PointCloud pc;
  for (double x = xa; x <= xb; x += 0.05)
    for (double z = 0.2; z <= zmax; z += 0.05) {
      const bool window = x > 3 && x < 4.2 && z > 1.5 && z < 3;
      const double y = y_wall - (window ? -0.15 : 0.0) + noise(rng);
      pc.points.push_back(Vec3(x, y, z) + kOrigin);
    }
  for (double x = xa; x <= xb; x += 0.1)
    for (double y = y_wall - 6; y < y_wall - 0.3; y += 0.1) pc.points.push_back(Vec3(x, y, noise(rng)) + kOrigin);
  return pc;
}

double max_abs_y_of_front(const Mesh& m, double expect_y) {
  double worst = 0.0;
  for (const auto& f : m.faces) {
    if (f.sem != Semantic::Wall) continue;
    std::vector<Vec3> poly;
    for (int v : f.v) poly.push_back(m.vertices[v] - kOrigin);
    const Vec3 n = (poly[1] - poly[0]).cross(poly[2] - poly[0]).normalized();
    if (n.y() > -0.9) continue;
    for (const auto& p : poly) worst = std::max(worst, std::abs(p.y() - expect_y));
  }
  return worst;
}

}  // namespace

TEST(Refine, MovesAnOutdatedFacadeOntoTheScan) {
  const Mesh coarse = box_soup(0, 12, -0.5, 8, 7);  // front wall 0.5 m too far out
  const PointCloud cloud = scan_front(0.0, 0.5, 11.5, 5.0, 1);
  RefineConfig prm;
  const RefineResult r = refine_building(coarse, cloud, prm);
  ASSERT_TRUE(r.valid) << r.reason;
  EXPECT_TRUE(r.refined()) << r.reason;
  EXPECT_EQ(r.outcome, Outcome::Refined);
  EXPECT_LT(max_abs_y_of_front(r.mesh, 0.0), 0.02);
  const Validation v = validate_mesh(r.mesh, kPlanarity);  // georeferenced frame: still valid
  EXPECT_TRUE(v.valid()) << v.problem;
  EXPECT_NEAR(v.volume, 12 * 8 * 7, 12 * 7 * 0.03);
  for (const auto& p : r.mesh.vertices) EXPECT_LE(p.z() - kOrigin.z(), 7.0 + 1e-6);  // roof kept
}

// The front facade is 0.5 m out; its scan ends in the open 0.8 m short of the right corner (the
// street goes on), but a few points of the side wall itself (too few for a plane) stand where
// the model has it. The corner move makes those farther, so the judge refuses it, and the
// building is refined once more on the facade's own points: the facade moves, the side stays.
// Where each face comes from (Face::provenance): the moved front wall from the scan, with the
// share of it the scan covers (x 0.5..11.5 of 12 m, z 0.2..5 of 7 m, each point covering 0.5 m
// around it: about 5.5 / 7), the roof and the other walls from the model.
TEST(Refine, TheMovedWallIsTheScansAndTheRoofTheModels) {
  const RefineResult r = refine_building(box_soup(0, 12, -0.5, 8, 7), scan_front(0.0, 0.5, 11.5, 5.0, 1), {});
  ASSERT_EQ(r.outcome, Outcome::Refined) << r.reason;
  int front = 0, roofs = 0;
  for (const Face& f : r.mesh.faces) {
    SCOPED_TRACE(semantic_name(f.sem));
    if (f.sem == Semantic::Wall && polygon_plane(face_points(r.mesh, f)).n.y() < -0.9) {
      ++front;
      EXPECT_EQ(f.provenance, Provenance::Scan);
      EXPECT_GT(f.coverage, 0.7);
      EXPECT_LT(f.coverage, 0.9);
      continue;
    }
    roofs += f.sem == Semantic::Roof;
    EXPECT_EQ(f.provenance, Provenance::Model);
  }
  EXPECT_EQ(front, 1);
  EXPECT_EQ(roofs, 1);
}

TEST(Refine, ACornerMoveTheJudgeRefusesIsDroppedAndTheFacadeStillMoves) {
  const Mesh coarse = box_soup(0, 12, -0.5, 8, 7);
  PointCloud cloud = scan_front(0.0, 0.02, 11.2, 5.0, 3);
  for (double x = 11.3; x < 15.0; x += 0.1)  // the street goes on
    for (double y = -6.0; y < -0.3; y += 0.1) cloud.points.push_back(Vec3(x, y, 0.0) + kOrigin);
  for (double y = 0.2; y < 1.9; y += 0.2)
    for (double z = 1.0; z < 5.1; z += 0.4) cloud.points.push_back(Vec3(12.0, y, z) + kOrigin);
  const RefineResult r = refine_building(coarse, cloud, RefineConfig{});
  ASSERT_TRUE(r.valid) << r.reason;
  ASSERT_EQ(r.outcome, Outcome::Refined) << r.reason;
  ASSERT_TRUE(r.trace.corners_refused.has_value());
  EXPECT_NE(r.trace.corners_refused->find("wall check"), std::string::npos) << *r.trace.corners_refused;
  EXPECT_LT(max_abs_y_of_front(r.mesh, 0.0), 0.02);
  double x_max = -1e9;
  for (const auto& p : r.mesh.vertices) x_max = std::max(x_max, p.x() - kOrigin.x());
  EXPECT_NEAR(x_max, 12.0, 0.01) << "the side wall stays";
}

TEST(Refine, MovesAFacadeInwardsAndKeepsTheRest) {
  const Mesh coarse = box_soup(0, 12, 0.6, 8, 7);  // front wall 0.6 m too far in
  const PointCloud cloud = scan_front(0.0, 0.5, 11.5, 5.0, 2);
  const RefineResult r = refine_building(coarse, cloud, RefineConfig{});
  ASSERT_TRUE(r.valid);
  EXPECT_TRUE(r.refined()) << r.reason;
  EXPECT_LT(max_abs_y_of_front(r.mesh, 0.0), 0.02) << r.reason;
  EXPECT_EQ(r.mesh.faces.size(), 6u);  // still a box: coplanar pieces merged back
}

TEST(Refine, NoScanFallsBackToTheRepairedOriginal) {
  const Mesh coarse = box_soup(0, 12, 0, 8, 7);
  PointCloud cloud;
  cloud.points.push_back(kOrigin + Vec3(100, 100, 0));
  const RefineResult r = refine_building(coarse, cloud, RefineConfig{});
  ASSERT_TRUE(r.valid);
  EXPECT_FALSE(r.refined());
  EXPECT_EQ(r.outcome, Outcome::Kept);
  EXPECT_EQ(r.reason, "no planes found in the cloud near the model");
  EXPECT_EQ(r.mesh.faces.size(), 6u);
}

// Three terraced houses A [0,12], B [12,24], C [24,36]: the tile holds the street from x = -0.6
// (a neighbour's facade left of A) to x = 24.6 (0.6 m of C). A is correct; B's front is 0.5 m
// too far out. B's front is fixed; no side wall moves to where the tile cuts the facade (A's
// left, B's right), so A comes out exactly as it went in.
TEST(Refine, ACorrectTerracedHouseBesideAMisplacedOneIsLeftAsItIs) {
  PointCloud cloud = fixtures::terraced_street_scan(-0.6, 24.6, 5);
  for (auto& p : cloud.points) p += kOrigin;
  const RefineConfig prm;
  const Mesh a = box_soup(0, 12, 0, 8, 7), b = box_soup(12, 24, -0.5, 8, 7);
  const RefineResult ra = refine_building(a, cloud, prm);
  ASSERT_TRUE(ra.valid) << ra.reason;
  EXPECT_FALSE(ra.refined()) << ra.reason;
  EXPECT_LE(fixtures::largest_vertex_move(ra.mesh, a), prm.repair.weld_tolerance) << ra.reason;

  const RefineResult rb = refine_building(b, cloud, prm);
  ASSERT_TRUE(rb.valid) << rb.reason;
  EXPECT_TRUE(rb.refined()) << rb.reason;
  EXPECT_LT(max_abs_y_of_front(rb.mesh, 0.0), 0.02);
  for (const auto& p : rb.mesh.vertices) {  // the side walls stay at x = 12 and x = 24
    const double x = p.x() - kOrigin.x();
    EXPECT_TRUE(std::abs(x - 12) <= prm.repair.weld_tolerance || std::abs(x - 24) <= prm.repair.weld_tolerance) << x;
  }
}

namespace {

// A 12 x 8.5 m block, its front wall 0.5 m out, under a roof of 1 m pyramids of four heights
// (so that no two triangles share a plane): hundreds of supporting planes that reach each other.
Mesh pyramid_roofed_block(int nx, int ny) {
  const double x1 = 12.0, y0 = -0.5, y1 = 8.0, h = 7.0;
  const double dx = x1 / nx, dy = (y1 - y0) / ny;
  Mesh m;
  auto vertex = [&](double x, double y, double z) {
    m.vertices.push_back(Vec3(x, y, z));
    return int(m.vertices.size()) - 1;
  };
  std::vector<int> grid;  // the roof's eaves grid, (nx + 1) x (ny + 1)
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) grid.push_back(vertex(i * dx, y0 + j * dy, h));
  auto at = [&](int i, int j) { return grid[j * (nx + 1) + i]; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double rise = 0.5 + 0.25 * ((i + 2 * j) % 4);  // slopes 45-68 degrees, beyond merge_angle_deg
      const int apex = vertex((i + 0.5) * dx, y0 + (j + 0.5) * dy, h + rise);
      const int a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      for (const auto& [p, q] : {std::pair{a, b}, {b, c}, {c, d}, {d, a}})
        m.faces.push_back({{p, q, apex}, Semantic::Roof});
    }
  const int g[4] = {vertex(0, y0, 0), vertex(x1, y0, 0), vertex(x1, y1, 0), vertex(0, y1, 0)};
  m.faces.push_back({{g[0], g[3], g[2], g[1]}, Semantic::Ground});
  Face front{{g[0], g[1]}, Semantic::Wall}, right{{g[1], g[2]}, Semantic::Wall};
  Face back{{g[2], g[3]}, Semantic::Wall}, left{{g[3], g[0]}, Semantic::Wall};
  for (int i = nx; i >= 0; --i) front.v.push_back(at(i, 0));
  for (int j = ny; j >= 0; --j) right.v.push_back(at(nx, j));
  for (int i = 0; i <= nx; ++i) back.v.push_back(at(i, ny));
  for (int j = 0; j <= ny; ++j) left.v.push_back(at(0, j));
  for (Face* f : {&front, &right, &back, &left}) m.faces.push_back(*f);
  m = as_soup(translated(m, kOrigin));
  m.id = "pyramids";
  return m;
}

}  // namespace

// A building whose arrangement passes kMaxCandidates ends its selection at once (the cap is what
// bounds its time and memory: without it this one grows past 100,000 candidates). A selection
// with no shell falls back to the best shell known: the facade moved by substitution, judged as
// any other.
TEST(Refine, ABuildingBeyondTheCandidateCapIsRefinedBySubstitutionQuickly) {
  const Mesh coarse = pyramid_roofed_block(12, 8);
  const PointCloud cloud = scan_front(0.0, 0.5, 11.5, 5.0, 1);
  const auto t0 = std::chrono::steady_clock::now();
  const RefineResult r = refine_building(coarse, cloud, RefineConfig{});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(r.valid) << r.reason;
  EXPECT_EQ(r.outcome, Outcome::Refined) << r.reason;
  EXPECT_NE(r.reason.find("1 wall(s) moved by substitution (the selection found no valid shell: too many candidate "
                          "faces (over " +
                          std::to_string(kMaxCandidates) + " from "),
            std::string::npos)
      << r.reason;
  EXPECT_EQ(r.mesh.faces.size(), coarse.faces.size());
  EXPECT_LT(max_abs_y_of_front(r.mesh, 0.0), 0.02);
  const Validation v = validate_mesh(r.mesh, kPlanarity);
  EXPECT_TRUE(v.valid()) << v.problem;
  EXPECT_LT(seconds, 20.0) << "the cap did not bound the time";
}

namespace {

// The box [0,12]x[y0,8]x[0,7] as an exported soup with only the faces listed (box(): 0 ground,
// 1 roof, walls 2 y = y0, 3 x = 12, 4 y = 8, 5 x = 0).
Mesh box_soup_with(double y0, std::initializer_list<int> keep) { return only_faces(box_soup(0, 12, y0, 8, 7), keep); }

PointCloud far_cloud() {
  PointCloud far;
  for (int i = 0; i < 200; ++i) far.points.push_back(kOrigin + Vec3(500.0 + 0.1 * i, 0.0, 0.0));
  return far;
}

}  // namespace

// A house exported as roof, ground and one end wall (no single face fills the hole the others
// leave) is no valid solid; its shell is rebuilt on its own planes and written as `repaired`,
// every vertex one of the input's.
TEST(Refine, AHouseMissingThreeWallsIsRepairedOnItsPlanes) {
  const Mesh coarse = box_soup_with(0.0, {0, 1, 3});
  const RefineResult r = refine_building(coarse, far_cloud(), RefineConfig{});
  ASSERT_EQ(r.outcome, Outcome::Repaired) << r.reason;
  EXPECT_TRUE(r.valid) << r.trace.output_validation.problem;
  EXPECT_EQ(r.reason.rfind("shell rebuilt on its planes", 0), 0u) << r.reason;
  ASSERT_TRUE(r.trace.rebuild.has_value());
  EXPECT_FALSE(r.trace.invalid_input.empty());
  EXPECT_NEAR(validate_mesh(r.mesh, kPlanarity).volume, 12 * 8 * 7, 1e-6);
  EXPECT_LE(largest_vertex_move(r.mesh, coarse), 1e-6);
  // The soup's three faces are the model's; the three walls closing the hole are added.
  int model = 0, added = 0;
  for (const Face& f : r.mesh.faces) {
    model += f.provenance == Provenance::Model;
    added += f.provenance == Provenance::Added;
    if (f.provenance == Provenance::Added) {
      EXPECT_EQ(f.sem, Semantic::Wall);
    }
  }
  EXPECT_EQ(model, 3);
  EXPECT_EQ(added, 3);
}

// The same house with its street facade scanned 0.5 m inside the model: the rebuilt shell is the
// start of the refinement, which moves the facade.
TEST(Refine, ARepairedHouseIsRefinedOnItsScan) {
  const Mesh coarse = box_soup_with(-0.5, {0, 1, 2});  // the front wall kept, 0.5 m too far out
  const RefineResult r = refine_building(coarse, scan_front(0.0, 0.5, 11.5, 5.0, 7), RefineConfig{});
  ASSERT_EQ(r.outcome, Outcome::Refined) << r.reason;
  EXPECT_TRUE(r.valid) << r.trace.output_validation.problem;
  ASSERT_TRUE(r.trace.rebuild.has_value());
  EXPECT_TRUE(r.trace.rebuild->ok);
  EXPECT_LT(max_abs_y_of_front(r.mesh, 0.0), 0.02);
}

// A wall standing 3 m above the roof (a fin) is no part of the solid: the house is repaired, the
// fin written beside it as read.
TEST(Refine, AHouseWithAFinIsRepairedWithTheFinBesideIt) {
  Mesh coarse = box_soup(0, 12, 0, 8, 7);
  const int n = int(coarse.vertices.size());
  for (const Vec3& p : {Vec3(0, 0, 7), Vec3(0, 8, 7), Vec3(0, 8, 10), Vec3(0, 0, 10)})
    coarse.vertices.push_back(p + kOrigin);
  coarse.faces.push_back({{n, n + 1, n + 2, n + 3}, Semantic::Wall, 6});
  const RefineResult r = refine_building(coarse, far_cloud(), RefineConfig{});
  ASSERT_EQ(r.outcome, Outcome::Repaired) << r.reason;
  EXPECT_TRUE(r.valid);
  const std::size_t at = r.reason.find(" m² of fins beside it");
  ASSERT_NE(at, std::string::npos) << r.reason;
  EXPECT_NEAR(std::stod(r.reason.substr(r.reason.rfind(' ', at - 1))), 24.0, 0.5) << r.reason;
  EXPECT_NEAR(validate_mesh(r.mesh, 0.01).volume, 12.0 * 8.0 * 7.0, 1e-6);
  ASSERT_EQ(r.fins.faces.size(), 1u);
  EXPECT_EQ(r.fins.id, coarse.id);
  for (const Vec3& p : r.fins.vertices) {
    double nearest = 1e300;
    for (const Vec3& q : coarse.vertices) nearest = std::min(nearest, (p - q).norm());
    EXPECT_LT(nearest, 1e-6);
  }
}

// The same fin on a front wall that stands 0.5 m too far out: moving the wall onto its scan would
// leave the fin standing in the air, so the refinement is not written; the repaired house and its
// fin are. An OBJ gets the fin after the solid's faces.
TEST(Refine, ARefinementThatWouldLeaveAFinFloatingIsNotWritten) {
  Mesh coarse = box_soup(0, 12, -0.5, 8, 7);
  const int n = int(coarse.vertices.size());
  for (const Vec3& p : {Vec3(0, -0.5, 7), Vec3(12, -0.5, 7), Vec3(12, -0.5, 10), Vec3(0, -0.5, 10)})
    coarse.vertices.push_back(p + kOrigin);
  coarse.faces.push_back({{n, n + 1, n + 2, n + 3}, Semantic::Wall, 6});
  const RefineResult r = refine_building(coarse, scan_front(0.0, 0.5, 11.5, 5.0, 7), RefineConfig{});
  ASSERT_EQ(r.outcome, Outcome::Repaired) << r.reason;
  EXPECT_NE(r.reason.find("a fin beside the shell would stand apart from it"), std::string::npos) << r.reason;
  EXPECT_LT(largest_vertex_move(r.mesh, coarse), 0.01);
  ASSERT_FALSE(r.fins.faces.empty());
  // A second pass reads the house with its fin (a city file's Solid and fins MultiSurface, an
  // OBJ's fins group): a soup again, rebuilt, and the same refinement is not written.
  const RefineResult r2 = refine_building(merged(r.mesh, r.fins), scan_front(0.0, 0.5, 11.5, 5.0, 7), RefineConfig{});
  ASSERT_EQ(r2.outcome, Outcome::Repaired) << r2.reason;
  EXPECT_NE(r2.reason.find("a fin beside the shell would stand apart from it"), std::string::npos) << r2.reason;
  EXPECT_LT(largest_vertex_move(r2.mesh, coarse), 0.01);
  ASSERT_EQ(r2.fins.faces.size(), r.fins.faces.size());
}

// The defect classes of municipal exports the rebuild must leave where they are (issue #38): a
// roof crossing its wall by 5 mm, a wall face exported twice 5 mm apart, a 1 cm sliver between
// roof and wall. Each house comes out a valid solid of the box's volume (kept or repaired),
// no vertex of it off the input's by more than the weld tolerance.
TEST(Refine, MunicipalDefectsLeaveTheHouseWhereItIs) {
  const RefineConfig cfg;
  std::vector<std::pair<std::string, Mesh>> cases;
  {
    Mesh m = box_soup(0, 12, 0, 8, 7);  // roof (face 1) 5 mm past the wall y = 0
    for (int v : m.faces[1].v)
      if (m.vertices[std::size_t(v)].y() < kOrigin.y() + 1e-9) m.vertices[std::size_t(v)].y() -= 0.005;
    cases.emplace_back("roof crossing its wall by 5 mm", m);
  }
  {
    Mesh m = box_soup(0, 12, 0, 8, 7);  // wall y = 0 (face 2) again, 5 mm out
    Face twin = m.faces[2];
    for (int& v : twin.v) {
      m.vertices.push_back(m.vertices[std::size_t(v)] - Vec3(0, 0.005, 0));
      v = int(m.vertices.size()) - 1;
    }
    m.faces.push_back(twin);
    cases.emplace_back("a wall exported twice 5 mm apart", m);
  }
  {
    Mesh m = box_soup(0, 12, 0, 8, 7);  // the roof lowered 1 cm along y = 0, a sliver closing it
    const int n = int(m.vertices.size());
    for (const Vec3& p : {Vec3(0, 0, 6.99), Vec3(12, 0, 6.99), Vec3(12, 0, 7), Vec3(0, 0, 7)})
      m.vertices.push_back(kOrigin + p);
    m.faces.push_back({{n, n + 1, n + 2, n + 3}, Semantic::Wall, 6});
    cases.emplace_back("a 1 cm sliver on the wall's top", m);
  }
  for (const auto& [what, coarse] : cases) {
    const RefineResult r = refine_building(coarse, far_cloud(), cfg);
    EXPECT_TRUE(r.outcome == Outcome::Kept || r.outcome == Outcome::Repaired) << what << ": " << r.reason;
    EXPECT_TRUE(r.valid) << what << ": " << r.trace.output_validation.problem;
    EXPECT_NEAR(validate_mesh(r.mesh, kPlanarity).volume, 12 * 8 * 7, 12 * 8 * 0.02) << what;
    EXPECT_LE(largest_vertex_move(r.mesh, coarse), cfg.repair.weld_tolerance) << what;
  }
}

namespace {

// Two storeys, their fronts facing -y, as an exported soup: the lower one [0,12] x [0,8] x [0,6],
// its front y = 0 for x in [0,8] and y = `step` beyond x = 8; the upper one [0,12] x [0.37,8] x
// [6,9], set back 0.37 m over a ledge (City3D 08835's upper storey).
constexpr double kSetback = 0.37;
Mesh setback_storey_soup(double step) {
  Mesh m;
  m.id = "setback storey";
  auto add = [&](std::vector<Vec3> pts, Semantic sem) {
    Face face{{}, sem};
    for (const auto& p : pts) {
      face.v.push_back(int(m.vertices.size()));
      m.vertices.push_back(p + kOrigin);
    }
    m.faces.push_back(face);
  };
  const double s = kSetback;
  add({{0, 0, 0}, {0, 8, 0}, {12, 8, 0}, {12, step, 0}, {8, step, 0}, {8, 0, 0}}, Semantic::Ground);
  add({{0, 0, 0}, {8, 0, 0}, {8, 0, 6}, {0, 0, 6}}, Semantic::Wall);
  add({{8, 0, 0}, {8, step, 0}, {8, step, 6}, {8, 0, 6}}, Semantic::Wall);
  add({{8, step, 0}, {12, step, 0}, {12, step, 6}, {8, step, 6}}, Semantic::Wall);
  add({{0, 0, 6}, {8, 0, 6}, {8, step, 6}, {12, step, 6}, {12, s, 6}, {0, s, 6}}, Semantic::Roof);  // the ledge
  add({{0, s, 6}, {12, s, 6}, {12, s, 9}, {0, s, 9}}, Semantic::Wall);
  add({{0, s, 9}, {12, s, 9}, {12, 8, 9}, {0, 8, 9}}, Semantic::Roof);
  add({{12, 8, 0}, {0, 8, 0}, {0, 8, 9}, {12, 8, 9}}, Semantic::Wall);
  add({{12, step, 0}, {12, 8, 0}, {12, 8, 9}, {12, s, 9}, {12, s, 6}, {12, step, 6}}, Semantic::Wall);
  add({{0, 8, 0}, {0, 0, 0}, {0, 0, 6}, {0, s, 6}, {0, s, 9}, {0, 8, 9}}, Semantic::Wall);
  return m;
}

// The upper storey's front scanned `out` in front of the model's (the lower 70 % of its height,
// 5 cm apart, 1 cm range noise), and the street in front of the building.
PointCloud upper_front_scan(double out) {
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.01);
  PointCloud pc;
  for (double x = 0.025; x < 12.0; x += 0.05)
    for (double z = 6.025; z < 6.0 + 0.7 * 3.0; z += 0.05)
      pc.points.push_back(kOrigin + Vec3(x, kSetback - out + noise(rng), z));
  for (double x = 0.0; x < 12.0; x += 0.1)
    for (double y = -0.5; y > -4.0; y -= 0.1) pc.points.push_back(kOrigin + Vec3(x, y, noise(rng)));
  return pc;
}

// The faces of `m` facing -y (its fronts), in the local frame.
std::vector<std::vector<Vec3>> front_faces(const Mesh& m) {
  std::vector<std::vector<Vec3>> out;
  for (const auto& f : m.faces) {
    std::vector<Vec3> poly;
    for (int v : f.v) poly.push_back(m.vertices[std::size_t(v)] - kOrigin);
    if (newell_normal(poly).normalized().y() < -0.99) out.push_back(std::move(poly));
  }
  return out;
}

}  // namespace

// The upper storey's front, set back 0.37 m over a ledge, is 0.30 m out: on its scan it stands
// 0.07 m behind the lower front's left part but 0.14 m before its right part (y = 0.21), so
// moving it folds the ledge's roof there and the substitution is refused (City3D 08835). The
// selection's budget, scaled down as this program is (its search finds the refinement after
// about 0.08 units of work; 08835's after 2,000-3,000 of its 60), ends where it starts: the
// start is the model with that wall on its scan plane, the arrangement closing the rest (the
// ledge narrows on the left and becomes a soffit on the right). The lower storey stays.
TEST(Refine, AnUpperStoreyOverALedgeIsMovedWhereItsSubstitutionFolds) {
  constexpr double kStep = 0.21, kOut = 0.30;
  RefineConfig prm;
  prm.selection.mip_work_limit = 0.04;
  const auto t0 = std::chrono::steady_clock::now();
  const RefineResult r = refine_building(setback_storey_soup(kStep), upper_front_scan(kOut), prm);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(r.trace.substitution.has_value());
  EXPECT_FALSE(r.trace.substitution->ok) << "the case is one whose substitution folds";
  ASSERT_EQ(r.outcome, Outcome::Refined) << r.reason;
  const Validation v = validate_mesh(r.mesh, kPlanarity);
  EXPECT_TRUE(v.valid()) << v.problem;
  int upper = 0, lower = 0;
  for (const auto& poly : front_faces(r.mesh)) {
    double top = -1e300;
    for (const auto& p : poly) top = std::max(top, p.z());
    if (top > 6.0 + 1e-6) {
      ++upper;
      for (const auto& p : poly) EXPECT_LT(std::abs(p.y() - (kSetback - kOut)), 0.01) << "upper front off its scan";
      continue;
    }
    ++lower;
    for (const auto& p : poly) {  // unmoved: y = 0 left of x = 8, y = kStep right of it
      if (std::abs(p.x() - 8.0) < 1e-6) continue;
      EXPECT_NEAR(p.y(), p.x() < 8.0 ? 0.0 : kStep, 1e-3) << "the lower front moved at x = " << p.x();
    }
  }
  EXPECT_EQ(upper, 1);
  EXPECT_EQ(lower, 2);
  EXPECT_NEAR(v.volume, 12 * 8 * 9 - 4 * kStep * 6 - 12 * (kSetback - kOut) * 3, 0.05);
  EXPECT_LT(seconds, 5.0);
}

namespace {

// The median distance (m) of a generated building's scanned truth wall `w` to `m`, on samples
// 0.25 m apart.
double wall_median_distance(const SynthBuilding& b, const MovedWall& w, const Mesh& m) {
  std::vector<double> d = cloud_to_mesh(m, sample_faces(b.truth, w.truth_faces, 0.25));
  for (double& x : d) x = std::abs(x);
  std::nth_element(d.begin(), d.begin() + std::ptrdiff_t(d.size() / 2), d.end());
  return d[d.size() / 2];
}

}  // namespace

// The starting shell's fallback, one wall at a time (refine.cpp's one_wall_at_a_time): generated
// hips (synth hip seeds 38 and 53) with three scanned walls 0.05-0.75 m out. Moved at once, the
// shell's faces intersect; moved one at a time, each re-matched on the shell before, all three
// land on the truth. With the call switched off both hips are kept, every wall where it was: the
// selection from the input, the moves as its warm start, ends on the input (no candidate changed).
TEST(Refine, AHipWhoseWallsCannotMoveAtOnceMovesThemOneAtATime) {
  for (std::uint64_t seed : {38u, 53u}) {
    const SynthBuilding b = make_building(BuildingType::Hip, seed);
    SCOPED_TRACE(b.id);
    const RefineResult r = refine_building(b.coarse, b.cloud, RefineConfig{});
    ASSERT_TRUE(r.trace.substitution.has_value());
    EXPECT_FALSE(r.trace.substitution->ok) << "the case is one whose walls cannot move at once";
    EXPECT_EQ(r.outcome, Outcome::Refined) << r.reason;
    int scanned = 0;
    for (const MovedWall& w : b.moved_walls) {
      if (!w.scanned) continue;
      ++scanned;
      EXPECT_GT(wall_median_distance(b, w, b.coarse), 0.04)
          << "truth wall " << w.truth_faces[0] << " is out in the input";
      EXPECT_LT(wall_median_distance(b, w, r.mesh), 0.01) << "truth wall " << w.truth_faces[0];
    }
    EXPECT_EQ(scanned, 3);
  }
}

// A wall the fallback moved that the judge refuses is dropped on its own, as a scan move is: a
// generated gable (synth gable seed 45) whose fallback moved one wall a second time, onto a plane
// with none of its points in front. The whole building was kept, its scanned walls 0.19 m out;
// now that wall's input faces stay and the others move onto the truth.
TEST(Refine, AWallTheFallbackMovedThatTheJudgeRefusesIsDroppedAlone) {
  const SynthBuilding b = make_building(BuildingType::Gable, 45);
  const RefineResult r = refine_building(b.coarse, b.cloud, RefineConfig{});
  ASSERT_TRUE(r.trace.substitution.has_value());
  EXPECT_FALSE(r.trace.substitution->ok) << "the case is one whose walls cannot move at once";
  ASSERT_EQ(r.outcome, Outcome::Refined) << r.reason;
  ASSERT_EQ(r.trace.walls_refused.size(), 1u);
  EXPECT_NE(r.trace.walls_refused[0].find("0 scan points in front of it"), std::string::npos)
      << r.trace.walls_refused[0];
  double before = 0, after = 0;
  int scanned = 0;
  for (const MovedWall& w : b.moved_walls) {
    if (!w.scanned) continue;
    ++scanned;
    before += wall_median_distance(b, w, b.coarse);
    after += wall_median_distance(b, w, r.mesh);
  }
  ASSERT_GT(scanned, 0);
  EXPECT_GT(before / scanned, 0.15);
  EXPECT_LT(after / scanned, 0.03);
}

TEST(Refine, OutcomeNamesReadBack) {
  for (Outcome o :
       {Outcome::Refined, Outcome::Kept, Outcome::Repaired, Outcome::KeptInvalid, Outcome::Untouched, Outcome::Failed})
    EXPECT_EQ(parse_outcome(outcome_name(o)), o) << outcome_name(o);
  EXPECT_EQ(std::string(outcome_name(Outcome::KeptInvalid)), "kept-invalid");
  EXPECT_FALSE(parse_outcome("Refined").has_value());
  EXPECT_FALSE(parse_outcome("").has_value());
}
