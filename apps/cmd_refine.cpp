// `lodrefine refine`: one coarse building + its MLS crop -> the refined building.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include "commands.h"
#include "lodrefine/base/files.h"
#include "lodrefine/city/cityfile.h"
#include "lodrefine/city/progress.h"
#include "lodrefine/city/refine_report.h"
#include "lodrefine/formats/cloud.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/refine/refine.h"
#include "lodrefine/tools/review.h"
#include "lodrefine/version.h"
#include "options.h"

namespace lodrefine::app {
namespace {

struct RefineArgs {
  std::string model, out, report;
  std::vector<std::string> clouds;  // --cloud values: files or folders (cloud_files)
  RefineConfig params;
  CloudOptions cloud_options;
  std::string building, lod;  // city files only
  std::string html;           // city files only: the review page
  int jobs = default_jobs();  // city files only
  bool quiet = false;
  bool repair_all = false;                                // city files only
  std::uint64_t max_crop_points = kDefaultMaxCropPoints;  // city files only
  // The options above marked "city files only", each with what it does: given with an OBJ
  // model, one is refused by name (refuse_city_options), never ignored.
  std::vector<std::pair<const CLI::Option*, std::string>> city_only;
};

// The first option of a city file's refine given with an OBJ model, refused in one line.
void refuse_city_options(const RefineArgs& a) {
  for (const auto& [option, what] : a.city_only)
    if (option->count() > 0)
      throw InputError(a.model + ": " + option->get_name() + " (" + what +
                       ") applies to a city file as --model (CityJSON, CityJSONSeq, CityGML), not to an OBJ");
}

// Scan points per refined or repaired building on the review page: enough to see each facade, and
// what bounds the collector's memory (only those buildings keep meshes and points).
constexpr std::size_t kReviewPoints = 3000;

// Collects the review page's data while the city is refined (CityRefineOptions::on_building):
// every building's outline; for a refined or repaired one its view (meshes + capped points), built outside
// the lock as the hook may be called from several threads, in any order: page() puts them in file
// order, so the page is the same whatever finished first.
struct ReviewCollector {
  struct Entry {
    std::size_t index;
    Vec3 origin;  // the building's local origin: the first building's is the district frame
    CityReviewBuilding building;
  };
  std::vector<Entry> entries;
  std::mutex mutex;

  void operator()(std::size_t index, const Mesh& model, const CityBuildingOutcome* o, const RefineResult* r,
                  const PointCloud* crop) {
    CityReviewBuilding b;
    b.id = model.id;
    b.outcome = o ? o->outcome : Outcome::Untouched;
    if (o) b.reason = o->reason, b.points = o->points, b.facades_moved = std::size_t(o->facades_moved);
    if (r && r->trace.judgement && r->trace.judgement->building.points > 0)  // the judge's fit on the scan near it
      b.fit_before = r->trace.judgement->building.rms_before, b.fit_after = r->trace.judgement->building.rms_after;
    if (r && (b.outcome == Outcome::Refined || b.outcome == Outcome::Repaired)) {
      if (b.outcome == Outcome::Refined) add_moves(b, r->trace.facades);
      b.view = review_view(b.id, model, r->mesh, crop ? crop->points : std::vector<Vec3>{}, kReviewPoints);
    }
    b.outline = review_outline(model, Vec3::Zero());
    const std::lock_guard<std::mutex> lock(mutex);
    entries.push_back({index, local_origin(model), std::move(b)});
  }

  // The buildings in file order, their outlines in the first one's frame.
  CityReview page() {
    std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.index < b.index; });
    CityReview review;
    for (Entry& e : entries) {
      for (auto& ring : e.building.outline)
        for (Vec2& p : ring) p -= entries.front().origin.head<2>();
      review.buildings.push_back(std::move(e.building));
    }
    return review;
  }

  static void add_moves(CityReviewBuilding& b, const std::vector<RefineTrace::FacadeMove>& moves) {
    if (moves.empty()) return;
    b.moved_max = b.moved_mean = 0.0;
    for (const auto& m : moves) b.moved_max = std::max(b.moved_max, m.max_move), b.moved_mean += m.mean_move;
    b.moved_mean /= double(moves.size());
  }
};

void write_review(const RefineArgs& a, const std::vector<std::string>& clouds, const CityRefineSummary& s,
                  ReviewCollector& c) {
  CityReview review = c.page();
  std::vector<std::string> names;
  for (const std::string& path : clouds) names.push_back(std::filesystem::path(path).filename().string());
  review.title = "lodrefine city refine: " + std::filesystem::path(a.model).filename().string() + " with " +
                 cloud_files_text(names);
  // No times: the same input gives the same page (stdout and --report have them).
  char line[512];
  std::snprintf(line, sizeof line,
                "%s: %d building(s): %d refined, %d repaired, %d kept, %d kept-invalid, %d untouched (no cloud "
                "points)\ncloud: %llu points, %llu in building crops\n",
                s.input_format.c_str(), s.buildings, s.refined, s.repaired, s.kept, s.kept_invalid, s.untouched,
                (unsigned long long)s.cloud_points, (unsigned long long)s.cropped_points);
  review.summary = line;
  write_file_atomic(a.html, city_review_html(review));
}

// Refuses, before anything is read, an output that is an input or another output (compared
// as files: links and other spellings of one path count). --html too: it replaced the model,
// a cloud file or the city file out without a word.
void check_outputs_are_new(const RefineArgs& a, const std::vector<std::string>& clouds) {
  std::vector<FileOption> inputs = {{"--model", a.model}};
  for (const std::string& cloud : clouds) inputs.push_back({"--cloud", cloud});
  refuse_overwrites(inputs, {{"--out", a.out}, {"--report", a.report}, {"--html", a.html}});
}

// The report's "cloud" files: each file's path, the points read from it and their bounds (null
// when none), in reading order; "path" too when the cloud is one file, as before several were read.
// Then the entries of the cloud folders skipped as no cloud files, each with its path and why.
nlohmann::json cloud_json(const std::vector<CloudFileRead>& files, const std::vector<SkippedEntry>& skipped) {
  nlohmann::json cloud = nlohmann::json::object(), list = nlohmann::json::array();
  if (files.size() == 1) cloud["path"] = files.front().path;
  const auto xyz = [](const Vec3& p) { return nlohmann::json::array({p.x(), p.y(), p.z()}); };
  for (const CloudFileRead& f : files)
    list.push_back(
        {{"path", f.path},
         {"points", f.points},
         {"bounds", f.bounds.isEmpty() ? nlohmann::json()
                                       : nlohmann::json{{"min", xyz(f.bounds.min())}, {"max", xyz(f.bounds.max())}}}});
  for (const SkippedEntry& e : skipped) list.push_back({{"path", e.path}, {"skipped", e.reason}});
  cloud["files"] = std::move(list);
  return cloud;
}

// The cloud folders' skipped entries, one line on stdout before the outcome (none when none).
void print_skipped(const std::vector<SkippedEntry>& skipped) {
  if (!skipped.empty()) std::printf("%s\n", skipped_entries_text(skipped).c_str());
}

// "12 refined, 2 repaired, 3 kept, 1 kept-invalid": the progress line's tally.
std::string tally_text(const CityRefineSummary& s) {
  return std::to_string(s.refined) + " refined, " + std::to_string(s.repaired) + " repaired, " +
         std::to_string(s.kept) + " kept, " + std::to_string(s.kept_invalid) + " kept-invalid";
}

// A city file (CityJSON, CityJSONSeq, CityGML) in: every building the cloud covers, one
// CityJSON 2.0 file out.
void run_city(const RefineArgs& a, const std::vector<std::string>& clouds, const std::vector<SkippedEntry>& skipped) {
  CityRefineOptions o;
  o.building = a.building;
  o.lod = a.lod;
  o.cloud = a.cloud_options;
  o.max_crop_points = a.max_crop_points;
  o.jobs = a.jobs;
  o.repair_all = a.repair_all;
  ReviewCollector review;
  if (!a.html.empty()) o.on_building = std::ref(review);
  const Progress::Mode mode = Progress::mode_for_stderr(a.quiet);
  std::unique_ptr<Progress> crop, refine;
  o.crop_progress = [&](std::uint64_t read) {
    if (!crop) crop = std::make_unique<Progress>("crop", "points", cloud_point_count(clouds), mode);
    crop->update(read);
  };
  o.progress = [&](const CityRefineSummary& s) {
    if (crop) crop->finish();
    if (!refine) refine = std::make_unique<Progress>("refine", "buildings", std::uint64_t(s.buildings), mode);
    refine->update(std::uint64_t(s.refined + s.repaired + s.kept + s.kept_invalid + s.untouched), tally_text(s));
  };
  const CityRefineSummary s = refine_city(a.model, clouds, a.out, a.params, o);
  if (crop) crop->finish();
  if (refine) refine->finish();
  if (!a.html.empty()) write_review(a, clouds, s, review);
  if (!a.report.empty()) {
    nlohmann::json j = {{"lodrefine_version", LODREFINE_VERSION},
                        {"model", a.model},
                        {"cloud", cloud_json(s.clouds, skipped)},
                        {"written", a.out},
                        {"input", s.input_format},
                        {"buildings", s.buildings},
                        {"refined", s.refined},
                        {"repaired", s.repaired},
                        {"kept", s.kept},
                        {"kept_invalid", s.kept_invalid},
                        {"untouched", s.untouched},
                        {"objects_without_lod", s.objects_without_lod},
                        {"cloud_points", s.cloud_points},
                        {"cropped_points", s.cropped_points},
                        {"refused", s.refused},
                        {"seconds",
                         {{"read", s.seconds_read},
                          {"crop", s.seconds_crop},
                          {"refine", s.seconds_refine},
                          {"write", s.seconds_write}}},
                        {"params", params_json(a.params)},
                        {"outcomes", nlohmann::json::array()}};
    if (!s.warnings.empty()) j["warnings"] = s.warnings;
    for (const auto& b : s.outcomes) j["outcomes"].push_back(city_outcome_json(b));
    write_file_atomic(a.report, j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  }
  std::string refused;  // "; never worse refused N (building a, wall b)"
  int n_refused = 0;
  for (const auto& [check, n] : s.refused) {
    refused += (refused.empty() ? "" : ", ") + check + " " + std::to_string(n);
    n_refused += n;
  }
  print_skipped(skipped);
  for (const std::string& w : s.warnings) std::printf("warning: %s\n", escaped_line(w).c_str());
  std::printf(
      "%s: %d building(s), %llu cloud points (%llu in building crops): %d refined, %d repaired, %d kept (never "
      "worse refused %d%s), %d kept-invalid, %d untouched (no cloud points) -> %s (read %.1f s, crop %.1f s, "
      "refine %.1f s, write %.1f s)\n",
      escaped_line(s.input_format).c_str(), s.buildings, (unsigned long long)s.cloud_points,
      (unsigned long long)s.cropped_points, s.refined, s.repaired, s.kept, n_refused,
      refused.empty() ? "" : (": " + refused).c_str(), s.kept_invalid, s.untouched, escaped_line(a.out).c_str(),
      s.seconds_read, s.seconds_crop, s.seconds_refine, s.seconds_write);
}

bool is_city_file(const std::string& path) {
  const FileKind k = sniff_file(path);
  return k == FileKind::Xml || k == FileKind::Json;
}

void run(const RefineArgs& a) {
  a.params.validate();
  std::vector<SkippedEntry> skipped;
  const std::vector<std::string> clouds = cloud_files(a.clouds, "--cloud", &skipped);
  check_outputs_are_new(a, clouds);
  check_output_dir(a.out);
  check_output_dir(a.report);
  check_output_dir(a.html);
  if (is_city_file(a.model)) {
    const std::string ext = std::filesystem::path(a.out).extension().string();
    if (ext == ".obj" || ext == ".OBJ")
      throw InputError(a.out + ": a city file in gives a CityJSON city file out; name it e.g. refined.city.json");
    return run_city(a, clouds, skipped);
  }
  refuse_city_options(a);
  std::vector<char> in_fins;  // per face: in the model's fins group (a model refine wrote)
  const Mesh model = read_obj(a.model, in_fins);
  std::vector<CloudFileRead> read;
  const PointCloud cloud = read_cloud(clouds, a.cloud_options, &read);
  // A crop the scan did not reach is empty: its building is kept as read, as in a city file. A
  // class filter that leaves none of a cloud's points is a mistake in the command.
  if (cloud.points.empty() && !a.cloud_options.classes.empty())
    if (const std::uint64_t all = cloud_point_count(clouds); all > 0)
      throw InputError(cloud_files_text(clouds) + ": the cloud has no points of classes " +
                       classes_text(a.cloud_options.classes) + " (of " + std::to_string(all) + ")");
  // Said on stdout and in the report (stderr is for the one error line of a failed run).
  std::vector<std::string> warnings = overlap_problems(read, bounding_box(model.vertices));
  if (cloud.points.empty()) warnings.push_back(cloud_files_text(clouds) + ": the cloud has no points");
  const RefineResult r = refine_building(model, cloud, a.params);
  nlohmann::json report = refine_report(r);
  for (const std::string& w : warnings) report["warnings"].push_back(w);
  report["model"] = a.model;
  report["cloud"].update(cloud_json(read, skipped));
  report["params"] = params_json(a.params);
  report["written"] = a.out;
  // The model first: a report never names a model that is not there. Its fins (faces no solid
  // holds, beside a rebuilt shell) follow the solid's faces in their own group; a model kept as
  // read (kept-invalid: the same faces in the same order) keeps its fins group as read.
  const bool as_read = r.outcome == Outcome::KeptInvalid && r.mesh.faces.size() == in_fins.size() &&
                       std::count(in_fins.begin(), in_fins.end(), 1) > 0;
  const ObjModel written = as_read ? split_fins(r.mesh, in_fins) : ObjModel{r.mesh, r.fins};
  write_obj(a.out, written.solid, written.fins);
  if (!a.report.empty())
    write_file_atomic(a.report, report.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  // One line whatever the model's name holds (batch logs keep it): a CR let `o ok\rFAKE: …` print
  // over the outcome.
  print_skipped(skipped);
  std::string warned;
  for (const std::string& w : warnings) warned += "; warning: " + escaped_line(w);
  std::printf("%s: %s (%s) -> %s (%.2f s)%s\n", line_id(model.id).c_str(), outcome_name(r.outcome),
              escaped_line(r.reason).c_str(), escaped_line(a.out).c_str(), r.trace.stage_seconds("total").value_or(0.0),
              warned.c_str());
}

}  // namespace

void add_refine_command(CLI::App& app) {
  static RefineArgs args;
  auto* cmd = app.add_subcommand("refine", "Refine one building model with an MLS point cloud");
  cmd->add_option("--model", args.model,
                  "Coarse building model (OBJ, CityGML fan-out export), or a city file (" +
                      formats_text(kCityFormatNames) + "): then --out is a CityJSON 2.0 city file")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--cloud", args.clouds,
                  "MLS point cloud (" + formats_text(kCloudFormatNames) +
                      "): the building's crop, or a city file's tile; a folder gives "
                      "its cloud files by name; repeat for several (one per drive or tile): read one after another "
                      "as one cloud")
      ->required()
      ->check(CLI::ExistingPath);
  cmd->add_option("--out", args.out, "Refined model (OBJ; CityJSON for a city file), written atomically")->required();
  // What only a city file's refine does: one help group, and refused with an OBJ model.
  const auto city_only = [&](CLI::Option* option, const char* what) {
    option->group("City files (a city file as --model; refused with an OBJ)");
    args.city_only.emplace_back(option, what);
  };
  city_only(cmd->add_option("--building", args.building, "Refine only this CityObject id"), "one building of the city");
  city_only(cmd->add_option("--lod", args.lod, "The LoD geometry to refine, e.g. 2.2 (default: the highest 2.x)")
                ->check(lod_validator()),
            "the city's LoD to refine");
  city_only(cmd->add_option("--html", args.html,
                            "Write a review page (self-contained HTML, three.js embedded): summary, the buildings "
                            "the cloud reached, a district map, each refined building in 3D over its scan"),
            "the review page of a city refine");
  city_only(add_ranged_option(cmd, "--jobs", args.jobs,
                              "Buildings refined at once, one thread each (default: all cores; the output is the "
                              "same whatever the number)",
                              1, 1024),
            "buildings refined at once");
  city_only(cmd->add_flag("--repair-all", args.repair_all,
                          "Also the buildings the cloud does not reach go through repair: each one that is no "
                          "valid solid is rebuilt on its own planes (outcome repaired) or says why not "
                          "(kept-invalid); the valid ones are kept as read. Every building then gets "
                          "lodrefine_outcome"),
            "repair of the buildings the cloud does not reach");
  city_only(cmd->add_option("--max-crop-points", args.max_crop_points,
                            "Refuse the run when the buildings' crop boxes hold more points together (each is "
                            "held in memory, 24 bytes); refine the district in parts")
                ->capture_default_str(),
            "the bound on the buildings' crops");
  cmd->add_flag("--quiet", args.quiet, "No progress line on stderr (a city file's; an OBJ refine prints none)");
  cmd->add_option("--report", args.report, "JSON report: matches, planes, candidates, MIP, timings, validation");
  add_cloud_options(cmd, args.cloud_options);
  add_param_options(cmd, args.params);
  cmd->callback([] { run(args); });
}

}  // namespace lodrefine::app
