// The coarse model's errors (src/synth/perturb.cpp, internal to synth): the walls of a shell as
// the perturbations see them, facade lines moved by the options' shifts, the exporter's soup and
// its logged defects.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "support/synth_shape_fixtures.h"
#include "synth/perturb.h"

using namespace lodrefine;
using namespace lodrefine::synth;
using synth_fixtures::box_mesh;
using synth_fixtures::box_spec;

TEST(SynthPerturb, WallsOfABoxFaceOutwardWithTheirLengths) {
  const Mesh m = box_mesh();
  std::vector<WallInfo> walls = wall_infos(m);
  ASSERT_EQ(walls.size(), 4u);
  std::sort(walls.begin(), walls.end(), [](const WallInfo& a, const WallInfo& b) { return a.line < b.line; });
  const Vec2 normals[] = {{0, -1}, {1, 0}, {0, 1}, {-1, 0}};
  const Vec2 mids[] = {{5, 0}, {10, 3}, {5, 6}, {0, 3}};
  const double lengths[] = {10, 6, 10, 6};
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(walls[i].line, i);
    EXPECT_EQ(m.faces[std::size_t(walls[i].face)].source, i);
    EXPECT_NEAR((walls[i].n - normals[i]).norm(), 0.0, 1e-9) << i;
    EXPECT_NEAR((walls[i].mid - mids[i]).norm(), 0.0, 1e-9) << i;
    EXPECT_NEAR(walls[i].length, lengths[i], 1e-9) << i;
  }
}

TEST(SynthPerturb, MovedFacadesStayWithinTheOptionsShifts) {
  SynthOptions o;
  o.min_shift = 0.3, o.max_shift = 0.5, o.max_rotation_deg = 0.0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    Spec s = box_spec();
    const Mesh m = build_mesh(s);
    Rng r(seed);
    const std::vector<MovedWall> moved = move_facades(s, wall_infos(m), {0}, o, r);
    ASSERT_GE(moved.size(), 1u);
    ASSERT_LE(moved.size(), 3u);
    for (const MovedWall& w : moved) {
      EXPECT_GE(std::abs(w.offset), 0.3 - 1e-12) << seed;
      EXPECT_LE(std::abs(w.offset), 0.5 + 1e-12) << seed;
      EXPECT_DOUBLE_EQ(w.rotation_deg, 0.0);
      EXPECT_FALSE(w.truth_faces.empty());
    }
  }
}

TEST(SynthPerturb, SoupGivesEveryFaceItsOwnCorners) {
  const Mesh m = box_mesh();
  const Mesh soup = to_soup(m);
  ASSERT_EQ(soup.faces.size(), m.faces.size());
  std::size_t corners = 0;
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    ASSERT_EQ(soup.faces[f].v.size(), m.faces[f].v.size());
    EXPECT_EQ(soup.faces[f].sem, m.faces[f].sem);
    for (std::size_t i = 0; i < m.faces[f].v.size(); ++i) {
      EXPECT_EQ(soup.faces[f].v[i], int(corners + i));
      EXPECT_EQ(soup.vertices[std::size_t(soup.faces[f].v[i])], m.vertices[std::size_t(m.faces[f].v[i])]);
    }
    corners += m.faces[f].v.size();
  }
  EXPECT_EQ(soup.vertices.size(), corners);  // 6 faces x 4 corners
  EXPECT_EQ(corners, 24u);
}

TEST(SynthPerturb, DefectsAreLoggedAsMade) {
  int with_missing_ground = 0;
  for (std::uint64_t seed = 1; seed <= 30; ++seed) {
    Mesh soup = to_soup(box_mesh());
    Rng r(seed);
    const std::vector<std::string> defects = add_defects(soup, r);
    int grounds = 0;
    for (const Face& f : soup.faces) grounds += f.sem == Semantic::Ground;
    const bool missing = std::count(defects.begin(), defects.end(), "missing_ground") > 0;
    with_missing_ground += missing;
    EXPECT_EQ(grounds, missing ? 0 : 1) << seed;
    for (const std::string& d : defects) {
      if (d.rfind("duplicate_face:", 0) == 0) {
        const std::size_t f = std::stoul(d.substr(15));
        ASSERT_LT(f, soup.faces.size());
        EXPECT_EQ(soup.faces[f].sem, soup.faces.back().sem) << d;
      }
    }
  }
  EXPECT_GT(with_missing_ground, 0);
  EXPECT_LT(with_missing_ground, 30);
}
