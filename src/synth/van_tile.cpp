// A dev tile scanned again by the van (see synth.h, rescan_tile): the same truths and models, the
// clouds replaced by a van's scan of each building's street in its own neighbourhood.
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>

#include "lodrefine/base/files.h"
#include "lodrefine/base/geometry.h"
#include "lodrefine/city/crop.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/formats/cityjson.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/formats/ply.h"
#include "lodrefine/synth/synth.h"
#include "van.h"

namespace lodrefine {

using namespace synth;

namespace {

namespace fs = std::filesystem;

// m: city buildings whose box comes this close to the scanned building's stand in its street.
constexpr double kNeighbourhood = 40.0;
// The face corners a street's city buildings may hold together: the van's scene (an AABB tree of
// their triangles, ~150 bytes a corner) is built for each scanned building, so a city stacking
// buildings each within size_problem's bounds at one spot made memory and time grow without end.
// 50 buildings at those bounds; a street of LoD2 buildings holds thousands (Delfshaven's largest
// building 1,916).
constexpr std::size_t kMaxStreetCorners = 1000000;
// The dev tiles' crop: the model's box grown by 10 % and 3 m.
constexpr double kCropRelative = 0.1, kCropAbsolute = 3.0;

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "rescan_tile writes the host's doubles and ints as binary_little_endian"
#endif

// The dev tiles' cloud layout: x y z (double), label (0 facade, 1 window, 2 clutter, 3 ground)
// and building (index in meta.json, -1 none), binary little endian.
constexpr const char* kDevtileProperties =
    "property double x\nproperty double y\nproperty double z\nproperty int label\nproperty int building\n";
constexpr const char* kDevtileComment = "lodrefine synth --rescan (van)";

// One building's crop in that layout.
struct DevtileCloud {
  std::string records;  // 32 bytes a point
  std::size_t points = 0, facade = 0;

  void add(const Vec3& p, int label, int building, bool own_facade) {
    char rec[32];
    std::memcpy(rec, p.data(), 24);
    std::memcpy(rec + 24, &label, 4);
    std::memcpy(rec + 28, &building, 4);
    records.append(rec, 32);
    ++points;
    facade += own_facade;
  }
  void write_to(PlyStream& ply) const { ply.write(records.data(), records.size(), points); }
};

// A scene label as the dev tiles' (label, building) for building `b`.
std::pair<int, int> devtile_label(int label, int b) {
  if (label >= 0) return {0, b};
  switch (label) {
    case kWindow: return {1, b};
    case kRelief:
    case kInterior: return {2, b};
    case kGround: return {3, -1};
    case kNeighbour: return {0, -1};
    default: return {2, -1};
  }
}

// One building of the tile, read and checked (with every other) before anything is written.
struct TileBuilding {
  std::string id;
  Mesh truth, model;              // as read, georeferenced
  std::vector<int> street;        // truth face indices of the walls scanned_walls names
  std::vector<std::size_t> self;  // the city buildings that are this one: kept out of its street
};

struct City {
  std::string path;
  std::vector<CityJsonBuilding> buildings;
  std::vector<Eigen::AlignedBox3d> boxes;
};

City read_city(const std::string& path) {
  City c{path, {}, {}};
  if (path.empty()) return c;
  c.buildings = read_cityjson(path).buildings;
  for (const auto& b : c.buildings) c.boxes.push_back(bounding_box(b.mesh.vertices));
  return c;
}

// "<tile>/meta.json: building "<id>"": where a fault in one building's entry lies.
std::string where_in(const std::string& tile, const std::string& id) {
  return tile + "/meta.json: building " + shown_id(id);
}

// The truth's faces that `scanned_walls` names (positions among its walls), each once: a wall
// listed again adds nothing (its relief would be drawn again, and the scan's time with it). An
// entry that is no wall of the truth is refused.
std::vector<int> street_faces(const Mesh& truth, const nlohmann::json& b, const std::string& where) {
  std::vector<int> walls, out;
  for (int f = 0; f < int(truth.faces.size()); ++f)
    if (truth.faces[std::size_t(f)].sem == Semantic::Wall) walls.push_back(f);
  const auto it = b.find("scanned_walls");
  if (it == b.end()) return out;
  if (!it->is_array()) throw InputError(where + ": scanned_walls is no list of wall indices");
  std::vector<bool> listed(walls.size(), false);
  for (const auto& w : *it) {
    const bool index = w.is_number_integer() && w.get<long long>() >= 0 && w.get<long long>() < (long long)walls.size();
    if (!index)
      throw InputError(where + ": scanned_walls holds " + escaped_line(w.dump().substr(0, 40)) + ", no index of its " +
                       std::to_string(walls.size()) + " walls");
    if (!listed[std::size_t(w.get<long long>())]) out.push_back(walls[std::size_t(w.get<long long>())]);
    listed[std::size_t(w.get<long long>())] = true;
  }
  return out;
}

// Area of the overlap of two boxes' footprints over that of their union.
double footprint_overlap(const Eigen::AlignedBox3d& a, const Eigen::AlignedBox3d& b) {
  const Eigen::Vector2d lo = a.min().head<2>().cwiseMax(b.min().head<2>());
  const Eigen::Vector2d hi = a.max().head<2>().cwiseMin(b.max().head<2>());
  const double both = (hi - lo).cwiseMax(0.0).prod();
  const double area_a = a.sizes().head<2>().prod(), area_b = b.sizes().head<2>().prod();
  return both > 0 ? both / (area_a + area_b - both) : 0.0;
}

// The city buildings that are the building itself (its copy must not stand in its own street):
// the one meta's cityjson_id names and its parts; without one (or ""), those standing where the truth
// stands: footprint boxes overlapping by half or more (a copy, a coarse model off by a metre),
// or a box within the truth's grown by 1 m (a part).
std::vector<std::size_t> city_self(const City& city, const Mesh& truth, const nlohmann::json& b,
                                   const std::string& where) {
  std::vector<std::size_t> out;
  const auto it = b.find("cityjson_id");
  bool named = it != b.end() && !it->is_null();
  if (named && !it->is_string()) throw InputError(where + ": cityjson_id is no string");
  if (city.path.empty()) return out;
  const std::string id = named ? it->get<std::string>() : std::string();
  named = !id.empty();  // "" would be every building's parent
  const Eigen::AlignedBox3d box = bounding_box(truth.vertices);
  const Eigen::AlignedBox3d grown(box.min() - Vec3(1, 1, 1e9), box.max() + Vec3(1, 1, 1e9));
  for (std::size_t i = 0; i < city.buildings.size(); ++i) {
    const CityJsonBuilding& c = city.buildings[i];
    const bool same = named ? c.mesh.id == id || c.parent == id
                            : footprint_overlap(box, city.boxes[i]) >= 0.5 || grown.contains(city.boxes[i]);
    if (same) out.push_back(i);
  }
  if (named && out.empty())
    throw InputError(where + ": cityjson_id " + shown_id(id) + " is no building of " + city.path);
  return out;
}

// The city's buildings near `box` (world frame), but `self`: those that stand in its street.
std::vector<std::size_t> near_buildings(const City& city, const Eigen::AlignedBox3d& box,
                                        const std::vector<std::size_t>& self) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < city.buildings.size(); ++i) {
    if (std::find(self.begin(), self.end(), i) != self.end()) continue;
    const auto& b = city.boxes[i];
    if (b.min().x() > box.max().x() + kNeighbourhood || b.max().x() < box.min().x() - kNeighbourhood ||
        b.min().y() > box.max().y() + kNeighbourhood || b.max().y() < box.min().y() - kNeighbourhood)
      continue;
    out.push_back(i);
  }
  return out;
}

// The city's buildings in the street of a building whose box is `box`, moved by -origin.
std::vector<Mesh> neighbours(const City& city, const Eigen::AlignedBox3d& box, const std::vector<std::size_t>& self,
                             const Vec3& origin) {
  std::vector<Mesh> out;
  for (std::size_t i : near_buildings(city, box, self)) out.push_back(translated(city.buildings[i].mesh, -origin));
  return out;
}

// The neighbours the van will meet, each within the bounds refine holds models to (size_problem:
// a face of 60,000 vertices made every ray slow), naming the city's building, and together
// within kMaxStreetCorners, naming the scanned building (`where`).
void check_neighbours(const City& city, const Eigen::AlignedBox3d& box, const std::vector<std::size_t>& self,
                      const std::string& where) {
  std::size_t corners = 0;
  for (std::size_t i : near_buildings(city, box, self)) {
    const Mesh& m = city.buildings[i].mesh;
    if (const std::string too_large = size_problem(m); !too_large.empty())
      throw InputError(city.path + ": building " + shown_id(m.id) + ": " + too_large);
    for (const Face& f : m.faces) corners += f.v.size();
  }
  if (corners > kMaxStreetCorners)
    throw InputError(where + ": the --city buildings within " + std::to_string(int(kNeighbourhood)) + " m of it hold " +
                     std::to_string(corners) + " face corners, more than " + std::to_string(kMaxStreetCorners) +
                     " (a street of LoD2 buildings holds thousands)");
}

// The tile's origin, once meta.json is known to be a dev tile's: an origin of three numbers, and
// a list of buildings.
Vec3 tile_origin(const nlohmann::json& meta, const std::string& tile) {
  const std::string where = tile + "/meta.json: ";
  const auto& o = meta.contains("origin") ? meta["origin"] : nlohmann::json();
  if (!o.is_array() || o.size() != 3 || !o[0].is_number() || !o[1].is_number() || !o[2].is_number())
    throw InputError(where + "no origin of three numbers: not a dev tile");
  if (!meta.contains("buildings") || !meta["buildings"].is_array())
    throw InputError(where + "no buildings: not a dev tile");
  const Vec3 origin(o[0].get<double>(), o[1].get<double>(), o[2].get<double>());
  if (!(origin.array().abs() <= kMaxCoordinate).all()) throw InputError(where + "an origin beyond 1e9 m");
  return origin;
}

// A building's id: a safe name (it names the tile's files, and ours), given once.
std::string building_id(const nlohmann::json& b, const std::string& tile, std::set<std::string>& seen) {
  const bool named = b.is_object() && b.contains("id") && b["id"].is_string();
  const std::string id = named ? b["id"].get<std::string>() : std::string();
  if (!is_safe_name(id))
    throw InputError(tile + "/meta.json: a building without a safe id (" +
                     (named ? shown_id(id) : escaped_line(b.dump().substr(0, 60))) +
                     "): ids name the tile's files: [A-Za-z0-9._-], at most " + std::to_string(kMaxSafeName) +
                     " bytes, no leading '.' or '-'");
  if (!seen.insert(id).second) throw InputError(where_in(tile, id) + ": listed twice");
  return id;
}

// A model of the tile: read, no wider than a building can be (a stray vertex would have the van
// drive for kilometres), within the bounds refine holds models to (size_problem: the van's rays
// meet every face).
Mesh read_model(const fs::path& path) {
  Mesh m = read_obj(path.string());
  std::string problem = building_extent_problem(m);
  if (problem.empty()) problem = size_problem(m);
  if (!problem.empty()) throw InputError(path.string() + ": " + problem);
  return m;
}

// Every building of meta.json, read and checked: ids, files, sizes, walls, the city's copy and
// the van's rays. Nothing is written before this returns.
std::vector<TileBuilding> read_tile(const nlohmann::json& meta, const std::string& tile, const Vec3& origin,
                                    const City& city, const SynthOptions& opt) {
  const fs::path in(tile);
  std::vector<TileBuilding> out;
  std::set<std::string> seen;
  for (const auto& b : meta["buildings"]) {
    TileBuilding t;
    t.id = building_id(b, tile, seen);
    const std::string where = where_in(tile, t.id);
    t.truth = read_model(in / "truth" / (t.id + ".obj"));
    t.model = read_model(in / "models" / (t.id + ".obj"));
    t.street = street_faces(t.truth, b, where);
    t.self = city_self(city, t.truth, b, where);
    check_neighbours(city, bounding_box(t.truth.vertices), t.self, where);
    require_van_rays(van_scan_rays(translated(t.truth, -origin), t.street, opt.van), where);
    out.push_back(std::move(t));
  }
  return out;
}

// Refuses a rescan whose output would overwrite one of its inputs (a --city file where a
// building's truth goes, say): every file named before the first is written.
void check_rescan_outputs(const std::vector<TileBuilding>& buildings, const std::string& tile,
                          const std::string& city_path, const std::string& out) {
  const fs::path in(tile), to(out);
  std::vector<RunFile> inputs{{"tile's meta.json", (in / "meta.json").string()}, {"--city file", city_path}};
  std::vector<RunFile> outputs{{"the rescan's meta.json", (to / "meta.json").string()},
                               {"the rescan's tile.ply", (to / "tile.ply").string()}};
  for (const TileBuilding& t : buildings) {
    for (const char* sub : {"truth", "models"}) {
      const std::string what = std::string(sub) + " of " + shown_id(t.id);
      inputs.push_back({"tile's " + what, (in / sub / (t.id + ".obj")).string()});
      outputs.push_back({"the rescan's " + what, (to / sub / (t.id + ".obj")).string()});
    }
    outputs.push_back({"the rescan's cloud of " + shown_id(t.id), (to / "clouds" / (t.id + ".ply")).string()});
  }
  refuse_overwritten(inputs, outputs);
}

// Building `index`'s van scan, cropped as the dev tiles' (the model's box grown by 10 % and 3 m),
// with its drives recorded in its meta entry `b`.
DevtileCloud scan_building(const TileBuilding& t, std::size_t index, const City& city, const Vec3& origin,
                           const SynthOptions& opt, std::uint64_t seed, nlohmann::json& b) {
  const Mesh local = translated(t.truth, -origin);
  double z0 = 1e300;
  for (const auto& v : local.vertices) z0 = std::min(z0, v.z());
  Rng r(splitmix64(seed * 1000003 + std::uint64_t(index)));
  const VanScan scan =
      van_scan(local, t.street, z0, neighbours(city, bounding_box(t.truth.vertices), t.self, origin), opt, r);
  const CropTarget crop = crop_target(t.model, kCropRelative, kCropAbsolute);
  DevtileCloud cloud;
  for (std::size_t i = 0; i < scan.pts.size(); ++i) {
    const Vec3 p = scan.pts[i] + origin;
    if ((p.array() < crop.lo.array()).any() || (p.array() > crop.hi.array()).any()) continue;
    const auto [label, owner] = devtile_label(scan.labels[i], int(index));
    cloud.add(p, label, owner, owner == int(index) && label <= 1);
  }
  b["points"] = cloud.facade;
  b["crop_points"] = cloud.points;
  b["drives"] = scan.drives.size();
  if (scan.misregistration.size() > 1) {
    const Vec3& s = scan.misregistration[1].shift;
    b["misregistration"] = {{"shift", {s.x(), s.y(), s.z()}}, {"heading_deg", scan.misregistration[1].heading_deg}};
  }
  return cloud;
}

// meta.json's "scanner": how the clouds were made.
nlohmann::json scanner_json(const std::string& tile, const std::string& city_path, const SynthOptions& opt,
                            std::uint64_t seed) {
  const VanOptions& v = opt.van;
  return {{"kind", "van"},
          {"source_tile", tile},
          {"city", city_path},
          {"seed", seed},
          {"speed", v.speed},
          {"profile_rate", v.profile_rate},
          {"angle_step_deg", v.angle_step_deg},
          {"height", v.height},
          {"yaw_deg", v.yaw_deg},
          {"max_range", v.max_range},
          {"drives", v.drives},
          {"offset", v.offset},
          {"heading_deg", v.heading_deg},
          {"noise", opt.noise},
          {"relief", opt.nuisances}};
}

// <root>/<sub>/<name>, its folder made when the first file goes into it: a run killed while the
// van scans leaves no empty folders behind.
std::string file_in(OutputTree& tree, const char* sub, const std::string& name) {
  tree.folder(sub);
  return tree.file(std::string(sub) + "/" + name);
}

}  // namespace

void rescan_tile(const std::string& tile, const std::string& city_path, const std::string& out, const SynthOptions& opt,
                 std::uint64_t seed, const std::function<void(const std::string&, std::size_t)>& progress) {
  check_synth_options(opt);
  OutputTree tree(out);
  const fs::path in(tile);
  if (fs::exists(fs::path(out) / "meta.json")) throw InputError(out + ": already holds a tile; give an empty folder");
  for (const char* sub : {"clouds", "models", "truth"}) tree.check_folder(sub);  // a planted link refused
  nlohmann::json meta = parse_json(read_file((in / "meta.json").string()), (in / "meta.json").string());
  const Vec3 origin = tile_origin(meta, tile);
  const City city = read_city(city_path);
  const std::vector<TileBuilding> buildings = read_tile(meta, tile, origin, city, opt);
  check_rescan_outputs(buildings, tile, city_path, out);
  // The tile's cloud streamed, one building's crop in memory at a time; opened with the first
  // building's files.
  std::optional<PlyStream> whole;
  for (std::size_t index = 0; index < buildings.size(); ++index) {
    const TileBuilding& t = buildings[index];
    const DevtileCloud cloud = scan_building(t, index, city, origin, opt, seed, meta["buildings"][index]);
    PlyStream own(file_in(tree, "clouds", t.id + ".ply"), kDevtileComment, kDevtileProperties);
    cloud.write_to(own);
    own.commit();
    copy_file_atomic((in / "truth" / (t.id + ".obj")).string(), file_in(tree, "truth", t.id + ".obj"));
    copy_file_atomic((in / "models" / (t.id + ".obj")).string(), file_in(tree, "models", t.id + ".obj"));
    if (!whole) whole.emplace(tree.file("tile.ply"), kDevtileComment, kDevtileProperties);
    cloud.write_to(*whole);
    if (progress) progress(t.id, cloud.points);
  }
  if (!whole) {  // a tile of no buildings
    tree.folder();
    whole.emplace(tree.file("tile.ply"), kDevtileComment, kDevtileProperties);
  }
  meta["scanner"] = scanner_json(tile, city_path, opt, seed);
  whole->commit();
  write_file_atomic(tree.file("meta.json"), meta.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  tree.keep();
}

}  // namespace lodrefine
