// Writing CityJSON geometry (see cityjson_write.h).
#include "lodrefine/formats/cityjson_write.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

namespace lodrefine {

using json = nlohmann::ordered_json;

namespace {

// `mesh`'s faces as a geometry with semantics (a Solid of one shell when `solid`, else a
// MultiSurface), its vertices appended to `vertices` quantised by the transform.
json cityjson_surfaces(const Mesh& mesh, bool solid, const std::string& lod, const Vec3& scale, const Vec3& translate,
                       json& vertices) {
  const long long base = (long long)vertices.size();
  for (const auto& p : mesh.vertices) {
    json q = json::array();
    for (int a = 0; a < 3; ++a) q.push_back(std::llround((p[a] - translate[a]) / scale[a]));
    vertices.push_back(std::move(q));
  }
  json shell = json::array(), values = json::array();
  // One semantic surface per semantic, provenance and coverage (in hundredths).
  std::map<std::tuple<Semantic, Provenance, long>, int> surface_of;
  json surfaces = json::array();
  for (const Face& f : mesh.faces) {
    json ring = json::array();
    for (int v : f.v) ring.push_back(base + v);
    shell.push_back(json::array({std::move(ring)}));
    if (f.sem == Semantic::Other) {
      values.push_back(nullptr);
      continue;
    }
    const bool scan = f.provenance == Provenance::Scan;
    const long hundredths = scan ? std::lround(std::clamp(f.coverage, 0.0, 1.0) * 100.0) : 0;
    auto it = surface_of.find({f.sem, f.provenance, hundredths});
    if (it == surface_of.end()) {
      it = surface_of.emplace(std::make_tuple(f.sem, f.provenance, hundredths), int(surfaces.size())).first;
      json surface = {{"type", semantic_name(f.sem)}};
      if (f.provenance != Provenance::None) surface["lodrefine_source"] = provenance_name(f.provenance);
      if (scan) surface["lodrefine_coverage"] = double(hundredths) / 100.0;
      surfaces.push_back(std::move(surface));
    }
    values.push_back(it->second);
  }
  json g = {{"type", solid ? "Solid" : "MultiSurface"},
            {"lod", lod},
            {"boundaries", solid ? json::array({std::move(shell)}) : std::move(shell)}};
  g["semantics"] = {{"surfaces", std::move(surfaces)},
                    {"values", solid ? json::array({std::move(values)}) : std::move(values)}};
  return g;
}

}  // namespace

json cityjson_solid(const Mesh& mesh, const std::string& lod, const Vec3& scale, const Vec3& translate,
                    json& vertices) {
  return cityjson_surfaces(mesh, true, lod, scale, translate, vertices);
}

json cityjson_multisurface(const Mesh& mesh, const std::string& lod, const Vec3& scale, const Vec3& translate,
                           json& vertices) {
  return cityjson_surfaces(mesh, false, lod, scale, translate, vertices);
}

}  // namespace lodrefine
