// The generator's closed shell of a spec (src/synth/shell.cpp, build_mesh in shapes.h): outward
// faces, a wall per footprint line with its line as source, roofs as the planes' lower envelope,
// and a spec that folds refused.
#include <gtest/gtest.h>

#include "lodrefine/base/geometry.h"
#include "lodrefine/core/validate.h"
#include "support/synth_shape_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::synth;
using synth_fixtures::box_spec;

namespace {

double volume(const Mesh& m) {
  double v = 0.0;
  for (const Face& f : m.faces)
    for (std::size_t i = 1; i + 1 < f.v.size(); ++i)
      v += m.vertices[std::size_t(f.v[0])].dot(
          m.vertices[std::size_t(f.v[i])].cross(m.vertices[std::size_t(f.v[i + 1])]));
  return v / 6.0;
}

int count(const Mesh& m, Semantic s) {
  int n = 0;
  for (const Face& f : m.faces) n += f.sem == s;
  return n;
}

}  // namespace

TEST(SynthShell, FlatBoxIsSixOutwardFaces) {
  const Mesh m = build_mesh(box_spec({flat_roof(5.0)}));
  ASSERT_EQ(m.faces.size(), 6u);
  EXPECT_EQ(count(m, Semantic::Wall), 4);
  EXPECT_EQ(count(m, Semantic::Roof), 1);
  EXPECT_EQ(count(m, Semantic::Ground), 1);
  EXPECT_EQ(m.vertices.size(), 8u);  // shared vertices
  EXPECT_NEAR(volume(m), 300.0, 1e-9);
  std::vector<int> sources;
  for (const Face& f : m.faces)
    if (f.sem == Semantic::Wall) sources.push_back(f.source);
    else EXPECT_EQ(f.source, -1);
  std::sort(sources.begin(), sources.end());
  EXPECT_EQ(sources, (std::vector<int>{0, 1, 2, 3}));
  EXPECT_TRUE(validate_mesh(m, 0.01).valid()) << validate_mesh(m, 0.01).problem;
}

TEST(SynthShell, GableIsTheLowerEnvelopeOfItsRoofPlanes) {
  const double k = 2.0 / 3.0;  // 2 m up over 3 m: ridge at y = 3, z = 7
  const Mesh m =
      build_mesh(box_spec({sloped_roof(Vec2(0, 0), Vec2(0, 1), 5.0, k), sloped_roof(Vec2(0, 6), Vec2(0, -1), 5.0, k)}));
  EXPECT_EQ(count(m, Semantic::Roof), 2);
  EXPECT_EQ(count(m, Semantic::Wall), 4);
  EXPECT_NEAR(volume(m), 300.0 + 10.0 * 6.0 * 2.0 / 2.0, 1e-9);
  double top = 0.0;
  for (const Vec3& v : m.vertices) top = std::max(top, v.z());
  EXPECT_NEAR(top, 7.0, 1e-9);
  EXPECT_TRUE(validate_mesh(m, 0.01).valid()) << validate_mesh(m, 0.01).problem;
}

TEST(SynthShell, ASpecThatFoldsIsAShapeError) {
  EXPECT_THROW(build_mesh(box_spec({flat_roof(0.3)})), ShapeError);  // roof within 0.5 m of the ground
  Spec crossed;                                                      // a bow-tie footprint
  Part p;
  p.lines = {add_line(crossed, Vec2(0, 0), Vec2(1, 0)), add_line(crossed, Vec2(10, 0), Vec2(0, 1)),
             add_line(crossed, Vec2(0, 6), Vec2(1, -1)), add_line(crossed, Vec2(10, 6), Vec2(-1, -1))};
  p.roof = {flat_roof(5.0)};
  crossed.parts = {p};
  EXPECT_THROW(build_mesh(crossed), ShapeError);
}
