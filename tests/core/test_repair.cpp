#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "lodrefine/base/geometry.h"
#include "lodrefine/core/repair.h"
#include "lodrefine/core/validate.h"
#include "support/hang_guard.h"

using namespace lodrefine;

namespace {

using Polygon = std::vector<Vec3>;

// A polygon soup as exported from CityGML: every face has its own copies of its corners.
Mesh soup(const std::vector<std::pair<Polygon, Semantic>>& polys) {
  Mesh m;
  m.id = "test";
  for (const auto& [poly, sem] : polys) {
    Face f{{}, sem, int(m.faces.size())};
    for (const Vec3& p : poly) {
      f.v.push_back(int(m.vertices.size()));
      m.vertices.push_back(p);
    }
    m.faces.push_back(f);
  }
  return m;
}

Polygon reversed(Polygon p) {
  std::reverse(p.begin(), p.end());
  return p;
}

// The outward faces of an axis-aligned box: top, bottom, then the walls front/right/back/left.
std::vector<std::pair<Polygon, Semantic>> box(const Vec3& lo, const Vec3& hi) {
  const double x0 = lo.x(), y0 = lo.y(), z0 = lo.z(), x1 = hi.x(), y1 = hi.y(), z1 = hi.z();
  return {{{{x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}}, Semantic::Roof},
          {{{x0, y0, z0}, {x0, y1, z0}, {x1, y1, z0}, {x1, y0, z0}}, Semantic::Ground},
          {{{x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}}, Semantic::Wall},
          {{{x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}}, Semantic::Wall},
          {{{x1, y1, z0}, {x0, y1, z0}, {x0, y1, z1}, {x1, y1, z1}}, Semantic::Wall},
          {{{x0, y1, z0}, {x0, y0, z0}, {x0, y0, z1}, {x0, y1, z1}}, Semantic::Wall}};
}

int count_sem(const Mesh& m, Semantic s) {
  return int(std::count_if(m.faces.begin(), m.faces.end(), [s](const Face& f) { return f.sem == s; }));
}

void expect_valid_solid(const Mesh& m, double volume) {
  const Validation v = validate_mesh(m, 0.01);
  EXPECT_TRUE(v.valid()) << v.problem;
  EXPECT_NEAR(v.volume, volume, 0.01);
}

}  // namespace

TEST(Repair, CubeSoupWithExportDefectsBecomesClosedSolid) {
  auto faces = box({0, 0, 0}, {1, 1, 1});
  faces.erase(faces.begin() + 1);                                            // ground missing
  faces[1].first = reversed(faces[1].first);                                 // front wall flipped
  faces[2].first.insert(faces[2].first.begin() + 1, faces[2].first[1]);      // repeated corner
  faces.push_back({reversed(faces[3].first), Semantic::Wall});               // back wall again, reversed
  faces.push_back({{{0, 0, 1}, {0, 0, 1.001}, {1, 0, 1}}, Semantic::Roof});  // degenerate sliver
  Mesh in = soup(faces);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.002, 0.002);
  for (Vec3& p : in.vertices) p += Vec3(jitter(rng), jitter(rng), jitter(rng));

  RepairReport r;
  const Mesh out = repair_model(in, 0.01, &r);
  EXPECT_EQ(r.input_vertices, 28);
  EXPECT_EQ(r.input_faces, 7);
  EXPECT_EQ(r.welded_vertices, 20);
  EXPECT_EQ(r.removed_degenerate_faces, 1);
  EXPECT_EQ(r.removed_duplicate_faces, 1);
  EXPECT_EQ(r.split_t_junctions, 0);
  EXPECT_EQ(r.flipped_faces, 1);
  EXPECT_EQ(r.filled_holes, 1);
  EXPECT_TRUE(r.closed);
  EXPECT_EQ(out.vertices.size(), 8u);
  ASSERT_EQ(out.faces.size(), 6u);
  EXPECT_EQ(out.id, "test");
  expect_valid_solid(out, 1.0);
  EXPECT_EQ(count_sem(out, Semantic::Roof), 1);
  EXPECT_EQ(count_sem(out, Semantic::Wall), 4);
  ASSERT_EQ(count_sem(out, Semantic::Ground), 1);
  for (const Face& f : out.faces) {
    EXPECT_EQ(f.v.size(), 4u);
    EXPECT_EQ(f.source == -1, f.sem == Semantic::Ground);  // the filled hole is the only new face
  }
  EXPECT_EQ(out.faces[1].source, 1);  // the flipped wall keeps its origin
}

TEST(Repair, TJunctionOfLongWallAndSplitRoofIsSplitAndThenMerged) {
  auto faces = box({0, 0, 0}, {2, 1, 1});
  faces[0] = {{{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}, Semantic::Roof};
  faces.push_back({{{1, 0, 1}, {2, 0, 1}, {2, 1, 1}, {1, 1, 1}}, Semantic::Roof});
  faces[0].first[1].z() += 0.004;  // millimetre gap between the two roof polygons
  RepairReport r;
  const Mesh out = repair_model(soup(faces), 0.01, &r);
  EXPECT_EQ(r.split_t_junctions, 2);  // front and back wall tops get the roof split vertex
  EXPECT_EQ(r.filled_holes, 0);
  EXPECT_EQ(out.vertices.size(), 10u);
  EXPECT_EQ(out.faces.size(), 7u);
  expect_valid_solid(out, 2.0);

  const Mesh merged = merge_coplanar_faces(out, 0.5, 0.005);
  EXPECT_EQ(merged.vertices.size(), 8u);  // the split vertices went with the roof split
  ASSERT_EQ(merged.faces.size(), 6u);
  for (const Face& f : merged.faces) EXPECT_EQ(f.v.size(), 4u);
  EXPECT_EQ(count_sem(merged, Semantic::Roof), 1);
  expect_valid_solid(merged, 2.0);
}

TEST(Repair, InvertedLShapedPrismWithoutGroundIsOrientedAndClosed) {
  const std::vector<Vec2> foot = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};  // counter-clockwise
  std::vector<std::pair<Polygon, Semantic>> faces;
  Polygon roof;
  for (std::size_t i = 0; i < foot.size(); ++i) {
    const Vec2 &a = foot[i], &b = foot[(i + 1) % foot.size()];
    faces.push_back(
        {reversed({{a.x(), a.y(), 0}, {b.x(), b.y(), 0}, {b.x(), b.y(), 3}, {a.x(), a.y(), 3}}), Semantic::Wall});
    roof.push_back({a.x(), a.y(), 3});
  }
  faces.push_back({reversed(roof), Semantic::Roof});  // every face inward, as some exporters do
  RepairReport r;
  const Mesh out = repair_model(soup(faces), 0.01, &r);
  EXPECT_EQ(r.flipped_faces, 7);
  EXPECT_EQ(r.filled_holes, 1);
  EXPECT_EQ(out.vertices.size(), 12u);
  ASSERT_EQ(out.faces.size(), 8u);
  EXPECT_EQ(count_sem(out, Semantic::Ground), 1);
  expect_valid_solid(out, 9.0);
  const Mesh merged = merge_coplanar_faces(out);
  EXPECT_EQ(merged.faces.size(), 8u);  // nothing coplanar to merge: the L's walls all differ
  expect_valid_solid(merged, 9.0);
}

TEST(Repair, NonPlanarHoleIsTriangulatedAndNoted) {
  // A gable house whose two roof slopes are both missing: the hole rises to the ridge.
  const Mesh house = soup({{{{0, 0, 0}, {0, 2, 0}, {4, 2, 0}, {4, 0, 0}}, Semantic::Ground},
                           {{{0, 0, 0}, {4, 0, 0}, {4, 0, 2}, {0, 0, 2}}, Semantic::Wall},
                           {{{4, 2, 0}, {0, 2, 0}, {0, 2, 2}, {4, 2, 2}}, Semantic::Wall},
                           {{{4, 0, 0}, {4, 2, 0}, {4, 2, 2}, {4, 1, 3}, {4, 0, 2}}, Semantic::Wall},
                           {{{0, 2, 0}, {0, 0, 0}, {0, 0, 2}, {0, 1, 3}, {0, 2, 2}}, Semantic::Wall}});
  RepairReport r;
  const Mesh out = repair_model(house, 0.01, &r);
  EXPECT_EQ(r.filled_holes, 1);
  ASSERT_EQ(r.notes.size(), 1u);
  EXPECT_NE(r.notes[0].find("not planar"), std::string::npos) << r.notes[0];
  EXPECT_EQ(out.faces.size(), 5u + 4u);  // the 6-vertex loop gives 4 triangles
  const Validation v = validate_mesh(out, 1.0);
  EXPECT_TRUE(v.watertight());
  EXPECT_EQ(v.inconsistent_edges, 0);
  EXPECT_GT(v.volume, 16.0);  // the box below the eaves plus some of the roof prism
  EXPECT_LE(v.volume, 20.0 + 1e-9);
}

TEST(Repair, UnclosableInputThrowsOneLineInputError) {
  const auto expect_rejected = [](const Mesh& m, const std::string& reason) {
    RepairReport r;
    try {
      repair_model(m, 0.01, &r);
      ADD_FAILURE() << "accepted: " << reason;
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(reason), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
    EXPECT_FALSE(r.closed);
  };
  expect_rejected(Mesh{}, "only 0 usable faces");
  expect_rejected(soup({{{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, Semantic::Roof},
                        {{{0, 0, 0}, {0, 0, 0.001}, {0, 1, 0}}, Semantic::Roof}}),
                  "only 0 usable faces");
  // Two cubes sharing one edge: four faces on that edge cannot form a 2-manifold.
  auto faces = box({0, 0, 0}, {1, 1, 1});
  const auto other = box({1, 1, 0}, {2, 2, 1});
  faces.insert(faces.end(), other.begin(), other.end());
  expect_rejected(soup(faces), "non-manifold edges");
  Mesh bad = soup(box({0, 0, 0}, {1, 1, 1}));
  bad.faces[0].v[0] = 99;
  expect_rejected(bad, "references missing vertex 99");
}

// Issue 15, item 12: a face pinched at one vertex 6000 times took minutes: the T-junction
// split searched every candidate vertex in the whole ring, cubic in the ring's length.
TEST(Repair, FacePinchedThousandsOfTimesIsRepairedQuickly) {
  Mesh m;
  m.vertices.push_back(Vec3(85000, 447000, 0));
  Face f;
  f.sem = Semantic::Roof;
  const int petals = 6000;
  for (int k = 0; k < petals; ++k) {
    for (const double s : {0.0, 0.5}) {
      const double a = 2 * kPi * (k + s) / petals;
      m.vertices.push_back(Vec3(85000 + 100 * std::cos(a), 447000 + 100 * std::sin(a), 0));
    }
    f.v.insert(f.v.end(), {0, 2 * k + 1, 2 * k + 2});
  }
  m.faces.push_back(f);
  const auto t0 = std::chrono::steady_clock::now();
  try {
    RepairReport r;
    repair_model(m, 0.01, &r);  // one flat face closes nothing: refused, but at once
  } catch (const InputError&) {
  }
  EXPECT_LT(fixtures::seconds_since(t0), fixtures::kHangGuardSeconds);
}

TEST(Repair, MergeJoinsCoplanarTilesButKeepsARingAroundAHoleApart) {
  // A box whose flat roof is exported as 3 x 3 tiles; its walls are single long quads.
  const auto roof_tiles = [](Semantic centre) {
    auto faces = box({0, 0, 0}, {3, 3, 1});
    faces.erase(faces.begin());
    for (double x = 0; x < 3; ++x)
      for (double y = 0; y < 3; ++y)
        faces.push_back(
            {{{x, y, 1}, {x + 1, y, 1}, {x + 1, y + 1, 1}, {x, y + 1, 1}}, x == 1 && y == 1 ? centre : Semantic::Roof});
    RepairReport r;
    const Mesh m = repair_model(soup(faces), 0.01, &r);
    EXPECT_EQ(r.split_t_junctions, 8);  // two tile corners on each wall's top edge
    EXPECT_EQ(m.faces.size(), 5u + 9u);
    return m;
  };
  const Mesh all_roof = merge_coplanar_faces(roof_tiles(Semantic::Roof));
  EXPECT_EQ(all_roof.faces.size(), 6u);
  EXPECT_EQ(all_roof.vertices.size(), 8u);
  expect_valid_solid(all_roof, 9.0);

  // A different centre leaves the eight roof tiles as a ring with a hole: they stay apart, and
  // the walls keep the tile corners so that no T-junction appears.
  const Mesh ring = merge_coplanar_faces(roof_tiles(Semantic::Other));
  EXPECT_EQ(ring.faces.size(), 14u);
  EXPECT_EQ(count_sem(ring, Semantic::Roof), 8);
  expect_valid_solid(ring, 9.0);
}
