// CityJSON 1.x made 2.0 (see cityjson_upgrade.h).
#include "cityjson_upgrade.h"

#include <cmath>
#include <sstream>

#include "lodrefine/base/types.h"
#include "lodrefine/formats/citygml.h"
#include "lodrefine/formats/cityjson_write.h"

namespace lodrefine {

using json = nlohmann::ordered_json;

void upgrade_objects(json& objects) {
  for (auto& [id, obj] : objects.items()) {
    if (!obj.is_object()) continue;
    const auto type = obj.find("type");
    if (type != obj.end() && type->is_string() && *type == "+GenericCityObject") *type = "GenericCityObject";
    if (!obj.contains("geometry") || !obj["geometry"].is_array()) continue;
    for (auto& g : obj["geometry"])
      if (g.is_object() && g.contains("lod") && g["lod"].is_number()) {
        std::ostringstream s;
        s << g["lod"].get<double>();
        g["lod"] = s.str();
      }
  }
}

void upgrade_header(json& doc) {
  json& md = doc["metadata"];
  if (!md.is_object()) {
    doc.erase("metadata");
    return;
  }
  if (md.contains("referenceSystem") && md["referenceSystem"].is_string())
    md["referenceSystem"] = crs_url(md["referenceSystem"].get<std::string>());
  if (md.contains("pointOfContact") && md["pointOfContact"].is_object()) {
    json& poc = md["pointOfContact"];
    if (poc.contains("address") && poc["address"].is_string()) poc["address"] = {{"addressLine", poc["address"]}};
  }
}

void ensure_transform(json& doc) {
  if (doc.contains("transform")) return;
  Eigen::AlignedBox3d box;
  for (const auto& v : doc["vertices"]) box.extend(Vec3(v[0].get<double>(), v[1].get<double>(), v[2].get<double>()));
  const Vec3 translate = box.isEmpty() ? Vec3::Zero() : Vec3(box.min().array().floor());
  const double scale = kCityGmlResolution;
  for (auto& v : doc["vertices"])
    for (int a = 0; a < 3; ++a) v[a] = std::llround((v[a].get<double>() - translate[a]) / scale);
  doc["transform"] = {{"scale", {scale, scale, scale}}, {"translate", {translate.x(), translate.y(), translate.z()}}};
}

}  // namespace lodrefine
