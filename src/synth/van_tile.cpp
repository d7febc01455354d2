// A dev tile scanned again by the van (see synth.h, rescan_tile): the same truths and models, the
// clouds replaced by a van's scan of each building's street in its own neighbourhood.
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "lodrefine/base/files.h"
#include "lodrefine/base/geometry.h"
#include "lodrefine/city/crop.h"
#include "lodrefine/formats/cityjson.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/synth/synth.h"
#include "van.h"

namespace lodrefine {

using namespace synth;

namespace {

namespace fs = std::filesystem;

// m: city buildings whose box comes this close to the scanned building's stand in its street.
constexpr double kNeighbourhood = 40.0;
// The dev tiles' crop: the model's box grown by 10 % and 3 m.
constexpr double kCropRelative = 0.1, kCropAbsolute = 3.0;

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "rescan_tile writes the host's doubles and ints as binary_little_endian"
#endif

// The dev tiles' cloud layout: x y z (double), label (0 facade, 1 window, 2 clutter, 3 ground)
// and building (index in meta.json, -1 none), binary little endian.
struct DevtileCloud {
  std::vector<Vec3> pts;
  std::vector<int> label, building;

  std::string ply() const {
    std::string s = "ply\nformat binary_little_endian 1.0\ncomment lodrefine synth --rescan (van)\nelement vertex " +
                    std::to_string(pts.size()) +
                    "\nproperty double x\nproperty double y\nproperty double z\nproperty int label\nproperty int "
                    "building\nend_header\n";
    for (std::size_t i = 0; i < pts.size(); ++i) {
      char rec[32];
      std::memcpy(rec, pts[i].data(), 24);
      std::memcpy(rec + 24, &label[i], 4);
      std::memcpy(rec + 28, &building[i], 4);
      s.append(rec, 32);
    }
    return s;
  }
  void append(const DevtileCloud& o) {
    pts.insert(pts.end(), o.pts.begin(), o.pts.end());
    label.insert(label.end(), o.label.begin(), o.label.end());
    building.insert(building.end(), o.building.begin(), o.building.end());
  }
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

// The indices of the truth's faces that meta's scanned_walls names (positions among its walls).
std::vector<int> street_faces(const Mesh& truth, const nlohmann::json& scanned_walls) {
  std::vector<int> walls, out;
  for (int f = 0; f < int(truth.faces.size()); ++f)
    if (truth.faces[std::size_t(f)].sem == Semantic::Wall) walls.push_back(f);
  for (const auto& w : scanned_walls)
    if (w.is_number_integer() && w.get<long long>() >= 0 && w.get<long long>() < (long long)walls.size())
      out.push_back(walls[std::size_t(w.get<long long>())]);
  return out;
}

struct City {
  std::vector<Mesh> meshes;
  std::vector<Eigen::AlignedBox3d> boxes;
};

City read_city(const std::string& path) {
  City c;
  if (path.empty()) return c;
  for (auto& b : read_cityjson(path).buildings) {
    c.boxes.push_back(bounding_box(b.mesh.vertices));
    c.meshes.push_back(std::move(b.mesh));
  }
  return c;
}

// The city's buildings near `box` (world frame), but `self`, moved by -origin.
std::vector<Mesh> neighbours(const City& city, const Eigen::AlignedBox3d& box, const std::string& self,
                             const Vec3& origin) {
  std::vector<Mesh> out;
  for (std::size_t i = 0; i < city.meshes.size(); ++i) {
    if (city.meshes[i].id == self) continue;
    const auto& b = city.boxes[i];
    if (b.min().x() > box.max().x() + kNeighbourhood || b.max().x() < box.min().x() - kNeighbourhood ||
        b.min().y() > box.max().y() + kNeighbourhood || b.max().y() < box.min().y() - kNeighbourhood)
      continue;
    out.push_back(translated(city.meshes[i], -origin));
  }
  return out;
}

// The tile's origin, once meta.json is known to be a dev tile's: an origin of three numbers, and
// buildings each with an id that names a file in the tile's folders (no path, nothing hidden).
Vec3 tile_origin(const nlohmann::json& meta, const std::string& tile) {
  const std::string where = tile + "/meta.json: ";
  const auto& o = meta.contains("origin") ? meta["origin"] : nlohmann::json();
  if (!o.is_array() || o.size() != 3 || !o[0].is_number() || !o[1].is_number() || !o[2].is_number())
    throw InputError(where + "no origin of three numbers: not a dev tile");
  if (!meta.contains("buildings") || !meta["buildings"].is_array())
    throw InputError(where + "no buildings: not a dev tile");
  for (const auto& b : meta["buildings"]) {
    const bool named = b.is_object() && b.contains("id") && b["id"].is_string();
    const std::string id = named ? b["id"].get<std::string>() : std::string();
    if (id.empty() || id.find('/') != std::string::npos || id.find('\0') != std::string::npos || id[0] == '.')
      throw InputError(where + "a building without a safe id (" + (named ? id : b.dump().substr(0, 60)) + ")");
  }
  return {o[0].get<double>(), o[1].get<double>(), o[2].get<double>()};
}

}  // namespace

void rescan_tile(const std::string& tile, const std::string& city_path, const std::string& out, const SynthOptions& opt,
                 std::uint64_t seed, const std::function<void(const std::string&, std::size_t)>& progress) {
  const fs::path in(tile), to(out);
  if (fs::exists(to / "meta.json")) throw InputError(out + ": already holds a tile; give an empty folder");
  nlohmann::json meta = parse_json(read_file((in / "meta.json").string()), (in / "meta.json").string());
  const Vec3 origin = tile_origin(meta, tile);  // meta.json checked whole before anything is written
  const City city = read_city(city_path);
  for (const char* sub : {"clouds", "models", "truth"}) fs::create_directories(to / sub);
  DevtileCloud whole;
  int index = 0;
  for (auto& b : meta["buildings"]) {
    const std::string id = b["id"].get<std::string>();
    const Mesh truth = read_obj((in / "truth" / (id + ".obj")).string());
    const Mesh model = read_obj((in / "models" / (id + ".obj")).string());
    const Mesh local = translated(truth, -origin);
    double z0 = 1e300;
    for (const auto& v : local.vertices) z0 = std::min(z0, v.z());
    Rng r(splitmix64(seed * 1000003 + std::uint64_t(index)));
    const std::string self = b.value("cityjson_id", std::string());
    const VanScan scan = van_scan(local, street_faces(local, b.value("scanned_walls", nlohmann::json::array())), z0,
                                  neighbours(city, bounding_box(truth.vertices), self, origin), opt, r);
    const CropTarget crop = crop_target(model, kCropRelative, kCropAbsolute);
    DevtileCloud cloud;
    for (std::size_t i = 0; i < scan.pts.size(); ++i) {
      const Vec3 p = scan.pts[i] + origin;
      if ((p.array() < crop.lo.array()).any() || (p.array() > crop.hi.array()).any()) continue;
      const auto [label, owner] = devtile_label(scan.labels[i], index);
      cloud.pts.push_back(p), cloud.label.push_back(label), cloud.building.push_back(owner);
    }
    write_file_atomic((to / "clouds" / (id + ".ply")).string(), cloud.ply());
    fs::copy_file(in / "truth" / (id + ".obj"), to / "truth" / (id + ".obj"), fs::copy_options::overwrite_existing);
    fs::copy_file(in / "models" / (id + ".obj"), to / "models" / (id + ".obj"), fs::copy_options::overwrite_existing);
    int facade = 0;
    for (std::size_t i = 0; i < cloud.pts.size(); ++i) facade += cloud.building[i] == index && cloud.label[i] <= 1;
    b["points"] = facade;
    b["crop_points"] = cloud.pts.size();
    b["drives"] = scan.drives.size();
    if (scan.misregistration.size() > 1) {
      const Vec3& s = scan.misregistration[1].shift;
      b["misregistration"] = {{"shift", {s.x(), s.y(), s.z()}}, {"heading_deg", scan.misregistration[1].heading_deg}};
    }
    whole.append(cloud);
    if (progress) progress(id, cloud.pts.size());
    ++index;
  }
  const VanOptions& v = opt.van;
  meta["scanner"] = {{"kind", "van"},
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
  write_file_atomic((to / "tile.ply").string(), whole.ply());
  write_file_atomic((to / "meta.json").string(), meta.dump(1) + "\n");
}

}  // namespace lodrefine
