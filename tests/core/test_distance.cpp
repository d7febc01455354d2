// Point-to-mesh distances (core/distance.h): the nearest face and the signed distance to it, the
// pseudonormal sign on edges and vertices, precision in georeferenced frames, face sampling.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "lodrefine/core/distance.h"
#include "support/mesh_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

namespace {

Mesh unit_cube() { return box(Vec3::Zero(), Vec3::Ones()); }

// 10 × 10 m footprint without the 6 × 6 m square x > 4, y > 4: a reflex vertical edge at (4, 4).
Mesh l_shape() { return extrusion({{0, 0}, {10, 0}, {10, 4}, {4, 4}, {4, 10}, {0, 10}}, 0.0, 6.0); }

// The 10 × 8 × 6 m box with a wall every 0.5 m (coplanar neighbours): 284 triangles, enough for
// the distance to search its tree.
Mesh tiled_box() {
  std::vector<Vec2> footprint;
  for (int i = 0; i < 20; ++i) footprint.emplace_back(0.5 * i, 0.0);
  for (int i = 0; i < 16; ++i) footprint.emplace_back(10.0, 0.5 * i);
  for (int i = 0; i < 20; ++i) footprint.emplace_back(10.0 - 0.5 * i, 8.0);
  for (int i = 0; i < 16; ++i) footprint.emplace_back(0.0, 8.0 - 0.5 * i);
  return extrusion(footprint, 0.0, 6.0);
}

// A point, its signed distance to the mesh and the face of its nearest point.
struct Probe {
  Vec3 p;
  double distance;
  int face;
};

void expect_nearest(const Mesh& mesh, const std::vector<Probe>& probes, double tolerance) {
  const MeshDistance index(mesh);
  for (std::size_t i = 0; i < probes.size(); ++i) {
    const auto s = index.nearest(probes[i].p, true), u = index.nearest(probes[i].p, false);
    EXPECT_NEAR(s.distance, probes[i].distance, tolerance) << "probe " << i;
    EXPECT_NEAR(u.distance, std::abs(probes[i].distance), tolerance) << "probe " << i;
    EXPECT_EQ(s.face, probes[i].face) << "probe " << i;
    EXPECT_EQ(u.face, probes[i].face) << "probe " << i;
  }
}

}  // namespace

TEST(CloudToMesh, UnitCubeFaceEdgeVertexAndInside) {
  const std::vector<Vec3> pts = {
      {0.5, 0.5, 1.3},   // above the roof
      {0.5, 0.5, 0.8},   // inside, nearest the roof
      {0.5, 0.5, 0.5},   // centre: all six faces tie
      {1.2, 0.5, 1.2},   // nearest an edge
      {1.2, 1.2, 1.2},   // nearest a vertex
      {-0.3, 0.5, 0.1},  // outside a wall
      {0.9, 0.5, 0.9},   // inside, equidistant to two faces
      {1.0, 0.3, 0.7},   // on the surface
  };
  const std::vector<double> want = {0.3, -0.2, -0.5, std::sqrt(0.08), std::sqrt(0.12), 0.3, -0.1, 0.0};
  const auto got = cloud_to_mesh(unit_cube(), pts);
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_NEAR(got[i], want[i], 1e-12) << "point " << i;
  const auto unsigned_got = unsigned_distances(unit_cube(), pts);
  ASSERT_EQ(unsigned_got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_NEAR(unsigned_got[i], std::abs(want[i]), 1e-12) << "point " << i;
}

TEST(CloudToMesh, SoupAndGeoreferencedFrameGiveTheSameDistances) {
  const std::vector<Vec3> pts = {{1.2, 0.5, 1.2}, {1.2, 1.2, 1.2}, {0.5, 0.5, 0.8}, {-0.1, -0.1, 0.5}};
  const auto ref = cloud_to_mesh(unit_cube(), pts);
  const Vec3 shift(85000.0, 447000.0, 12.0);
  Mesh geo = as_soup(unit_cube());
  for (auto& v : geo.vertices) v += shift;
  std::vector<Vec3> geo_pts = pts;
  for (auto& p : geo_pts) p += shift;
  const auto got = cloud_to_mesh(geo, geo_pts);
  for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_NEAR(got[i], ref[i], 1e-9) << "point " << i;
}

TEST(CloudToMesh, NeedleApexUsesThePseudonormal) {
  const auto d = cloud_to_mesh(needle(), {{-0.5, 0.0, 10.5}, {0.5, 0.0, 10.5}, {0.0, 0.5, 10.5}, {0.0, 0.0, 9.5}});
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(d[std::size_t(i)], std::sqrt(0.5), 1e-12) << "point " << i;
  EXPECT_NEAR(d[3], -0.5 / std::sqrt(101.0), 1e-12);  // inside, nearest a side face
}

TEST(MeshDistance, EmptyOrDegenerateMeshIsAnInputError) {
  EXPECT_THROW(cloud_to_mesh(Mesh{}, {{0, 0, 0}}), InputError);
  Mesh flat;
  flat.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  flat.faces = {{{0, 1, 2}, Semantic::Wall}};
  EXPECT_THROW(MeshDistance{flat}, InputError);
}

// Box 10 × 8 × 6: faces 0 ground, 1 roof, 2 y = 0, 3 x = 10, 4 y = 8, 5 x = 0.
TEST(MeshDistance, NearestFaceAndSignedDistanceOnTheBoxFaces) {
  expect_nearest(box({0, 0, 0}, {10, 8, 6}),
                 {{{5, 4, 7.5}, 1.5, 1},
                  {{5, 4, -0.25}, 0.25, 0},
                  {{5, 4, 0.5}, -0.5, 0},
                  {{5, -2, 3}, 2.0, 2},
                  {{12.5, 4, 3}, 2.5, 3},
                  {{5, 7, 3}, -1.0, 4},
                  {{1, 4, 3}, -1.0, 5},
                  {{3, 8.75, 1}, 0.75, 4}},
                 1e-12);
}

TEST(MeshDistance, EdgeAndVertexTakeTheSignOfThePseudonormal) {
  const Mesh b = box({0, 0, 0}, {10, 8, 6});
  const MeshDistance index(b);
  // Outside a convex edge (x = 10, y = 0) and beyond a convex vertex (10, 0, 6).
  const auto edge = index.nearest({11, -1, 3}, true);
  EXPECT_NEAR(edge.distance, std::sqrt(2.0), 1e-12);
  EXPECT_TRUE(edge.face == 2 || edge.face == 3) << edge.face;
  const auto vertex = index.nearest({11, -1, 7}, true);
  EXPECT_NEAR(vertex.distance, std::sqrt(3.0), 1e-12);
  EXPECT_TRUE(vertex.face == 1 || vertex.face == 2 || vertex.face == 3) << vertex.face;
  // Inside, nearest the reflex edge of an L (the walls y = 4 and x = 4 end there): negative;
  // in the notch, on the bisector of the two walls: positive.
  const auto reflex = cloud_to_mesh(l_shape(), {{3.5, 3.5, 3}, {3.9, 3.6, 3}, {4.5, 4.5, 3}});
  EXPECT_NEAR(reflex[0], -std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(reflex[1], -std::hypot(0.1, 0.4), 1e-12);
  EXPECT_NEAR(reflex[2], 0.5, 1e-12);
}

// A point nearest an edge or vertex ties between the faces that meet there: the batch reports
// what nearest() reports, the face included (the judge's wall regions take their points by it).
TEST(MeshDistance, TheBatchGivesATieThePlainSearchsFace) {
  const MeshDistance index(box({0, 0, 0}, {10, 8, 6}));
  const std::vector<Vec3> probes = {{11, -1, 3},  // outside the edge of walls 2 and 3
                                    {11, -1, 7},  // beyond the vertex of the roof and walls 2, 3
                                    {10, 0, 3},   // on that edge
                                    {5, 4, 3},    // inside, 3 m from both ground and roof
                                    {9, 1, 5}};   // inside, 1 m from the roof and walls 2, 3
  const auto batch = index.nearest_all(probes);
  for (std::size_t i = 0; i < probes.size(); ++i) {
    const auto plain = index.nearest(probes[i], false);
    EXPECT_EQ(batch[i].face, plain.face) << probes[i].transpose();
    EXPECT_EQ(batch[i].distance, plain.distance) << probes[i].transpose();
  }
}

// A point nearest an edge ties between the faces meeting there: it goes to the face whose plane
// lies nearest it, in both searches (the tree's own pick was arbitrary: the first it visited).
TEST(MeshDistance, ATieGoesToTheFaceWhosePlaneIsNearest) {
  struct Tie {
    Vec3 p;
    int box_face, tiled_face;  // tiled_box: ground 0, roof 1, wall tile i (footprint edge i) 2 + i
  };
  const std::vector<Tie> ties = {
      {{5.25, -1, 0}, 0, 0},      // street ground beyond the wall's foot: the ground
      {{11, 0, 3}, 2, 21},        // the wall y = 0 running on beyond its end: that wall
      {{10.2, -0.5, 3}, 3, 22},   // nearer the plane x = 10 than y = 0: the wall x = 10
      {{5.25, -0.5, 6.2}, 1, 1},  // above the eaves, nearer the roof's plane
      {{5.0, -1, 3}, 2, 11},      // before the joint of two coplanar tiles: the lower face
  };
  const MeshDistance plain(box({0, 0, 0}, {10, 8, 6})), tiled(tiled_box());
  std::vector<Vec3> points;
  for (const auto& t : ties) points.push_back(t.p);
  const auto plain_all = plain.nearest_all(points), tiled_all = tiled.nearest_all(points);
  for (std::size_t i = 0; i < ties.size(); ++i) {
    EXPECT_EQ(plain.nearest(ties[i].p, false).face, ties[i].box_face) << ties[i].p.transpose();
    EXPECT_EQ(plain_all[i].face, ties[i].box_face) << ties[i].p.transpose();
    EXPECT_EQ(tiled.nearest(ties[i].p, true).face, ties[i].tiled_face) << ties[i].p.transpose();
    EXPECT_EQ(tiled_all[i].face, ties[i].tiled_face) << ties[i].p.transpose();
    EXPECT_EQ(tiled.distance(ties[i].p, false), tiled_all[i].distance) << ties[i].p.transpose();
  }
}

// The batch search (cells of candidate triangles; measured directly on a small mesh, found in
// the tree on a large one) equals the plain search on a lattice full of ties (edges, vertices,
// medial planes, cell boundaries): nearest()'s distance and face bit for bit, the distance to
// each face alone; bit for bit the same when every point is searched alone.
TEST(MeshDistance, TheBatchSearchEqualsThePlainOneOnTies) {
  const Vec3 shift(85000.0, 447000.0, 12.0);
  Mesh far = l_shape();
  for (auto& v : far.vertices) v += shift;
  for (const Mesh& mesh : {l_shape(), gable_house(), as_soup(box({0, 0, 0}, {10, 8, 6})), far, tiled_box()}) {
    const Vec3 o = mesh.vertices.front().array().floor().matrix();
    std::vector<Vec3> points;
    for (double x = -3; x <= 13; x += 0.5)
      for (double y = -3; y <= 13; y += 0.5)
        for (double z = -3; z <= 12; z += 0.5) points.push_back(o + Vec3(x, y, z));
    std::vector<std::unique_ptr<MeshDistance>> each;  // the distance to each face alone
    for (const auto& f : mesh.faces) {
      Mesh one = mesh;
      one.faces = {f};
      each.push_back(std::make_unique<MeshDistance>(one));
    }
    const MeshDistance index(mesh);
    const auto batch = index.nearest_all(points);
    ASSERT_EQ(batch.size(), points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      std::vector<double> d;
      for (const auto& e : each) d.push_back(e->nearest(points[i], false).distance);
      const auto plain = index.nearest(points[i], false);
      EXPECT_EQ(batch[i].distance, plain.distance) << points[i].transpose();
      EXPECT_EQ(batch[i].face, plain.face) << points[i].transpose();
      EXPECT_NEAR(batch[i].distance, *std::min_element(d.begin(), d.end()), 1e-12) << points[i].transpose();
    }
    // A far outlier makes the batch's grid too large: every point is then searched alone.
    points.push_back(o + Vec3(3e6, -2e6, 5));
    const auto alone = index.nearest_all(points);
    for (std::size_t i = 0; i < batch.size(); ++i) {
      EXPECT_EQ(alone[i].distance, batch[i].distance);
      EXPECT_EQ(alone[i].face, batch[i].face);
    }
    EXPECT_NEAR(alone.back().distance, index.nearest(points.back(), false).distance, 1e-9);
  }
}

// A 7-digit northing (UTM): squared distances in the file's frame would lose the millimetres.
TEST(MeshDistance, GeoreferencedCoordinatesKeepSubMillimetrePrecision) {
  const Vec3 shift(693512.37, 5336218.91, 312.5);
  Mesh geo = as_soup(box({0, 0, 0}, {10, 8, 6}));
  for (auto& v : geo.vertices) v += shift;
  expect_nearest(geo,
                 {{Vec3(5, -0.0003, 3) + shift, 0.0003, 2},
                  {Vec3(5, 0.0002, 3) + shift, -0.0002, 2},
                  {Vec3(4, 3, 5.9996) + shift, -0.0004, 1},
                  {Vec3(10.0007, 4, 2) + shift, 0.0007, 3},
                  {Vec3(3, 8.0001, 1) + shift, 0.0001, 4}},
                 1e-8);
  const auto edge = cloud_to_mesh(geo, {Vec3(10.0003, -0.0004, 3) + shift});
  EXPECT_NEAR(edge[0], 0.0005, 1e-8);
}

TEST(SampleFaces, OneSampleACellOfTheSpacing) {
  const Mesh cube = unit_cube();
  const auto s = sample_faces(cube, {1}, 0.1);  // the 1 m² roof
  EXPECT_EQ(s.size(), 100u);
  for (const auto& p : s) EXPECT_NEAR(p.z(), 1.0, 1e-12);

  const Mesh b = box({0, 0, 0}, {10, 8, 6});
  EXPECT_EQ(sample_faces(b, {1}, 0.5).size(), 20u * 16u);
  EXPECT_EQ(sample_faces(b, {2}, 1.0).size(), 10u * 6u);
  EXPECT_EQ(sample_faces(b, {2}, 0.25).size(), 40u * 24u);
  EXPECT_EQ(sample_faces(b, {1, 2, 3}, 1.0).size(), 80u + 60u + 48u);
  EXPECT_TRUE(sample_faces(b, {}, 1.0).empty());
  // Samples lie on their face: zero distance to the mesh, inside the face's outline.
  const auto wall = sample_faces(b, {3}, 0.5);
  ASSERT_EQ(wall.size(), 16u * 12u);
  for (const auto& d : unsigned_distances(b, wall)) EXPECT_NEAR(d, 0.0, 1e-12);
  for (const auto& p : wall) {
    EXPECT_NEAR(p.x(), 10.0, 1e-12);
    EXPECT_TRUE(p.y() > 0 && p.y() < 8 && p.z() > 0 && p.z() < 6) << p.transpose();
  }
  // A non-convex roof: only the cell centres inside the L (64 of the 100 m² box).
  const auto l_roof = sample_faces(l_shape(), {1}, 1.0);
  EXPECT_EQ(l_roof.size(), 64u);
  for (const auto& p : l_roof) EXPECT_FALSE(p.x() > 4 && p.y() > 4) << p.transpose();
}

TEST(SampleFaces, AFaceSmallerThanTheSpacingGivesItsCentroid) {
  const auto s = sample_faces(unit_cube(), {1, 3}, 2.0);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_NEAR((s[0] - Vec3(0.5, 0.5, 1.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((s[1] - Vec3(1.0, 0.5, 0.5)).norm(), 0.0, 1e-12);
}
