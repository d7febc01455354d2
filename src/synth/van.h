// A mapping van's scan (internal to synth): a street scene of triangles (buildings, their facade
// relief, parked cars, people, lamp posts, tree trunks, the ground) and porous tree crowns, ray
// cast from the van's profilers with CGAL's AABB tree, first hit. Frame: any local one.
#pragma once
#include <memory>
#include <vector>

#include "lodrefine/synth/synth.h"
#include "rng.h"

namespace lodrefine::synth {

// What a ray hit, as SynthBuilding::point_label: a truth face index (>= 0) of a scanned
// building, or one of these.
enum SceneLabel : int {
  kWindow = -1,     // a door or window pane set back in its reveal
  kClutter = -2,    // cars, people, lamp posts, trees
  kGround = -3,     // the street
  kNeighbour = -4,  // a building that is not being scanned for
  kRelief = -5,     // balconies, cornices, ledges: proud of the wall
  kInterior = -6,   // a room seen through glass
};

// An opening in a wall, in the wall's (s along u, z) coordinates: the pane is `reveal` metres
// behind the wall plane; through glass the ray returns from a room `room` metres behind it, or
// not at all.
struct Opening {
  enum class Pane { Opaque, Dark, Room };
  double s0, s1, z0, z1, reveal;
  Pane pane;
  double room = 0;
};

// A wall that carries openings: a point o on it, u horizontal along it, n outward.
struct SceneWall {
  Vec3 o, u, n;
  std::vector<Opening> openings;
};

// A porous tree crown: each metre of a ray inside it returns with probability `density`.
struct Crown {
  Vec3 c;
  double r, density;
};

// The van's path for one drive, at scanner height; `side` (horizontal, unit) points from the
// path to the facades it scans.
struct Drive {
  Vec3 start, end, side;
};

struct ScenePoint {
  Vec3 p;
  int label;     // SceneLabel or a truth face index
  int building;  // owner given to add_face / add_box (-1: none)
  int drive;     // index of the drive that recorded it
};

class StreetScene {
 public:
  StreetScene();
  ~StreetScene();
  StreetScene(const StreetScene&) = delete;
  StreetScene& operator=(const StreetScene&) = delete;

  // A planar polygon; `wall` indexes walls() (-1: no openings on it).
  void add_face(const std::vector<Vec3>& polygon, int label, int building, int wall = -1);
  // Every face of `m`: labelled with its face index when `faces_labelled`, else kNeighbour;
  // face f carries the openings of walls()[face_walls[f]] where that is given and >= 0.
  void add_mesh(const Mesh& m, int building, bool faces_labelled, const std::vector<int>& face_walls = {});
  // An oriented box: centre, horizontal axes u and n (unit, orthogonal), half sizes along u, n, z.
  void add_box(const Vec3& c, const Vec3& u, const Vec3& n, const Vec3& half, int label, int building);
  int add_wall(SceneWall w);
  void add_crown(const Crown& c) { crowns_.push_back(c); }
  std::vector<SceneWall>& walls() { return walls_; }
  std::size_t triangles() const;

  // Points recorded along `drive` (profiles every speed / profile_rate metres, each of the two
  // profilers turned +-yaw_deg from across the street, rays every angle_step_deg from 45 deg
  // below to 85 deg above the horizon on the facades' side), first hit within max_range, range
  // noise `noise` (sigma, m) along the ray. Deterministic for (scene, drive, options, r).
  std::vector<ScenePoint> scan(const Drive& drive, int drive_index, const VanOptions& o, double noise, Rng& r) const;

 private:
  struct Tree;
  std::vector<std::array<Vec3, 3>> tris_;
  struct Owner {
    int label, building, wall;
  };
  std::vector<Owner> owners_;
  std::vector<SceneWall> walls_;
  std::vector<Crown> crowns_;
  mutable std::unique_ptr<Tree> tree_;  // built on the first scan
};

// Facade relief on a street wall of a scanned building (the LoD2 truth stays the plain wall):
// storeys of windows (glass dark or showing the room, or a pane in its reveal), a door, a shop
// front, and boxes proud of the wall: balconies, a cornice, ledges. `poly` is the wall's
// polygon, z0 the ground. Returns the wall record that carries the openings (for add_mesh's
// face_walls), -1 for a wall too small for any.
int add_relief(StreetScene& scene, const std::vector<Vec3>& poly, double z0, int building, Rng& r);

// Street furniture along a drive's facade line (from a to b, `out` pointing to the street):
// parked cars, people, lamp posts and trees between the van and the facades.
void add_street_clutter(StreetScene& scene, const Vec3& a, const Vec3& b, const Vec3& out, double z0, Rng& r);

// The rigid misregistration of a drive: turned by heading_deg about the vertical through
// `pivot`, then shifted horizontally by `offset` (m) in a random direction.
struct Misregistration {
  Vec3 shift = Vec3::Zero();
  double heading_deg = 0;
  Vec3 pivot = Vec3::Zero();
  Vec3 apply(const Vec3& p) const;
};
Misregistration draw_misregistration(const VanOptions& o, const Vec3& pivot, Rng& r);

// m: each drive runs this far past the building's ends (so even a building of no width needs
// drives of 2 x kVanRunOn).
constexpr double kVanRunOn = 15.0;

// Rays one drive of `length` m casts at most: a profile every speed / profile_rate m along it,
// two profilers, a ray every angle_step_deg over each profile's 130 degrees.
double van_drive_rays(const VanOptions& o, double length);
// Rays van_scan casts at most for `truth` and its `street_faces`: o.drives drives along the
// building (plus the run-on) for each group of street faces facing one way (van_scan may skip
// some). Cheap: no scene is made.
double van_scan_rays(const Mesh& truth, const std::vector<int>& street_faces, const VanOptions& o);
// Throws InputError "<what>: the van would cast N rays ..., more than kMaxVanRays ..." when
// `rays` (van_scan_rays) pass kMaxVanRays.
void require_van_rays(double rays, const std::string& what);

// One building's van scan: the points (local frame), their labels and drives, the drives and each
// drive's misregistration (the first one's is the identity).
struct VanScan {
  std::vector<Vec3> pts;
  std::vector<int> labels;  // as SynthBuilding::point_label
  std::vector<int> drive;   // per point
  std::vector<Drive> drives;
  std::vector<Misregistration> misregistration;
  double spacing = 0;  // m between profiles along the drive
};

// Scans the building `truth` (ground at z0; its faces labelled by index): its `street_faces`
// (truth face indices) get facade relief and street clutter in front; the van drives past the
// largest group of them facing one way and past each other group turned more than 30 degrees
// whose street is clear (no building between the facade and the far lane), o.van.drives times
// each. `neighbours` stand in the scene as kNeighbour; with none, boxes stand in for them past
// the street's ends. Noise o.noise along each ray. Throws InputError (require_van_rays) before
// any work when the scan would pass kMaxVanRays.
VanScan van_scan(const Mesh& truth, const std::vector<int>& street_faces, double z0,
                 const std::vector<Mesh>& neighbours, const SynthOptions& o, Rng& r);

}  // namespace lodrefine::synth
