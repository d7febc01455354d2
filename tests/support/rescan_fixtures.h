// A small dev tile (the ../shared/devtiles layout) for `synth --rescan`: a terrace of three
// 12 x 8 x 7 m boxes along x (A, B, C), B the tile's one building, and a CityJSON file holding
// all three (B's copy optionally shifted, as a coarse city's would be).
#pragma once
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lodrefine/base/files.h"
#include "lodrefine/base/types.h"

namespace rescan_fixtures {

namespace fs = std::filesystem;
using json = nlohmann::json;
using lodrefine::Vec3;

inline const Vec3 kTileOrigin(85000.0, 447000.0, 0.0);

// The box [x0, x0 + 12] x [y0, y0 + 8] x [0, 7] (local to kTileOrigin): its 8 corners and its
// faces as corner indices, outward; ground, roof, then the walls front (y = y0, facing -y, wall
// 0), right, back, left.
inline std::vector<Vec3> box_corners(double x0, double y0) {
  std::vector<Vec3> c;
  for (double z : {0.0, 7.0})
    for (const auto& [x, y] : {std::pair{0.0, 0.0}, {12.0, 0.0}, {12.0, 8.0}, {0.0, 8.0}})
      c.push_back(Vec3(x0 + x, y0 + y, z));
  return c;
}
inline const int kBoxFaces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
inline const char* const kBoxGroups[6] = {"GroundSurface", "RoofSurface", "WallSurface",
                                          "WallSurface",   "WallSurface", "WallSurface"};

// OBJ text of the box at x0 (front at y0), georeferenced; `extra` is appended.
inline std::string box_obj_text(double x0, double y0, const std::string& extra = "") {
  std::ostringstream s;
  s.precision(12);
  s << "o B\n";
  for (const Vec3& p : box_corners(x0, y0)) {
    const Vec3 q = p + kTileOrigin;
    s << "v " << q.x() << " " << q.y() << " " << q.z() << "\n";
  }
  for (int f = 0; f < 6; ++f)
    s << "g " << kBoxGroups[f] << "\nf " << kBoxFaces[f][0] + 1 << " " << kBoxFaces[f][1] + 1 << " "
      << kBoxFaces[f][2] + 1 << " " << kBoxFaces[f][3] + 1 << "\n";
  return s.str() + extra;
}

// CityJSON 2.0 with the boxes A (x0 = -12), B (x0 = 0, its front at b_front) and C (x0 = 12),
// each a Solid at LoD 2.2 with wall, roof and ground semantics.
inline std::string terrace_city(double b_front = 0.0) {
  json doc = {{"type", "CityJSON"},
              {"version", "2.0"},
              {"transform", {{"scale", {0.001, 0.001, 0.001}}, {"translate", {kTileOrigin.x(), kTileOrigin.y(), 0.0}}}},
              {"CityObjects", json::object()},
              {"vertices", json::array()}};
  const std::pair<const char*, Vec3> boxes[] = {
      {"A", Vec3(-12, 0, 0)}, {"B", Vec3(0, b_front, 0)}, {"C", Vec3(12, 0, 0)}};
  for (const auto& [id, at] : boxes) {
    const int first = int(doc["vertices"].size());
    for (const Vec3& p : box_corners(at.x(), at.y()))
      doc["vertices"].push_back({std::llround(p.x() * 1000), std::llround(p.y() * 1000), std::llround(p.z() * 1000)});
    json shell = json::array(), values = json::array();
    for (int f = 0; f < 6; ++f) {
      json ring = json::array();
      for (int k : kBoxFaces[f]) ring.push_back(first + k);
      shell.push_back({ring});
      values.push_back(f == 0 ? 0 : f == 1 ? 1 : 2);
    }
    const json semantics = {
        {"surfaces", {{{"type", "GroundSurface"}}, {{"type", "RoofSurface"}}, {{"type", "WallSurface"}}}},
        {"values", {values}}};
    doc["CityObjects"][id] = {
        {"type", "Building"},
        {"geometry", {{{"type", "Solid"}, {"lod", "2.2"}, {"boundaries", {shell}}, {"semantics", semantics}}}}};
  }
  return doc.dump();
}

// Files through the library's own helpers (the tests write small fixtures, read outputs whole).
inline void write_text(const fs::path& path, const std::string& text) {
  lodrefine::write_file_atomic(path.string(), text);
}
inline std::string read_bytes(const fs::path& path) { return lodrefine::read_file(path.string()); }

// Writes <root>/tile/{meta.json, truth/B.obj, models/B.obj} (the model's front 0.4 m out) and
// <root>/city.json (terrace_city()). `building` is meta's entry; returns the tile's folder.
inline std::string write_tile(const fs::path& root,
                              const json& building = {{"id", "B"}, {"cityjson_id", "B"}, {"scanned_walls", {0}}}) {
  fs::remove_all(root);
  fs::create_directories(root / "tile" / "truth");
  fs::create_directories(root / "tile" / "models");
  write_text(root / "tile" / "meta.json",
             json{{"origin", {kTileOrigin.x(), kTileOrigin.y(), 0.0}}, {"buildings", {building}}}.dump());
  write_text(root / "tile" / "truth" / "B.obj", box_obj_text(0, 0));
  write_text(root / "tile" / "models" / "B.obj", box_obj_text(0, -0.4));
  write_text(root / "city.json", terrace_city());
  return (root / "tile").string();
}

// Writes <root>/tile with `count` boxes 30 m apart along x (ids B00, B01, ...: truth, and a model
// with its front 0.4 m out), each scanned on its front wall, and no city file. Returns the tile.
inline std::string write_row_tile(const fs::path& root, int count) {
  fs::remove_all(root);
  fs::create_directories(root / "tile" / "truth");
  fs::create_directories(root / "tile" / "models");
  json buildings = json::array();
  for (int i = 0; i < count; ++i) {
    const std::string id = (i < 10 ? "B0" : "B") + std::to_string(i);
    write_text(root / "tile" / "truth" / (id + ".obj"), box_obj_text(30.0 * i, 0));
    write_text(root / "tile" / "models" / (id + ".obj"), box_obj_text(30.0 * i, -0.4));
    buildings.push_back({{"id", id}, {"scanned_walls", {0}}});
  }
  write_text(root / "tile" / "meta.json",
             json{{"origin", {kTileOrigin.x(), kTileOrigin.y(), 0.0}}, {"buildings", buildings}}.dump());
  return (root / "tile").string();
}

// OBJ text of a face of `n` vertices on a circle of 3 m about (6, 4, 3) (local, georeferenced by
// kTileOrigin), its vertices numbered from `first` (1-based): a huge face to append.
inline std::string circle_face_obj(int n, int first) {
  std::ostringstream s;
  s.precision(12);
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    s << "v " << kTileOrigin.x() + 6 + 3 * std::cos(a) << " " << kTileOrigin.y() + 4 + 3 * std::sin(a) << " 3\n";
  }
  s << "g RoofSurface\nf";
  for (int k = 0; k < n; ++k) s << " " << first + k;
  return s.str() + "\n";
}

}  // namespace rescan_fixtures
