#include <gtest/gtest.h>

#include <vector>

#include "lodrefine/base/topology.h"

using namespace lodrefine;

TEST(Topology, DisjointSetsUniteKeepsTheSecondRoot) {
  DisjointSets s(6);
  s.unite(0, 1);  // 0 under 1
  s.unite(2, 3);
  s.unite(1, 3);  // {0,1} under 3
  EXPECT_EQ(s.find(0), 3);
  EXPECT_EQ(s.find(1), 3);
  EXPECT_EQ(s.find(2), 3);
  EXPECT_EQ(s.find(3), 3);
  EXPECT_EQ(s.find(4), 4);
  EXPECT_EQ(s.find(5), 5);
}

TEST(Topology, DisjointSetsLinkTakesTheChosenRoot) {
  DisjointSets s(4);
  s.link(3, 0);  // 3 under 0, not the other way round
  EXPECT_EQ(s.find(3), 0);
  s.link(s.find(1), s.find(3));
  EXPECT_EQ(s.find(1), 0);
  EXPECT_EQ(s.find(2), 2);
}

TEST(Topology, DropRepeats) {
  std::vector<int> v{1, 1, 2, 3, 3, 1};
  drop_repeats(v);
  EXPECT_EQ(v, (std::vector<int>{1, 2, 3}));
  v = {1, 2, 2, 1, 1};
  drop_repeats(v);
  EXPECT_EQ(v, (std::vector<int>{1, 2}));
  v = {4, 4, 4};
  drop_repeats(v);
  EXPECT_EQ(v, (std::vector<int>{4}));
  v = {1, 2, 1, 2};  // no consecutive repeat, last differs from first: unchanged
  drop_repeats(v);
  EXPECT_EQ(v, (std::vector<int>{1, 2, 1, 2}));
  v.clear();
  drop_repeats(v);
  EXPECT_TRUE(v.empty());
}

TEST(Topology, InsideSegmentParameterAndDistance) {
  const Vec3 a(0, 0, 0), b(4, 0, 0);
  const auto t = inside_segment(a, b, Vec3(1, 0.25, 0), SegmentRule{0.5});
  ASSERT_TRUE(t.has_value());
  EXPECT_DOUBLE_EQ(*t, 0.25);
  // Exactly 0.5 off the line: inside with <=, outside with <.
  EXPECT_TRUE(inside_segment(a, b, Vec3(1, 0.5, 0), SegmentRule{0.5, false}).has_value());
  EXPECT_FALSE(inside_segment(a, b, Vec3(1, 0.5, 0), SegmentRule{0.5, true}).has_value());
  // The ends and beyond never count; t margins shrink the open interval.
  EXPECT_FALSE(inside_segment(a, b, a, SegmentRule{0.5}).has_value());
  EXPECT_FALSE(inside_segment(a, b, b, SegmentRule{0.5}).has_value());
  EXPECT_FALSE(inside_segment(a, b, Vec3(5, 0, 0), SegmentRule{0.5}).has_value());
  EXPECT_FALSE(inside_segment(a, b, Vec3(1, 0, 0), SegmentRule{0.5, false, 0.25}).has_value());  // t = 0.25
  EXPECT_TRUE(inside_segment(a, b, Vec3(1, 0, 0), SegmentRule{0.5, false, 0.125}).has_value());
  // End clearance: within it of an end (inclusive) is excluded.
  EXPECT_FALSE(inside_segment(a, b, Vec3(1, 0, 0), SegmentRule{0.5, false, 0.0, 1.0}).has_value());
  EXPECT_TRUE(inside_segment(a, b, Vec3(1.5, 0, 0), SegmentRule{0.5, false, 0.0, 1.0}).has_value());
  // A zero-length segment holds nothing.
  EXPECT_FALSE(inside_segment(a, a, Vec3(0, 0, 0), SegmentRule{0.5}).has_value());
}

TEST(Topology, VerticesOnSegmentOrderAndExclusions) {
  const std::vector<Vec3> V = {
      {0, 0, 0},    // 0: a
      {4, 0, 0},    // 1: b
      {3, 0, 0},    // 2: t = 0.75
      {1, 0, 0},    // 3: t = 0.25
      {2, 0.1, 0},  // 4: t = 0.5, 0.1 off
      {2, 0, 0},    // 5: t = 0.5, on the line (tie with 4: index order)
      {2, 1, 0},    // 6: too far off
      {0, 0, 0},    // 7: a's position under another index: t = 0
      {5, 0, 0},    // 8: beyond b
  };
  const SegmentRule rule{0.2};
  EXPECT_EQ(vertices_on_segment(V, 0, 1, rule), (std::vector<int>{3, 4, 5, 2}));
  EXPECT_EQ(vertices_on_segment(V, 1, 0, rule), (std::vector<int>{2, 4, 5, 3}));  // from b to a
  const std::vector<int> candidates{2, 3, 6, 8};
  EXPECT_EQ(vertices_on_segment(V, 0, 1, rule, &candidates), (std::vector<int>{3, 2}));
  const std::vector<int> exclude{3, 5};
  EXPECT_EQ(vertices_on_segment(V, 0, 1, rule, nullptr, &exclude), (std::vector<int>{4, 2}));
  EXPECT_EQ(vertices_on_segment(V, 0, 1, SegmentRule{0.05}), (std::vector<int>{3, 5, 2}));
  EXPECT_EQ(vertices_on_segment(V, 0, 1, SegmentRule{0.2, false, 0.0, 1.0}), (std::vector<int>{4, 5}));
}

TEST(Topology, GridKeysAndHash) {
  const PointGrid grid(0.5);
  EXPECT_EQ(grid.key(Vec3(-0.25, 0.25, 1.0)), (GridKey{-1, 0, 2}));
  EXPECT_EQ(grid.key(Vec3(0.0, -0.5, 0.75)), (GridKey{0, -1, 1}));
  // Unsigned products: defined (wrapping) for any key, equal to the plain products for small ones.
  EXPECT_EQ(GridKeyHash{}({1, 2, 3}), std::size_t((73856093ull) ^ (2 * 19349663ull) ^ (3 * 83492791ull)));
  const GridKey huge{1LL << 60, -(1LL << 60), 7};
  EXPECT_EQ(GridKeyHash{}(huge), std::size_t((std::uint64_t(1) << 60) * 73856093ull ^
                                             std::uint64_t(-(1LL << 60)) * 19349663ull ^ 7 * 83492791ull));
}

TEST(Topology, GridVisitsTheNeighbouringCellsOnly) {
  PointGrid grid(1.0);
  grid.insert(Vec3(0.5, 0.5, 0.5), 0);
  grid.insert(Vec3(1.5, 0.5, 0.5), 1);     // next cell in x
  grid.insert(Vec3(-0.5, -0.5, -0.5), 2);  // diagonal neighbour
  grid.insert(Vec3(2.5, 0.5, 0.5), 3);     // two cells away
  grid.insert(Vec3(0.25, 0.25, 0.25), 4);  // same cell as 0, inserted later
  std::vector<int> seen;
  EXPECT_FALSE(grid.visit_near(Vec3(0.9, 0.1, 0.1), [&](int id) {
    seen.push_back(id);
    return false;
  }));
  EXPECT_EQ(seen, (std::vector<int>{2, 0, 4, 1}));  // x, then y, then z from -1; insertion order
  seen.clear();
  EXPECT_TRUE(grid.visit_near(Vec3(0.9, 0.1, 0.1), [&](int id) {
    seen.push_back(id);
    return id == 0;
  }));
  EXPECT_EQ(seen, (std::vector<int>{2, 0}));
}

TEST(Topology, WelderAcrossCellBoundaries) {
  PointWelder w(0.25);  // cells of 1.0
  EXPECT_EQ(w.add(Vec3(0.875, 0, 0)), 0);
  EXPECT_EQ(w.add(Vec3(1.125, 0, 0)), 0);        // next cell in x, exactly 0.25 away: welded
  EXPECT_EQ(w.add(Vec3(1.1875, 0.0625, 0)), 1);  // 0.319 away: a new point
  EXPECT_EQ(w.add(Vec3(-0.0625, 0, 0)), 2);      // cell -1, 0.94 from point 0
  EXPECT_EQ(w.add(Vec3(0.0625, 0, 0)), 2);       // cell 0, 0.125 from point 2 in cell -1
  EXPECT_EQ(w.add(Vec3(0.0625, 0, 0.3125)), 3);  // 0.337 from point 2: outside
  EXPECT_EQ(w.add(Vec3(0, 0, -0.1875)), 2);      // cell (0, 0, -1), 0.198 from point 2 in (-1, 0, 0)
  EXPECT_EQ(w.add(Vec3(0.0625, 0, -0.25)), 4);   // 0.280 from point 2: outside
  ASSERT_EQ(w.points().size(), 5u);
  EXPECT_EQ(w.points()[0], Vec3(0.875, 0, 0));  // a cluster keeps its first point
  EXPECT_EQ(w.points()[2], Vec3(-0.0625, 0, 0));
}

TEST(Topology, EdgeUsesForwardFlags) {
  const std::vector<Face> faces = {
      {{0, 1, 2}, Semantic::Other, -1},
      {{2, 1, 3}, Semantic::Other, -1},
      {{3, 3, 1, 4}, Semantic::Other, -1},  // a repeated vertex makes no edge
  };
  const EdgeUses uses = edge_uses(faces);
  ASSERT_EQ(uses.size(), 7u);
  EXPECT_EQ(uses.count({3, 3}), 0u);
  const auto& e01 = uses.at({0, 1});
  ASSERT_EQ(e01.size(), 1u);
  EXPECT_EQ(e01[0].face, 0);
  EXPECT_TRUE(e01[0].forward);
  const auto& e12 = uses.at({1, 2});
  ASSERT_EQ(e12.size(), 2u);
  EXPECT_EQ(e12[0].face, 0);
  EXPECT_TRUE(e12[0].forward);  // 1 -> 2
  EXPECT_EQ(e12[1].face, 1);
  EXPECT_FALSE(e12[1].forward);              // 2 -> 1
  EXPECT_FALSE(uses.at({0, 2})[0].forward);  // face 0 closes 2 -> 0
  const auto& e13 = uses.at({1, 3});
  ASSERT_EQ(e13.size(), 2u);
  EXPECT_EQ(e13[0].face, 1);
  EXPECT_TRUE(e13[0].forward);
  EXPECT_EQ(e13[1].face, 2);
  EXPECT_FALSE(e13[1].forward);

  const EdgeUses some = edge_uses(faces, {1});
  ASSERT_EQ(some.size(), 3u);
  for (const auto& [e, u] : some) {
    ASSERT_EQ(u.size(), 1u);
    EXPECT_EQ(u[0].face, 1);
  }
  EXPECT_EQ(edge_key(5, 2), std::make_pair(2, 5));
}

TEST(Topology, ComponentsCountEdgeConnectedFaces) {
  const std::vector<Face> faces = {
      {{0, 1, 2}, Semantic::Other, -1},
      {{2, 1, 3}, Semantic::Other, -1},  // shares edge 1-2 with face 0
      {{3, 4, 5}, Semantic::Other, -1},  // touches face 1 at vertex 3 only
      {{6, 7, 8}, Semantic::Other, -1},
  };
  const EdgeUses uses = edge_uses(faces);
  EXPECT_EQ(count_components(faces.size(), uses), 3);
  EXPECT_EQ(count_components(5, uses), 4);  // a face with no edges is a component of its own
  EXPECT_EQ(count_components(0, EdgeUses{}), 0);
}
