// The occupancy grid of a plane's scan points (occupancy.h): frames, marked cells, shares.
#include <gtest/gtest.h>

#include "refine/occupancy.h"

using namespace lodrefine;
using namespace lodrefine::detail;

TEST(Occupancy, FrameIsThePlanesBasisAtTheCentreProjected) {
  const Plane front = Plane::through({0, 0, 0}, {0, -1, 0});  // the wall y = 0, facing -y
  const Frame2 frame = frame_of(front, {5, 3, 3});
  EXPECT_NEAR((frame.o - Vec3(5, 0, 3)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((frame(Vec3(6, 0, 4)) - Vec2(1, 1)).norm(), 0.0, 1e-12);   // u along +x, v up
  EXPECT_NEAR((frame(Vec3(6, -2, 4)) - Vec2(1, 1)).norm(), 0.0, 1e-12);  // projected along the normal
  EXPECT_NEAR((frame.lifted(Vec2(1, 1)) - Vec3(6, 0, 4)).norm(), 0.0, 1e-12);
}

TEST(Occupancy, CellKeysOfNegativeIndicesAreDistinct) {
  EXPECT_NE(cell_key(-1, 0), cell_key(0, -1));
  EXPECT_NE(cell_key(-1, -1), cell_key(0, 0));
  EXPECT_NE(cell_key(1, 0), cell_key(0, 1));
  EXPECT_EQ(cell_key(-3, 7), cell_key(-3, 7));
}

TEST(Occupancy, APointMarksItsCellAndTwoAround) {
  const Frame2 frame{Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ()};
  CellSet cells;
  mark_scanned(cells, {{0.1, 0, 0.1}, {0.2, 0, 0.05}}, frame);  // both in cell (0, 0)
  EXPECT_EQ(cells.size(), 25u);                                 // 5 x 5
  mark_scanned(cells, {{0.3, 0, 0.1}}, frame);                  // cell (1, 0): one column more
  EXPECT_EQ(cells.size(), 30u);
  EXPECT_EQ(cells.count(cell_key(-2, -2)), 1u);
  EXPECT_EQ(cells.count(cell_key(3, 2)), 1u);
  EXPECT_EQ(cells.count(cell_key(4, 0)), 0u);
}

TEST(Occupancy, ScannedShareCountsCellCentresInThePolygon) {
  const Frame2 frame{Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ()};
  CellSet cells;
  mark_scanned(cells, {{0.1, 0, 0.1}}, frame);  // cells -2..2 x -2..2
  // The 1 m square from the origin holds 4 x 4 cell centres, 3 x 3 of them marked.
  const std::vector<Vec2> square{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  EXPECT_DOUBLE_EQ(scanned_share(square, cells), 9.0 / 16.0);
  // A sliver holding no cell centre: its centroid's cell decides.
  EXPECT_DOUBLE_EQ(scanned_share({{0.01, 0.01}, {0.1, 0.01}, {0.01, 0.1}}, cells), 1.0);
  EXPECT_DOUBLE_EQ(scanned_share({{2.01, 2.01}, {2.1, 2.01}, {2.01, 2.1}}, cells), 0.0);
  EXPECT_DOUBLE_EQ(scanned_share(square, CellSet{}), 0.0);
  EXPECT_DOUBLE_EQ(scanned_share({}, cells), 0.0);
}
