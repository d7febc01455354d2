// Real city files refined with their clouds (when ../shared is present): the Rotterdam CityJSON
// district and the Den Haag CityGML, under the same contract as the generated cities.
#include <gtest/gtest.h>

#include "support/city_fixtures.h"
#include "support/cli_fixtures.h"
#include "support/cpu_burners.h"
#include "support/io_fixtures.h"
#include "support/mesh_fixtures.h"
#include "support/scan_fixtures.h"
#include "support/schema_fixtures.h"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <random>

#include "lodrefine/base/files.h"
#include "lodrefine/base/geometry.h"
#include "lodrefine/city/cityfile.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/formats/citygml.h"
#include "lodrefine/formats/cityjson.h"
#include "lodrefine/formats/las.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/formats/ply.h"
#include "lodrefine/refine/refine.h"
#include "lodrefine/refine/selection.h"
#include "lodrefine/synth/synth.h"
#include "support/test_paths.h"

using namespace lodrefine;
using namespace lodrefine::city_fixtures;
namespace fs = std::filesystem;

TEST(CityFile, RotterdamDelfshaven) {
  const fs::path path = shared_dir() / "realdata/val3dity/data/rotterdam/3-20-DELFSHAVEN.city.json";
  if (!fs::exists(path)) GTEST_SKIP() << path << " absent";
  const std::string dir = test_dir();
  const CityJsonFile city = read_cityjson(path.string());
  ASSERT_EQ(city.buildings.size(), 853u);
  // A scan of three buildings: every wall sampled, the largest one 0.4 m out of place.
  std::mt19937 rng(3);
  PointCloud cloud;
  int chosen = 0;
  for (const auto& b : city.buildings) {
    if (chosen == 3) break;
    if (b.mesh.faces.size() < 6 || b.mesh.faces.size() > 14) continue;
    std::size_t largest = 0;
    double area = 0;
    for (std::size_t k = 0; k < b.mesh.faces.size(); ++k) {
      if (b.mesh.faces[k].sem != Semantic::Wall) continue;
      const double a = polygon_area(face_points(b.mesh, b.mesh.faces[k]));
      if (a > area) area = a, largest = k;
    }
    if (area < 40) continue;
    for (std::size_t k = 0; k < b.mesh.faces.size(); ++k)
      if (b.mesh.faces[k].sem == Semantic::Wall)
        sample_face(face_points(b.mesh, b.mesh.faces[k]), k == largest ? 0.4 : 0.0, 0.1, rng, cloud);
    ++chosen;
  }
  ASSERT_EQ(chosen, 3);
  write_ply(dir + "/scan.ply", cloud);
  const Cli r = run_cli("refine --model " + path.string() + " --cloud " + dir + "/scan.ply --out " + dir +
                            "/rotterdam.city.json --report " + dir + "/report.json",
                        dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  std::printf("  %s  (%.1f s wall clock)\n", r.out.substr(0, r.out.find('\n')).c_str(), r.seconds);
  const json rep = load(dir + "/report.json");
  CityRefineSummary s;
  s.buildings = rep["buildings"], s.refined = rep["refined"], s.kept = rep["kept"];
  s.kept_invalid = rep["kept_invalid"], s.untouched = rep["untouched"];
  const auto codes = [](const json& errors) {  // the report's errors: their codes are what is checked
    std::vector<ValidityError> out;
    for (const auto& e : errors) out.push_back({ValidityCode(e["code"].get<int>()), {}, e["info"]});
    return out;
  };
  for (const auto& o : rep["outcomes"]) {
    s.outcomes.push_back({o["id"], parse_outcome(o["outcome"]).value(), o["reason"], o["facades_moved"], {}});
    s.outcomes.back().errors_before = codes(o["errors_before"]);
    s.outcomes.back().errors_after = codes(o["errors_after"]);
  }
  EXPECT_EQ(s.buildings, 853);
  EXPECT_GE(s.refined, 1);
  check_city_output(load(path.string()), dir + "/rotterdam.city.json", s);
}

TEST(CityFile, DenHaagCityGml) {
  const fs::path path = shared_dir() / "realdata/val3dity/data/gml/DenHaag_1BwBP.gml";
  if (!fs::exists(path)) GTEST_SKIP() << path << " absent";
  const std::string dir = test_dir();
  const CityJsonFile city = read_citygml(path.string());
  std::mt19937 rng(4);
  PointCloud cloud;
  const Mesh& m = city.buildings[0].mesh;
  bool moved = false;
  for (const Face& f : m.faces)
    if (f.sem == Semantic::Wall) {
      const auto poly = face_points(m, f);
      const bool big = !moved && polygon_area(poly) > 20;
      sample_face(poly, big ? 0.4 : 0.0, 0.08, rng, cloud);
      moved = moved || big;
    }
  write_ply(dir + "/scan.ply", cloud);
  const CityRefineSummary s =
      refine_city(path.string(), {dir + "/scan.ply"}, dir + "/denhaag.city.json", RefineConfig{}, {});
  EXPECT_EQ(s.input_format, "CityGML 1.0");
  EXPECT_EQ(s.buildings, 6);
  EXPECT_GE(s.outcomes.size(), 1u);
  check_city_output(citygml_to_cityjson(path.string()), dir + "/denhaag.city.json", s);
  const json out = load(dir + "/denhaag.city.json");
  EXPECT_EQ(out["metadata"]["referenceSystem"], "https://www.opengis.net/def/crs/EPSG/0/28992");
  for (const auto& [id, obj] : out["CityObjects"].items()) EXPECT_EQ(id.find("genID"), std::string::npos) << id;
  // Every building of this export is a valid solid: with --repair-all each gets an outcome and
  // none but the scanned one changes (check_city_output: kept ones object by object, vertex by vertex).
  CityRefineOptions all;
  all.repair_all = true;
  const CityRefineSummary r =
      refine_city(path.string(), {dir + "/scan.ply"}, dir + "/denhaag_all.city.json", RefineConfig{}, all);
  EXPECT_EQ(int(r.outcomes.size()), r.buildings);
  EXPECT_EQ(r.repaired, 0);
  EXPECT_EQ(r.kept_invalid, 0);
  EXPECT_EQ(r.refined, s.refined);
  check_city_output(citygml_to_cityjson(path.string()), dir + "/denhaag_all.city.json", r);
}
