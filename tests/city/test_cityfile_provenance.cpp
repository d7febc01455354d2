// A refined building's CityJSON says where each semantic surface comes from ("lodrefine_source",
// "lodrefine_coverage" on the semantic surface objects; cityfile.h's cityjson_solid).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "lodrefine/city/cityfile.h"

using namespace lodrefine;
using json = nlohmann::ordered_json;

// One surface object per semantic, source and coverage (in hundredths); faces without a source
// (a model as read) keep the plain object, faces of no semantic a null value.
TEST(CityFileProvenance, SemanticSurfacesCarrySourceAndCoverage) {
  Mesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  auto face = [](Semantic sem, Provenance p, double coverage = 0.0) {
    Face f;
    f.v = {0, 1, 2, 3};
    f.sem = sem;
    f.provenance = p;
    f.coverage = coverage;
    return f;
  };
  m.faces = {face(Semantic::Wall, Provenance::Scan, 0.857), face(Semantic::Wall, Provenance::Scan, 0.8551),
             face(Semantic::Wall, Provenance::Scan, 0.5),   face(Semantic::Roof, Provenance::Model),
             face(Semantic::Wall, Provenance::Added),       face(Semantic::Wall, Provenance::None),
             face(Semantic::Other, Provenance::Model)};
  json vertices = json::array();
  const json g = cityjson_solid(m, "2.2", Vec3::Constant(0.001), Vec3::Zero(), vertices);
  const json& surfaces = g["semantics"]["surfaces"];
  ASSERT_EQ(surfaces.size(), 5u) << surfaces.dump();
  EXPECT_EQ(surfaces[0], json({{"type", "WallSurface"}, {"lodrefine_source", "scan"}, {"lodrefine_coverage", 0.86}}));
  EXPECT_EQ(surfaces[1], json({{"type", "WallSurface"}, {"lodrefine_source", "scan"}, {"lodrefine_coverage", 0.5}}));
  EXPECT_EQ(surfaces[2], json({{"type", "RoofSurface"}, {"lodrefine_source", "model"}}));
  EXPECT_EQ(surfaces[3], json({{"type", "WallSurface"}, {"lodrefine_source", "added"}}));
  EXPECT_EQ(surfaces[4], json({{"type", "WallSurface"}}));
  EXPECT_EQ(g["semantics"]["values"], json::parse("[[0, 0, 1, 2, 3, 4, null]]"));
}
