// Every building of a city file validated under val3dity's codes (see validity.h).
#include "lodrefine/city/validity.h"

#include <map>
#include <set>

#include "lodrefine/base/files.h"
#include "lodrefine/city/refine_report.h"
#include "lodrefine/formats/citygml.h"
#include "lodrefine/formats/cityjson.h"
#include "lodrefine/version.h"

namespace lodrefine {

int CityValidity::invalid() const {
  int n = 0;
  for (const BuildingValidity& b : buildings) n += b.valid() ? 0 : 1;
  return n;
}

CityValidity validate_city(const std::string& path, const std::string& lod, const ValidityTolerances& tolerances) {
  const bool gml = sniff_file(path) == FileKind::Xml;
  if (gml && !lod.empty() && lod != "2")
    throw InputError(path + ": CityGML buildings are read at LoD 2 only (--lod " + lod + ")");
  const CityJsonFile file = gml ? read_citygml(path) : read_cityjson(path, lod);
  CityValidity out;
  out.path = path;
  out.tolerances = tolerances;
  out.input_format = file.format + (file.sequence ? "Seq " : " ") + file.version;
  out.ids_without_lod = file.ids_without_lod2;
  if (file.buildings.empty())
    throw InputError(path + ": no Building/BuildingPart with " +
                     (lod.empty() ? std::string("an LoD 2.x") : "an LoD " + lod) + " geometry (" +
                     std::to_string(file.objects_without_lod2) +
                     " building object(s) without one); nothing to validate");
  for (const CityJsonBuilding& b : file.buildings) {
    BuildingValidity v{b.mesh.id, b.type, b.lod, b.geometry_type, validate_soup(solid_soup(b), tolerances)};
    if (b.skipped_rings > 0) {  // dropped by the reader: the faces validated are without them
      v.validation.errors.insert(
          v.validation.errors.begin(),
          {ValidityCode::TooFewPoints,
           {},
           std::to_string(b.skipped_rings) + " ring(s) with fewer than 3 distinct vertices (left out of the shell)"});
      if (v.validation.problem.empty()) v.validation.problem = v.validation.errors.front().info;
    }
    out.buildings.push_back(std::move(v));
  }
  return out;
}

namespace {

// {type, total, valid} per key, keys in order.
nlohmann::json overview(const std::map<std::string, std::pair<int, int>>& counts) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& [type, n] : counts) out.push_back({{"type", type}, {"total", n.first}, {"valid", n.second}});
  return out;
}

}  // namespace

nlohmann::json validity_report_json(const CityValidity& city) {
  nlohmann::json features = nlohmann::json::array();
  std::map<std::string, std::pair<int, int>> by_feature, by_primitive;
  std::set<int> all;
  for (const BuildingValidity& b : city.buildings) {
    for (auto* counts : {&by_feature[b.type], &by_primitive[b.geometry_type]})
      ++counts->first, counts->second += b.valid();
    for (int code : error_codes(b.validation)) all.insert(code);
    features.push_back({{"id", b.id},
                        {"type", b.type},
                        {"validity", b.valid()},
                        {"errors", validity_errors_json(b.validation.errors)},
                        {"lod", b.lod},
                        {"geometry_type", b.geometry_type}});
  }
  return {{"type", "val3dity_report"},
          {"generator", "lodrefine " LODREFINE_VERSION},
          {"input_file", city.path},
          {"input_file_type", city.input_format},
          {"parameters", {{"snap_tol", city.tolerances.snap}, {"planarity_d2p_tol", city.tolerances.planarity}}},
          {"features_overview", overview(by_feature)},
          {"primitives_overview", overview(by_primitive)},
          {"features", std::move(features)},
          {"dataset_errors", nlohmann::json::array()},
          {"all_errors", std::vector<int>(all.begin(), all.end())},
          {"validity", city.invalid() == 0}};
}

std::string errors_text(const std::vector<ValidityError>& errors) {
  std::string out;
  for (const ValidityError& e : errors)
    out +=
        (out.empty() ? "" : "; ") + std::to_string(code_number(e.code)) + " " + code_name(e.code) + " (" + e.info + ")";
  return out;
}

}  // namespace lodrefine
