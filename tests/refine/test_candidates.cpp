// Stage 5, selection: the candidate arrangement of the supporting planes inside the region.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "lodrefine/refine/candidates.h"
#include "lodrefine/refine/selection.h"
#include "support/candidate_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

TEST(Candidates, BoxArrangementHasNinePiecesPerPlane) {
  const auto planes = box_planes(10, 8, 6);
  const Region region = box_region(10, 8, 6);
  const CandidateSet cs = build_candidates(planes, region);
  ASSERT_EQ(cs.size(), 54);  // each plane section is cut by 4 perpendicular planes into 3x3
  double total = 0.0;
  for (int f = 0; f < cs.size(); ++f) total += area_of(cs, f);
  // Sections: planes x=const are (8+2*1.8)x(6+2*1.6) ... compare with the region's cross-sections.
  const double expect = 2 * (2 * region.half.y() * 2 * region.half.z()) +
                        2 * (2 * region.half.x() * 2 * region.half.z()) +
                        2 * (2 * region.half.x() * 2 * region.half.y());
  EXPECT_NEAR(total, expect, 1e-6);
  // Interior edges (not on the region boundary) are shared by exactly 4 faces (2 planes x 2 sides).
  for (const auto& e : cs.edges) {
    const auto [a, b] = cs.ends(e);
    bool on_box = false;
    for (const Plane& p : region.planes())
      on_box = on_box || (std::abs(p.distance(cs.vertices[a])) < 1e-6 && std::abs(p.distance(cs.vertices[b])) < 1e-6);
    if (on_box) EXPECT_EQ(e.size(), 1u);
    else EXPECT_EQ(e.size(), 4u);
  }
}

TEST(Candidates, NearAxisAlignedPlanesGiveFiniteVertices) {
  // Refitted planes carry normals like (1e-19, 1, 1e-17): the meets must stay on the box.
  auto planes = box_planes(10, 8, 6);
  planes[2].plane = Plane(Vec3(1e-19, -1, 3e-17), 1e-18);
  planes[5].plane = Plane(Vec3(2e-18, -1e-19, 1), -6);
  const Region region = box_region(10, 8, 6);
  const CandidateSet cs = build_candidates(planes, region);
  ASSERT_EQ(cs.size(), 54);
  for (const auto& v : cs.vertices) EXPECT_TRUE(region.contains(v, 1e-6)) << v.transpose();
}

// The candidates are the faces of a Surface_mesh: face f is candidate f with its plane in
// candidate_props::support; pieces of one plane share their edges (one component per plane), pieces of
// different planes never do (their edges meet only in the fans).
TEST(Candidates, LiveOnASurfaceMeshOneComponentPerPlane) {
  const CandidateSet cs = build_candidates(box_planes(10, 8, 6), box_region(10, 8, 6));
  ASSERT_EQ(int(cs.mesh.number_of_faces()), cs.size());
  ASSERT_TRUE(CGAL::is_valid_polygon_mesh(cs.mesh));
  const auto support = candidate_props::support.find(cs.mesh);
  ASSERT_TRUE(support.second);
  for (int f = 0; f < cs.size(); ++f) EXPECT_EQ(support.first[CandidateMesh::Face_index(f)], plane_of(cs, f));
  int shared = 0;
  for (auto e : cs.mesh.edges()) {
    const auto h = cs.mesh.halfedge(e);
    if (cs.mesh.is_border(e)) continue;
    ++shared;
    EXPECT_EQ(support.first[cs.mesh.face(h)], support.first[cs.mesh.face(cs.mesh.opposite(h))]);
  }
  // Each 3x3 plane section has 12 interior edges.
  EXPECT_EQ(shared, 6 * 12);
  // Every fan lists a halfedge of each face whose boundary runs along it: that halfedge runs
  // along the segment, and its face has the segment. Inside a component the two faces of a mesh
  // edge are in one fan, through the halfedge and its opposite.
  const auto point = candidate_props::point.get(cs.mesh);
  int opposite_pairs = 0;
  for (const auto& e : cs.edges) {
    const auto [ea, eb] = cs.ends(e);
    for (auto h : e) {
      const int f = cs.face(h);
      const int s = point[cs.mesh.source(h)], t = point[cs.mesh.target(h)];
      EXPECT_EQ(std::min(s, t), ea);
      EXPECT_EQ(std::max(s, t), eb);
      const auto c = cs.corners(f);
      bool has = false;
      for (std::size_t k = 0; k < c.size(); ++k) {
        const int a = c[k], b = c[(k + 1) % c.size()];
        has = has || (std::min(a, b) == ea && std::max(a, b) == eb);
      }
      EXPECT_TRUE(has) << "face " << f << " listed on edge " << ea << "-" << eb;
      opposite_pairs +=
          !cs.mesh.is_border(cs.mesh.opposite(h)) && std::count(e.begin(), e.end(), cs.mesh.opposite(h)) == 1;
    }
  }
  EXPECT_EQ(opposite_pairs, 2 * shared);
}

// Pruning the candidates a program fixes unselected: the box's six faces alone, each on its 4
// box edges with exactly one neighbour, and the program over them selects all six.
TEST(Candidates, KeptCandidatesAreTheSameProgram) {
  const double a = 10, b = 8, c = 6;
  const CandidateSet cs = build_candidates(box_planes(a, b, c), box_region(a, b, c));
  std::vector<char> keep(std::size_t(cs.size()), 0);
  for (std::size_t f = 0; f < keep.size(); ++f) keep[f] = inside_box(centroid_of(cs, f), a, b, c);
  CandidateSet k = kept_candidates(cs, keep);
  ASSERT_EQ(k.size(), 6);
  EXPECT_EQ(k.mesh.number_of_faces(), 6u);
  int box_edges = 0;
  for (const auto& e : k.edges) {
    if (e.size() == 2) ++box_edges;
    for (auto h : e) EXPECT_LT(k.face(h), 6);
  }
  EXPECT_EQ(box_edges, 12);
  std::vector<double> cost;
  for (int f = 0; f < k.size(); ++f) cost.push_back(-area_of(k, f));
  const SelectionResult r = select_faces(k, cost, std::vector<int>(k.edges.size(), 0), SelectionConfig{});
  ASSERT_TRUE(r.ok) << r.status_text();
  const std::vector<char> selected = selected_faces(k);
  EXPECT_EQ(std::count(selected.begin(), selected.end(), 1), 6);
  // The program's variables are face maps: a column for each of the six (none is fixed).
  const auto variable = candidate_props::variable.find(k.mesh);
  ASSERT_TRUE(variable.second);
  std::set<int> columns;
  for (auto f : k.mesh.faces()) columns.insert(variable.first[f]);
  EXPECT_EQ(columns, (std::set<int>{1, 2, 3, 4, 5, 6}));
}

namespace {

// A terrace of n gabled houses along x (6 m wide, 10 m deep), each with its own eaves and ridge
// height (so no two roof planes coincide or share an eave line): its supporting planes, the
// reach of each (its faces grown by `margin`, as the pipeline's plane_reach) and inside-ness.
struct Terrace {
  static constexpr double kWidth = 6.0, kDepth = 10.0, kMargin = 2.25;
  int n;
  double eave(int i) const { return 6.0 + 0.2 * i; }
  double ridge(int i) const { return 9.0 + 0.3 * i; }
  double roof_z(int i, double y) const {  // the roof over (., y) of house i
    const double half = 0.5 * kDepth, t = y < half ? y / half : (kDepth - y) / half;
    return eave(i) + (ridge(i) - eave(i)) * t;
  }
  bool inside(const Vec3& p) const {
    const double len = n * kWidth;
    if (p.x() <= 0 || p.x() >= len || p.y() <= 0 || p.y() >= kDepth || p.z() <= 0) return false;
    return p.z() < roof_z(std::min(n - 1, int(p.x() / kWidth)), p.y());
  }
  Region region() const { return Region::around({Vec3(0, 0, 0), Vec3(n * kWidth, kDepth, ridge(n - 1))}, 0.0, 1.0); }
  // Planes with the box of their faces (lo, hi).
  void add(std::vector<SupportPlane>& planes, std::vector<Region>& reach, const Plane& pl, Semantic sem, const Vec3& lo,
           const Vec3& hi) const {
    planes.push_back({pl, sem, false, int(planes.size())});
    Region r;
    r.center = 0.5 * (lo + hi);
    r.half = 0.5 * (hi - lo) + Vec3::Constant(kMargin);
    reach.push_back(r);
  }
  std::vector<SupportPlane> planes(std::vector<Region>& reach) const {
    std::vector<SupportPlane> p;
    const double len = n * kWidth, top = ridge(n - 1);
    add(p, reach, Plane(Vec3(0, -1, 0), 0), Semantic::Wall, Vec3(0, 0, 0), Vec3(len, 0, top));
    add(p, reach, Plane(Vec3(0, 1, 0), -kDepth), Semantic::Wall, Vec3(0, kDepth, 0), Vec3(len, kDepth, top));
    add(p, reach, Plane(Vec3(0, 0, -1), 0), Semantic::Ground, Vec3(0, 0, 0), Vec3(len, kDepth, 0));
    for (int i = 0; i <= n; ++i)  // end and party walls
      add(p, reach, Plane(Vec3(1, 0, 0), -i * kWidth), Semantic::Wall, Vec3(i * kWidth, 0, 0),
          Vec3(i * kWidth, kDepth, ridge(std::min(i, n - 1))));
    for (int i = 0; i < n; ++i) {
      const double half = 0.5 * kDepth, rise = ridge(i) - eave(i);
      const Vec3 a(i * kWidth, 0, eave(i)), b((i + 1) * kWidth, half, ridge(i)), c(i * kWidth, kDepth, eave(i));
      add(p, reach, Plane::through(a, Vec3(0, -rise, half).normalized()), Semantic::Roof, a, b);
      add(p, reach, Plane::through(c, Vec3(0, rise, half).normalized()), Semantic::Roof,
          Vec3(i * kWidth, half, eave(i)), Vec3((i + 1) * kWidth, kDepth, ridge(i)));
    }
    return p;
  }
  // The candidates on the terrace's surface: inside on one side of the face, outside on the other.
  std::vector<char> shell(const CandidateSet& cs) const {
    std::vector<char> on(std::size_t(cs.size()), 0);
    for (std::size_t f = 0; f < std::size_t(cs.size()); ++f) {
      const Vec3 c = centroid_of(cs, f), d = 1e-4 * cs.planes[plane_of(cs, f)].plane.n;
      on[f] = inside(c + d) != inside(c - d);
    }
    return on;
  }
  double surface_area() const {
    double a = n * kWidth * kDepth;  // ground
    for (int i = 0; i < n; ++i) {
      const double half = 0.5 * kDepth, rise = ridge(i) - eave(i);
      a += 2 * kWidth * std::hypot(half, rise);             // the two slopes
      a += 2 * kWidth * eave(i);                            // front and back walls
      const double gable = kDepth * eave(i) + half * rise;  // a gable's area
      if (i == 0) a += gable;
      if (i == n - 1) a += gable;
      if (i > 0) a += std::abs(gable - (kDepth * eave(i - 1) + half * (ridge(i - 1) - eave(i - 1))));
    }
    return a;
  }
};

}  // namespace

// Local sections: on a terrace every roof plane meets its neighbours' only, so the candidates
// grow far slower than over the whole region, where every plane cuts every other (cubic). The
// terrace's own surface stays a closed selection of candidates, with its exact area.
TEST(Candidates, LocalSectionsGrowLinearlyOnATerrace) {
  auto count = [](int n, bool local) {
    const Terrace t{n};
    std::vector<Region> reach;
    const auto planes = t.planes(reach);
    return build_candidates(planes, t.region(), local ? reach : std::vector<Region>{}).size();
  };
  // Measured: 274, 1462, 3942 pieces (the long front, back and ground planes still meet every
  // plane along them); over the whole region 568 -> 17354 from 4 to 16 houses.
  const std::size_t local4 = count(4, true), local16 = count(16, true), local32 = count(32, true);
  EXPECT_LT(local16, 6 * local4) << local4 << " -> " << local16;    // 4x the houses; cubic: 64x
  EXPECT_LT(local32, 3 * local16) << local16 << " -> " << local32;  // 2x the houses; cubic: 8x
  EXPECT_LT(local32, 125u * 32);
  EXPECT_GT(count(16, false), 10 * local16);  // the whole-region arrangement, for contrast

  for (int n : {1, 3, 8}) {
    const Terrace t{n};
    std::vector<Region> reach;
    const auto planes = t.planes(reach);
    const CandidateSet cs = build_candidates(planes, t.region(), reach);
    const std::vector<char> shell = t.shell(cs);
    EXPECT_TRUE(every_edge_used_0_or_2(cs, shell)) << n << " houses";
    double area = 0.0;
    for (std::size_t f = 0; f < shell.size(); ++f) area += shell[f] ? area_of(cs, f) : 0.0;
    EXPECT_NEAR(area, t.surface_area(), 1e-6) << n << " houses";
  }
}

// Beyond max_candidates the build stops and says so, with no candidates (the building is kept).
TEST(Candidates, StopsAtTheCap) {
  const Terrace t{8};
  std::vector<Region> reach;
  const auto planes = t.planes(reach);
  const CandidateSet all = build_candidates(planes, t.region(), reach);
  EXPECT_FALSE(all.capped);
  const CandidateSet cs = build_candidates(planes, t.region(), reach, all.size() / 2);
  EXPECT_TRUE(cs.capped);
  EXPECT_TRUE(cs.size() == 0);
  EXPECT_TRUE(cs.edges.empty());
  EXPECT_FALSE(build_candidates(planes, t.region(), reach, all.size()).capped);
}
