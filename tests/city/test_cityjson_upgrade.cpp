// CityJSON 1.0 / 1.1 made 2.0 as the city refine writes it (src/city/cityjson_upgrade.cpp,
// internal to city): "lod" numbers become strings, GenericCityObject core, the CRS a URL, a point
// of contact's address an object, and a transform made for a file without one; end to end, a 1.1
// city refined comes out as a schema-valid 2.0 file.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "city/cityjson_upgrade.h"
#include "lodrefine/base/files.h"
#include "lodrefine/city/cityfile.h"
#include "lodrefine/formats/ply.h"
#include "support/city_fixtures.h"
#include "support/schema_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::city_fixtures;

namespace {

using schema_fixtures::schema_verdict;

}  // namespace

TEST(CityJsonUpgrade, LodNumbersBecomeStringsAndGenericObjectsCore) {
  json objects = json::parse(R"({
    "a": {"type": "Building", "geometry": [{"type": "Solid", "lod": 2.2}, {"type": "MultiSurface", "lod": 1},
                                          {"type": "MultiSurface", "lod": "1.3"}]},
    "b": {"type": "+GenericCityObject", "geometry": [{"type": "MultiSurface", "lod": 0}]},
    "c": {"type": "+NoiseBarrier"},
    "d": 5
  })");
  upgrade_objects(objects);
  EXPECT_EQ(objects["a"]["geometry"][0]["lod"], "2.2");
  EXPECT_EQ(objects["a"]["geometry"][1]["lod"], "1");
  EXPECT_EQ(objects["a"]["geometry"][2]["lod"], "1.3");
  EXPECT_EQ(objects["b"]["type"], "GenericCityObject");
  EXPECT_EQ(objects["b"]["geometry"][0]["lod"], "0");
  EXPECT_EQ(objects["c"]["type"], "+NoiseBarrier");  // other extensions stay theirs
  EXPECT_EQ(objects["d"], 5);
}

TEST(CityJsonUpgrade, HeaderCrsBecomesAUrlAndTheAddressAnObject) {
  json doc = {{"metadata",
               {{"referenceSystem", "urn:ogc:def:crs:EPSG::7415"},
                {"pointOfContact", {{"contactName", "someone"}, {"address", "Julianalaan 134, Delft"}}}}}};
  upgrade_header(doc);
  EXPECT_EQ(doc["metadata"]["referenceSystem"], "https://www.opengis.net/def/crs/EPSG/0/7415");
  EXPECT_EQ(doc["metadata"]["pointOfContact"]["address"], json({{"addressLine", "Julianalaan 134, Delft"}}));
  EXPECT_EQ(doc["metadata"]["pointOfContact"]["contactName"], "someone");
  json not_an_object = {{"metadata", "text"}};
  upgrade_header(not_an_object);
  EXPECT_FALSE(not_an_object.contains("metadata"));
}

TEST(CityJsonUpgrade, ATransformIsMadeAtATenthOfAMillimetre) {
  json doc = {{"vertices", {{93000.25, 436000.5, -1.5}, {93010.0001, 436001.0, 7.25}}}};
  ensure_transform(doc);
  EXPECT_EQ(doc["transform"]["scale"], json({0.0001, 0.0001, 0.0001}));
  EXPECT_EQ(doc["transform"]["translate"], json({93000.0, 436000.0, -2.0}));  // the box's floor
  EXPECT_EQ(doc["vertices"][0], json({2500, 5000, 5000}));
  EXPECT_EQ(doc["vertices"][1], json({100001, 10000, 92500}));
  json has = {{"transform", {{"scale", {1, 1, 1}}}}, {"vertices", {{1.5, 2, 3}}}};
  ensure_transform(has);
  EXPECT_EQ(has["vertices"][0], json({1.5, 2, 3}));  // a file with a transform is left alone
}

TEST(CityFile, CityJson1xUpgradedTo2) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs = synth_street({BuildingType::Gable, BuildingType::Flat}, 41, 6000, 1, cloud);
  json in = synth_city(bs, Vec3(93000, 436000, 0));
  in["version"] = "1.1";
  in["metadata"]["referenceSystem"] = "urn:ogc:def:crs:EPSG::7415";
  in["metadata"]["pointOfContact"] = {
      {"contactName", "someone"}, {"emailAddress", "someone@example.org"}, {"address", "Julianalaan 134, Delft"}};
  for (auto& [id, obj] : in["CityObjects"].items()) obj["geometry"][1]["lod"] = 2.2;  // a number, as 1.0 wrote it
  write_file_atomic(dir + "/city.json", in.dump());
  write_ply(dir + "/cloud.ply", cloud);
  const CityRefineSummary s =
      refine_city(dir + "/city.json", {dir + "/cloud.ply"}, dir + "/out.city.json", RefineConfig{}, {});
  EXPECT_EQ(s.input_format, "CityJSON 1.1");
  EXPECT_EQ(s.untouched, 1);
  const json out = load(dir + "/out.city.json");
  EXPECT_EQ(out["version"], "2.0");
  EXPECT_EQ(out["metadata"]["referenceSystem"], "https://www.opengis.net/def/crs/EPSG/0/7415");
  EXPECT_EQ(out["metadata"]["pointOfContact"]["address"]["addressLine"], "Julianalaan 134, Delft");
  for (const auto& [id, obj] : out["CityObjects"].items()) EXPECT_EQ(obj["geometry"][1]["lod"], "2.2") << id;
  const std::string verdict = schema_verdict(dir + "/out.city.json");
  if (!verdict.empty()) {
    EXPECT_EQ(verdict, "valid");
  }
}
