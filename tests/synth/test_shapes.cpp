// The generator's building shapes (src/synth/shapes.h, internal to synth): footprint lines,
// roof planes, crossing segments, and the specs drawn for each building type.
#include <gtest/gtest.h>

#include "synth/shapes.h"

using namespace lodrefine;
using namespace lodrefine::synth;

TEST(SynthShapes, LinesAreAPointAndAUnitDirection) {
  Spec s;
  EXPECT_EQ(add_line(s, Vec2(1, 1), Vec2(4, 5)), 0);
  ASSERT_EQ(s.lines.size(), 1u);
  EXPECT_EQ(s.lines[0].p, Vec2(1, 1));
  EXPECT_NEAR((s.lines[0].d - Vec2(0.6, 0.8)).norm(), 0.0, 1e-12);
  // A rectangle's lines counter-clockwise from its bottom edge, after those already there.
  const std::vector<int> r = rect_lines(s, 0, 0, 10, 6);
  EXPECT_EQ(r, (std::vector<int>{1, 2, 3, 4}));
  EXPECT_NEAR((s.lines[1].d - Vec2(1, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((s.lines[2].d - Vec2(0, 1)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((s.lines[3].d - Vec2(-1, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((s.lines[4].d - Vec2(0, -1)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(s.lines[3].p.y(), 6.0, 1e-12);
}

TEST(SynthShapes, RoofPlanesGiveTheirHeights) {
  EXPECT_DOUBLE_EQ(flat_roof(7.5).z(Vec2(100, -3)), 7.5);
  const RoofPlane r = sloped_roof(Vec2(2, 0), Vec2(0, 1), 5.0, 0.5);  // rising 0.5 m per m in +y
  EXPECT_NEAR(r.z(Vec2(2, 0)), 5.0, 1e-12);
  EXPECT_NEAR(r.z(Vec2(9, 0)), 5.0, 1e-12);  // level along the eave
  EXPECT_NEAR(r.z(Vec2(2, 4)), 7.0, 1e-12);
  EXPECT_NEAR(r.z(Vec2(2, -2)), 4.0, 1e-12);
}

TEST(SynthShapes, SegmentsCross) {
  EXPECT_TRUE(segments_cross(Vec2(0, 0), Vec2(2, 2), Vec2(0, 2), Vec2(2, 0)));
  EXPECT_FALSE(segments_cross(Vec2(0, 0), Vec2(1, 0), Vec2(0, 1), Vec2(1, 1)));  // parallel
  EXPECT_FALSE(segments_cross(Vec2(0, 0), Vec2(1, 1), Vec2(3, 0), Vec2(2, 5)));  // apart
}

TEST(SynthShapes, EveryTypesSpecStandsOnItsGround) {
  for (const BuildingType t : all_building_types()) {
    Rng r(11);
    const Spec s = make_spec(t, r, 2.5);
    SCOPED_TRACE(building_type_name(t));
    EXPECT_DOUBLE_EQ(s.z0, 2.5);
    ASSERT_FALSE(s.parts.empty());
    for (const Part& p : s.parts) {
      EXPECT_GE(p.lines.size(), 3u);
      EXPECT_FALSE(p.roof.empty());
      for (int l : p.lines) EXPECT_LT(std::size_t(l), s.lines.size());
    }
    // The street-facade types name their street and the generalised front; the others neither.
    EXPECT_EQ(!s.street.empty(), street_facade_type(t));
    EXPECT_EQ(s.coarse_front >= 0, street_facade_type(t));
    EXPECT_EQ(!s.generalised.empty(), street_facade_type(t));
  }
}
