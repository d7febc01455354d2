// The city-file tests' fixtures (tests/city/test_cityfile*.cpp): generated buildings as a
// CityJSON document or CityJSONSeq, and the contract checked on a written city file (every
// building accounted for, the untouched and kept ones as read, the refined ones valid Solids).
#pragma once
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "lodrefine/base/geometry.h"
#include "lodrefine/city/cityfile.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/formats/cityjson.h"
#include "lodrefine/refine/refine.h"
#include "lodrefine/synth/synth.h"
#include "support/cli_fixtures.h"
#include "support/scan_fixtures.h"
#include "support/schema_fixtures.h"

namespace lodrefine::city_fixtures {

using json = nlohmann::ordered_json;
using cli_fixtures::Cli;
using cli_fixtures::run_cli;
using fixtures::sample_face;
using schema_fixtures::schema_verdict;
using schema_fixtures::shared_dir;

// Validation at the parameter table's planarity tolerance.
inline double planarity() { return RefineConfig{}.repair.planarity_tolerance; }

inline std::string test_dir() { return cli_fixtures::test_dir("lodrefine_city"); }

inline json load(const std::string& path) {
  std::ifstream in(path);
  return json::parse(in);
}

// The building's faces welded on identical coordinates (the file's integers), then checked.
inline std::string geometry_problem(const Mesh& soup) {
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
  const Validation v = validate_mesh(translated(m, -o), planarity());
  return v.valid() ? "" : v.problem;
}

// A CityJSON 2.0 document of generated buildings: the coarse soup as an LoD 2.2 MultiSurface
// with semantics, plus an LoD 1 block and attributes, so the test sees both kept exactly.
inline json synth_city(const std::vector<SynthBuilding>& bs, const Vec3& translate) {
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

// The outcome's attributes of a building the city refine reached (`o`, written from `obj`)
// checked against its reported outcome `r` (named `outcome`), then erased: what is left is the
// object as read.
inline void without_outcome_attributes(json& o, const json& obj, const CityBuildingOutcome& r,
                                       const std::string& outcome) {
  const std::string id = r.id;
  EXPECT_EQ(o["attributes"]["lodrefine_outcome"], outcome) << id;
  // The codes only where the building had or has errors (issue 50): a valid one's
  // attributes stay as read but for its outcome.
  const bool codes = !r.errors_before.empty() || !r.errors_after.empty();
  EXPECT_EQ(o["attributes"].contains("lodrefine_errors_before"), codes) << id;
  EXPECT_EQ(o["attributes"].contains("lodrefine_errors_after"), codes) << id;
  if (codes) {
    EXPECT_EQ(o["attributes"]["lodrefine_errors_before"], json(error_codes(r.errors_before))) << id;
    EXPECT_EQ(o["attributes"]["lodrefine_errors_after"], json(error_codes(r.errors_after))) << id;
  }
  for (const char* k : {"lodrefine_outcome", "lodrefine_reason", "lodrefine_facades_moved", "lodrefine_errors_before",
                        "lodrefine_errors_after"})
    o["attributes"].erase(k);
  if (o["attributes"].empty() && !obj.contains("attributes")) o.erase("attributes");
}

// Refined and repaired buildings of a written city file (`outcome`: id -> outcome name) are
// Solids (their fins apart) that pass the project's validity check, with walls, roof and ground.
inline void expect_valid_solids(const std::string& out_path, const std::map<std::string, std::string>& outcome) {
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
}

// Checks the contract on an output: counts add up, untouched and kept buildings identical to
// the input (objects and their vertices), refined and repaired ones a valid Solid with semantics,
// schema.
inline void check_city_output(const json& in, const std::string& out_path, const CityRefineSummary& s) {
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
    if (it != outcome.end()) without_outcome_attributes(o, obj, *reported.at(id), it->second);
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
  expect_valid_solids(out_path, outcome);
  const std::string verdict = schema_verdict(out_path);
  if (!verdict.empty()) {
    EXPECT_EQ(verdict, "valid");
  }
  std::printf("  %s: %d building(s): %d refined, %d repaired, %d kept, %d kept-invalid, %d untouched; schema: %s\n",
              out_path.c_str(), s.buildings, s.refined, s.repaired, s.kept, s.kept_invalid, s.untouched,
              verdict.empty() ? "not checked (validator or schemas absent)" : verdict.c_str());
}

// Generated buildings 80 m apart along x and the clouds of the first `scanned` of them.
inline std::vector<SynthBuilding> synth_street(const std::vector<BuildingType>& types, std::uint64_t first_seed,
                                               int points, std::size_t scanned, PointCloud& cloud) {
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

// A CityJSONSeq of one feature per building, as cjseq writes them.
inline std::string synth_sequence(const std::vector<SynthBuilding>& bs, const Vec3& translate) {
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

}  // namespace lodrefine::city_fixtures
