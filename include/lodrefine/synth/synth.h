// Generator of test buildings with known ground truth: the true building, a coarse LoD2-like
// model of it (facades shifted/rotated, export defects) and a simulated MLS crop.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "lodrefine/base/files.h"
#include "lodrefine/base/types.h"

namespace lodrefine {

// Recess, Bay and Setback are the street-facade types: the true street facade has a full-height
// recess (back wall and two returns), a bay (front and two sides) or a facade line stepping back
// part-way, which the coarse model generalises to one plain front line.
enum class BuildingType { Flat, Gable, Hip, Shed, Stepped, LShape, TShape, Polygon, Recess, Bay, Setback };
const char* building_type_name(BuildingType t);            // "flat", "gable", ...
BuildingType building_type_from_name(const std::string&);  // throws InputError
std::vector<BuildingType> all_building_types();
// Recess, Bay, Setback: the coarse model lacks faces of the truth's street facade.
bool street_facade_type(BuildingType t);

// A mapping van's profile scanners (`--scanner van`): two profilers turned +-yaw_deg from across
// the street, `height` above the road, the van at `speed`; each profiler records a profile every
// 1 / profile_rate s with a ray every angle_step_deg, first hit within max_range. `drives` passes
// (the second back the other way in the far lane), misregistered against the first by a
// horizontal offset of up to `offset` m and a heading of up to heading_deg.
struct VanOptions {
  double speed = 10.0;          // m/s
  double profile_rate = 50.0;   // Hz, per profiler
  double angle_step_deg = 0.3;  // within a profile
  double height = 2.3;          // m above the road
  double yaw_deg = 45.0;        // profilers turned +- this from across the street
  double max_range = 40.0;      // m
  int drives = 2;
  double offset = 0.08;       // m: the second drive's misregistration, drawn in [offset / 4, offset]
  double heading_deg = 0.03;  // deg: and its heading error, drawn in [-heading_deg, heading_deg]
};

// The most rays one building's van scan may cast over all its drives (each return holds ~80
// bytes until the building is cropped: ~0.8 GB at most). The defaults cast ~0.5 M rays past a
// 20 m facade; --points bounds the even scanner the same way.
inline constexpr double kMaxVanRays = 10e6;

enum class Scanner {
  Even,  // the facades sampled evenly (a jittered grid), nuisances cut from it
  Van,   // ray cast from a van's trajectory (VanOptions), facade relief and street clutter
};

struct SynthOptions {
  double max_shift = 0.8;         // facade offset, uniform in [min_shift, max_shift] with random sign (m);
  double min_shift = 0.2;         // the street types' generalised front: [min_shift/2, 0.75 max_shift], no rotation
  double max_rotation_deg = 3.0;  // facade rotation about a vertical axis
  double global_shift = 0.03;     // whole coarse model shifted by up to this (m)
  int scanned_facades = 0;        // 0: random 1..3 (street types: the street walls, ignoring this)
  double noise = 0.01;            // MLS range noise sigma (m)
  int target_points = 30000;      // points on scanned facades, before nuisances
  bool defects = true;            // missing ground / mm gaps / flipped face / duplicate face
  bool nuisances = true;          // windows, recesses, occlusion holes, trees, cars, ground, neighbours
  Vec3 origin{85000.0, 447000.0, 0.0};  // georeferenced offset (RD New-like by default)
  Scanner scanner = Scanner::Even;
  VanOptions van;  // with Scanner::Van (target_points is then unused)
};

// A facade of the coarse model that differs from the truth.
struct MovedWall {
  std::vector<int> truth_faces;  // truth walls on the moved facade plane (first: the pivot wall)
  double offset = 0.0;           // perpendicular shift (m), positive = outward
  double rotation_deg = 0.0;     // about a vertical axis through the pivot wall's midpoint, CCW seen from above
  bool scanned = false;          // one of scanned_truth_faces
};

struct SynthBuilding {
  std::string id;
  BuildingType type;
  std::uint64_t seed = 0;
  SynthOptions options;
  Vec3 frame_origin = Vec3::Zero();  // georeferenced origin of the building's own frame
  double frame_rotation_deg = 0.0;   // rotation of the building's own frame about z
  std::vector<MovedWall> moved_walls;
  Vec3 coarse_shift = Vec3::Zero();      // global shift applied to the whole coarse model
  std::vector<std::string> defects;      // export defects of the coarse soup, e.g. "reversed_face:7"
  double point_spacing = 0.0;            // facade sampling grid step (m)
  Mesh truth;                            // closed, oriented, shared vertices, georeferenced
  Mesh coarse;                           // polygon soup as exported from CityGML (defects included), georeferenced
  PointCloud cloud;                      // georeferenced MLS crop
  std::vector<int> scanned_truth_faces;  // indices into truth.faces of the scanned walls (street types:
                                         // every street wall, returns and bay sides seen obliquely)
  Vec3 misregistration = Vec3::Zero();   // Scanner::Van: the second drive's shift against the first (m)
  std::vector<int> point_label;  // per cloud point: truth face index for facade points, -1 window recess, -2 clutter,
                                 // -3 ground, -4 neighbour, -5 relief (balcony, cornice), -6 room behind glass
};

// Throws InputError, one line naming the rule, for options out of their ranges, and with
// Scanner::Van for a van that would pass kMaxVanRays on even the smallest building (one street,
// its drives each of the 2 x 15 m they run on past the building's ends). make_building and
// rescan_tile call it; a command calls it first, before anything is written.
void check_synth_options(const SynthOptions& opt);

// The id make_building gives the building of (type, seed), and its folder's name:
// "synth_<type>_<seed, at least 4 digits>".
std::string synth_building_id(BuildingType type, std::uint64_t seed);

// Deterministic for (type, seed, options).
SynthBuilding make_building(BuildingType type, std::uint64_t seed, const SynthOptions& opt = {});

// Writes <out>/<id>/{truth.obj, coarse.obj, cloud.ply, meta.json} (without cloud.ply when
// `with_cloud` is false), recorded in `out` (a folder <id> that is a symbolic link is refused,
// InputError; a link at a file is replaced, never followed).
void write_synth_building(OutputTree& out, const SynthBuilding& b, bool with_cloud = true);

// Checks, before anything is made, that write_synth_building can write the buildings `ids` in
// `out`: throws InputError when a building's folder is a symbolic link or no folder, or when
// `tile_ply` (may be empty) is a building's folder or one of its files ("<tile>: the tile would
// be overwritten by "<id>"'s truth.obj; give another --out"). write_synth_tile calls it; a
// command writing buildings one by one calls it first.
void check_synth_outputs(const OutputTree& out, const std::vector<std::string>& ids, const std::string& tile_ply = "");

// A city tile for the city-scale bench: `count` buildings (types cycling, seeds first_seed...)
// on a square grid of `spacing` metres from opt.origin, each written as <out>/<id>/{truth.obj,
// coarse.obj, meta.json}, and all their clouds streamed into one binary PLY `tile_ply` (one
// building in memory at a time; written under a temporary name, renamed when complete, so a
// failure leaves the tile as it was). `progress` (may be empty) gets each building after it is
// written. Every output is checked first (check_synth_outputs). Returns the tile's points.
std::uint64_t write_synth_tile(OutputTree& out, const std::string& tile_ply, int count, std::uint64_t first_seed,
                               double spacing, const SynthOptions& opt,
                               const std::function<void(const SynthBuilding&)>& progress);

// A dev tile (../shared/devtiles layout: meta.json, truth/, models/, clouds/; from this
// project's tile generators) scanned again by the van: OUT gets the same truths, models and
// meta.json (with a "scanner" object and, per building, its drives and misregistration), and
// clouds/<id>.ply and tile.ply from the van (labels and building as the dev tiles'). Each
// building's van drives past the walls meta.json's scanned_walls names; `city` (a CityJSON
// file, may be empty) puts its buildings within 40 m in the street as neighbours (the one named
// by cityjson_id excepted); without it, boxes stand in for them. Crops: the model's box grown
// by 10 % and 3 m. Deterministic for (tile, city, opt, seed). `progress` (may be empty) gets each
// building's id and crop size. Throws InputError when OUT already holds a meta.json.
void rescan_tile(const std::string& tile, const std::string& city, const std::string& out, const SynthOptions& opt,
                 std::uint64_t seed, const std::function<void(const std::string&, std::size_t)>& progress);

}  // namespace lodrefine
