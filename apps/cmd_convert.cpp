// `lodrefine convert`: a CityJSON / CityJSONSeq or CityGML file -> one OBJ per LoD2 building, as an FME
// fan-out export writes them (polygon soup, `o <id>`, WallSurface/RoofSurface/GroundSurface
// groups, georeferenced coordinates), ready for `lodrefine refine` / `crop`.
#include <cstdio>
#include <filesystem>
#include <set>

#include "commands.h"
#include "lodrefine/io/citygml.h"
#include "lodrefine/io/obj.h"

namespace lodrefine::app {
namespace {

namespace fs = std::filesystem;

struct ConvertArgs {
  std::string cityjson, citygml, out_dir, lod;
  std::vector<std::string> ids;
};

void run(const ConvertArgs& a) {
  if (a.cityjson.empty() && a.citygml.empty()) throw InputError("convert needs --cityjson FILE or --citygml FILE");
  const std::string& path = a.citygml.empty() ? a.cityjson : a.citygml;
  if (!a.citygml.empty() && !a.lod.empty() && a.lod != "2")
    throw InputError(path + ": CityGML buildings are read at LoD 2 only (--lod " + a.lod + ")");
  const CityJsonFile file = a.citygml.empty() ? read_cityjson(path, a.lod) : read_citygml(path);
  const std::set<std::string> wanted(a.ids.begin(), a.ids.end());
  std::vector<const CityJsonBuilding*> chosen;
  std::set<std::string> found;
  for (const auto& b : file.buildings)
    if (wanted.empty() || wanted.count(b.mesh.id)) chosen.push_back(&b), found.insert(b.mesh.id);
  for (const auto& id : wanted)
    if (!found.count(id)) throw InputError(path + ": no Building/BuildingPart '" + id + "' with an LoD 2.x geometry");
  if (chosen.empty())
    throw InputError(path + ": no Building/BuildingPart with " +
                     (a.lod.empty() ? std::string("an LoD 2.x") : "an LoD " + a.lod) + " geometry (" +
                     std::to_string(file.objects_without_lod2) + " building object(s) without one); nothing to convert");
  fs::create_directories(a.out_dir);
  std::set<std::string> stems;
  for (const CityJsonBuilding* b : chosen) {
    std::string stem = file_stem_for_id(b->mesh.id);
    for (int k = 2; !stems.insert(stem).second; ++k) stem = file_stem_for_id(b->mesh.id) + "_" + std::to_string(k);
    write_obj((fs::path(a.out_dir) / (stem + ".obj")).string(), b->mesh);
    if (b->skipped_holes + b->skipped_rings + b->skipped_shells > 0)
      std::fprintf(stderr, "lodrefine: note: %s: dropped %d inner ring(s), %d degenerate surface(s), %d interior shell(s)\n",
                   b->mesh.id.c_str(), b->skipped_holes, b->skipped_rings, b->skipped_shells);
  }
  std::printf("%zu building(s) written to %s (%s %s%s, %s; %d object(s) without LoD %s skipped)\n", chosen.size(),
              a.out_dir.c_str(), file.format.c_str(), file.version.c_str(), file.sequence ? " sequence" : "",
              file.crs.empty() ? "no CRS" : file.crs.c_str(), file.objects_without_lod2,
              a.lod.empty() ? "2.x" : a.lod.c_str());
}

}  // namespace

void add_convert_command(CLI::App& app) {
  static ConvertArgs args;
  auto* cmd = app.add_subcommand("convert", "Write each LoD2 building of a CityJSON (Seq) or CityGML file as its own OBJ");
  auto* json_in = cmd->add_option("--cityjson", args.cityjson, "CityJSON 1.0/1.1/2.0 file or CityJSONSeq (.jsonl)")
                      ->check(CLI::ExistingFile);
  cmd->add_option("--citygml", args.citygml, "CityGML 1.0/2.0 file (Building, BuildingPart)")
      ->check(CLI::ExistingFile)
      ->excludes(json_in);
  cmd->add_option("--lod", args.lod, "The LoD geometry to write, e.g. 2.2 or 1.2 (default: the highest 2.x)");
  cmd->add_option("--id", args.ids, "Only these CityObject ids (repeatable; default: every building)");
  cmd->add_option("--out-dir", args.out_dir, "Directory for <id>.obj (created if missing)")->required();
  cmd->callback([] { run(args); });
}

}  // namespace lodrefine::app
