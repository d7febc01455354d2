// A city file in, a city file out: generated buildings in a CityJSON file refined with a cloud;
// every building accounted for, the untouched ones byte-identical, the output schema-valid
// (CityJSON 2.0.2, python3-jsonschema) and its refined geometry valid by the project's own check;
// the buildings that cannot be refined, repair, fins, attributes and the LoD chosen.
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
