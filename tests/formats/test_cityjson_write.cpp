// CityJSON geometry written from a mesh (formats/cityjson_write.h): vertices quantised by the
// document's transform and appended after those already there, boundaries as a Solid of one
// shell or a MultiSurface, one semantic value per face. The formats library alone writes it.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "lodrefine/formats/cityjson_write.h"

using namespace lodrefine;
using json = nlohmann::ordered_json;

namespace {

// A unit square wall and a triangle roof sharing two vertices.
Mesh two_faces() {
  Mesh m;
  m.vertices = {{10.0004, 20, 0}, {11, 20, 0}, {11, 20, 1}, {10, 20, 1}, {10.5, 20.5, 1.5}};
  Face wall, roof;
  wall.v = {0, 1, 2, 3};
  wall.sem = Semantic::Wall;
  roof.v = {3, 2, 4};
  roof.sem = Semantic::Roof;
  m.faces = {wall, roof};
  return m;
}

}  // namespace

TEST(CityJsonWrite, SolidQuantisesAndAppendsVertices) {
  json vertices = json::array({json::array({0, 0, 0})});  // one vertex already in the document
  const json g = cityjson_solid(two_faces(), "2.2", Vec3::Constant(0.001), Vec3(10, 20, 0), vertices);
  ASSERT_EQ(vertices.size(), 6u);
  EXPECT_EQ(vertices[1], json::array({0, 0, 0}));  // 10.0004 m rounds to the millimetre grid
  EXPECT_EQ(vertices[5], json::array({500, 500, 1500}));
  EXPECT_EQ(g["type"], "Solid");
  EXPECT_EQ(g["lod"], "2.2");
  EXPECT_EQ(g["boundaries"], json::parse("[[[[1, 2, 3, 4]], [[4, 3, 5]]]]"));
  EXPECT_EQ(g["semantics"]["surfaces"], json::parse(R"([{"type": "WallSurface"}, {"type": "RoofSurface"}])"));
  EXPECT_EQ(g["semantics"]["values"], json::parse("[[0, 1]]"));
}

TEST(CityJsonWrite, MultiSurfaceHasOneLevelLess) {
  json vertices = json::array();
  const json g = cityjson_multisurface(two_faces(), "2", Vec3::Constant(0.01), Vec3::Zero(), vertices);
  EXPECT_EQ(vertices[0], json::array({1000, 2000, 0}));
  EXPECT_EQ(g["type"], "MultiSurface");
  EXPECT_EQ(g["boundaries"], json::parse("[[[0, 1, 2, 3]], [[3, 2, 4]]]"));
  EXPECT_EQ(g["semantics"]["values"], json::parse("[0, 1]"));
}
