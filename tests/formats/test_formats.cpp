// Files in the wrong place or of the wrong kind: one clear line naming what the file is, and
// a cloud of another CRS or tile called out as such.
#include <gtest/gtest.h>

#include "support/cli_fixtures.h"

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "lodrefine/formats/las.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/formats/ply.h"
#include "lodrefine/synth/synth.h"

using namespace lodrefine;
namespace fs = std::filesystem;

namespace {

using cli_fixtures::Cli;
using cli_fixtures::run_cli;
using cli_fixtures::slurp;

std::string test_dir() { return cli_fixtures::test_dir("lodrefine_formats"); }

// One line on stderr, "lodrefine: error: ..." containing `fault`, and a non-zero exit.
void expect_error(const Cli& r, const std::string& fault) {
  EXPECT_NE(r.exit, 0);
  EXPECT_EQ(r.err.rfind("lodrefine: error: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(fault), std::string::npos) << r.err;
}

const char* kLod1CityJson =
    R"({"type":"CityJSON","version":"2.0","transform":{"scale":[0.001,0.001,0.001],"translate":[0,0,0]},
"CityObjects":{"b1":{"type":"Building","geometry":[{"type":"Solid","lod":"1.2","boundaries":[[[[0,1,2,3]],[[4,5,6,7]]]]}]}},
"vertices":[[0,0,0],[1000,0,0],[1000,1000,0],[0,1000,0],[0,0,3000],[1000,0,3000],[1000,1000,3000],[0,1000,3000]]})";

}  // namespace

TEST(Formats, WrongKindOfFileSaysWhatItIs) {
  const std::string dir = test_dir();
  const SynthBuilding b = make_building(BuildingType::Flat, 1, {});
  write_obj(dir + "/m.obj", b.coarse);
  write_ply(dir + "/c.ply", b.cloud);
  write_las(dir + "/c.las", b.cloud, {}, LasWriteOptions{});
  std::ofstream(dir + "/city.gml")
      << "<?xml version=\"1.0\"?>\n<CityModel xmlns=\"http://www.opengis.net/citygml/2.0\"/>\n";
  std::ofstream(dir + "/lod1.city.json") << kLod1CityJson;
  std::ofstream(dir + "/other.json") << "{\"type\": \"FeatureCollection\", \"features\": []}";
  const std::string out = " --out " + dir + "/r.obj";
  expect_error(
      run_cli("eval --original " + dir + "/city.gml --refined " + dir + "/m.obj --cloud " + dir + "/c.ply", dir),
      "city.gml: not an OBJ model: the file is XML (a CityGML model?)");
  // A city file as the model is the city workflow; one without LoD 2 buildings is an error.
  expect_error(
      run_cli("refine --model " + dir + "/city.gml --cloud " + dir + "/c.ply --out " + dir + "/r.city.json", dir),
      "city.gml: no Building/BuildingPart with an LoD 2.x geometry");
  expect_error(
      run_cli("refine --model " + dir + "/lod1.city.json --cloud " + dir + "/c.ply --out " + dir + "/r.city.json", dir),
      "lod1.city.json: no Building/BuildingPart with an LoD 2.x geometry (1 building object(s) without one); nothing "
      "to refine");
  expect_error(
      run_cli("refine --model " + dir + "/lod1.city.json --cloud " + dir + "/c.ply --out " + dir + "/r.obj", dir),
      "r.obj: a city file in gives a CityJSON city file out; name it e.g. refined.city.json");
  expect_error(
      run_cli("refine --model " + dir + "/other.json --cloud " + dir + "/c.ply --out " + dir + "/r.city.json", dir),
      "other.json: not a CityJSON file (no \"type\": \"CityJSON\")");
  expect_error(run_cli("refine --model " + dir + "/c.ply --cloud " + dir + "/m.obj" + out, dir),
               "c.ply: not an OBJ model: the file is a PLY point cloud");
  expect_error(run_cli("refine --model " + dir + "/c.las --cloud " + dir + "/c.ply" + out, dir),
               "c.las: not an OBJ model: the file is a LAS/LAZ point cloud");
  expect_error(run_cli("refine --model " + dir + "/m.obj --cloud " + dir + "/other.json" + out, dir),
               "other.json: not a PLY or LAS point cloud: the file is JSON");
  expect_error(run_cli("crop --tile " + dir + "/city.gml --models " + dir + " --out " + dir + "/run", dir),
               "city.gml: not a PLY or LAS point cloud: the file is XML");
  expect_error(run_cli("convert --cityjson " + dir + "/city.gml --out-dir " + dir + "/o", dir),
               "city.gml: not a CityJSON file: the file is XML (a CityGML model?)");
  expect_error(run_cli("convert --cityjson " + dir + "/other.json --out-dir " + dir + "/o", dir),
               "other.json: not a CityJSON file (no \"type\": \"CityJSON\")");
  expect_error(run_cli("convert --cityjson " + dir + "/c.las --out-dir " + dir + "/o", dir),
               "c.las: not a CityJSON file: the file is a LAS/LAZ point cloud");
  // LoD1 only: nothing can be converted, which is an error, not "0 written".
  expect_error(run_cli("convert --cityjson " + dir + "/lod1.city.json --out-dir " + dir + "/o", dir),
               "no Building/BuildingPart with an LoD 2.x geometry (1 building object(s) without one)");
  EXPECT_FALSE(fs::exists(dir + "/r.obj"));
}

TEST(Formats, CloudOfAnotherTileIsCalledOut) {
  const std::string dir = test_dir();
  const SynthBuilding b = make_building(BuildingType::Flat, 1, {});
  write_obj(dir + "/m.obj", b.coarse);
  PointCloud far = b.cloud;
  for (auto& p : far.points) p.x() += 10000.0;  // e.g. the neighbouring tile, or another false easting
  write_ply(dir + "/far.ply", far);
  const Cli r = run_cli("refine --model " + dir + "/m.obj --cloud " + dir + "/far.ply --out " + dir +
                            "/r.obj --report " + dir + "/r.json",
                        dir);
  EXPECT_EQ(r.exit, 0) << r.err;  // the building still gets its (repaired) original
  EXPECT_EQ(r.err, "");           // stderr is only for the error line of a failed run
  EXPECT_NE(r.out.find("; warning: " + dir + "/far.ply: cloud x "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("does not overlap the model x "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(": wrong CRS or tile?"), std::string::npos) << r.out;
  const auto report = nlohmann::json::parse(slurp(dir + "/r.json"));
  ASSERT_TRUE(report.contains("warnings"));
  EXPECT_NE(report["warnings"][0].get<std::string>().find("wrong CRS or tile?"), std::string::npos);
  // The model's own cloud raises no warning.
  write_ply(dir + "/near.ply", b.cloud);
  const Cli ok = run_cli("refine --model " + dir + "/m.obj --cloud " + dir + "/near.ply --out " + dir + "/r.obj", dir);
  EXPECT_EQ(ok.exit, 0) << ok.err;
  EXPECT_EQ(ok.out.find("warning"), std::string::npos) << ok.out;
}
