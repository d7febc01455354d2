// City file in, city file out (see cityfile.h).
#include "lodrefine/cityfile.h"

#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "lodrefine/cityjson.h"
#include "lodrefine/citygml.h"
#include "lodrefine/cityjson_write.h"
#include "lodrefine/crop.h"
#include "lodrefine/io.h"
#include "lodrefine/refine.h"

namespace lodrefine {
namespace {

using json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// The outcome of one building in the three words of the report, with its reason: anything
// refine_building does not call "refined" is kept (its original geometry stays), and a kept
// building whose repaired original is not valid either is kept-invalid.
CityBuildingOutcome classify(const RefineResult& r) {
  CityBuildingOutcome o;
  const std::string& s = r.outcome;
  if (r.refined && r.valid && s == "refined") {
    o.outcome = "refined";
  } else {
    o.outcome = (!r.valid || s.rfind("kept-invalid", 0) == 0) ? "kept-invalid" : "kept";
    o.reason = r.report.value("reason", std::string());
    const auto open = s.find('('), close = s.rfind(')');
    if (o.reason.empty() && open != std::string::npos && close != std::string::npos && close > open)
      o.reason = s.substr(open + 1, close - open - 1);
    if (o.reason.empty()) o.reason = s;
    if (!r.valid && r.report.contains("output_validation"))
      o.reason += " (not valid: " + r.report["output_validation"].value("problem", std::string("invalid")) + ")";
  }
  if (r.report.contains("replacements"))
    for (const auto& step : r.report["replacements"]) o.facades_moved += step.value("ok", false) ? 1 : 0;
  if (o.outcome != "refined") o.facades_moved = 0;
  return o;
}

Eigen::AlignedBox3d model_box(const std::vector<CityJsonBuilding>& buildings) {
  Eigen::AlignedBox3d box;
  for (const auto& b : buildings)
    for (const auto& v : b.mesh.vertices) box.extend(v);
  return box;
}

// One document (a whole CityJSON file, or one CityJSONFeature with the header's transform):
// its buildings and the crop targets the cloud pass fills.
struct Work {
  std::vector<CityJsonBuilding> buildings;
  std::vector<std::size_t> target_of;  // per building: index into the targets, or npos
};

// Refines the buildings of `doc` that have points and writes the results into `doc`.
void refine_document(json& doc, const std::vector<CityJsonBuilding>& buildings, std::vector<CropTarget>& targets,
                     const std::vector<std::size_t>& target_of, const Params& params, CityRefineSummary& sum) {
  const json& t = doc.contains("transform") ? doc["transform"] : json();
  const Vec3 scale = t.is_object() ? Vec3(t["scale"][0], t["scale"][1], t["scale"][2]) : Vec3::Ones();
  const Vec3 translate = t.is_object() ? Vec3(t["translate"][0], t["translate"][1], t["translate"][2]) : Vec3::Zero();
  json& objects = doc["CityObjects"];
  for (std::size_t i = 0; i < buildings.size(); ++i) {
    const CityJsonBuilding& b = buildings[i];
    if (target_of[i] == std::string::npos || targets[target_of[i]].cloud.points.empty()) {
      ++sum.untouched;
      continue;
    }
    PointCloud cloud = std::move(targets[target_of[i]].cloud);
    targets[target_of[i]].cloud = PointCloud();  // the crop is no longer needed: free it now
    const auto t0 = Clock::now();
    CityBuildingOutcome o;
    RefineResult r;
    try {
      r = refine_building(b.mesh, cloud, params);
      o = classify(r);
    } catch (const std::exception& e) {  // never lose a building: keep it as read
      o.outcome = "kept-invalid";
      o.reason = e.what();
    }
    o.id = b.mesh.id;
    o.points = cloud.points.size();
    o.seconds = seconds_since(t0);
    json& obj = objects[b.mesh.id];
    if (o.outcome == "refined") {
      const std::string lod = obj["geometry"][std::size_t(b.geometry_index)]["lod"].is_string()
                                  ? obj["geometry"][std::size_t(b.geometry_index)]["lod"].get<std::string>()
                                  : b.lod;
      obj["geometry"][std::size_t(b.geometry_index)] = cityjson_solid(r.mesh, lod, scale, translate, doc["vertices"]);
      ++sum.refined;
    } else {
      ++(o.outcome == "kept" ? sum.kept : sum.kept_invalid);
    }
    if (!obj.contains("attributes") || !obj["attributes"].is_object()) obj["attributes"] = json::object();
    obj["attributes"]["lodrefine_outcome"] = o.outcome;
    obj["attributes"]["lodrefine_reason"] = o.reason;
    obj["attributes"]["lodrefine_facades_moved"] = o.facades_moved;
    sum.outcomes.push_back(std::move(o));
  }
}

// CityJSON 1.x without a transform: 2.0 needs integer vertices, so one is made (0.1 mm).
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

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Chooses the buildings to refine and their crop boxes.
std::vector<CropTarget> make_targets(const std::vector<CityJsonBuilding>& buildings, const CityRefineOptions& o,
                                     std::vector<std::size_t>& target_of) {
  std::vector<CropTarget> targets;
  target_of.assign(buildings.size(), std::string::npos);
  for (std::size_t i = 0; i < buildings.size(); ++i) {
    if (!o.building.empty() && buildings[i].mesh.id != o.building) continue;
    target_of[i] = targets.size();
    targets.push_back(crop_target(buildings[i].mesh, o.crop_expand, o.crop_margin));
  }
  return targets;
}

void check_cloud_reaches(const std::vector<CropTarget>& targets, const Eigen::AlignedBox3d& cloud_box,
                         const Eigen::AlignedBox3d& city_box, const std::string& cloud_path) {
  for (const auto& t : targets)
    if (!t.cloud.points.empty()) return;
  std::string why = overlap_problem(cloud_box, city_box, "the city model");
  if (why.empty()) why = "the cloud has no point within " + std::to_string(targets.size()) + " building box(es)";
  throw InputError(cloud_path + ": " + why);
}

}  // namespace

json cityjson_solid(const Mesh& mesh, const std::string& lod, const Vec3& scale, const Vec3& translate, json& vertices) {
  const long long base = (long long)vertices.size();
  for (const auto& p : mesh.vertices) {
    json q = json::array();
    for (int a = 0; a < 3; ++a) q.push_back(std::llround((p[a] - translate[a]) / scale[a]));
    vertices.push_back(std::move(q));
  }
  json shell = json::array(), values = json::array();
  std::map<Semantic, int> surface_of;
  json surfaces = json::array();
  for (const Face& f : mesh.faces) {
    json ring = json::array();
    for (int v : f.v) ring.push_back(base + v);
    shell.push_back(json::array({std::move(ring)}));
    if (f.sem == Semantic::Other) {
      values.push_back(nullptr);
      continue;
    }
    auto it = surface_of.find(f.sem);
    if (it == surface_of.end()) {
      it = surface_of.emplace(f.sem, int(surfaces.size())).first;
      surfaces.push_back({{"type", semantic_name(f.sem)}});
    }
    values.push_back(it->second);
  }
  json g = {{"type", "Solid"}, {"lod", lod}, {"boundaries", json::array({std::move(shell)})}};
  g["semantics"] = {{"surfaces", std::move(surfaces)}, {"values", json::array({std::move(values)})}};
  return g;
}

CityRefineSummary refine_city(const std::string& model_path, const std::string& cloud_path, const std::string& out_path,
                              const Params& params, const CityRefineOptions& options) {
  CityRefineSummary sum;
  auto t = Clock::now();
  json doc;
  std::string format;
  if (sniff_file(model_path) == FileKind::Xml) {
    std::string version;
    doc = citygml_to_cityjson(model_path, &version);
    format = "CityGML " + version;
  } else {
    const std::string text = read_text(model_path);
    if (is_cityjson_sequence(text)) throw InputError(model_path + ": CityJSONSeq: not handled by this path");
    doc = json::parse(text, nullptr, false);
    if (doc.is_discarded()) parse_cityjson(text, model_path);  // throws the reader's own message
    format = "CityJSON " + (doc.contains("version") && doc["version"].is_string() ? doc["version"].get<std::string>() : "?");
  }
  const CityJsonFile file = read_cityjson_document(doc, model_path, options.lod);
  sum.input_format = format;
  sum.buildings = int(file.buildings.size());
  sum.objects_without_lod = file.objects_without_lod2;
  if (file.buildings.empty())
    throw InputError(model_path + ": no Building/BuildingPart with " +
                     (options.lod.empty() ? std::string("an LoD 2.x") : "an LoD " + options.lod) + " geometry (" +
                     std::to_string(file.objects_without_lod2) + " building object(s) without one); nothing to refine");
  std::vector<std::size_t> target_of;
  std::vector<CropTarget> targets = make_targets(file.buildings, options, target_of);
  if (targets.empty()) throw InputError(model_path + ": no building '" + options.building + "' with the LoD asked for");
  sum.seconds_read = seconds_since(t);

  t = Clock::now();
  Eigen::AlignedBox3d cloud_box;
  sum.cloud_points = crop_tile(cloud_path, targets, options.cloud, &cloud_box);
  check_cloud_reaches(targets, cloud_box, model_box(file.buildings), cloud_path);
  sum.seconds_crop = seconds_since(t);

  t = Clock::now();
  ensure_transform(doc);
  refine_document(doc, file.buildings, targets, target_of, params, sum);
  sum.seconds_refine = seconds_since(t);

  t = Clock::now();
  doc["version"] = "2.0";
  write_file_atomic(out_path, doc.dump() + "\n");
  sum.seconds_write = seconds_since(t);
  return sum;
}

}  // namespace lodrefine
