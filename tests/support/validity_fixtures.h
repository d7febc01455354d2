// City files of crafted boxes for `lodrefine validate` and `repair` (tests/app/test_validate.cpp,
// test_repair.cpp): each building a 10 x 8 x 6 m box Solid, with faces left out or turned over.
#pragma once
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace validity_fixtures {

struct BoxBuilding {
  std::string id;
  std::vector<int> missing;  // faces left out (0 ground, 1 roof, 2..5 walls)
  std::vector<int> flipped;  // faces turned over
  double x = 0.0;            // where it stands (m east of the others)
};

// A CityJSON 2.0 file of the boxes (transform 1 mm, georeferenced near Rotterdam), one Solid of
// LoD 2.2 with semantics each.
inline std::string box_city(const std::vector<BoxBuilding>& buildings) {
  using json = nlohmann::json;
  const double box[8][3] = {{0, 0, 0}, {10, 0, 0}, {10, 8, 0}, {0, 8, 0}, {0, 0, 6}, {10, 0, 6}, {10, 8, 6}, {0, 8, 6}};
  const int quads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  json doc = {{"type", "CityJSON"},
              {"version", "2.0"},
              {"transform", {{"scale", {0.001, 0.001, 0.001}}, {"translate", {92000.0, 437000.0, 0.0}}}},
              {"metadata", {{"referenceSystem", "https://www.opengis.net/def/crs/EPSG/0/7415"}}},
              {"CityObjects", json::object()},
              {"vertices", json::array()}};
  for (const BoxBuilding& b : buildings) {
    const long long base = (long long)doc["vertices"].size();
    for (const auto& p : box)
      doc["vertices"].push_back(
          {std::llround((p[0] + b.x) * 1000), std::llround(p[1] * 1000), std::llround(p[2] * 1000)});
    json shell = json::array(), values = json::array();
    for (int f = 0; f < 6; ++f) {
      if (std::count(b.missing.begin(), b.missing.end(), f)) continue;
      std::vector<long long> ring;
      for (int k : quads[f]) ring.push_back(base + k);
      if (std::count(b.flipped.begin(), b.flipped.end(), f)) std::reverse(ring.begin(), ring.end());
      shell.push_back({ring});
      values.push_back(f == 0 ? 0 : f == 1 ? 1 : 2);
    }
    doc["CityObjects"][b.id] = {
        {"type", "Building"},
        {"attributes", {{"name", b.id}}},
        {"geometry",
         {{{"type", "Solid"},
           {"lod", "2.2"},
           {"boundaries", {shell}},
           {"semantics",
            {{"surfaces", {{{"type", "GroundSurface"}}, {{"type", "RoofSurface"}}, {{"type", "WallSurface"}}}},
             {"values", {values}}}}}}}};
  }
  return doc.dump();
}

}  // namespace validity_fixtures
