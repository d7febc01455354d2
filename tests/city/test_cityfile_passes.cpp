// City files read back: a refined city refined again (its fins read with their Solid, every fin on
// its solid after each pass), and a CityGML file's rings as CityJSON writes them.
#include <gtest/gtest.h>

#include "support/cli_fixtures.h"
#include "support/fins_fixtures.h"
#include "support/mesh_fixtures.h"
#include "support/scan_fixtures.h"

#include <filesystem>
#include <fstream>

#include "lodrefine/base/files.h"
#include "lodrefine/base/geometry.h"
#include "lodrefine/city/cityfile.h"
#include "lodrefine/core/params.h"
#include "lodrefine/formats/citygml.h"
#include "lodrefine/formats/cityjson.h"
#include "lodrefine/formats/cityjson_write.h"
#include "lodrefine/formats/ply.h"

using namespace lodrefine;
namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

namespace {

const Vec3 kCityOrigin(93000.0, 436000.0, 0.0);

std::string test_dir() { return cli_fixtures::test_dir("lodrefine_city_passes"); }

json load(const std::string& path) {
  std::ifstream in(path);
  return json::parse(in);
}

// A house whose front wall stands 0.5 m before its scan, with a wall 3 m above its roof on that
// front (a fin): pass 1 repairs it and writes the fin beside the Solid, and the refinement
// that would move the front off the fin is not written.
json house_with_fin_city() {
  Mesh house = fixtures::as_soup(translated(fixtures::box(Vec3(0, -0.5, 0), Vec3(12, 8, 7)), kCityOrigin));
  const int n = int(house.vertices.size());
  for (const Vec3& p : {Vec3(0, -0.5, 7), Vec3(12, -0.5, 7), Vec3(12, -0.5, 10), Vec3(0, -0.5, 10)})
    house.vertices.push_back(p + kCityOrigin);
  house.faces.push_back({{n, n + 1, n + 2, n + 3}, Semantic::Wall, 6});
  json doc = {{"type", "CityJSON"},
              {"version", "2.0"},
              {"transform", {{"scale", {0.001, 0.001, 0.001}}, {"translate", {93000.0, 436000.0, 0.0}}}},
              {"CityObjects", json::object()},
              {"vertices", json::array()}};
  const json g = cityjson_multisurface(house, "2.2", Vec3::Constant(0.001), kCityOrigin, doc["vertices"]);
  doc["CityObjects"]["fin"] = {{"type", "Building"}, {"attributes", {{"name", "kept"}}}, {"geometry", {g}}};
  return doc;
}

// The building's geometries after a pass: exactly a Solid and, after it, its fins, standing on
// the solid (within the weld tolerance).
void expect_fins_on_solid(const std::string& path, const std::string& pass) {
  SCOPED_TRACE(pass);
  const json out = load(path);
  const json& g = out["CityObjects"]["fin"]["geometry"];
  ASSERT_EQ(g.size(), 2u) << g.dump();
  EXPECT_EQ(g[0]["type"], "Solid");
  EXPECT_EQ(g[1]["type"], "MultiSurface");
  EXPECT_EQ(g[1]["lod"], g[0]["lod"]);
  EXPECT_LE(fixtures::fins_apart(fixtures::geometry_mesh(out, g[1]), fixtures::geometry_mesh(out, g[0])),
            RefineConfig{}.repair.weld_tolerance);
  EXPECT_EQ(out["CityObjects"]["fin"]["attributes"]["name"], "kept");
}

}  // namespace

// Refining our own output again with the same scan: the second pass reads the fins with their
// Solid (a soup again, rebuilt), so it no more moves the front off the fin than the first did.
// Before, it read the Solid alone, moved the front onto the scan and left the fin 0.5 m off.
TEST(CityFilePasses, ASecondPassKeepsEveryFinOnItsSolid) {
  const std::string dir = test_dir();
  write_file_atomic(dir + "/city.json", house_with_fin_city().dump());
  PointCloud scan = fixtures::terraced_street_scan(0.5, 11.5, 3);
  for (Vec3& p : scan.points) p += kCityOrigin;
  write_ply(dir + "/cloud.ply", scan);
  const CityRefineSummary s1 = refine_city(dir + "/city.json", {dir + "/cloud.ply"}, dir + "/pass1.city.json", {}, {});
  ASSERT_EQ(s1.outcomes.size(), 1u);
  EXPECT_EQ(s1.outcomes[0].outcome, Outcome::Repaired) << s1.outcomes[0].reason;
  expect_fins_on_solid(dir + "/pass1.city.json", "pass 1");

  const CityJsonFile read = read_cityjson(dir + "/pass1.city.json");
  ASSERT_EQ(read.buildings.size(), 1u);
  EXPECT_EQ(read.buildings[0].fins_index, 1);
  EXPECT_EQ(read.buildings[0].fin_faces, 1);
  EXPECT_EQ(read.buildings[0].mesh.faces.back().sem, Semantic::Wall);

  const CityRefineSummary s2 =
      refine_city(dir + "/pass1.city.json", {dir + "/cloud.ply"}, dir + "/pass2.city.json", {}, {});
  ASSERT_EQ(s2.outcomes.size(), 1u);
  EXPECT_EQ(s2.outcomes[0].outcome, Outcome::Repaired) << s2.outcomes[0].reason;
  EXPECT_NE(s2.outcomes[0].reason.find("a fin beside the shell would stand apart from it"), std::string::npos)
      << s2.outcomes[0].reason;
  expect_fins_on_solid(dir + "/pass2.city.json", "pass 2");
  // The codes: pass 1 read a soup that is no solid; pass 2 reads a valid Solid (its fin beside
  // it is no part of it), so it has nothing to say and the codes pass 1 wrote are gone.
  const json a1 = load(dir + "/pass1.city.json")["CityObjects"]["fin"]["attributes"];
  EXPECT_FALSE(s1.outcomes[0].errors_before.empty());
  EXPECT_EQ(a1["lodrefine_errors_before"], json(error_codes(s1.outcomes[0].errors_before)));
  EXPECT_EQ(a1["lodrefine_errors_after"], json::array());
  EXPECT_EQ(error_codes(s2.outcomes[0].errors_before), std::vector<int>{});
  EXPECT_EQ(error_codes(s2.outcomes[0].errors_after), std::vector<int>{});
  const json a2 = load(dir + "/pass2.city.json")["CityObjects"]["fin"]["attributes"];
  EXPECT_FALSE(a2.contains("lodrefine_errors_before")) << a2.dump();
  EXPECT_FALSE(a2.contains("lodrefine_errors_after")) << a2.dump();
}

// A CityGML ring closes by repeating its first position; the CityJSON written (untouched and
// kept-invalid buildings keep the converted geometry) repeats no vertex at a ring's end, and
// is otherwise the geometry read.
TEST(CityFilePasses, CityGmlRingsAreWrittenWithoutTheirClosingVertex) {
  const std::string dir = test_dir();
  const Vec3 o(512000.125, 5403000.5, 100.0);
  std::string gml = R"(<?xml version="1.0" encoding="UTF-8"?>
<CityModel xmlns="http://www.opengis.net/citygml/2.0" xmlns:bldg="http://www.opengis.net/citygml/building/2.0"
 xmlns:gml="http://www.opengis.net/gml">)";
  const Mesh box = fixtures::box(o, o + Vec3(10, 8, 6));
  // "far", and "near" 200 m away, where the cloud is: "far" is untouched.
  for (const auto& [id, offset] : {std::pair<std::string, Vec3>{"far", Vec3::Zero()}, {"near", Vec3(200, 0, 0)}}) {
    gml += "<cityObjectMember><bldg:Building gml:id=\"" + id +
           "\"><bldg:lod2Solid><gml:Solid><gml:exterior><gml:CompositeSurface>";
    for (const Face& f : box.faces) {
      gml += "<gml:surfaceMember><gml:Polygon><gml:exterior><gml:LinearRing><gml:posList srsDimension=\"3\">";
      for (std::size_t i = 0; i <= f.v.size(); ++i) {
        const Vec3 p = box.vertices[std::size_t(f.v[i % f.v.size()])] + offset;
        gml += std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) + " ";
      }
      gml += "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>";
    }
    gml += "</gml:CompositeSurface></gml:exterior></gml:Solid></bldg:lod2Solid></bldg:Building></cityObjectMember>";
  }
  gml += "</CityModel>\n";
  write_file_atomic(dir + "/city.gml", gml);
  PointCloud near;
  for (double x = 0; x < 5; x += 0.1) near.points.push_back(o + Vec3(200 + x, -1, 1));
  write_ply(dir + "/cloud.ply", near);
  const CityRefineSummary s = refine_city(dir + "/city.gml", {dir + "/cloud.ply"}, dir + "/out.city.json", {}, {});
  EXPECT_EQ(s.untouched, 1);
  const json out = load(dir + "/out.city.json");
  const json& g = out["CityObjects"]["far"]["geometry"];
  ASSERT_EQ(g.size(), 1u);
  const Mesh written = fixtures::geometry_mesh(out, g[0]);
  ASSERT_EQ(written.faces.size(), box.faces.size());
  for (std::size_t k = 0; k < box.faces.size(); ++k) {
    const json& ring = g[0]["boundaries"][k][0];  // a MultiSurface: surfaces, rings
    ASSERT_EQ(ring.size(), box.faces[k].v.size()) << ring.dump();
    EXPECT_NE(ring.front(), ring.back()) << ring.dump();
    for (std::size_t i = 0; i < ring.size(); ++i)
      EXPECT_LT(
          (written.vertices[std::size_t(written.faces[k].v[i])] - box.vertices[std::size_t(box.faces[k].v[i])]).norm(),
          1e-6);
  }
}
