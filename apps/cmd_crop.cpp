// `lodrefine crop`: one cloud per building from a large tile, in one streaming pass.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.h"
#include "lodrefine/io/crop.h"
#include "lodrefine/io/obj.h"
#include "lodrefine/io/progress.h"
#include "options.h"

namespace lodrefine::app {
namespace {

namespace fs = std::filesystem;

struct CropArgs {
  std::string tile, models, out;
  double expand = 0.1, margin = 3.0;
  // Points held in memory before spilling to per-building files: ~100 MB at 24 bytes a point,
  // whatever the tile's size.
  std::size_t buffer_points = 4000000;
  CloudOptions cloud_options;
  bool quiet = false;
};

// Models: DIR/*.obj (id = stem) or DIR/<id>/coarse.obj.
std::vector<std::pair<std::string, fs::path>> find_models(const fs::path& dir) {
  std::vector<std::pair<std::string, fs::path>> found;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.is_regular_file() && e.path().extension() == ".obj") found.emplace_back(e.path().stem().string(), e.path());
    if (e.is_directory() && fs::exists(e.path() / "coarse.obj"))
      found.emplace_back(e.path().filename().string(), e.path() / "coarse.obj");
  }
  std::sort(found.begin(), found.end());
  return found;
}

void run(const CropArgs& a) {
  if (!fs::is_directory(a.models)) throw InputError(a.models + ": not a directory");
  const auto models = find_models(a.models);
  if (models.empty()) throw InputError(a.models + ": no *.obj or */coarse.obj models");
  std::vector<CropTarget> targets;
  std::vector<std::string> ids;
  int skipped = 0;
  for (const auto& [id, path] : models) {
    try {
      targets.push_back(crop_target(read_obj(path.string()), a.expand, a.margin));
      ids.push_back(id);
    } catch (const InputError& e) {  // one broken model must not stop the tile
      std::fprintf(stderr, "lodrefine: warning: skipping %s: %s\n", id.c_str(), e.what());
      ++skipped;
    }
  }
  std::vector<std::string> clouds;
  for (const auto& id : ids) {
    fs::create_directories(fs::path(a.out) / id);
    clouds.push_back((fs::path(a.out) / id / "cloud.ply").string());
  }
  std::vector<std::size_t> counts;
  std::unique_ptr<Progress> progress;  // made once the tile reads (its header count is the total)
  const std::size_t n = crop_tile_to_files(a.tile, targets, clouds, a.buffer_points, counts, a.cloud_options,
                                           [&](std::uint64_t read) {
                                             if (!progress)
                                               progress = std::make_unique<Progress>(
                                                   "crop", "points", cloud_point_count(a.tile),
                                                   Progress::mode_for_stderr(a.quiet));
                                             progress->update(read);
                                           });
  if (progress) progress->update(n), progress->finish();
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const fs::path dir = fs::path(a.out) / ids[i];
    const fs::path model = models[i].second;
    if (fs::absolute(model) != fs::absolute(dir / "coarse.obj")) {  // copied atomically, as every output
      const fs::path tmp = dir / ("coarse.obj.tmp." + std::to_string(::getpid()));
      fs::copy_file(model, tmp, fs::copy_options::overwrite_existing);
      fs::rename(tmp, dir / "coarse.obj");
    }
    std::printf("%s: %zu points\n", ids[i].c_str(), counts[i]);
  }
  std::printf("%zu tile points, %zu buildings cropped, %d skipped\n", n, targets.size(), skipped);
  if (skipped) exit_code() = 1;
}

}  // namespace

void add_crop_command(CLI::App& app) {
  static CropArgs args;
  auto* cmd = app.add_subcommand("crop", "Cut one cloud per building from a large PLY or LAS tile (streaming)");
  cmd->add_option("--tile", args.tile, "Large point cloud tile (PLY or LAS)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--models", args.models, "Folder of models: *.obj or <id>/coarse.obj")->required();
  cmd->add_option("--out", args.out, "Run folder: writes <id>/cloud.ply and <id>/coarse.obj")->required();
  add_ranged_option(cmd, "--expand", args.expand, "Relative box growth on each side", 0.0, 10.0);
  add_ranged_option(cmd, "--margin", args.margin, "Absolute box growth on each side (m)", 0.0, 1000.0);
  add_ranged_option(cmd, "--buffer-points", args.buffer_points, "Points held in memory before spilling to disk (memory bound)", std::size_t(1), std::size_t(1) << 40);
  add_cloud_options(cmd, args.cloud_options);
  cmd->add_flag("--quiet", args.quiet, "No progress line on stderr");
  cmd->callback([] { run(args); });
}

}  // namespace lodrefine::app
