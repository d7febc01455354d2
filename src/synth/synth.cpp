// Synthetic buildings with known truth (see synth.h): the building types, and make_building,
// which draws a shape (shapes.h, shell.cpp), the coarse model's errors (perturb.h) and the scan
// (scan.h) from separate random streams, then georeferences them. Writing: tiles.cpp.
#include "lodrefine/synth/synth.h"

#include <cctype>
#include <cmath>
#include <cstdio>

#include "lodrefine/base/geometry.h"
#include "perturb.h"
#include "scan.h"
#include "shapes.h"
#include "van.h"

namespace lodrefine {

using namespace synth;

namespace {

// m: a van scan is cropped to the building's box grown by this and 10 %.
constexpr double kCropMargin = 3.0;

// Georeferencing.
struct Frame {
  Vec3 origin;
  double angle;  // rad
  Vec3 apply(const Vec3& p) const {
    const double c = std::cos(angle), s = std::sin(angle);
    return origin + Vec3(c * p.x() - s * p.y(), s * p.x() + c * p.y(), p.z());
  }
};

Mesh to_world(Mesh m, const Frame& f, const Vec3& shift) {
  for (auto& v : m.vertices) v = f.apply(v) + shift;
  for (int i = 0; i < int(m.faces.size()); ++i) m.faces[i].source = i;
  return m;
}

}  // namespace

void check_synth_options(const SynthOptions& o) {
  if (o.min_shift < 0 || o.max_shift < o.min_shift) throw InputError("synth: need 0 <= min_shift <= max_shift");
  if (o.max_shift > 3.0) throw InputError("synth: max_shift above 3 m would break the building's shape");
  if (o.max_rotation_deg < 0 || o.max_rotation_deg > 15) throw InputError("synth: max_rotation_deg must be in 0..15");
  if (o.noise < 0 || o.global_shift < 0) throw InputError("synth: noise and global_shift must be >= 0");
  if (o.target_points < 100) throw InputError("synth: target_points must be >= 100");
  if (o.scanned_facades < 0) throw InputError("synth: scanned_facades must be >= 0");
  const VanOptions& v = o.van;
  if (!(v.speed > 0 && v.profile_rate > 0 && v.speed / v.profile_rate >= 0.005))
    throw InputError("synth: the van needs speed / profile_rate >= 5 mm between profiles");
  if (!(v.angle_step_deg >= 0.01 && v.angle_step_deg <= 10))
    throw InputError("synth: angle_step_deg must be in 0.01..10");
  if (!(v.max_range > 1 && v.max_range <= 1000) || !(v.height > 0 && v.height < 10))
    throw InputError("synth: the van needs max_range in 1..1000 m and height in 0..10 m");
  if (v.drives < 1 || v.drives > 8 || !(v.offset >= 0 && v.offset <= 5) || !(std::abs(v.heading_deg) <= 5))
    throw InputError("synth: the van needs 1..8 drives, offset in 0..5 m and heading_deg in -5..5");
  if (o.scanner == Scanner::Van)
    require_van_rays(v.drives * van_drive_rays(v, 2 * kVanRunOn), "synth: on even the smallest building");
}

namespace {

// Every building type with its name, in the order `--type all` generates them.
constexpr std::pair<BuildingType, const char*> kBuildingTypes[] = {
    {BuildingType::Flat, "flat"},     {BuildingType::Gable, "gable"},     {BuildingType::Hip, "hip"},
    {BuildingType::Shed, "shed"},     {BuildingType::Stepped, "stepped"}, {BuildingType::LShape, "lshape"},
    {BuildingType::TShape, "tshape"}, {BuildingType::Polygon, "polygon"}, {BuildingType::Recess, "recess"},
    {BuildingType::Bay, "bay"},       {BuildingType::Setback, "setback"}};
}  // namespace

const char* building_type_name(BuildingType t) {
  for (const auto& [type, name] : kBuildingTypes)
    if (type == t) return name;
  return "unknown";
}

BuildingType building_type_from_name(const std::string& name) {
  std::string n;
  for (char c : name)
    if (c != '-' && c != '_') n += char(std::tolower(static_cast<unsigned char>(c)));
  std::string known;
  for (const auto& [type, type_name] : kBuildingTypes) {
    if (n == type_name) return type;
    known += (known.empty() ? "" : ", ") + std::string(type_name);
  }
  throw InputError("unknown building type '" + name + "' (" + known + ")");
}

std::vector<BuildingType> all_building_types() {
  std::vector<BuildingType> all;
  for (const auto& entry : kBuildingTypes) all.push_back(entry.first);
  return all;
}

bool street_facade_type(BuildingType t) {
  return t == BuildingType::Recess || t == BuildingType::Bay || t == BuildingType::Setback;
}

std::string synth_building_id(BuildingType type, std::uint64_t seed) {
  char id[64];
  std::snprintf(id, sizeof id, "synth_%s_%04llu", building_type_name(type), static_cast<unsigned long long>(seed));
  return id;
}

SynthBuilding make_building(BuildingType type, std::uint64_t seed, const SynthOptions& opt) {
  check_synth_options(opt);
  // One stream per stage, so --no-defects / --no-nuisances leave the other outputs unchanged.
  const std::uint64_t key = splitmix64(seed * 16 + std::uint64_t(type));
  Rng r(key), r_defects(splitmix64(key ^ 1)), r_scan(splitmix64(key ^ 2));
  SynthBuilding b;
  b.id = synth_building_id(type, seed);
  b.type = type;
  b.seed = seed;
  b.options = opt;
  const Frame frame{opt.origin + Vec3(r.uniform(-300, 300), r.uniform(-300, 300), 0), r.uniform(0, 2 * kPi)};
  b.frame_origin = frame.origin;
  b.frame_rotation_deg = frame.angle * 180.0 / kPi;
  const double z0 = r.uniform(-0.5, 2.0);

  const Spec spec = make_spec(type, r, z0);
  const Mesh truth = build_mesh(spec);
  const auto walls = wall_infos(truth);
  std::vector<int> scanned;
  if (spec.street.empty()) {
    const int k = opt.scanned_facades > 0 ? opt.scanned_facades : r.integer(1, 3);
    scanned = choose_scanned(truth, walls, k, r);
  } else {
    scanned = choose_street(truth, walls, spec.street, r);
  }
  b.scanned_truth_faces = wall_faces(scanned, walls);

  Mesh coarse_local;
  for (int attempt = 0;; ++attempt) {  // large moves can fold a part or sink an eave: redraw
    Spec moved = spec;
    if (spec.generalised.empty()) {
      b.moved_walls = move_facades(moved, walls, scanned, opt, r);
    } else {
      b.moved_walls = move_generalised(moved, walls, scanned, opt, r);
      moved.parts = moved.generalised;
    }
    try {
      coarse_local = build_mesh(moved);
      break;
    } catch (const ShapeError& e) {
      if (attempt == 19)
        throw std::runtime_error("synth: " + b.id + ": facade moves keep breaking the building (" + e.what() +
                                 "); reduce max_shift / max_rotation_deg");
    }
  }
  b.coarse_shift = r.unit3() * r.uniform(0, opt.global_shift);
  Mesh coarse = to_soup(to_world(coarse_local, frame, b.coarse_shift));
  if (opt.defects) b.defects = add_defects(coarse, r_defects);
  for (int i = 0; i < int(coarse.faces.size()); ++i) coarse.faces[i].source = i;

  if (opt.scanner == Scanner::Van) {
    const VanScan sc = van_scan(truth, b.scanned_truth_faces, z0, {}, opt, r_scan);
    b.point_spacing = sc.spacing;
    Eigen::AlignedBox3d crop = bounding_box(truth.vertices);  // a crop: the building's box grown by 3 m and 10 %
    const Vec3 grow = 0.1 * crop.sizes() + Vec3::Constant(kCropMargin);
    crop = Eigen::AlignedBox3d(crop.min() - grow, crop.max() + grow);
    for (std::size_t i = 0; i < sc.pts.size(); ++i)
      if (crop.contains(sc.pts[i]))
        b.cloud.points.push_back(frame.apply(sc.pts[i])), b.point_label.push_back(sc.labels[i]);
    if (sc.misregistration.size() > 1)
      b.misregistration = frame.apply(sc.misregistration[1].shift) - frame.apply(Vec3::Zero());
  } else {
    ScanResult sc = simulate_scan(truth, b.scanned_truth_faces, z0, spec.street_normal, opt, r_scan);
    b.point_spacing = sc.spacing;
    for (const auto& p : sc.pts) b.cloud.points.push_back(frame.apply(p));
    b.point_label = std::move(sc.labels);
  }

  b.truth = to_world(truth, frame, Vec3::Zero());
  b.truth.id = coarse.id = b.id;
  b.coarse = std::move(coarse);
  return b;
}

}  // namespace lodrefine
