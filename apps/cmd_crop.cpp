// `lodrefine crop`: one cloud per building from a large tile, in one streaming pass.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <tuple>

#include "commands.h"
#include "lodrefine/base/files.h"
#include "lodrefine/city/crop.h"
#include "lodrefine/city/progress.h"
#include "lodrefine/formats/obj.h"
#include "options.h"

namespace lodrefine::app {
namespace {

namespace fs = std::filesystem;

struct CropArgs {
  std::vector<std::string> tiles;  // --tile values: files or folders (cloud_files)
  std::string models, out;
  double expand = 0.1, margin = 3.0;
  // Points held in memory before spilling to per-building files: ~100 MB at 24 bytes a point,
  // whatever the tile's size.
  std::size_t buffer_points = 4000000;
  CloudOptions cloud_options;
  bool quiet = false;
};

// One building: its id (the model's file stem or folder name), its model file and the run
// folder's sub-folder it gets (a safe name).
struct Model {
  std::string id;
  fs::path path;
  std::string folder;
  std::string own_id;  // the id the model file holds (`o`, `# id:`), empty if none; set once read
};

// Models: DIR/*.obj (id = stem) or DIR/<id>/coarse.obj, in id order, each with its own safe
// folder name; two models with one id are refused (one would silently replace the other).
std::vector<Model> find_models(const fs::path& dir) {
  std::vector<Model> found;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.is_regular_file() && e.path().extension() == ".obj")
      found.push_back({e.path().stem().string(), e.path(), "", ""});
    if (e.is_directory() && fs::exists(e.path() / "coarse.obj"))
      found.push_back({e.path().filename().string(), e.path() / "coarse.obj", "", ""});
  }
  std::sort(found.begin(), found.end(),
            [](const Model& a, const Model& b) { return std::tie(a.id, a.path) < std::tie(b.id, b.path); });
  for (std::size_t i = 1; i < found.size(); ++i)
    if (found[i].id == found[i - 1].id)
      throw InputError(dir.string() + ": two models for building " + shown_id(found[i].id) + " (" +
                       found[i - 1].path.string() + ", " + found[i].path.string() + "); keep one");
  SafeNames names({"plots"});  // the run folder's own sub-folder
  for (auto& m : found) m.folder = names.add(m.id);
  return found;
}

// The outputs of the kept models, refused before anything is written when one is the tile or
// another model (with --out the --models folder, `a b.obj`'s hashed folder can be where a model
// `a_b--<hash>/coarse.obj` lies, renamed itself: its model was replaced without a word).
void check_outputs(const std::vector<Model>& models, const std::vector<Model>& kept,
                   const std::vector<std::string>& tiles, const CropArgs& a) {
  std::vector<RunFile> tile_files, outputs;
  for (const std::string& tile : tiles) tile_files.push_back({"tile", tile});
  for (const auto& m : kept)
    for (const char* name : {"cloud.ply", "coarse.obj"})
      outputs.push_back({shown_id(m.id) + "'s " + name, (fs::path(a.out) / m.folder / name).string()});
  refuse_overwritten(tile_files, outputs);
  std::map<std::string, const Model*> inputs;  // by path with its folders' links resolved
  for (const auto& m : models) inputs[fs::weakly_canonical(m.path).string()] = &m;
  for (const auto& m : kept)
    for (const char* name : {"cloud.ply", "coarse.obj"}) {
      const fs::path out = fs::path(a.out) / m.folder / name;
      const auto it = inputs.find((fs::weakly_canonical(out.parent_path()) / name).string());
      if (it != inputs.end() && it->second->id != m.id)
        throw InputError(it->second->path.string() + ": the model of " + shown_id(it->second->id) +
                         " would be overwritten by " + shown_id(m.id) + "'s " + name + "; give another --out");
    }
}

// A building's coarse.obj in the run folder: the model's bytes, with a `# id:` line in front when
// the model holds no id and the folder name is not its id (the OBJ reader would take the stem
// "coarse" otherwise).
void place_model(const Model& m, const fs::path& dir) {
  const fs::path target = dir / "coarse.obj";
  if (same_file(m.path.string(), target.string())) return;
  const bool one_line = m.id.find_first_of("\r\n") == std::string::npos;
  if (m.folder == m.id || !m.own_id.empty() || !one_line) return copy_file_atomic(m.path.string(), target.string());
  std::ifstream in(m.path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  write_file_atomic(target.string(), "# id: " + m.id + "\n" + text.str());
}

// The box of every model kept (their crop boxes): a tile that misses it is of another area or CRS.
Eigen::AlignedBox3d models_box(const std::vector<CropTarget>& targets) {
  Eigen::AlignedBox3d box;
  for (const CropTarget& t : targets)
    if ((t.lo.array() <= t.hi.array()).all()) box.extend(t.lo), box.extend(t.hi);
  return box;
}

void run(const CropArgs& a) {
  std::vector<SkippedEntry> not_tiles;  // the folders' entries that are no cloud files
  const std::vector<std::string> tiles = cloud_files(a.tiles, "--tile", &not_tiles);
  if (!fs::is_directory(a.models)) throw InputError(a.models + ": not a directory");
  const auto models = find_models(a.models);
  if (models.empty()) throw InputError(a.models + ": no *.obj or */coarse.obj models");
  std::vector<CropTarget> targets;
  std::vector<Model> kept;  // kept[i] is targets[i]'s model
  int skipped = 0;
  for (const auto& m : models) {
    try {
      const Mesh model = read_obj(m.path.string());
      targets.push_back(crop_target(model, a.expand, a.margin));
      kept.push_back(m);
      if (model.id != m.path.stem().string()) kept.back().own_id = model.id;
    } catch (const InputError& e) {  // one broken model must not stop the tile
      std::fprintf(stderr, "lodrefine: warning: skipping %s: %s\n", shown_id(m.id).c_str(),
                   escaped_line(e.what()).c_str());
      ++skipped;
    }
  }
  check_outputs(models, kept, tiles, a);
  OutputTree tree(a.out);  // a failed crop removes the folders and files it created (not those it replaced)
  std::vector<std::size_t> counts;
  std::size_t n = 0;
  std::vector<CloudFileRead> read;
  tree.folder();
  std::vector<std::string> clouds;
  for (const auto& m : kept) {
    // A building's folder that is a symbolic link (a run folder from elsewhere, used as --models
    // and --out) would take the building's files wherever it points: refused.
    tree.folder(m.folder);
    clouds.push_back(tree.file(m.folder + "/cloud.ply"));
    tree.file(m.folder + "/coarse.obj");
  }
  std::unique_ptr<Progress> progress;  // made once the tiles read (their header counts are the total)
  n = crop_tile_to_files(
      tiles, targets, clouds, a.buffer_points, counts, a.cloud_options,
      [&](std::uint64_t points) {
        if (!progress)
          progress = std::make_unique<Progress>("crop", "points", cloud_point_count(tiles),
                                                Progress::mode_for_stderr(a.quiet));
        progress->update(points);
      },
      &read);
  if (progress) progress->update(n), progress->finish();
  for (const auto& m : kept) place_model(m, fs::path(a.out) / m.folder);
  tree.keep();
  if (!not_tiles.empty()) std::printf("%s\n", skipped_entries_text(not_tiles).c_str());
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const std::string& id = kept[i].own_id.empty() ? kept[i].id : kept[i].own_id;
    if (kept[i].folder == id) std::printf("%s: %zu points\n", kept[i].folder.c_str(), counts[i]);
    else std::printf("%s: %zu points (building %s)\n", kept[i].folder.c_str(), counts[i], shown_id(id).c_str());
  }
  for (const std::string& w : overlap_problems(read, models_box(targets), "the models"))
    std::fprintf(stderr, "lodrefine: warning: %s\n", escaped_line(w).c_str());
  if (tiles.size() > 1)
    for (const CloudFileRead& f : read)
      std::printf("tile %s: %llu points\n", escaped_line(f.path).c_str(), (unsigned long long)f.points);
  std::printf("%zu tile points, %zu buildings cropped, %d skipped\n", n, targets.size(), skipped);
  if (skipped) exit_code() = 1;
}

}  // namespace

void add_crop_command(CLI::App& app) {
  static CropArgs args;
  auto* cmd = app.add_subcommand(
      "crop", "Cut one cloud per building from a large " + formats_text(kCloudFormatNames) + " tile (streaming)");
  cmd->add_option("--tile", args.tiles,
                  "Large point cloud tile (" + formats_text(kCloudFormatNames) +
                      "); a folder gives its cloud files by name; repeat for "
                      "several (one per drive or tile): read one after another as one cloud")
      ->required()
      ->check(CLI::ExistingPath);
  cmd->add_option("--models", args.models, "Folder of models (OBJ): *.obj or <id>/coarse.obj")->required();
  cmd->add_option("--out", args.out,
                  "Run folder: writes <name>/cloud.ply and <name>/coarse.obj (<name>: the id when it is a safe folder "
                  "name, else a safe form with a hash)")
      ->required();
  add_ranged_option(cmd, "--expand", args.expand, "Relative box growth on each side", 0.0, 10.0);
  add_ranged_option(cmd, "--margin", args.margin, "Absolute box growth on each side (m)", 0.0, 1000.0);
  add_ranged_option(cmd, "--buffer-points", args.buffer_points,
                    "Points held in memory before spilling to disk (memory bound)", std::size_t(1),
                    std::size_t(1) << 40);
  add_cloud_options(cmd, args.cloud_options);
  cmd->add_flag("--quiet", args.quiet, "No progress line on stderr");
  cmd->callback([] { run(args); });
}

}  // namespace lodrefine::app
