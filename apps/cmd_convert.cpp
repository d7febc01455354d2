// `lodrefine convert`: a CityJSON / CityJSONSeq or CityGML file -> one OBJ per LoD2 building, as an FME
// fan-out export writes them (polygon soup, `o <id>`, WallSurface/RoofSurface/GroundSurface
// groups, georeferenced coordinates), ready for `lodrefine refine` / `crop`; fins lodrefine
// wrote beside a Solid follow in the fins group, as refine writes them.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <set>

#include "commands.h"
#include "lodrefine/base/files.h"
#include "lodrefine/formats/citygml.h"
#include "lodrefine/formats/obj.h"
#include "options.h"

namespace lodrefine::app {
namespace {

namespace fs = std::filesystem;

struct ConvertArgs {
  std::string cityjson, citygml, out_dir, lod;
  std::vector<std::string> ids;
};

// Output names for the chosen buildings: safe and distinct (SafeNames), each <name>.obj new
// in --out-dir and none the input file, all checked before anything is written.
std::vector<fs::path> output_paths(const std::vector<const CityJsonBuilding*>& chosen, const ConvertArgs& a,
                                   const std::string& input) {
  SafeNames names;
  std::vector<fs::path> out;
  for (const CityJsonBuilding* b : chosen) {
    out.push_back(fs::path(a.out_dir) / (names.add(b->mesh.id) + ".obj"));
    if (same_file(out.back().string(), input))
      throw InputError(out.back().string() + ": would overwrite the input file; give another --out-dir");
    std::error_code ec;
    if (fs::exists(fs::symlink_status(out.back(), ec)))
      throw InputError(out.back().string() +
                       ": already exists (convert never overwrites); give an empty or new --out-dir");
  }
  return out;
}

// A building's faces and, apart, the fins read beside its Solid (its OBJ's fins group).
ObjModel solid_and_fins(const CityJsonBuilding& b) {
  std::vector<char> in_fins(b.mesh.faces.size(), 0);
  std::fill(in_fins.end() - b.fin_faces, in_fins.end(), 1);
  return split_fins(b.mesh, in_fins);
}

// A building lodrefine wrote whose Solid kept no surface (every ring degenerate) but whose fins
// did: its fins alone are no model of it.
bool fins_only(const CityJsonBuilding& b) { return b.fin_faces > 0 && std::size_t(b.fin_faces) == b.mesh.faces.size(); }

// Writes every model or none: on a failure (a full disk) what was written is removed again.
void write_all(const std::vector<const CityJsonBuilding*>& chosen, const std::vector<fs::path>& paths,
               const ConvertArgs& a) {
  const bool made_dir = fs::create_directories(a.out_dir);
  std::size_t written = 0;
  try {
    for (; written < chosen.size(); ++written) {
      const ObjModel m = solid_and_fins(*chosen[written]);
      write_obj(paths[written].string(), m.solid, m.fins);
    }
  } catch (...) {
    for (std::size_t i = 0; i < written; ++i) fs::remove(paths[i]);
    if (made_dir) fs::remove(a.out_dir);
    throw;
  }
}

void run(const ConvertArgs& a) {
  if (a.cityjson.empty() && a.citygml.empty()) throw InputError("convert needs --cityjson FILE or --citygml FILE");
  const std::string& path = a.citygml.empty() ? a.cityjson : a.citygml;
  if (!a.citygml.empty() && !a.lod.empty() && a.lod != "2")
    throw InputError(path + ": CityGML buildings are read at LoD 2 only (--lod " + a.lod + ")");
  const CityJsonFile file = a.citygml.empty() ? read_cityjson(path, a.lod) : read_citygml(path);
  const std::set<std::string> wanted(a.ids.begin(), a.ids.end());
  std::vector<const CityJsonBuilding*> chosen;
  std::vector<std::string> no_solid;  // fins_only: skipped, each named
  std::set<std::string> found;
  for (const auto& b : file.buildings) {
    if (!wanted.empty() && !wanted.count(b.mesh.id)) continue;
    found.insert(b.mesh.id);
    if (fins_only(b)) no_solid.push_back(b.mesh.id);
    else chosen.push_back(&b);
  }
  for (const auto& id : wanted)
    if (!found.count(id))
      throw InputError(path + ": no Building/BuildingPart " + shown_id(id) + " with an LoD 2.x geometry");
  // A building asked for by name is converted or the run refused, never skipped with a note.
  if ((chosen.empty() || !wanted.empty()) && !no_solid.empty())
    throw InputError(path + ": " + shown_id(no_solid.front()) + "'s Solid has no usable surface, only fins beside it" +
                     (no_solid.size() > 1 ? " (and " + std::to_string(no_solid.size() - 1) + " more)" : "") +
                     "; nothing to convert");
  if (chosen.empty())
    throw InputError(path + ": no Building/BuildingPart with " +
                     (a.lod.empty() ? std::string("an LoD 2.x") : "an LoD " + a.lod) + " geometry (" +
                     std::to_string(file.objects_without_lod2) +
                     " building object(s) without one); nothing to convert");
  const std::vector<fs::path> paths = output_paths(chosen, a, path);
  write_all(chosen, paths, a);
  // Every building by name: the ones written (file <- id), then what the reader dropped or changed.
  for (std::size_t i = 0; i < chosen.size(); ++i)
    std::printf("%s <- %s\n", paths[i].filename().string().c_str(), shown_id(chosen[i]->mesh.id).c_str());
  for (const auto& note : file.notes)
    std::fprintf(stderr, "lodrefine: note: %s: %s\n", escaped_line(path).c_str(), escaped_line(note).c_str());
  for (const auto& id : no_solid)
    std::fprintf(stderr, "lodrefine: note: %s: %s's Solid has no usable surface, only fins beside it: skipped\n",
                 escaped_line(path).c_str(), shown_id(id).c_str());
  for (const auto& id : file.ids_without_lod2)
    std::fprintf(stderr, "lodrefine: note: %s: %s has no LoD %s geometry, skipped\n", escaped_line(path).c_str(),
                 shown_id(id).c_str(), a.lod.empty() ? "2.x" : a.lod.c_str());
  const std::string fins_alone =
      no_solid.empty() ? "" : ", " + std::to_string(no_solid.size()) + " with fins and no usable Solid skipped";
  std::printf("%zu building(s) written to %s (%s %s%s, %s; %d object(s) without LoD %s skipped%s)\n", chosen.size(),
              escaped_line(a.out_dir).c_str(), file.format.c_str(), escaped_line(file.version).c_str(),
              file.sequence ? " sequence" : "", file.crs.empty() ? "no CRS" : escaped_line(file.crs).c_str(),
              file.objects_without_lod2, a.lod.empty() ? "2.x" : a.lod.c_str(), fins_alone.c_str());
}

}  // namespace

void add_convert_command(CLI::App& app) {
  static ConvertArgs args;
  auto* cmd =
      app.add_subcommand("convert", "Write each LoD2 building of a CityJSON (Seq) or CityGML file as its own OBJ");
  auto* json_in = cmd->add_option("--cityjson", args.cityjson, "CityJSON 1.0/1.1/2.0 file or CityJSONSeq (.jsonl)")
                      ->check(CLI::ExistingFile);
  cmd->add_option("--citygml", args.citygml, "CityGML 1.0/2.0 file (Building, BuildingPart)")
      ->check(CLI::ExistingFile)
      ->excludes(json_in);
  cmd->add_option("--lod", args.lod, "The LoD geometry to write, e.g. 2.2 or 1.2 (default: the highest 2.x)")
      ->check(lod_validator());
  cmd->add_option("--id", args.ids, "Only these CityObject ids (repeatable; default: every building)");
  cmd->add_option("--out-dir", args.out_dir,
                  "Directory for <name>.obj (created if missing; existing files are never overwritten). <name> is the "
                  "id when it is a safe file name ([A-Za-z0-9._-], at most 100 bytes), else a safe form with a hash; "
                  "the id stays inside the file")
      ->required();
  cmd->callback([] { run(args); });
}

}  // namespace lodrefine::app
