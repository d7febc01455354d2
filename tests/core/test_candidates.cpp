// Stage 3: the candidate arrangement of the supporting planes inside the region.
#include <gtest/gtest.h>

#include <algorithm>

#include "lodrefine/core/candidates.h"
#include "lodrefine/core/selection.h"
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
  const double expect = 2 * (2 * region.half.y() * 2 * region.half.z()) +
                        2 * (2 * region.half.x() * 2 * region.half.z()) +
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

// The candidates are the faces of a Surface_mesh: face f is candidate f with its plane in
// "f:support"; pieces of one plane share their edges (one component per plane), pieces of
// different planes never do (their edges meet only in the fans).
TEST(Candidates, LiveOnASurfaceMeshOneComponentPerPlane) {
  const CandidateSet cs = build_candidates(box_planes(10, 8, 6), box_region(10, 8, 6));
  ASSERT_EQ(cs.mesh.number_of_faces(), cs.faces.size());
  ASSERT_TRUE(CGAL::is_valid_polygon_mesh(cs.mesh));
  const auto support = cs.mesh.property_map<CandidateMesh::Face_index, int>("f:support");
  ASSERT_TRUE(support.second);
  for (int f = 0; f < int(cs.faces.size()); ++f)
    EXPECT_EQ(support.first[CandidateMesh::Face_index(f)], cs.faces[f].plane);
  int shared = 0;
  for (auto e : cs.mesh.edges()) {
    const auto h = cs.mesh.halfedge(e);
    if (cs.mesh.is_border(e)) continue;
    ++shared;
    EXPECT_EQ(support.first[cs.mesh.face(h)], support.first[cs.mesh.face(cs.mesh.opposite(h))]);
  }
  // Each 3x3 plane section has 12 interior edges.
  EXPECT_EQ(shared, 6 * 12);
  // Every fan lists each face whose boundary runs along it, and that face has the segment.
  for (const auto& e : cs.edges)
    for (int f : e.faces) {
      const auto c = cs.corners(f);
      bool has = false;
      for (std::size_t k = 0; k < c.size(); ++k) {
        const int a = c[k], b = c[(k + 1) % c.size()];
        has = has || (std::min(a, b) == e.a && std::max(a, b) == e.b);
      }
      EXPECT_TRUE(has) << "face " << f << " listed on edge " << e.a << "-" << e.b;
    }
}

// Pruning the candidates a program fixes unselected: the box's six faces alone, each on its 4
// box edges with exactly one neighbour, and the program over them selects all six.
TEST(Candidates, KeptCandidatesAreTheSameProgram) {
  const double a = 10, b = 8, c = 6;
  const CandidateSet cs = build_candidates(box_planes(a, b, c), box_region(a, b, c));
  std::vector<char> keep(cs.faces.size(), 0);
  for (std::size_t f = 0; f < keep.size(); ++f) keep[f] = inside_box(cs.faces[f].centroid, a, b, c);
  const CandidateSet k = kept_candidates(cs, keep);
  ASSERT_EQ(k.faces.size(), 6u);
  EXPECT_EQ(k.mesh.number_of_faces(), 6u);
  int box_edges = 0;
  for (const auto& e : k.edges) {
    if (e.faces.size() == 2) ++box_edges;
    for (int f : e.faces) EXPECT_LT(f, 6);
  }
  EXPECT_EQ(box_edges, 12);
  std::vector<double> cost;
  for (const auto& f : k.faces) cost.push_back(-f.area);
  const SelectionResult r = select_faces(k, cost, std::vector<int>(k.edges.size(), 0), Params{});
  ASSERT_TRUE(r.ok) << r.status_text();
  EXPECT_EQ(std::count(r.selected.begin(), r.selected.end(), 1), 6);
  EXPECT_EQ(r.column.size(), 6u);
}
