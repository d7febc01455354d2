// Fins in a written city file, read from its JSON directly (what any CityJSON reader sees,
// independent of ours): a MultiSurface of a Solid's LoD right after it, in a building lodrefine
// wrote, and how far its vertices stand off the Solid.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <vector>

#include "lodrefine/base/geometry.h"
#include "lodrefine/core/distance.h"
#include "lodrefine/refine/refine.h"

namespace lodrefine::fixtures {

// The surfaces of geometry `g` of `doc` (a Solid's exterior shell, or a MultiSurface), outer
// rings only, in the file's frame.
inline Mesh geometry_mesh(const nlohmann::ordered_json& doc, const nlohmann::ordered_json& g) {
  const auto& tf = doc["transform"];
  Mesh m;
  const auto& surfaces = g["type"] == "Solid" ? g["boundaries"][0] : g["boundaries"];
  for (const auto& surface : surfaces) {
    Face f;
    for (const auto& i : surface[0]) {
      const auto& q = doc["vertices"][i.get<std::size_t>()];
      Vec3 p;
      for (int a = 0; a < 3; ++a)
        p[a] = q[a].get<double>() * tf["scale"][a].get<double>() + tf["translate"][a].get<double>();
      f.v.push_back(int(m.vertices.size()));
      m.vertices.push_back(p);
    }
    m.faces.push_back(f);
  }
  return m;
}

// How far the fins stand apart from `solid` (m): over the connected pieces of `fins` (faces
// meeting at a vertex position, to 0.1 mm), the largest of each piece's nearest distance to the
// solid. A fin standing on its solid gives ~0; one left floating beside a moved wall, its offset.
inline double fins_apart(const Mesh& fins, const Mesh& solid) {
  const Vec3 o = local_origin(solid);
  const MeshDistance to_solid(translated(solid, -o));
  std::vector<int> parent(fins.faces.size());
  for (std::size_t k = 0; k < parent.size(); ++k) parent[k] = int(k);
  const std::function<int(int)> root = [&](int k) { return parent[k] == k ? k : parent[k] = root(parent[k]); };
  std::map<std::array<long long, 3>, int> first_face;
  for (std::size_t k = 0; k < fins.faces.size(); ++k)
    for (int v : fins.faces[k].v) {
      const Vec3& p = fins.vertices[std::size_t(v)];
      const std::array<long long, 3> key = {std::llround(p.x() * 1e4), std::llround(p.y() * 1e4),
                                            std::llround(p.z() * 1e4)};
      const auto [it, added] = first_face.emplace(key, int(k));
      if (!added) parent[std::size_t(root(int(k)))] = root(it->second);
    }
  std::map<int, double> nearest;  // piece root -> its nearest vertex distance
  for (std::size_t k = 0; k < fins.faces.size(); ++k)
    for (int v : fins.faces[k].v) {
      const double d = to_solid.distance(fins.vertices[std::size_t(v)] - o, false);
      auto [it, added] = nearest.emplace(root(int(k)), d);
      if (!added) it->second = std::min(it->second, d);
    }
  double worst = 0.0;
  for (const auto& [piece, d] : nearest) worst = std::max(worst, d);
  return worst;
}

struct FinsInFile {
  int buildings = 0;     // with fins beside their Solid
  double apart = 0.0;    // m: the fins farthest apart from their Solid (fins_apart), over the file
  std::string worst_id;  // the building it is in
};

// Every building of `doc` lodrefine wrote with fins beside its Solid.
inline FinsInFile fins_in_file(const nlohmann::ordered_json& doc) {
  FinsInFile out;
  for (const auto& [id, obj] : doc["CityObjects"].items()) {
    if (!obj.contains("attributes") || !obj["attributes"].contains("lodrefine_outcome")) continue;
    const auto& g = obj["geometry"];
    for (std::size_t k = 0; k + 1 < g.size(); ++k) {
      if (g[k]["type"] != "Solid" || g[k + 1]["type"] != "MultiSurface" || g[k + 1]["lod"] != g[k]["lod"]) continue;
      ++out.buildings;
      const double d = fins_apart(geometry_mesh(doc, g[k + 1]), geometry_mesh(doc, g[k]));
      if (d > out.apart) out.apart = d, out.worst_id = id;
    }
  }
  return out;
}

}  // namespace lodrefine::fixtures
