// `lodrefine refine`: one coarse building + its MLS crop -> the refined building.
#include <cstdio>
#include <filesystem>

#include "commands.h"
#include "lodrefine/cloud.h"
#include "lodrefine/io.h"
#include "lodrefine/refine.h"
#include "options.h"

namespace lodrefine::app {
namespace {

struct RefineArgs {
  std::string model, cloud, out, report;
  std::uint64_t max_points = 20000000;
  Params params;
  CloudOptions cloud_options;
};

nlohmann::json params_json(const Params& p) {
  nlohmann::json j;
#define LODREFINE_PARAM_JSON(type, name, def, lo, hi, help) j[#name] = p.name;
  LODREFINE_PARAMS(LODREFINE_PARAM_JSON)
#undef LODREFINE_PARAM_JSON
  return j;
}

// Fails before any work when an output could not be written (so nothing is left half done).
void check_output_dir(const std::string& path) {
  if (path.empty()) return;
  const std::filesystem::path dir = std::filesystem::absolute(path).parent_path();
  if (!std::filesystem::is_directory(dir)) throw InputError(path + ": output directory " + dir.string() + " does not exist");
  if (std::filesystem::is_directory(path)) throw InputError(path + ": is a directory");
}

void run(const RefineArgs& a) {
  a.params.validate();
  check_output_dir(a.out);
  check_output_dir(a.report);
  const Mesh model = read_obj(a.model);
  const std::uint64_t declared = cloud_point_count(a.cloud);
  if (declared > a.max_points)
    throw InputError(a.cloud + ": " + std::to_string(declared) + " points, more than --max-points " +
                     std::to_string(a.max_points) + "; cut a crop per building first (lodrefine crop)");
  const PointCloud cloud = read_cloud(a.cloud, a.cloud_options);
  if (cloud.points.empty())
    throw InputError(a.cloud + ": the cloud has no points" +
                     (a.cloud_options.classes.empty() ? std::string()
                                                      : " of classes " + classes_text(a.cloud_options.classes) +
                                                            " (of " + std::to_string(declared) + ")"));
  const std::string overlap = overlap_problem(bounding_box(cloud.points), bounding_box(model.vertices));
  if (!overlap.empty()) std::fprintf(stderr, "lodrefine: warning: %s\n", overlap.c_str());
  RefineResult r = refine_building(model, cloud, a.params);
  if (!overlap.empty()) r.report["warnings"].push_back(overlap);
  r.report["model"] = a.model;
  r.report["cloud"]["path"] = a.cloud;
  r.report["params"] = params_json(a.params);
  r.report["written"] = r.valid ? a.out : "";
  if (!a.report.empty()) write_file_atomic(a.report, r.report.dump(2) + "\n");
  if (r.valid) write_obj(a.out, r.mesh);
  if (!r.valid) {
    std::fprintf(stderr, "lodrefine: error: %s: no valid building to write: %s\n", model.id.c_str(),
                 r.report["output_validation"].value("problem", std::string("invalid")).c_str());
    exit_code() = 3;
    return;
  }
  std::printf("%s: %s -> %s (%.2f s)\n", model.id.c_str(), r.outcome.c_str(), a.out.c_str(),
              r.report["seconds"].value("total", 0.0));
}

}  // namespace

void add_refine_command(CLI::App& app) {
  static RefineArgs args;
  auto* cmd = app.add_subcommand("refine", "Refine one building model with an MLS point cloud");
  cmd->add_option("--model", args.model, "Coarse building model (OBJ, CityGML fan-out export)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--cloud", args.cloud, "MLS point cloud crop around the building (PLY or LAS)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", args.out, "Refined model (OBJ), written atomically")->required();
  cmd->add_option("--report", args.report, "JSON report: matches, planes, candidates, MIP, timings, validation");
  cmd->add_option("--max-points", args.max_points, "Refuse clouds with more points (a tile, not a crop)")->capture_default_str();
  add_cloud_options(cmd, args.cloud_options);
  add_param_options(cmd, args.params);
  cmd->callback([] { run(args); });
}

}  // namespace lodrefine::app
