// A city file in, a city file out: generated buildings in a CityJSON file, the Rotterdam
// CityJSON and the Den Haag CityGML (when ../shared is present) refined with a cloud; every
// building accounted for, the untouched ones byte-identical, the output schema-valid (CityJSON
// 2.0.2, python3-jsonschema) and its refined geometry valid by the project's own check.
#include <gtest/gtest.h>

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
#include "lodrefine/core/refine.h"
#include "lodrefine/core/selection.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/formats/citygml.h"
#include "lodrefine/formats/cityjson.h"
#include "lodrefine/formats/las.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/formats/ply.h"
#include "lodrefine/synth/synth.h"
#include "support/test_paths.h"

using namespace lodrefine;

// Validation at the parameter table's planarity tolerance.
const double kPlanarity = RefineConfig{}.repair.planarity_tolerance;

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

namespace {

using fixtures::sample_face;

using cli_fixtures::Cli;
using cli_fixtures::run_cli;

std::string test_dir() { return cli_fixtures::test_dir("lodrefine_city"); }

json load(const std::string& path) {
  std::ifstream in(path);
  return json::parse(in);
}

using schema_fixtures::schema_verdict;
using schema_fixtures::shared_dir;

// The building's faces welded on identical coordinates (the file's integers), then checked.
std::string geometry_problem(const Mesh& soup) {
  Mesh m;
  m.id = soup.id;
  std::map<std::array<double, 3>, int> index;
  for (const Face& f : soup.faces) {
    Face g = f;
    g.v.clear();
    for (int v : f.v) {
      const Vec3& p = soup.vertices[std::size_t(v)];
      const auto [it, added] = index.emplace(std::array<double, 3>{p.x(), p.y(), p.z()}, int(m.vertices.size()));
      if (added) m.vertices.push_back(p);
      g.v.push_back(it->second);
    }
    m.faces.push_back(g);
  }
  const Vec3 o = local_origin(m);
  const Validation v = validate_mesh(translated(m, -o), kPlanarity);
  return v.valid() ? "" : v.problem;
}

// A CityJSON 2.0 document of generated buildings: the coarse soup as an LoD 2.2 MultiSurface
// with semantics, plus an LoD 1 block and attributes, so the test sees both kept exactly.
json synth_city(const std::vector<SynthBuilding>& bs, const Vec3& translate) {
  json doc = {
      {"type", "CityJSON"},
      {"version", "2.0"},
      {"transform", {{"scale", {0.001, 0.001, 0.001}}, {"translate", {translate.x(), translate.y(), translate.z()}}}},
      {"metadata", {{"referenceSystem", "https://www.opengis.net/def/crs/EPSG/0/7415"}, {"title", "synth"}}},
      {"CityObjects", json::object()},
      {"vertices", json::array()}};
  for (const auto& b : bs) {
    json boundaries = json::array(), values = json::array();
    for (const Face& f : b.coarse.faces) {
      json ring = json::array();
      for (int v : f.v) {
        const Vec3 q = (b.coarse.vertices[std::size_t(v)] - translate) / 0.001;
        ring.push_back(doc["vertices"].size());
        doc["vertices"].push_back({std::llround(q.x()), std::llround(q.y()), std::llround(q.z())});
      }
      boundaries.push_back(json::array({ring}));
      values.push_back(f.sem == Semantic::Wall ? 0 : f.sem == Semantic::Roof ? 1 : f.sem == Semantic::Ground ? 2 : -1);
      if (values.back() == -1) values.back() = nullptr;
    }
    json lod2 = {{"type", "MultiSurface"},
                 {"lod", "2.2"},
                 {"boundaries", boundaries},
                 {"semantics",
                  {{"surfaces", {{{"type", "WallSurface"}}, {{"type", "RoofSurface"}}, {{"type", "GroundSurface"}}}},
                   {"values", values}}}};
    json lod1 = {{"type", "MultiSurface"}, {"lod", "1"}, {"boundaries", json::array({boundaries[0]})}};
    doc["CityObjects"][b.id] = {{"type", "Building"},
                                {"attributes", {{"yearOfConstruction", 1931}, {"function", "residential"}}},
                                {"geometry", {lod1, lod2}}};
  }
  return doc;
}

// Checks the contract on an output: counts add up, untouched and kept buildings identical to
// the input (objects and their vertices), refined and repaired ones a valid Solid with semantics,
// schema.
void check_city_output(const json& in, const std::string& out_path, const CityRefineSummary& s) {
  const json out = load(out_path);
  EXPECT_EQ(out["version"], "2.0");
  EXPECT_EQ(out["metadata"], in["metadata"]);
  EXPECT_EQ(out["transform"], in["transform"]);
  ASSERT_EQ(out["CityObjects"].size(), in["CityObjects"].size());
  EXPECT_EQ(s.refined + s.repaired + s.kept + s.kept_invalid + s.untouched, s.buildings);
  std::map<std::string, std::string> outcome;
  std::map<std::string, const CityBuildingOutcome*> reported;
  for (const auto& o : s.outcomes) outcome[o.id] = outcome_name(o.outcome), reported[o.id] = &o;
  int identical = 0;
  std::size_t vertex_mismatches = 0;
  for (const auto& [id, obj] : in["CityObjects"].items()) {
    ASSERT_TRUE(out["CityObjects"].contains(id)) << id;
    json o = out["CityObjects"][id];
    const auto it = outcome.find(id);
    if (it != outcome.end()) {
      EXPECT_EQ(o["attributes"]["lodrefine_outcome"], it->second) << id;
      // The codes only where the building had or has errors (issue 50): a valid one's
      // attributes stay as read but for its outcome.
      const CityBuildingOutcome& r = *reported.at(id);
      const bool codes = !r.errors_before.empty() || !r.errors_after.empty();
      EXPECT_EQ(o["attributes"].contains("lodrefine_errors_before"), codes) << id;
      EXPECT_EQ(o["attributes"].contains("lodrefine_errors_after"), codes) << id;
      if (codes) {
        EXPECT_EQ(o["attributes"]["lodrefine_errors_before"], json(error_codes(r.errors_before))) << id;
        EXPECT_EQ(o["attributes"]["lodrefine_errors_after"], json(error_codes(r.errors_after))) << id;
      }
      for (const char* k : {"lodrefine_outcome", "lodrefine_reason", "lodrefine_facades_moved",
                            "lodrefine_errors_before", "lodrefine_errors_after"})
        o["attributes"].erase(k);
      if (o["attributes"].empty() && !obj.contains("attributes")) o.erase("attributes");
    }
    if (it != outcome.end() && (it->second == "refined" || it->second == "repaired")) {
      EXPECT_EQ(o.value("attributes", json()), obj.value("attributes", json())) << id;
      // The same geometries, and a MultiSurface of fins beside the Solid where the input had any.
      const json og = o.value("geometry", json::array());
      const std::size_t n_in = obj.value("geometry", json::array()).size();
      EXPECT_TRUE(og.size() == n_in || og.size() == n_in + 1) << id;
      for (std::size_t i = 0; og.size() == n_in + 1 && i + 1 < og.size(); ++i)
        if (og[i + 1]["type"] == "MultiSurface" && og[i]["type"] == "Solid") {
          EXPECT_EQ(og[i + 1]["lod"], og[i]["lod"]) << id;
        }
      continue;
    }
    // Kept and untouched: the object and every vertex it uses exactly as read.
    if (o != obj) ADD_FAILURE() << id << " changed";
    std::function<void(const json&)> same_vertices = [&](const json& j) {
      if (j.is_array()) {
        for (const auto& e : j) same_vertices(e);
      } else if (j.is_number_integer()) {
        vertex_mismatches += out["vertices"][j.get<std::size_t>()] != in["vertices"][j.get<std::size_t>()];
      }
    };
    if (obj.contains("geometry"))
      for (const auto& g : obj["geometry"]) same_vertices(g["boundaries"]);
    ++identical;
  }
  EXPECT_EQ(vertex_mismatches, 0u);
  EXPECT_EQ(identical, s.buildings - s.refined - s.repaired + int(in["CityObjects"].size()) - s.buildings);
  // Refined geometry passes the project's validity check.
  const CityJsonFile back = read_cityjson(out_path);
  for (const auto& b : back.buildings) {
    const auto it = outcome.find(b.mesh.id);
    if (it == outcome.end() || (it->second != "refined" && it->second != "repaired")) continue;
    EXPECT_EQ(b.geometry_type, "Solid") << b.mesh.id;
    Mesh solid = b.mesh;  // its fins, read with it, come last
    solid.faces.resize(solid.faces.size() - std::size_t(b.fin_faces));
    EXPECT_EQ(geometry_problem(solid), "") << b.mesh.id;
    int walls = 0, roofs = 0, grounds = 0;
    for (const Face& f : solid.faces)
      walls += f.sem == Semantic::Wall, roofs += f.sem == Semantic::Roof, grounds += f.sem == Semantic::Ground;
    EXPECT_GE(walls, 4) << b.mesh.id;
    EXPECT_GE(roofs, 1) << b.mesh.id;
    EXPECT_GE(grounds, 1) << b.mesh.id;
  }
  const std::string verdict = schema_verdict(out_path);
  if (!verdict.empty()) {
    EXPECT_EQ(verdict, "valid");
  }
  std::printf("  %s: %d building(s): %d refined, %d repaired, %d kept, %d kept-invalid, %d untouched; schema: %s\n",
              out_path.c_str(), s.buildings, s.refined, s.repaired, s.kept, s.kept_invalid, s.untouched,
              verdict.empty() ? "not checked (validator or schemas absent)" : verdict.c_str());
}

// Generated buildings 80 m apart along x and the clouds of the first `scanned` of them.
std::vector<SynthBuilding> synth_street(const std::vector<BuildingType>& types, std::uint64_t first_seed, int points,
                                        std::size_t scanned, PointCloud& cloud) {
  std::vector<SynthBuilding> bs;
  SynthOptions so;
  so.target_points = points;
  so.scanned_facades = 2;
  for (std::size_t k = 0; k < types.size(); ++k) {
    so.origin = Vec3(93000.0 + 80.0 * double(k), 436000.0, 0.0);
    bs.push_back(make_building(types[k], first_seed + k, so));
    if (k < scanned)
      cloud.points.insert(cloud.points.end(), bs.back().cloud.points.begin(), bs.back().cloud.points.end());
  }
  return bs;
}

}  // namespace

TEST(CityFile, GeneratedCityRefinedIntoCityJson2) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs = synth_street(
      {BuildingType::Gable, BuildingType::LShape, BuildingType::Flat, BuildingType::Hip}, 11, 8000, 3, cloud);
  const json in = synth_city(bs, Vec3(93000, 436000, 0));
  write_file_atomic(dir + "/city.json", in.dump());
  write_ply(dir + "/cloud.ply", cloud);

  const CityRefineSummary s =
      refine_city(dir + "/city.json", {dir + "/cloud.ply"}, dir + "/out.city.json", RefineConfig{}, {});
  EXPECT_EQ(s.buildings, 4);
  EXPECT_EQ(s.untouched, 1);  // the Hip building has no points
  EXPECT_EQ(s.outcomes.size(), 3u);
  EXPECT_GE(s.refined, 2);
  EXPECT_EQ(s.cloud_points, cloud.points.size());
  for (const auto& o : s.outcomes)
    if (o.outcome == Outcome::Refined) {
      EXPECT_GE(o.facades_moved, 1) << o.id;
    }
  check_city_output(in, dir + "/out.city.json", s);
  // The refined LoD 2.2 geometry replaced in place; the LoD 1 geometry before it kept.
  const json out = load(dir + "/out.city.json");
  for (const auto& o : s.outcomes) {
    if (o.outcome != Outcome::Refined) continue;
    EXPECT_EQ(out["CityObjects"][o.id]["geometry"][0], in["CityObjects"][o.id]["geometry"][0]);
    EXPECT_EQ(out["CityObjects"][o.id]["geometry"][1]["lod"], "2.2");
    EXPECT_EQ(out["CityObjects"][o.id]["geometry"][1]["type"], "Solid");
  }

  // --building picks one; the others are untouched.
  CityRefineOptions one;
  one.building = bs[1].id;
  const CityRefineSummary s1 =
      refine_city(dir + "/city.json", {dir + "/cloud.ply"}, dir + "/one.city.json", RefineConfig{}, one);
  ASSERT_EQ(s1.outcomes.size(), 1u);
  EXPECT_EQ(s1.outcomes[0].id, bs[1].id);
  EXPECT_EQ(s1.untouched, 3);
  check_city_output(in, dir + "/one.city.json", s1);
}

// The terraced street of Refine.ACorrectTerracedHouseBesideAMisplacedOneIsLeftAsItIs as a city:
// A [0,12] correct, B [12,24] with its front 0.5 m out, G [27,39] whose crop box the tile's
// edge (x = 24.6) only grazes. B is refined; A is kept exactly as read; G is kept because the
// scan covers none of its facades.
TEST(CityFile, OnlyTheMisplacedTerracedHouseChanges) {
  const std::string dir = test_dir();
  const Vec3 origin(93000.0, 436000.0, 0.0);
  const auto house = [&](const char* id, double x0, double x1, double y0) {
    SynthBuilding b;
    b.id = id;
    b.coarse = translated(fixtures::as_soup(fixtures::box({x0, y0, 0}, {x1, 8, 7})), origin);
    return b;
  };
  const json in = synth_city({house("A", 0, 12, 0), house("B", 12, 24, -0.5), house("G", 27, 39, 0)}, origin);
  write_file_atomic(dir + "/terraced.city.json", in.dump());
  PointCloud cloud = fixtures::terraced_street_scan(-0.6, 24.6, 5);
  for (auto& p : cloud.points) p += origin;
  write_ply(dir + "/terraced.ply", cloud);
  const CityRefineSummary s = refine_city(dir + "/terraced.city.json", {dir + "/terraced.ply"},
                                          dir + "/terraced.out.city.json", RefineConfig{}, {});
  ASSERT_EQ(s.outcomes.size(), 3u);
  std::map<std::string, CityBuildingOutcome> by_id;
  for (const auto& o : s.outcomes) by_id[o.id] = o;
  EXPECT_EQ(by_id["A"].outcome, Outcome::Kept) << by_id["A"].reason;
  EXPECT_EQ(by_id["B"].outcome, Outcome::Refined) << by_id["B"].reason;
  EXPECT_EQ(by_id["G"].outcome, Outcome::Kept);
  EXPECT_EQ(by_id["G"].reason, "scan covers no facade of this building");
  EXPECT_EQ(s.refused.size(), 0u);
  check_city_output(in, dir + "/terraced.out.city.json", s);  // A and G exactly as read
  // B's front is on the scan (y = 0), its side walls where they were. Each of its semantic
  // surfaces says where it comes from: the moved front the scan's, the untouched roof the model's.
  const json out = load(dir + "/terraced.out.city.json");
  int fronts = 0, roofs = 0;
  for (const auto& b : read_cityjson(dir + "/terraced.out.city.json").buildings) {
    if (b.mesh.id != "B") continue;
    const json& semantics = out["CityObjects"]["B"]["geometry"][std::size_t(b.geometry_index)]["semantics"];
    for (const auto& v : b.mesh.vertices) {
      const Vec3 p = v - origin;
      EXPECT_TRUE(std::abs(p.x() - 12) <= 0.01 || std::abs(p.x() - 24) <= 0.01) << p.transpose();
      EXPECT_GE(p.y(), -0.01) << p.transpose();
    }
    for (const Face& f : b.mesh.faces) {
      const json& surface =
          semantics["surfaces"][semantics["values"][std::size_t(0)][std::size_t(f.source)].get<std::size_t>()];
      ASSERT_TRUE(surface.contains("lodrefine_source")) << surface.dump();
      if (f.sem == Semantic::Wall && polygon_plane(face_points(b.mesh, f)).n.y() < -0.9) {
        ++fronts;
        EXPECT_EQ(surface["lodrefine_source"], "scan") << surface.dump();
        EXPECT_GT(surface["lodrefine_coverage"].get<double>(), 0.5) << surface.dump();
      } else if (f.sem == Semantic::Roof) {
        ++roofs;
        EXPECT_EQ(surface["lodrefine_source"], "model") << surface.dump();
      }
    }
  }
  EXPECT_EQ(fronts, 1);
  EXPECT_GE(roofs, 1);
}

TEST(CityFile, ErrorsAndBuildingsThatCannotBeRefined) {
  const std::string dir = test_dir();
  SynthOptions so;
  so.target_points = 4000;
  so.origin = Vec3(93000.0, 436000.0, 0.0);
  std::vector<SynthBuilding> bs = {make_building(BuildingType::Gable, 5, so)};
  json in = synth_city(bs, Vec3(93000, 436000, 0));
  // A second building of two triangles: no repair can close it, so refine_building throws.
  json& v = in["vertices"];
  const std::size_t n = v.size();
  for (const auto& q : {json{5000, 5000, 0}, json{6000, 5000, 0}, json{5000, 6000, 0}, json{5000, 5000, 1000}})
    v.push_back(q);
  in["CityObjects"]["broken"] = {
      {"type", "Building"},
      {"geometry",
       {{{"type", "MultiSurface"}, {"lod", "2"}, {"boundaries", {{{n, n + 1, n + 2}}, {{n, n + 1, n + 3}}}}}}}};
  write_file_atomic(dir + "/city.json", in.dump());
  PointCloud cloud = bs[0].cloud;
  for (int i = 0; i < 500; ++i) cloud.points.push_back(Vec3(93005.0 + 0.002 * i, 436005.5, 0.5));
  write_ply(dir + "/cloud.ply", cloud);
  const CityRefineSummary s =
      refine_city(dir + "/city.json", {dir + "/cloud.ply"}, dir + "/out.city.json", RefineConfig{}, {});
  ASSERT_EQ(s.outcomes.size(), 2u);
  EXPECT_EQ(s.outcomes[1].id, "broken");
  EXPECT_EQ(s.outcomes[1].outcome, Outcome::KeptInvalid);
  EXPECT_FALSE(s.outcomes[1].reason.empty());
  check_city_output(in, dir + "/out.city.json", s);

  const auto expect_error = [&](const std::string& args, const std::string& fault) {
    const Cli r = run_cli(args, dir);
    EXPECT_NE(r.exit, 0) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(fault), std::string::npos) << r.err;
  };
  PointCloud far = bs[0].cloud;
  for (auto& p : far.points) p += Vec3(-50000, 70000, 0);  // e.g. another CRS
  write_ply(dir + "/far.ply", far);
  expect_error("refine --model " + dir + "/city.json --cloud " + dir + "/far.ply --out " + dir + "/x.city.json",
               "does not overlap the city model x 92");
  expect_error("refine --model " + dir + "/city.json --cloud " + dir + "/cloud.ply --out " + dir +
                   "/x.city.json --building nope",
               "no building \"nope\"");
  expect_error(
      "refine --model " + dir + "/city.json --cloud " + dir + "/cloud.ply --out " + dir + "/x.city.json --lod 3",
      "no Building/BuildingPart with an LoD 3 geometry");
  EXPECT_FALSE(fs::exists(dir + "/x.city.json"));
  // --lod 1 picks the LoD 1 blocks (one face each: kept-invalid, kept exactly).
  const Cli lod1 = run_cli(
      "refine --model " + dir + "/city.json --cloud " + dir + "/cloud.ply --out " + dir + "/lod1.city.json --lod 1",
      dir);
  EXPECT_EQ(lod1.exit, 0) << lod1.err;
  EXPECT_NE(lod1.out.find("0 refined"), std::string::npos) << lod1.out;
}

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

// A building the cloud does not reach stays as read though it is no valid solid (a house exported
// as roof, ground and one end wall); with repair_all it is rebuilt on its planes, written as a
// Solid and says so, and a valid building the cloud does not reach is kept as read.
TEST(CityFile, RepairAllMendsTheBuildingsTheCloudDoesNotReach) {
  const std::string dir = test_dir();
  SynthOptions so;
  so.target_points = 4000;
  so.origin = Vec3(93000.0, 436000.0, 0.0);
  std::vector<SynthBuilding> bs = {make_building(BuildingType::Gable, 5, so)};
  SynthBuilding open = bs[0], whole = bs[0];
  open.id = "open";
  whole.id = "whole";
  const Mesh box = fixtures::as_soup(translated(fixtures::box(Vec3(0, 0, 0), Vec3(10, 8, 6)), Vec3(93200, 436000, 0)));
  whole.coarse = box;
  open.coarse = box;
  open.coarse.faces = {box.faces[0], box.faces[1], box.faces[3]};  // ground, roof, one end wall
  whole.coarse.vertices = box.vertices;
  for (auto& v : whole.coarse.vertices) v += Vec3(100, 0, 0);
  bs.push_back(open);
  bs.push_back(whole);
  const json in = synth_city(bs, Vec3(93000, 436000, 0));
  write_file_atomic(dir + "/city.json", in.dump());
  write_ply(dir + "/cloud.ply", bs[0].cloud);

  const CityRefineSummary plain =
      refine_city(dir + "/city.json", {dir + "/cloud.ply"}, dir + "/plain.city.json", RefineConfig{}, {});
  EXPECT_EQ(plain.untouched, 2);
  EXPECT_EQ(plain.repaired, 0);
  check_city_output(in, dir + "/plain.city.json", plain);

  CityRefineOptions all;
  all.repair_all = true;
  const CityRefineSummary s =
      refine_city(dir + "/city.json", {dir + "/cloud.ply"}, dir + "/all.city.json", RefineConfig{}, all);
  ASSERT_EQ(s.outcomes.size(), 3u);
  EXPECT_EQ(s.untouched, 0);
  EXPECT_EQ(s.outcomes[1].id, "open");
  EXPECT_EQ(s.outcomes[1].outcome, Outcome::Repaired) << s.outcomes[1].reason;
  EXPECT_EQ(s.outcomes[1].reason.rfind("shell rebuilt on its planes", 0), 0u) << s.outcomes[1].reason;
  EXPECT_EQ(s.outcomes[2].outcome, Outcome::Kept) << s.outcomes[2].reason;
  check_city_output(in, dir + "/all.city.json", s);
  const CityJsonFile back = read_cityjson(dir + "/all.city.json");
  for (const auto& b : back.buildings)
    if (b.mesh.id == "open") {
      EXPECT_NEAR(validate_mesh(b.mesh, 0.01).volume, 480.0, 0.5);
    }
}

// A house whose wall stands 3 m above its roof (a fin) is repaired: its geometry becomes the
// Solid and, beside it, a MultiSurface of the same LoD holding the fin as read.
TEST(CityFile, AFinIsWrittenBesideTheSolidAsAMultiSurface) {
  const std::string dir = test_dir();
  SynthOptions so;
  so.target_points = 4000;
  so.origin = Vec3(93000.0, 436000.0, 0.0);
  std::vector<SynthBuilding> bs = {make_building(BuildingType::Gable, 5, so)};
  SynthBuilding fin = bs[0];
  fin.id = "fin";
  fin.coarse = fixtures::as_soup(translated(fixtures::box(Vec3(0, 0, 0), Vec3(10, 8, 6)), Vec3(93200, 436000, 0)));
  const int n = int(fin.coarse.vertices.size());
  for (const Vec3& p : {Vec3(0, 0, 6), Vec3(0, 8, 6), Vec3(0, 8, 9), Vec3(0, 0, 9)})
    fin.coarse.vertices.push_back(p + Vec3(93200, 436000, 0));
  fin.coarse.faces.push_back({{n, n + 1, n + 2, n + 3}, Semantic::Wall, 6});
  bs.push_back(fin);
  const json in = synth_city(bs, Vec3(93000, 436000, 0));
  write_file_atomic(dir + "/city.json", in.dump());
  write_ply(dir + "/cloud.ply", bs[0].cloud);
  CityRefineOptions all;
  all.repair_all = true;
  const CityRefineSummary s =
      refine_city(dir + "/city.json", {dir + "/cloud.ply"}, dir + "/out.city.json", RefineConfig{}, all);
  ASSERT_EQ(s.outcomes.size(), 2u);
  EXPECT_EQ(s.outcomes[1].outcome, Outcome::Repaired) << s.outcomes[1].reason;
  check_city_output(in, dir + "/out.city.json", s);
  const json out = load(dir + "/out.city.json");
  const json& g = out["CityObjects"]["fin"]["geometry"];
  ASSERT_EQ(g.size(), 3u) << g.dump();  // LoD 1 as read, the Solid, the fin
  EXPECT_EQ(g[1]["type"], "Solid");
  EXPECT_EQ(g[2]["type"], "MultiSurface");
  EXPECT_EQ(g[2]["lod"], g[1]["lod"]);
  ASSERT_EQ(g[2]["boundaries"].size(), 1u);
  const json& ring = g[2]["boundaries"][0][0];
  ASSERT_EQ(ring.size(), 4u);
  const json& tf = out["transform"];
  for (const json& v : ring) {
    const json& q = out["vertices"][v.get<std::size_t>()];
    EXPECT_NEAR(q[0].get<double>() * tf["scale"][0].get<double>() + tf["translate"][0].get<double>(), 93200.0, 1e-3);
    EXPECT_GE(q[2].get<double>() * tf["scale"][2].get<double>() + tf["translate"][2].get<double>(), 6.0 - 1e-3);
  }
  EXPECT_EQ(g[2]["semantics"]["surfaces"][0]["type"], "WallSurface");
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

TEST(CityFile, CityJsonSeqStreamedThrough) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs =
      synth_street({BuildingType::Gable, BuildingType::Shed, BuildingType::Gable}, 31, 6000, 2, cloud);
  // One feature per building, each with its own vertices (as cjseq writes them).
  std::vector<json> lines;
  json header = synth_city({}, Vec3(93000, 436000, 0));
  lines.push_back(header);
  for (const auto& b : bs) {
    json one = synth_city({b}, Vec3(93000, 436000, 0));
    lines.push_back({{"type", "CityJSONFeature"},
                     {"id", b.id},
                     {"CityObjects", one["CityObjects"]},
                     {"vertices", one["vertices"]}});
  }
  std::string text;
  for (const auto& l : lines) text += l.dump() + "\n";
  write_file_atomic(dir + "/city.city.jsonl", text);
  write_ply(dir + "/cloud.ply", cloud);
  const CityRefineSummary s =
      refine_city(dir + "/city.city.jsonl", {dir + "/cloud.ply"}, dir + "/out.city.jsonl", RefineConfig{}, {});
  EXPECT_EQ(s.input_format, "CityJSONSeq 2.0");
  EXPECT_EQ(s.buildings, 3);
  EXPECT_EQ(s.untouched, 1);
  EXPECT_GE(s.refined, 1);
  EXPECT_EQ(s.refined + s.kept + s.kept_invalid + s.untouched, 3);
  std::ifstream in(dir + "/out.city.jsonl");
  std::vector<json> out;
  for (std::string l; std::getline(in, l);) out.push_back(json::parse(l));
  ASSERT_EQ(out.size(), 4u);
  EXPECT_EQ(out[0], lines[0]);
  EXPECT_EQ(out[3], lines[3]);  // no cloud points: the feature exactly as read
  const CityJsonFile back = read_cityjson(dir + "/out.city.jsonl");
  ASSERT_EQ(back.buildings.size(), 3u);
  for (const auto& o : s.outcomes)
    for (const auto& b : back.buildings)
      if (b.mesh.id == o.id && o.outcome == Outcome::Refined) {
        EXPECT_EQ(geometry_problem(b.mesh), "") << b.mesh.id;
      }
  const std::string verdict = schema_verdict(dir + "/out.city.jsonl", true);
  if (!verdict.empty()) {
    EXPECT_EQ(verdict, "valid");
  }
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

TEST(CityFile, LodPicksTheGeometryToRefine) {
  const fs::path path = shared_dir() / "realdata/val3dity/data/test_cityjson/several_lods_valid.json";
  if (!fs::exists(path)) GTEST_SKIP() << path << " absent";
  const std::string dir = test_dir();
  const json in = load(path.string());
  std::map<std::string, int> lods;  // the building part's solids (LoD 1.2, 1.3, 2.2) -> geometry index
  std::string id;
  for (const auto& [oid, obj] : in["CityObjects"].items()) {
    if (obj["type"] != "BuildingPart" || !obj.contains("geometry")) continue;
    for (std::size_t k = 0; k < obj["geometry"].size(); ++k) lods[obj["geometry"][k]["lod"]] = int(k), id = oid;
  }
  ASSERT_EQ(lods.size(), 3u);
  std::mt19937 rng(6);
  for (const auto& [lod, index] : lods) {
    const CityJsonFile f = read_cityjson(path.string(), lod);
    ASSERT_EQ(f.buildings.size(), 1u);
    EXPECT_EQ(f.buildings[0].geometry_index, index);
    PointCloud cloud;
    const Mesh& m = f.buildings[0].mesh;
    double largest = 0;
    std::size_t big = 0;
    const auto vertical = [&](std::size_t k) {
      return std::abs(newell_normal(face_points(m, m.faces[k])).normalized().z()) < 0.1;
    };
    for (std::size_t k = 0; k < m.faces.size(); ++k)
      if (vertical(k) && polygon_area(face_points(m, m.faces[k])) > largest)
        largest = polygon_area(face_points(m, m.faces[k])), big = k;
    for (std::size_t k = 0; k < m.faces.size(); ++k)
      if (vertical(k)) sample_face(face_points(m, m.faces[k]), k == big ? 0.3 : 0.0, 0.1, rng, cloud);
    write_ply(dir + "/c.ply", cloud);
    CityRefineOptions o;
    o.lod = lod;
    const CityRefineSummary s = refine_city(path.string(), {dir + "/c.ply"}, dir + "/out.city.json", RefineConfig{}, o);
    ASSERT_EQ(s.outcomes.size(), 1u);
    const json out = load(dir + "/out.city.json");
    for (std::size_t k = 0; k < in["CityObjects"][id]["geometry"].size(); ++k) {
      const json& before = in["CityObjects"][id]["geometry"][k];
      const json& after = out["CityObjects"][id]["geometry"][k];
      EXPECT_EQ(after["lod"], before["lod"]);
      if (int(k) != index || s.outcomes[0].outcome != Outcome::Refined)
        EXPECT_EQ(after, before) << "LoD " << before["lod"];
      else EXPECT_EQ(after["type"], "Solid");
    }
    std::printf("  --lod %s: %s (%s)\n", lod.c_str(), outcome_name(s.outcomes[0].outcome),
                s.outcomes[0].reason.c_str());
    // convert --lod writes that LoD's faces.
    const Cli c =
        run_cli("convert --cityjson " + path.string() + " --lod " + lod + " --out-dir " + dir + "/obj_" + lod, dir);
    ASSERT_EQ(c.exit, 0) << c.err;
    EXPECT_EQ(read_obj(dir + "/obj_" + lod + "/" + id + ".obj").faces.size(), m.faces.size()) << lod;
  }
}

TEST(CityFile, LasTileWithClassesThroughTheCli) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs = synth_street({BuildingType::Gable, BuildingType::LShape}, 51, 6000, 2, cloud);
  write_file_atomic(dir + "/city.json", synth_city(bs, Vec3(93000, 436000, 0)).dump());
  write_ply(dir + "/cloud.ply", cloud);
  // The same points as class 6, and as many class-1 points scattered through the buildings' boxes.
  PointCloud tile = cloud;
  std::vector<int> classes(cloud.points.size(), 6);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> jitter(-4.0, 4.0);
  for (const auto& p : cloud.points) {
    tile.points.push_back(p + Vec3(jitter(rng), jitter(rng), jitter(rng)));
    classes.push_back(1);
  }
  LasWriteOptions lo;
  lo.version_minor = 4, lo.point_format = 6, lo.scale = Vec3::Constant(1e-4), lo.offset = Vec3(93000, 436000, 0);
  write_las(dir + "/tile.las", tile, classes, lo);
  const Cli ply = run_cli("refine --model " + dir + "/city.json --cloud " + dir + "/cloud.ply --out " + dir +
                              "/a.city.json --report " + dir + "/a.json",
                          dir);
  const Cli las = run_cli("refine --model " + dir + "/city.json --cloud " + dir + "/tile.las --classes 6 --out " + dir +
                              "/b.city.json --report " + dir + "/b.json",
                          dir);
  ASSERT_EQ(ply.exit, 0) << ply.err;
  ASSERT_EQ(las.exit, 0) << las.err;
  const json a = load(dir + "/a.json"), b = load(dir + "/b.json");
  EXPECT_EQ(b["cloud_points"], cloud.points.size());
  ASSERT_EQ(a["outcomes"].size(), b["outcomes"].size());
  for (std::size_t i = 0; i < a["outcomes"].size(); ++i) {
    EXPECT_EQ(a["outcomes"][i]["outcome"], b["outcomes"][i]["outcome"]);
    EXPECT_EQ(a["outcomes"][i]["facades_moved"], b["outcomes"][i]["facades_moved"]);
  }
  EXPECT_GE(b["refined"].get<int>(), 1);
}

// --jobs: buildings refined on a pool, written in file order: the same bytes as one at a time,
// for a CityJSON file and for a CityJSONSeq, with the progress callback called once a building
// (once a feature) in order and counting up to the file's buildings.
TEST(CityFile, JobsWriteTheSameBytesAsOneAtATime) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs =
      synth_street({BuildingType::Gable, BuildingType::LShape, BuildingType::Flat, BuildingType::Hip,
                    BuildingType::Shed, BuildingType::Stepped, BuildingType::TShape},
                   41, 5000, 6, cloud);
  const json in = synth_city(bs, Vec3(93000, 436000, 0));
  write_file_atomic(dir + "/city.json", in.dump());
  std::string seq = synth_city({}, Vec3(93000, 436000, 0)).dump() + "\n";
  for (const auto& b : bs) {
    json one = synth_city({b}, Vec3(93000, 436000, 0));
    seq += json({{"type", "CityJSONFeature"},
                 {"id", b.id},
                 {"CityObjects", one["CityObjects"]},
                 {"vertices", one["vertices"]}})
               .dump() +
           "\n";
  }
  write_file_atomic(dir + "/city.city.jsonl", seq);
  write_ply(dir + "/cloud.ply", cloud);
  for (const std::string name : {"city.json", "city.city.jsonl"}) {
    std::map<int, std::string> written;
    std::map<int, std::vector<std::string>> order;
    for (int jobs : {1, 3}) {
      CityRefineOptions o;
      o.jobs = jobs;
      std::vector<int> done;
      o.progress = [&](const CityRefineSummary& s) {
        done.push_back(s.refined + s.kept + s.kept_invalid + s.untouched);
        EXPECT_EQ(s.buildings, int(bs.size()));
      };
      const std::string out = dir + "/out" + std::to_string(jobs) + "." + name;
      const CityRefineSummary s = refine_city(dir + "/" + name, {dir + "/cloud.ply"}, out, RefineConfig{}, o);
      EXPECT_EQ(s.refined + s.kept + s.kept_invalid, 6);
      EXPECT_GE(s.refined, 4) << name;
      ASSERT_EQ(done.size(), bs.size()) << name;
      for (std::size_t i = 0; i < done.size(); ++i) EXPECT_EQ(done[i], int(i) + 1);
      std::ifstream f(out, std::ios::binary);
      written[jobs].assign(std::istreambuf_iterator<char>(f), {});
      for (const auto& b : s.outcomes) order[jobs].push_back(b.id);
    }
    EXPECT_EQ(written[1], written[3]) << name << ": --jobs 3 wrote other bytes than --jobs 1";
    EXPECT_EQ(order[1], order[3]) << name << ": outcomes not in file order";
    EXPECT_GT(written[1].size(), 1000u);
  }
}

// Buildings whose selection ends at the work budget (made small here so that every search does)
// select the same faces on a pool of 2 and one at a time, while other threads load the CPU: the
// budget counts GLPK's work, not seconds.
TEST(CityFile, JobsWriteTheSameBytesWhenSelectionsEndAtTheBudget) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs = synth_street(
      {BuildingType::LShape, BuildingType::TShape, BuildingType::Stepped, BuildingType::Hip}, 43, 5000, 4, cloud);
  write_file_atomic(dir + "/city.json", synth_city(bs, Vec3(93000, 436000, 0)).dump());
  write_ply(dir + "/cloud.ply", cloud);
  RefineConfig prm;
  prm.selection.mip_work_limit = 0.02;
  fixtures::CpuBurners burners(2);
  std::map<int, std::string> written;
  int at_budget = 0;
  for (int jobs : {1, 2}) {
    CityRefineOptions o;
    o.jobs = jobs;
    o.on_building = [&](std::size_t, const Mesh&, const CityBuildingOutcome*, const RefineResult* r,
                        const PointCloud*) {
      if (jobs == 1 && r != nullptr && r->trace.selection &&
          r->trace.selection->selection.status == SolveStatus::FeasibleBudget)
        ++at_budget;
    };
    const std::string out = dir + "/out" + std::to_string(jobs) + ".city.json";
    const CityRefineSummary s = refine_city(dir + "/city.json", {dir + "/cloud.ply"}, out, prm, o);
    EXPECT_GE(s.refined, 1);
    std::ifstream f(out, std::ios::binary);
    written[jobs].assign(std::istreambuf_iterator<char>(f), {});
  }
  burners.stop();
  EXPECT_GE(at_budget, 1) << "no selection reached the budget: the test shows nothing";
  EXPECT_EQ(written[1], written[2]) << "--jobs 2 wrote other bytes than --jobs 1";
}

// The progress line: redrawn in place on a terminal (a pty from script(1)), absent from a
// short run into a file and with --quiet; stdout and the exit code the same either way.
TEST(CityFile, ProgressLineOnATerminalOnly) {
  if (std::system("script -V >/dev/null 2>&1") != 0) GTEST_SKIP() << "script(1) absent";
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs =
      synth_street({BuildingType::Gable, BuildingType::LShape, BuildingType::Hip}, 61, 6000, 3, cloud);
  write_file_atomic(dir + "/city.json", synth_city(bs, Vec3(93000, 436000, 0)).dump());
  write_ply(dir + "/cloud.ply", cloud);
  const std::string args =
      "refine --jobs 2 --model " + dir + "/city.json --cloud " + dir + "/cloud.ply --out " + dir + "/o.city.json";
  const Cli plain = run_cli(args, dir);
  ASSERT_EQ(plain.exit, 0) << plain.err;
  EXPECT_EQ(plain.err, "") << "a short run into a file prints no progress";
  EXPECT_NE(plain.out.find("3 building(s)"), std::string::npos) << plain.out;
  auto on_terminal = [&](const std::string& extra) {
    const std::string log = dir + "/tty.log";
    const int st = std::system(
        ("script -qec '" + test_paths::lodrefine_binary() + " " + args + extra + "' /dev/null > " + log + " 2>&1")
            .c_str());
    EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    std::ifstream in(log, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string tty = on_terminal("");
  EXPECT_NE(tty.find("\rrefine: "), std::string::npos) << tty;
  EXPECT_NE(tty.find("\x1b[K"), std::string::npos) << "the redrawn line clears its tail";
  EXPECT_NE(tty.find("refine: 3/3 buildings (100 %)"), std::string::npos) << "the last figures stay: " << tty;
  EXPECT_NE(tty.find(plain.out.substr(0, plain.out.find(" -> "))), std::string::npos) << "stdout unchanged";
  const std::string quiet = on_terminal(" --quiet");
  EXPECT_EQ(quiet.find("refine: "), std::string::npos) << quiet;
}

// Issue 15, items 9 and 11: a building lowered to the ground crashed validation (CGAL's face
// triangulation on a face of no area) and took the whole run down; a building with one vertex
// 1000 km away made the crop grid allocate gigabytes. Both are kept-invalid with their reason,
// the others refined or kept, everything written.
TEST(CityFileSecurity, FlatAndStrayBuildingsAreKeptInvalidTheRunGoesOn) {
  const std::string dir = test_dir();
  PointCloud cloud;
  std::vector<SynthBuilding> bs =
      synth_street({BuildingType::Gable, BuildingType::Hip, BuildingType::Gable}, 1, 6000, 3, cloud);
  double ground = 1e9;
  for (const auto& p : bs[1].coarse.vertices) ground = std::min(ground, p.z());
  for (auto& p : bs[1].coarse.vertices) p.z() = ground;  // the roof lowered onto the ground
  bs[2].coarse.vertices[0] += Vec3(1e6, 0, 0);           // one stray vertex 1000 km away
  const json in = synth_city(bs, Vec3(93000, 436000, 0));
  write_file_atomic(dir + "/city.json", in.dump());
  write_ply(dir + "/cloud.ply", cloud);
  const CityRefineSummary s =
      refine_city(dir + "/city.json", {dir + "/cloud.ply"}, dir + "/out.city.json", RefineConfig{}, {});
  ASSERT_EQ(s.outcomes.size(), 3u);
  EXPECT_NE(s.outcomes[0].outcome, Outcome::KeptInvalid) << s.outcomes[0].reason;
  EXPECT_EQ(s.outcomes[1].outcome, Outcome::KeptInvalid);
  EXPECT_EQ(s.outcomes[2].outcome, Outcome::KeptInvalid);
  EXPECT_NE(s.outcomes[2].reason.find("spans 1000 km, more than a building can"), std::string::npos)
      << s.outcomes[2].reason;
  EXPECT_EQ(s.outcomes[2].points, 0u);
  check_city_output(in, dir + "/out.city.json", s);
}

namespace {

// A CityJSONSeq of one feature per building, as cjseq writes them.
std::string synth_sequence(const std::vector<SynthBuilding>& bs, const Vec3& translate) {
  std::string text = synth_city({}, translate).dump() + "\n";
  for (const auto& b : bs) {
    const json one = synth_city({b}, translate);
    text += json({{"type", "CityJSONFeature"},
                  {"id", b.id},
                  {"CityObjects", one["CityObjects"]},
                  {"vertices", one["vertices"]}})
                .dump() +
            "\n";
  }
  return text;
}

}  // namespace

// The review page of a CityJSONSeq: its features are refined on the pool and finish in any
// order; the page lists them in file order, its map in the first building's frame, so runs with
// any --jobs write the same bytes (the page followed whichever building finished first).
TEST(CityFile, ReviewPageIsTheSameWhateverFinishesFirst) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs = synth_street({BuildingType::Gable, BuildingType::LShape, BuildingType::Hip,
                                                      BuildingType::Shed, BuildingType::TShape, BuildingType::Flat},
                                                     71, 4000, 6, cloud);
  write_file_atomic(dir + "/city.city.jsonl", synth_sequence(bs, Vec3(93000, 436000, 0)));
  write_ply(dir + "/cloud.ply", cloud);
  std::vector<std::string> pages;
  for (const int jobs : {1, 4, 4, 3}) {
    const std::string page = dir + "/review" + std::to_string(pages.size()) + ".html";
    const Cli r = run_cli("refine --quiet --model " + dir + "/city.city.jsonl --cloud " + dir + "/cloud.ply --out " +
                              dir + "/out" + std::to_string(pages.size()) + ".city.jsonl --jobs " +
                              std::to_string(jobs) + " --html " + page,
                          dir);
    ASSERT_EQ(r.exit, 0) << r.err;
    pages.push_back(cli_fixtures::slurp(page));
    EXPECT_TRUE(pages.back() == pages.front()) << "--jobs " << jobs << " wrote another page";
  }
  // In file order: each id's first mention follows the previous one's.
  std::size_t at = 0;
  for (const auto& b : bs) {
    const std::size_t found = pages.front().find(b.id, at);
    ASSERT_NE(found, std::string::npos) << b.id;
    at = found;
  }
}

// The hook is told each building's place in the file, once for each, whatever the threads.
TEST(CityFile, HookSeesEveryBuildingOnceWithItsIndex) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs = synth_street(
      {BuildingType::Gable, BuildingType::Shed, BuildingType::Hip, BuildingType::Gable}, 33, 3000, 3, cloud);
  write_file_atomic(dir + "/city.city.jsonl", synth_sequence(bs, Vec3(93000, 436000, 0)));
  write_ply(dir + "/cloud.ply", cloud);
  std::mutex m;
  std::map<std::size_t, std::string> seen;
  CityRefineOptions o;
  o.jobs = 3;
  o.on_building = [&](std::size_t index, const Mesh& model, const CityBuildingOutcome*, const RefineResult*,
                      const PointCloud*) {
    const std::lock_guard<std::mutex> lock(m);
    EXPECT_TRUE(seen.emplace(index, model.id).second) << index;
  };
  refine_city(dir + "/city.city.jsonl", {dir + "/cloud.ply"}, dir + "/out.city.jsonl", RefineConfig{}, o);
  ASSERT_EQ(seen.size(), bs.size());
  for (std::size_t i = 0; i < bs.size(); ++i) EXPECT_EQ(seen[i], bs[i].id);
}

// Ids are unique in a CityJSONSeq as in a document: a second feature with an id already seen is
// refused in one line naming both, by the reader and by the city refine (both copies were
// refined and written).
TEST(CityFile, SequenceWithAnIdTwiceIsRefused) {
  const std::string dir = test_dir();
  PointCloud cloud;
  std::vector<SynthBuilding> bs = synth_street({BuildingType::Gable, BuildingType::Shed}, 35, 3000, 2, cloud);
  bs[1].id = bs[0].id;
  write_file_atomic(dir + "/city.city.jsonl", synth_sequence(bs, Vec3(93000, 436000, 0)));
  write_ply(dir + "/cloud.ply", cloud);
  const std::string says = "line 3: CityObject \"" + bs[0].id + "\" is in an earlier feature too";
  try {
    read_cityjson(dir + "/city.city.jsonl");
    ADD_FAILURE() << "read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
  }
  try {
    refine_city(dir + "/city.city.jsonl", {dir + "/cloud.ply"}, dir + "/out.city.jsonl", RefineConfig{}, {});
    ADD_FAILURE() << "refined";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir + "/out.city.jsonl"));
}

// A building's "attributes" hold the owner's data and receive the outcome: a value that is no
// object (CityJSON requires one) is refused rather than replaced by the outcome's object.
TEST(CityFile, AttributesThatAreNoObjectAreRefusedNotReplaced) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs = synth_street({BuildingType::Gable}, 37, 3000, 1, cloud);
  json doc = synth_city(bs, Vec3(93000, 436000, 0));
  doc["CityObjects"][bs[0].id]["attributes"] = "owner-notes: keep me";
  write_file_atomic(dir + "/city.json", doc.dump());
  write_ply(dir + "/cloud.ply", cloud);
  try {
    refine_city(dir + "/city.json", {dir + "/cloud.ply"}, dir + "/out.city.json", RefineConfig{}, {});
    ADD_FAILURE() << "refined";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("object " + shown_id(bs[0].id) + ": \"attributes\" is not a JSON object"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(dir + "/out.city.json"));
}

// An LoD is a plain decimal that is the whole string: strtod read "2.2\0<script>…" as 2.2 (and
// the string went to the output) and "0x2.8p0" as 2.5.
TEST(CityFile, LodIsAPlainDecimal) {
  for (const std::string& bad : {std::string("2.2\0<script>", 12), std::string("0x2.8p0"), std::string("2."),
                                 std::string(" 2.2"), std::string("2.2e0"), std::string("")}) {
    EXPECT_FALSE(lod_number(bad)) << bad;
    PointCloud cloud;
    const std::vector<SynthBuilding> bs = synth_street({BuildingType::Gable}, 39, 500, 1, cloud);
    json doc = synth_city(bs, Vec3(93000, 436000, 0));
    doc["CityObjects"][bs[0].id]["geometry"][1]["lod"] = bad;
    try {
      parse_cityjson(doc.dump(), "city.json");
      ADD_FAILURE() << "accepted lod " << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("is not an LoD"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(lod_number("2.2"), 2.2);
  EXPECT_EQ(lod_number("2"), 2.0);
  EXPECT_EQ(lod_number("1.3"), 1.3);
}

// Issue 39: a survey delivered as several files (two parts of a drive; tiles cut along x through
// the buildings, in a folder with a file that is no cloud) refines the city as the one file
// holding their points in that order: the same bytes out, CityJSON and CityJSONSeq; every file
// accounted for.
TEST(CityFile, CloudInSeveralFilesRefinesAsTheMergedFile) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs =
      synth_street({BuildingType::Gable, BuildingType::LShape, BuildingType::Flat}, 11, 8000, 3, cloud);
  write_file_atomic(dir + "/city.json", synth_city(bs, Vec3(93000, 436000, 0)).dump());
  write_file_atomic(dir + "/city.city.jsonl", synth_sequence(bs, Vec3(93000, 436000, 0)));
  PointCloud first, second;  // a drive in two parts
  const std::size_t half = cloud.points.size() * 9 / 20;
  first.points.assign(cloud.points.begin(), cloud.points.begin() + std::ptrdiff_t(half));
  second.points.assign(cloud.points.begin() + std::ptrdiff_t(half), cloud.points.end());
  write_ply(dir + "/merged.ply", cloud);
  write_ply(dir + "/first.ply", first);
  write_ply(dir + "/second.ply", second);
  const CityRefineSummary one = refine_city(dir + "/city.json", {dir + "/merged.ply"}, dir + "/one.city.json", {}, {});
  const CityRefineSummary two =
      refine_city(dir + "/city.json", {dir + "/first.ply", dir + "/second.ply"}, dir + "/two.city.json", {}, {});
  EXPECT_GE(one.refined, 2);
  EXPECT_TRUE(cli_fixtures::slurp(dir + "/two.city.json") == cli_fixtures::slurp(dir + "/one.city.json"));
  ASSERT_EQ(two.outcomes.size(), one.outcomes.size());
  for (std::size_t i = 0; i < one.outcomes.size(); ++i) {
    EXPECT_EQ(two.outcomes[i].outcome, one.outcomes[i].outcome) << one.outcomes[i].id;
    EXPECT_EQ(two.outcomes[i].points, one.outcomes[i].points) << one.outcomes[i].id;
  }
  EXPECT_EQ(two.cloud_points, cloud.points.size());
  EXPECT_EQ(two.cropped_points, one.cropped_points);
  ASSERT_EQ(two.clouds.size(), 2u);
  EXPECT_EQ(two.clouds[0].path, dir + "/first.ply");
  EXPECT_EQ(two.clouds[0].points, first.points.size());
  EXPECT_EQ(two.clouds[1].path, dir + "/second.ply");
  EXPECT_EQ(two.clouds[1].points, second.points.size());
  EXPECT_TRUE(two.warnings.empty());

  // Tiles cut along x, each building's scan in two of them.
  const std::vector<PointCloud> parts = fixtures::split_by_x(cloud, 4);
  fixtures::write_tiles(dir + "/tiles", parts);
  write_file_atomic(dir + "/tiles/index.txt", "tile_00 tile_01 tile_02 tile_03\n");
  write_ply(dir + "/tiles.ply", fixtures::concatenated(parts));
  const std::vector<std::string> tiles = cloud_files({dir + "/tiles"});
  ASSERT_EQ(tiles.size(), 4u);
  for (const std::string name : {"city.json", "city.city.jsonl"}) {
    const std::string model = dir + "/" + name, merged = dir + "/tiles_" + name, split = dir + "/split_" + name;
    const CityRefineSummary m = refine_city(model, {dir + "/tiles.ply"}, merged, {}, {});
    const CityRefineSummary s = refine_city(model, tiles, split, {}, {});
    EXPECT_GE(m.refined, 2) << name;
    EXPECT_EQ(s.refined, m.refined) << name;
    EXPECT_TRUE(cli_fixtures::slurp(split) == cli_fixtures::slurp(merged)) << name;
    ASSERT_EQ(s.clouds.size(), 4u);
    for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(s.clouds[k].points, parts[k].points.size()) << k;
  }
}

// A file of another area among the cloud files is named on its own line, in the summary, on
// stdout and in the report, and the buildings get the other files' points; when no file reaches
// the model the run is refused as with one file.
TEST(CityFile, ACloudFileOfAnotherAreaIsNamed) {
  const std::string dir = test_dir();
  PointCloud cloud;
  const std::vector<SynthBuilding> bs = synth_street({BuildingType::Gable}, 5, 4000, 1, cloud);
  write_file_atomic(dir + "/city.json", synth_city(bs, Vec3(93000, 436000, 0)).dump());
  PointCloud far = cloud;
  for (auto& p : far.points) p += Vec3(-50000, 70000, 0);  // another tile, or another CRS
  const std::string near_path = dir + "/near.ply", far_path = dir + "/far.ply", far2_path = dir + "/far2.ply";
  write_ply(near_path, cloud);
  write_ply(far_path, far);
  write_ply(far2_path, far);
  const CityRefineSummary alone = refine_city(dir + "/city.json", {near_path}, dir + "/alone.city.json", {}, {});
  const CityRefineSummary s = refine_city(dir + "/city.json", {near_path, far_path}, dir + "/out.city.json", {}, {});
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0].rfind(far_path + ": cloud x 4", 0), 0u) << s.warnings[0];
  EXPECT_NE(s.warnings[0].find("does not overlap the city model x 92"), std::string::npos) << s.warnings[0];
  EXPECT_TRUE(alone.warnings.empty());
  EXPECT_EQ(s.cloud_points, 2 * cloud.points.size());
  EXPECT_EQ(s.cropped_points, alone.cropped_points);
  EXPECT_TRUE(cli_fixtures::slurp(dir + "/out.city.json") == cli_fixtures::slurp(dir + "/alone.city.json"));
  try {
    refine_city(dir + "/city.json", {far_path, far2_path}, dir + "/none.city.json", {}, {});
    ADD_FAILURE() << "no file reaches the model";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(far_path + " and 1 other cloud file: cloud x 4", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not overlap the city model"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir + "/none.city.json"));

  // The command line: a warning line per file on stdout, every file in the report.
  const Cli r = run_cli("refine --quiet --model " + dir + "/city.json --cloud " + near_path + " --cloud " + far_path +
                            " --out " + dir + "/cli.city.json --report " + dir + "/report.json",
                        dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out.rfind("warning: " + far_path + ": cloud x 4", 0), 0u) << r.out;
  EXPECT_EQ(r.out.find("warning: " + near_path), std::string::npos) << r.out;
  const json report = load(dir + "/report.json");
  ASSERT_EQ(report["warnings"].size(), 1u);
  EXPECT_EQ(report["warnings"][0], s.warnings[0]);
  EXPECT_FALSE(report["cloud"].contains("path")) << "several files: each in files";
  ASSERT_EQ(report["cloud"]["files"].size(), 2u);
  EXPECT_EQ(report["cloud"]["files"][0]["path"], near_path);
  EXPECT_EQ(report["cloud"]["files"][0]["points"], cloud.points.size());
  EXPECT_EQ(report["cloud"]["files"][1]["path"], far_path);
  const Eigen::AlignedBox3d far_box = bounding_box(far.points);
  EXPECT_EQ(report["cloud"]["files"][1]["bounds"]["min"],
            json({far_box.min().x(), far_box.min().y(), far_box.min().z()}));
  EXPECT_EQ(report["cloud"]["files"][1]["bounds"]["max"],
            json({far_box.max().x(), far_box.max().y(), far_box.max().z()}));
  const Cli single = run_cli("refine --quiet --model " + dir + "/city.json --cloud " + near_path + " --out " + dir +
                                 "/single.city.json --report " + dir + "/single.json",
                             dir);
  ASSERT_EQ(single.exit, 0) << single.err;
  const json single_report = load(dir + "/single.json");
  EXPECT_EQ(single_report["cloud"]["path"], near_path);
  EXPECT_EQ(single_report["cloud"]["files"].size(), 1u);
  EXPECT_FALSE(single_report.contains("warnings"));
}
