// Stage 3: the candidate arrangement of the supporting planes inside the region.
#include <gtest/gtest.h>

#include "lodrefine/core/candidates.h"
#include "support/candidate_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

TEST(Candidates, BoxArrangementHasNinePiecesPerPlane) {
  const auto planes = box_planes(10, 8, 6);
  const Region region = box_region(10, 8, 6);
  const CandidateSet cs = build_candidates(planes, region);
  ASSERT_EQ(cs.faces.size(), 54u);  // each plane section is cut by 4 perpendicular planes into 3x3
  double total = 0.0;
  for (const auto& f : cs.faces) total += f.area;
  // Sections: planes x=const are (8+2*1.8)x(6+2*1.6) ... compare with the region's cross-sections.
  const double expect = 2 * (2 * region.half.y() * 2 * region.half.z()) + 2 * (2 * region.half.x() * 2 * region.half.z()) +
                        2 * (2 * region.half.x() * 2 * region.half.y());
  EXPECT_NEAR(total, expect, 1e-6);
  // Interior edges (not on the region boundary) are shared by exactly 4 faces (2 planes x 2 sides).
  for (const auto& e : cs.edges) {
    if (e.box_plane >= 0) EXPECT_EQ(e.faces.size(), 1u);
    else EXPECT_EQ(e.faces.size(), 4u);
  }
}

TEST(Candidates, NearAxisAlignedPlanesGiveFiniteVertices) {
  // Refitted planes carry normals like (1e-19, 1, 1e-17): the meets must stay on the box.
  auto planes = box_planes(10, 8, 6);
  planes[2].plane = Plane(Vec3(1e-19, -1, 3e-17), 1e-18);
  planes[5].plane = Plane(Vec3(2e-18, -1e-19, 1), -6);
  const Region region = box_region(10, 8, 6);
  const CandidateSet cs = build_candidates(planes, region);
  ASSERT_EQ(cs.faces.size(), 54u);
  for (const auto& v : cs.vertices) EXPECT_TRUE(region.contains(v, 1e-6)) << v.transpose();
}
