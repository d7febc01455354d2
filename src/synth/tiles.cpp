// Writing generated buildings (see synth.h): one folder per building, or a city tile whose
// clouds stream into one PLY.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "lodrefine/base/files.h"
#include "lodrefine/base/geometry.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/formats/ply.h"
#include "lodrefine/synth/synth.h"

namespace lodrefine {

namespace {

using Json = nlohmann::ordered_json;  // keeps the fields in a readable order

Json vec_json(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

Json meta_json(const SynthBuilding& b) {
  using json = Json;
  const auto& o = b.options;
  json moved = json::array();
  for (const auto& m : b.moved_walls)
    moved.push_back({{"truth_faces", m.truth_faces},
                     {"offset", m.offset},
                     {"rotation_deg", m.rotation_deg},
                     {"scanned", m.scanned}});
  std::map<std::string, int> by_label;
  for (int l : b.point_label)
    by_label[l >= 0    ? "facade"
             : l == -1 ? "window_recess"
             : l == -2 ? "clutter"
             : l == -3 ? "ground"
             : l == -4 ? "neighbour"
             : l == -5 ? "relief"
                       : "interior"]++;
  return {
      {"id", b.id},
      {"type", building_type_name(b.type)},
      {"seed", b.seed},
      {"origin", vec_json(o.origin)},
      {"frame_origin", vec_json(b.frame_origin)},
      {"frame_rotation_deg", b.frame_rotation_deg},
      {"options",
       {{"min_shift", o.min_shift},
        {"max_shift", o.max_shift},
        {"max_rotation_deg", o.max_rotation_deg},
        {"global_shift", o.global_shift},
        {"scanned_facades", o.scanned_facades},
        {"noise", o.noise},
        {"target_points", o.target_points},
        {"defects", o.defects},
        {"nuisances", o.nuisances},
        {"scanner", o.scanner == Scanner::Van ? "van" : "even"}}},
      {"van", o.scanner != Scanner::Van ? Json(nullptr)
                                        : Json{{"speed", o.van.speed},
                                               {"profile_rate", o.van.profile_rate},
                                               {"angle_step_deg", o.van.angle_step_deg},
                                               {"height", o.van.height},
                                               {"yaw_deg", o.van.yaw_deg},
                                               {"max_range", o.van.max_range},
                                               {"drives", o.van.drives},
                                               {"offset", o.van.offset},
                                               {"heading_deg", o.van.heading_deg},
                                               {"misregistration", vec_json(b.misregistration)}}},
      {"moved_walls", moved},
      {"coarse_shift", vec_json(b.coarse_shift)},
      {"defects", b.defects},
      {"scanned_truth_faces", b.scanned_truth_faces},
      {"point_spacing", b.point_spacing},
      {"point_labels",
       "cloud.ply property 'label': truth face index for facade points, -1 window recess, "
       "-2 clutter (trees, cars, people), -3 street ground, -4 neighbouring building, -5 relief (balcony, "
       "cornice, ledge), -6 room behind glass"},
      {"counts",
       {{"truth_faces", b.truth.faces.size()},
        {"truth_vertices", b.truth.vertices.size()},
        {"coarse_faces", b.coarse.faces.size()},
        {"points", b.cloud.points.size()},
        {"points_by_label", by_label}}},
  };
}

}  // namespace

void write_synth_building(OutputTree& out, const SynthBuilding& b, bool with_cloud) {
  out.folder(b.id);
  write_obj(out.file(b.id + "/truth.obj"), b.truth);
  write_obj(out.file(b.id + "/coarse.obj"), b.coarse);
  if (with_cloud) {
    const std::vector<float> labels(b.point_label.begin(), b.point_label.end());
    write_ply(out.file(b.id + "/cloud.ply"), b.cloud, Vec3::Zero(), &labels, "label");
  }
  write_file_atomic(out.file(b.id + "/meta.json"),
                    meta_json(b).dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

void check_synth_outputs(const OutputTree& out, const std::vector<std::string>& ids, const std::string& tile_ply) {
  std::vector<RunFile> outputs;
  for (const std::string& id : ids) {
    out.check_folder(id);
    if (tile_ply.empty()) continue;
    const std::filesystem::path folder = std::filesystem::path(out.root()) / id;
    outputs.push_back({shown_id(id) + "'s folder", folder.string()});
    for (const char* name : {"truth.obj", "coarse.obj", "cloud.ply", "meta.json"})
      outputs.push_back({shown_id(id) + "'s " + name, (folder / name).string()});
  }
  refuse_overwritten({{"tile", tile_ply}}, outputs);
}

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "write_synth_tile writes the host's doubles as binary_little_endian"
#endif

std::uint64_t write_synth_tile(OutputTree& out, const std::string& tile_ply, int count, std::uint64_t first_seed,
                               double spacing, const SynthOptions& opt,
                               const std::function<void(const SynthBuilding&)>& progress) {
  const auto types = all_building_types();
  std::vector<std::string> ids;
  for (int i = 0; i < count; ++i)
    ids.push_back(synth_building_id(types[std::size_t(i) % types.size()], first_seed + std::uint64_t(i)));
  check_synth_outputs(out, ids, tile_ply);
  PlyStream tile(tile_ply, "lodrefine synth tile", "property double x\nproperty double y\nproperty double z\n");
  const int columns = std::max(1, int(std::ceil(std::sqrt(double(count)))));
  for (int i = 0; i < count; ++i) {
    SynthBuilding b = make_building(types[std::size_t(i) % types.size()], first_seed + std::uint64_t(i), opt);
    // Onto its grid cell: a pure translation, so truth, model, scan and meta stay consistent.
    const Vec3 cell = opt.origin + Vec3(spacing * (i % columns), spacing * (i / columns), 0.0);
    const Vec3 shift(cell.x() - b.frame_origin.x(), cell.y() - b.frame_origin.y(), 0.0);
    b.truth = translated(std::move(b.truth), shift);
    b.coarse = translated(std::move(b.coarse), shift);
    for (auto& p : b.cloud.points) p += shift;
    b.frame_origin += shift;
    write_synth_building(out, b, false);
    std::vector<double> xyz;
    xyz.reserve(3 * b.cloud.points.size());
    for (const auto& p : b.cloud.points) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
    tile.write(reinterpret_cast<const char*>(xyz.data()), xyz.size() * sizeof(double), b.cloud.points.size());
    if (progress) progress(b);
  }
  tile.commit();
  return tile.vertices();
}

}  // namespace lodrefine
