// City file in, city file out (see cityfile.h).
#include "lodrefine/city/cityfile.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <sstream>
#include <tuple>

#include "cityjson_upgrade.h"
#include "lodrefine/base/files.h"
#include "lodrefine/city/crop.h"
#include "lodrefine/city/in_order_pool.h"
#include "lodrefine/city/validity.h"
#include "lodrefine/formats/citygml.h"
#include "lodrefine/formats/cityjson.h"
#include "lodrefine/formats/cityjson_write.h"
#include "lodrefine/refine/provenance.h"
#include "lodrefine/refine/refine.h"

namespace lodrefine {
namespace {

using json = nlohmann::ordered_json;

// A CityJSONSeq header line holds metadata and the transform, never objects: a first line
// longer than this is a one-line CityJSON file, not parsed twice to find out.
constexpr std::size_t kMaxSequenceHeader = 1 << 20;

// A string member of an untrusted object; `otherwise` when it is absent or no string (the
// reader refuses a "version" or "type" that is no string, with the file's name; value() would
// throw a raw type_error).
std::string text_member(const json& j, const char* key, const std::string& otherwise = "") {
  if (!j.is_object()) return otherwise;
  const auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : otherwise;
}

// One building's outcome as refine_building decided it, in the words of the report: a refined or
// repaired building is written; anything else is kept (its original geometry stays).
CityBuildingOutcome classify(const RefineResult& r) {
  CityBuildingOutcome o;
  o.outcome = r.outcome;
  if (r.outcome == Outcome::Refined) {
    o.facades_moved = int(r.trace.facades.size());
    return o;
  }
  if (r.outcome == Outcome::Repaired) {
    o.reason = r.reason;
    return o;
  }
  o.reason = r.reason.empty() ? std::string(outcome_name(r.outcome)) : r.reason;
  if (r.trace.judgement && !r.trace.judgement->ok) o.refused_by = r.trace.judgement->check;
  // A crop that only grazes the building (its box's edge): no wall of it faces a scan plane.
  const bool no_facade =
      (r.trace.planes && r.trace.planes->empty()) || (r.trace.matching && r.trace.matching->walls.empty());
  if (o.outcome == Outcome::Kept && no_facade) o.reason = "scan covers no facade of this building";
  return o;
}

Eigen::AlignedBox3d model_box(const std::vector<CityJsonBuilding>& buildings) {
  Eigen::AlignedBox3d box;
  for (const auto& b : buildings)
    for (const auto& v : b.mesh.vertices) box.extend(v);
  return box;
}

// The transform of a CityJSON header (validated by the reader before this is used).
CityJsonTransform transform_of(const json& header) {
  CityJsonTransform t;
  const json& j = header.at("transform");
  t.scale = Vec3(j.at("scale")[0].get<double>(), j.at("scale")[1].get<double>(), j.at("scale")[2].get<double>());
  t.translate =
      Vec3(j.at("translate")[0].get<double>(), j.at("translate")[1].get<double>(), j.at("translate")[2].get<double>());
  return t;
}

// One building's refinement: the part that runs on the pool. Touches nothing shared (the
// crop is its own, refine_building keeps its state per call: CGAL's default random generator
// and GLPK's environment are thread-local, see ARCHITECTURE.md).
struct BuildingJob {
  std::size_t index = 0;    // in the document's buildings
  bool has_points = false;  // or refused, or every building is to be repaired: it gets an outcome
  std::string refused;      // why its crop target was refused (e.g. an absurd extent)
  PointCloud cloud;
  RefineResult result;
  bool returned = false;       // refine_building returned (result is set)
  bool valid_as_read = false;  // only_invalid: validated, found valid and left untouched
  CityBuildingOutcome outcome;
};

// `mesh` as the document will hold it: each coordinate on the transform's grid (cityjson_surfaces
// rounds them so), what validate finds when it reads the file back.
Mesh as_written(const Mesh& mesh, const CityJsonTransform& tf) {
  Mesh out = mesh;
  for (Vec3& p : out.vertices) {
    const std::array<long long, 3> q = tf.quantise(p);
    p = Vec3(double(q[0]), double(q[1]), double(q[2])).cwiseProduct(tf.scale) + tf.translate;
  }
  return out;
}

// lodrefine repair: a building invalid as read whose repair alone (welds, orientation, holes
// filled) made it a valid solid is written so, as repaired, when val3dity's tolerances find the
// result valid too; else it stays kept as read, and says what the repair still has.
void repaired_by_weld(BuildingJob& job, const CityJsonTransform& tf) {
  std::vector<ValidityError> after = validate_soup(as_written(job.result.mesh, tf)).errors;
  const bool mended = after.empty() && job.result.trace.repair;
  job.outcome.outcome = decide_outcome({Ending::Kept, mended, job.result.valid});
  if (!mended) {
    job.outcome.reason = "kept as read: its repair (welds, orientation, holes) still has " + errors_text(after);
    return;
  }
  const RepairReport& rr = *job.result.trace.repair;
  std::string what;
  const auto add = [&](int n, const char* text) {
    if (n > 0) what += (what.empty() ? "" : ", ") + std::to_string(n) + " " + text;
  };
  add(rr.welded_vertices, "vertices welded");
  add(rr.removed_degenerate_faces, "degenerate faces dropped");
  add(rr.removed_duplicate_faces, "duplicate faces dropped");
  add(rr.split_t_junctions, "T-junctions split");
  add(rr.flipped_faces, "faces turned outward");
  add(rr.filled_holes, "holes filled");
  add(rr.split_warped_faces, "warped faces split");
  complete_provenance(job.result.mesh);  // written: its faces the model's, a filled hole's added
  job.outcome.reason = "the repair made it a valid solid (" + (what.empty() ? std::string("faces merged") : what) + ")";
  job.outcome.errors_after = std::move(after);
}

void run_job(BuildingJob& job, const CityJsonBuilding& b, const RefineConfig& params, bool only_invalid,
             const CityJsonTransform& tf) {
  if (!job.has_points) return;
  const auto t0 = Clock::now();
  std::vector<ValidityError> before;
  try {
    before = validate_soup(solid_soup(b)).errors;
    if (only_invalid && before.empty()) {
      job.has_points = false;
      job.valid_as_read = true;
      return;
    }
    if (!job.refused.empty()) throw InputError(job.refused);
    job.result = refine_building(b.mesh, job.cloud, params);
    job.returned = true;
    job.outcome = classify(job.result);
  } catch (const std::exception& e) {  // never lose a building: keep it as read
    job.outcome.outcome = decide_outcome({Ending::AsRead});
    job.outcome.reason = e.what();
  }
  const bool rewritten = job.outcome.outcome == Outcome::Refined || job.outcome.outcome == Outcome::Repaired;
  job.outcome.errors_after = rewritten ? validate_soup(as_written(job.result.mesh, tf)).errors : before;
  if (only_invalid && job.outcome.outcome == Outcome::Kept && job.result.valid) repaired_by_weld(job, tf);
  job.outcome.errors_before = std::move(before);
  job.outcome.id = b.mesh.id;
  job.outcome.points = job.cloud.points.size();
  job.outcome.seconds = seconds_since(t0);
}

// Takes building i's crop out of the targets (npos target: not asked for; no points: nothing to
// refine, unless `repair_all`).
BuildingJob take_job(std::size_t i, std::vector<CropTarget>& targets, const std::vector<std::size_t>& target_of,
                     std::size_t first, bool repair_all) {
  BuildingJob job;
  job.index = i;
  const std::size_t ti = target_of[first + i];
  if (ti == std::string::npos || (targets[ti].cloud.points.empty() && targets[ti].refused.empty() && !repair_all))
    return job;
  job.has_points = true;
  job.refused = targets[ti].refused;
  job.cloud = std::move(targets[ti].cloud);
  targets[ti].cloud = PointCloud();
  return job;
}

// The codes before and after only where there is something to say (the building had or has
// errors): a valid building's own attributes stay as read but for the outcome. A pass over a
// file lodrefine wrote drops the codes an earlier pass left.
void write_error_codes(json& attributes, const CityBuildingOutcome& o) {
  attributes.erase("lodrefine_errors_before");
  attributes.erase("lodrefine_errors_after");
  if (o.errors_before.empty() && o.errors_after.empty()) return;
  attributes["lodrefine_errors_before"] = error_codes(o.errors_before);
  attributes["lodrefine_errors_after"] = error_codes(o.errors_after);
}

// Writes a finished job into the document (in input order: new vertices are appended).
// `hook` (may be empty) sees the building (`index` over the file), its outcome, result and crop;
// the crop is freed after.
void apply_job(json& doc, const CityJsonTransform& tf, const CityJsonBuilding& b, std::size_t index, BuildingJob&& job,
               const CityBuildingHook& hook, CityRefineSummary& sum) {
  if (!job.has_points) {
    ++sum.untouched;
    if (job.valid_as_read)
      sum.outcomes.push_back({b.mesh.id, decide_outcome({Ending::Untouched}), "a valid solid as read"});
    if (hook) hook(index, b.mesh, nullptr, nullptr, nullptr);
    return;
  }
  CityBuildingOutcome& o = job.outcome;
  json& obj = doc["CityObjects"][b.mesh.id];
  if (o.outcome == Outcome::Refined || o.outcome == Outcome::Repaired) {
    const std::string lod = obj["geometry"][std::size_t(b.geometry_index)]["lod"].is_string()
                                ? obj["geometry"][std::size_t(b.geometry_index)]["lod"].get<std::string>()
                                : b.lod;
    json& geometry = obj["geometry"];
    geometry[std::size_t(b.geometry_index)] =
        cityjson_solid(job.result.mesh, lod, tf.scale, tf.translate, doc["vertices"]);
    // The fins read with the Solid were part of its soup: the result's fins take their place.
    if (b.fins_index >= 0) geometry.erase(std::size_t(b.fins_index));
    if (!job.result.fins.faces.empty())
      geometry.insert(geometry.begin() + b.geometry_index + 1,
                      cityjson_multisurface(job.result.fins, lod, tf.scale, tf.translate, doc["vertices"]));
    ++(o.outcome == Outcome::Refined ? sum.refined : sum.repaired);
  } else {
    ++(o.outcome == Outcome::Kept ? sum.kept : sum.kept_invalid);
  }
  if (o.refused_by != JudgeCheck::None) ++sum.refused[check_name(o.refused_by)];
  if (!obj.contains("attributes") || !obj["attributes"].is_object()) obj["attributes"] = json::object();
  obj["attributes"]["lodrefine_outcome"] = outcome_name(o.outcome);
  obj["attributes"]["lodrefine_reason"] = o.reason;
  obj["attributes"]["lodrefine_facades_moved"] = o.facades_moved;
  write_error_codes(obj["attributes"], o);
  if (hook) hook(index, b.mesh, &o, job.returned ? &job.result : nullptr, &job.cloud);
  job.cloud = PointCloud();  // the crop is no longer needed: free it now
  sum.outcomes.push_back(std::move(o));
}

// Adds a feature's counts and outcomes to the file's.
void merge_into(CityRefineSummary& sum, CityRefineSummary&& part) {
  sum.refined += part.refined;
  sum.kept += part.kept;
  sum.kept_invalid += part.kept_invalid;
  sum.repaired += part.repaired;
  sum.untouched += part.untouched;
  for (const auto& [check, n] : part.refused) sum.refused[check] += n;
  for (auto& o : part.outcomes) sum.outcomes.push_back(std::move(o));
}

// Refines the buildings of `doc` (a CityJSON file or one CityJSONFeature: "CityObjects" and
// "vertices") that have points on `jobs` threads, and writes the results into `doc` in input
// order (the same bytes whatever `jobs`). `buildings` are the doc's buildings in order;
// `target_of[first + i]` is building i's crop target (npos: not asked for). `progress` (may be
// empty) is called after each building with the summary so far.
void refine_document(json& doc, const CityJsonTransform& tf, const std::vector<CityJsonBuilding>& buildings,
                     std::vector<CropTarget>& targets, const std::vector<std::size_t>& target_of, std::size_t first,
                     const CityRefineOptions& options, const RefineConfig& params, int jobs, CityRefineSummary& sum,
                     const std::function<void(const CityRefineSummary&)>& progress) {
  std::size_t next = 0;
  in_order_pool<BuildingJob>(
      jobs,
      [&]() -> std::shared_ptr<BuildingJob> {
        if (next == buildings.size()) return nullptr;
        const std::size_t i = next++;
        return std::make_shared<BuildingJob>(take_job(i, targets, target_of, first, options.repair_all));
      },
      [&](BuildingJob& job) { run_job(job, buildings[job.index], params, options.only_invalid, tf); },
      [&](BuildingJob& job) {
        apply_job(doc, tf, buildings[job.index], first + job.index, std::move(job), options.on_building, sum);
        if (progress) progress(sum);
      });
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Adds the buildings to refine and their crop boxes (appending to target_of).
void add_targets(const std::vector<CityJsonBuilding>& buildings, const CityRefineOptions& o,
                 std::vector<CropTarget>& targets, std::vector<std::size_t>& target_of) {
  for (const auto& b : buildings) {
    if (!o.building.empty() && b.mesh.id != o.building) {
      target_of.push_back(std::string::npos);
      continue;
    }
    target_of.push_back(targets.size());
    try {
      targets.push_back(crop_target(b.mesh, o.crop_expand, o.crop_margin));
    } catch (const InputError& e) {  // a building too wide to crop: kept-invalid, the run goes on
      CropTarget t;
      t.id = b.mesh.id;
      t.lo = Vec3::Constant(1.0);
      t.hi = Vec3::Zero();  // an empty box: no point reaches it
      t.refused = e.what();
      targets.push_back(std::move(t));
    }
  }
}

void check_targets(const std::vector<CropTarget>& targets, const std::string& model_path, const CityRefineOptions& o) {
  if (targets.empty())
    throw InputError(model_path + ": no building " + shown_id(o.building) + " with the LoD asked for");
}

[[noreturn]] void fail_no_lod(const std::string& model_path, const CityRefineOptions& o, int without) {
  throw InputError(model_path + ": no Building/BuildingPart with " +
                   (o.lod.empty() ? std::string("an LoD 2.x") : "an LoD " + o.lod) + " geometry (" +
                   std::to_string(without) + " building object(s) without one); nothing to refine");
}

// The cloud pass: one stream over the cloud files fills the targets' crops and the summary's
// cloud figures. Throws when no point reaches a building's box; a file whose bounds miss the city
// model while others reach it gets a warning of its own.
void crop_clouds(const std::vector<std::string>& cloud_paths, std::vector<CropTarget>& targets,
                 const Eigen::AlignedBox3d& city_box, const CityRefineOptions& o, CityRefineSummary& sum) {
  if (cloud_paths.empty()) {  // lodrefine repair: every building without a scan
    if (!o.repair_all) throw InputError("no cloud file: only a repair of every building runs without one");
    return;
  }
  sum.cloud_points = crop_tile(cloud_paths, targets, o.cloud, &sum.clouds, o.crop_progress, o.max_crop_points);
  std::uint64_t held = 0;
  for (const auto& t : targets) held += t.cloud.points.size();
  Eigen::AlignedBox3d cloud_box;
  for (const auto& f : sum.clouds) cloud_box.extend(f.bounds);
  if (held == 0) {
    std::string why = overlap_problem(cloud_box, city_box, "the city model");
    if (why.empty()) why = "the cloud has no point within " + std::to_string(targets.size()) + " building box(es)";
    throw InputError(cloud_files_text(cloud_paths) + ": " + why);
  }
  sum.warnings = overlap_problems(sum.clouds, city_box, "the city model");
  sum.cropped_points = held;
}

// A CityJSONSeq feature as a CityJSON document the reader takes: the header's transform
// with the feature's objects and vertices.
json feature_document(const json& header, json feature) {
  json d = {
      {"type", "CityJSON"}, {"version", text_member(header, "version", "2.0")}, {"transform", header.at("transform")}};
  d["CityObjects"] = std::move(feature["CityObjects"]);
  d["vertices"] = std::move(feature["vertices"]);
  return d;
}

// The first line of a file when it is a CityJSONSeq header (a "CityJSON" object on one line);
// null otherwise.
json sequence_header(const std::string& model_path) {
  std::ifstream in(model_path, std::ios::binary);
  std::string line;
  if (!in || !std::getline(in, line) || line.size() > kMaxSequenceHeader) return nullptr;
  json first;
  try {
    first = parse_city_json(line, model_path);
  } catch (const InputError&) {
    return nullptr;  // not a sequence header: the whole file is parsed, and refused with the reason
  }
  if (!first.is_object() || text_member(first, "type") != "CityJSON" ||
      (first.contains("CityObjects") && !first["CityObjects"].empty()))
    return nullptr;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) return first;
  return nullptr;
}

// One line of a CityJSONSeq after the header; `where` names it in the error.
json parse_feature(const std::string& line, const std::string& where) {
  json feature = parse_city_json(line, where);
  if (!feature.is_object() || text_member(feature, "type") != "CityJSONFeature")
    throw InputError(where + ": expected a CityJSONFeature object");
  return feature;
}

// Pass 1 of a CityJSONSeq: each feature's buildings read for their crop boxes, counted in `sum`.
struct SequenceTargets {
  std::vector<CropTarget> targets;
  std::vector<std::size_t> target_of;
  std::vector<std::size_t> feature_buildings;  // per feature line
  Eigen::AlignedBox3d city_box;
};
SequenceTargets sequence_targets(const json& header, const std::string& model_path, const CityRefineOptions& options,
                                 CityRefineSummary& sum) {
  SequenceTargets seq;
  std::ifstream in(model_path, std::ios::binary);
  std::string line;
  std::getline(in, line);
  std::unordered_set<std::string> ids;
  for (int n = 2; std::getline(in, line); ++n) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::string where = model_path + ": line " + std::to_string(n);
    json feature = parse_feature(line, where);
    add_feature_ids(feature, ids, where);
    const CityJsonFile f = read_cityjson_document(feature_document(header, std::move(feature)), where, options.lod);
    sum.buildings += int(f.buildings.size());
    seq.feature_buildings.push_back(f.buildings.size());
    sum.objects_without_lod += f.objects_without_lod2;
    seq.city_box.extend(model_box(f.buildings));
    add_targets(f.buildings, options, seq.targets, seq.target_of);
  }
  return seq;
}

// CityJSONSeq in, CityJSONSeq out, streamed: pass 1 reads each feature's buildings for the
// crop boxes (keeping only the boxes), the cloud pass fills them, pass 2 reads each feature
// again, refines its buildings (features on the pool) and writes the lines out in order.
CityRefineSummary refine_sequence(const json& header, const std::string& model_path,
                                  const std::vector<std::string>& cloud_paths, const std::string& out_path,
                                  const RefineConfig& params, const CityRefineOptions& options) {
  CityRefineSummary sum;
  sum.input_format = "CityJSONSeq " + text_member(header, "version", "?");
  if (!header.contains("transform"))
    throw InputError(model_path + ": line 1: a CityJSONSeq header needs a \"transform\"");
  // The header checked by the reader (transform shape, scale) before transform_of trusts it.
  read_cityjson_document(feature_document(header, {{"CityObjects", json::object()}, {"vertices", json::array()}}),
                         model_path + ": line 1");
  const CityJsonTransform tf = transform_of(header);
  auto t = Clock::now();
  SequenceTargets seq = sequence_targets(header, model_path, options, sum);
  std::vector<CropTarget>& targets = seq.targets;
  const std::vector<std::size_t>& target_of = seq.target_of;
  const std::vector<std::size_t>& feature_buildings = seq.feature_buildings;  // for pass 2's building indices
  std::size_t features = 0;
  if (sum.buildings == 0) fail_no_lod(model_path, options, sum.objects_without_lod);
  check_targets(seq.targets, model_path, options);
  sum.seconds_read = seconds_since(t);

  t = Clock::now();
  crop_clouds(cloud_paths, seq.targets, seq.city_box, options, sum);
  sum.seconds_crop = seconds_since(t);

  t = Clock::now();
  AtomicFile out(out_path);
  json h = header;
  const bool upgrade = text_member(header, "version") != "2.0";
  if (upgrade) upgrade_header(h);
  h["version"] = "2.0";
  out.write(h.dump(-1, ' ', false, json::error_handler_t::replace) + "\n");
  // Pass 2 on the pool, one feature an item: its line is parsed, refined and dumped on a
  // worker, and written here in file order.
  struct FeatureJob {
    int line = 0;
    std::string text;
    std::size_t first = 0;  // its first building's index over the file
    CityRefineSummary part;
  };
  std::ifstream in(model_path, std::ios::binary);
  std::string line;
  std::getline(in, line);
  int n = 1;
  std::size_t first = 0;
  in_order_pool<FeatureJob>(
      options.jobs,
      [&]() -> std::shared_ptr<FeatureJob> {
        while (std::getline(in, line)) {
          ++n;
          if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
          auto job = std::make_shared<FeatureJob>();
          job->line = n;
          job->text = std::move(line);
          job->first = first;
          if (feature_buildings.size() <= features) throw InputError(model_path + ": changed while being read");
          first += feature_buildings[features++];
          return job;
        }
        return nullptr;
      },
      [&](FeatureJob& job) {
        const std::string where = model_path + ": line " + std::to_string(job.line);
        json feature = parse_feature(job.text, where);
        const CityJsonFile f = read_cityjson_document(feature_document(header, feature), where, options.lod);
        if (upgrade) upgrade_objects(feature["CityObjects"]);
        refine_document(feature, tf, f.buildings, targets, target_of, job.first, options, params, 1, job.part, {});
        job.text = feature.dump(-1, ' ', false, json::error_handler_t::replace) + "\n";
      },
      [&](FeatureJob& job) {
        out.write(job.text);
        merge_into(sum, std::move(job.part));
        if (options.progress) options.progress(sum);
      });
  out.commit();
  sum.seconds_refine = seconds_since(t);
  return sum;
}

}  // namespace

CityRefineSummary refine_city(const std::string& model_path, const std::vector<std::string>& cloud_paths,
                              const std::string& out_path, const RefineConfig& params,
                              const CityRefineOptions& options) {
  CityRefineSummary sum;
  auto t = Clock::now();
  json doc;
  std::string format;
  if (sniff_file(model_path) != FileKind::Xml) {
    const json header = sequence_header(model_path);
    if (!header.is_null()) return refine_sequence(header, model_path, cloud_paths, out_path, params, options);
  }
  if (sniff_file(model_path) == FileKind::Xml) {
    std::string version;
    doc = citygml_to_cityjson(model_path, &version);
    format = "CityGML " + version;
  } else {
    const std::string text = read_text(model_path);
    doc = parse_city_json(text, model_path);
    format = "CityJSON " + text_member(doc, "version", "?");
  }
  const CityJsonFile file = read_cityjson_document(doc, model_path, options.lod);
  sum.input_format = format;
  sum.buildings = int(file.buildings.size());
  sum.objects_without_lod = file.objects_without_lod2;
  if (file.buildings.empty()) fail_no_lod(model_path, options, file.objects_without_lod2);
  std::vector<std::size_t> target_of;
  std::vector<CropTarget> targets;
  add_targets(file.buildings, options, targets, target_of);
  check_targets(targets, model_path, options);
  sum.seconds_read = seconds_since(t);

  t = Clock::now();
  crop_clouds(cloud_paths, targets, model_box(file.buildings), options, sum);
  sum.seconds_crop = seconds_since(t);

  t = Clock::now();
  if (text_member(doc, "version") != "2.0") {
    upgrade_header(doc);
    upgrade_objects(doc["CityObjects"]);
  }
  ensure_transform(doc);
  refine_document(doc, transform_of(doc), file.buildings, targets, target_of, 0, options, params, options.jobs, sum,
                  options.progress);
  sum.seconds_refine = seconds_since(t);

  t = Clock::now();
  doc["version"] = "2.0";
  write_file_atomic(out_path, doc.dump(-1, ' ', false, json::error_handler_t::replace) + "\n");
  sum.seconds_write = seconds_since(t);
  return sum;
}

}  // namespace lodrefine
