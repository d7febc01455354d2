// The mapping van's scan (see van.h).
#include "van.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "lodrefine/base/geometry.h"

namespace lodrefine::synth {

using K = CGAL::Simple_cartesian<double>;
using CgalTriangles = std::vector<K::Triangle_3>;
using Primitive = CGAL::AABB_triangle_primitive<K, CgalTriangles::const_iterator>;
using AabbTree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

struct StreetScene::Tree {
  CgalTriangles tris;
  AabbTree tree;
};

namespace {

// Rays from 45 deg below the horizon (the road beside the van) to 85 deg above (a facade's top
// seen from below).
constexpr double kLowestDeg = -45.0, kHighestDeg = 85.0;
// A beam this close to grazing (cosine of incidence) returns less often, in proportion.
constexpr double kGrazingCos = 0.15;

K::Point_3 cgal(const Vec3& p) { return {p.x(), p.y(), p.z()}; }
Vec3 eigen(const K::Point_3& p) { return {p.x(), p.y(), p.z()}; }

}  // namespace

StreetScene::StreetScene() = default;
StreetScene::~StreetScene() = default;

std::size_t StreetScene::triangles() const { return tris_.size(); }

void StreetScene::add_face(const std::vector<Vec3>& polygon, int label, int building, int wall) {
  for (const auto& t : triangulate_polygon(polygon)) {
    tris_.push_back({polygon[t[0]], polygon[t[1]], polygon[t[2]]});
    owners_.push_back({label, building, wall});
  }
  tree_.reset();
}

void StreetScene::add_mesh(const Mesh& m, int building, bool faces_labelled, const std::vector<int>& face_walls) {
  for (int f = 0; f < int(m.faces.size()); ++f)
    add_face(face_points(m, m.faces[f]), faces_labelled ? f : kNeighbour, building,
             std::size_t(f) < face_walls.size() ? face_walls[std::size_t(f)] : -1);
}

void StreetScene::add_box(const Vec3& c, const Vec3& u, const Vec3& n, const Vec3& half, int label, int building) {
  const Vec3 ax[3] = {u * half.x(), n * half.y(), Vec3::UnitZ() * half.z()};
  auto corner = [&](int i, int j, int k) {
    return c + (i ? 1 : -1) * ax[0] + (j ? 1 : -1) * ax[1] + (k ? 1 : -1) * ax[2];
  };
  const int quads[6][4][3] = {
      {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 0, 1}, {0, 1, 1}, {1, 1, 1}, {1, 0, 1}},
      {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}, {1, 0, 0}}, {{0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}},
      {{0, 0, 0}, {0, 1, 0}, {0, 1, 1}, {0, 0, 1}}, {{1, 0, 0}, {1, 0, 1}, {1, 1, 1}, {1, 1, 0}}};
  for (const auto& q : quads) {
    std::vector<Vec3> poly;
    for (const auto& v : q) poly.push_back(corner(v[0], v[1], v[2]));
    add_face(poly, label, building);
  }
}

int StreetScene::add_wall(SceneWall w) {
  walls_.push_back(std::move(w));
  return int(walls_.size()) - 1;
}

namespace {

struct Shot {
  Vec3 p;
  int label;
};

// Where a ray that hit a wall at `hit` (distance t along unit d) returns when the wall has an
// opening there: on the pane in its reveal, from the room behind, or nowhere (nullopt); the
// wall itself when no opening is hit.
std::optional<Shot> through_opening(const SceneWall& w, const Vec3& hit, const Vec3& d, int wall_label, Rng& r) {
  const double s = (hit - w.o).dot(w.u), z = hit.z();
  const double facing = -d.dot(w.n);
  for (const Opening& op : w.openings) {
    if (s < op.s0 || s > op.s1 || z < op.z0 || z > op.z1) continue;
    if (facing < 1e-3) return std::nullopt;
    const Vec3 pane = hit + d * (op.reveal / facing);
    const double sp = (pane - w.o).dot(w.u), zp = pane.z();
    if (sp < op.s0 || sp > op.s1 || zp < op.z0 || zp > op.z1) {  // the reveal's side takes it
      return Shot{hit + d * (r.uniform() * op.reveal / facing), kWindow};
    }
    switch (op.pane) {
      case Opening::Pane::Opaque: return Shot{pane, kWindow};
      case Opening::Pane::Dark: return std::nullopt;
      case Opening::Pane::Room:
        if (r.chance(0.3)) return std::nullopt;  // the glass reflects it away
        return Shot{pane + d * (op.room / facing), kInterior};
    }
  }
  return Shot{hit, wall_label};
}

// The first crown the ray returns from before distance `t_max`: (distance, found).
std::optional<double> crown_return(const std::vector<Crown>& crowns, const Vec3& o, const Vec3& d, double t_max,
                                   Rng& r) {
  std::optional<double> best;
  for (const Crown& c : crowns) {
    const Vec3 oc = o - c.c;
    const double b = oc.dot(d), disc = b * b - (oc.squaredNorm() - c.r * c.r);
    if (disc <= 0) continue;
    const double t0 = std::max(0.0, -b - std::sqrt(disc)), t1 = -b + std::sqrt(disc);
    if (t1 <= 0 || t0 >= t_max) continue;
    // Exponential free path through the foliage: returns within the chord with 1 - exp(-density * chord).
    const double u = std::max(r.uniform(), 1e-12);
    const double t = t0 - std::log(u) / c.density;
    if (t < std::min(t1, t_max) && (!best || t < *best)) best = t;
  }
  return best;
}

}  // namespace

std::vector<ScenePoint> StreetScene::scan(const Drive& drive, int drive_index, const VanOptions& o, double noise,
                                          Rng& r) const {
  if (!tree_) {
    tree_ = std::make_unique<Tree>();
    for (const auto& t : tris_) tree_->tris.emplace_back(cgal(t[0]), cgal(t[1]), cgal(t[2]));
    tree_->tree.insert(tree_->tris.begin(), tree_->tris.end());
    tree_->tree.build();
  }
  std::vector<ScenePoint> out;
  const Vec3 path = drive.end - drive.start;
  const double length = path.norm(), step = o.speed / o.profile_rate;
  if (length <= 0 || step <= 0 || tris_.empty()) return out;
  const Vec3 fwd = path / length;
  const double yaw = radians(o.yaw_deg), da = radians(o.angle_step_deg);
  for (double along = 0; along <= length; along += step) {
    for (int profiler = 0; profiler < 2; ++profiler) {
      const Vec3 origin = drive.start + fwd * (along + (profiler ? 0.5 * step : 0.0));
      const Vec3 h = (std::cos(yaw) * drive.side + (profiler ? -1 : 1) * std::sin(yaw) * fwd).normalized();
      for (double a = radians(kLowestDeg); a <= radians(kHighestDeg); a += da) {
        const Vec3 d = std::cos(a) * h + std::sin(a) * Vec3::UnitZ();
        const auto hit = tree_->tree.first_intersection(K::Ray_3(cgal(origin), K::Vector_3(d.x(), d.y(), d.z())));
        double t_hit = o.max_range;
        const K::Point_3* at = hit ? boost::get<K::Point_3>(&hit->first) : nullptr;
        if (at) t_hit = std::min(t_hit, (eigen(*at) - origin).norm());
        if (const auto tc = crown_return(crowns_, origin, d, t_hit, r)) {
          out.push_back({origin + d * (*tc + r.noise(noise)), kClutter, -1, drive_index});
          continue;
        }
        if (!at || t_hit >= o.max_range) continue;
        const std::size_t ti = std::size_t(hit->second - tree_->tris.begin());
        const auto& tri = tris_[ti];
        const Vec3 nt = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalized();
        if (r.uniform() * kGrazingCos > std::abs(nt.dot(d))) continue;
        const Owner& owner = owners_[ti];
        std::optional<Shot> shot = Shot{eigen(*at), owner.label};
        if (owner.wall >= 0) shot = through_opening(walls_[std::size_t(owner.wall)], eigen(*at), d, owner.label, r);
        if (!shot) continue;
        const double range = (shot->p - origin).norm();
        if (range >= o.max_range) continue;
        out.push_back({shot->p + d * r.noise(noise), shot->label, owner.building, drive_index});
      }
    }
  }
  return out;
}

namespace {

// The wall's frame: o at its lowest-s ground corner, u along it, n outward (horizontal).
SceneWall wall_frame(const std::vector<Vec3>& poly) {
  SceneWall w;
  const Vec3 nn = newell_normal(poly);
  w.n = Vec3(nn.x(), nn.y(), 0).normalized();
  w.u = along_wall(w.n);
  w.o = poly[0];
  double smin = 1e300;
  for (const auto& p : poly) smin = std::min(smin, (p - w.o).dot(w.u));
  w.o += smin * w.u;
  w.o.z() = 0;
  return w;
}

bool rect_inside(const std::vector<Vec2>& poly, double s0, double s1, double z0, double z1) {
  for (const Vec2& q : {Vec2(s0, z0), Vec2(s1, z0), Vec2(s1, z1), Vec2(s0, z1)})
    if (!point_in_polygon_2d(q, poly)) return false;
  return true;
}

Opening::Pane draw_pane(Rng& r) {
  const double x = r.uniform();
  return x < 0.35 ? Opening::Pane::Dark : x < 0.8 ? Opening::Pane::Room : Opening::Pane::Opaque;
}

}  // namespace

int add_relief(StreetScene& scene, const std::vector<Vec3>& poly, double z0, int building, Rng& r) {
  SceneWall w = wall_frame(poly);
  std::vector<Vec2> sz;
  double smax = 0, ztop = z0;
  for (const auto& p : poly) {
    sz.emplace_back((p - w.o).dot(w.u), p.z());
    smax = std::max(smax, sz.back().x());
  }
  for (const auto& q : sz)
    if (q.x() < 0.05 || q.x() > smax - 0.05) ztop = std::max(ztop, q.y());  // the eave at the wall's ends
  if (smax < 2.0 || ztop - z0 < 2.5) return -1;
  const double storey = r.uniform(2.8, 3.3), ww = r.uniform(1.0, 1.6), wh = r.uniform(1.3, 1.8);
  const double pitch = ww + r.uniform(0.9, 2.0), reveal = r.uniform(0.1, 0.3);
  const bool shop = r.chance(0.3);
  // Ground storey: a shop front (one wide glass, the room behind) or a door.
  if (shop && smax > 5.0) {
    const double s0 = r.uniform(0.5, 1.5), s1 = smax - r.uniform(0.5, 1.5);
    if (rect_inside(sz, s0, s1, z0 + 0.4, z0 + 2.8))
      w.openings.push_back({s0, s1, z0 + 0.4, z0 + 2.8, r.uniform(0.05, 0.2), Opening::Pane::Room, r.uniform(2, 6)});
  } else {
    const double s0 = r.uniform(0.5, std::max(0.6, smax - 1.6));
    if (rect_inside(sz, s0, s0 + 1.0, z0, z0 + 2.2))
      w.openings.push_back({s0, s0 + 1.0, z0 - 0.01, z0 + 2.2, r.uniform(0.1, 0.3), Opening::Pane::Opaque, 0});
  }
  for (int k = 1;; ++k) {  // upper storeys
    const double zb = z0 + k * storey + r.uniform(0.8, 1.0), zt = zb + wh;
    if (zt > ztop - 0.4) break;
    for (double s = r.uniform(0.6, 1.2); s + ww < smax - 0.5; s += pitch)
      if (rect_inside(sz, s - 0.2, s + ww + 0.2, zb - 0.2, zt + 0.2)) {
        const double room = r.uniform(1.0, 4.0);
        w.openings.push_back(
            {s, s + ww, zb, zt, std::clamp(reveal + r.uniform(-0.03, 0.03), 0.1, 0.3), draw_pane(r), room});
      }
  }
  // Proud of the wall: a cornice under the eave, ledges at storey lines, balconies.
  auto proud_box = [&](double s0, double s1, double zb, double zt, double depth) {
    const Vec3 c = w.o + 0.5 * (s0 + s1) * w.u + 0.5 * depth * w.n + 0.5 * (zb + zt) * Vec3::UnitZ();
    scene.add_box(c, w.u, w.n, Vec3(0.5 * (s1 - s0), 0.5 * depth, 0.5 * (zt - zb)), kRelief, building);
  };
  if (r.chance(0.5) && ztop - z0 > 4) {
    const double h = r.uniform(0.3, 0.5), zc = ztop - r.uniform(0.1, 0.3);
    if (rect_inside(sz, 0.02, smax - 0.02, zc - h, zc)) proud_box(0.0, smax, zc - h, zc, r.uniform(0.1, 0.3));
  }
  if (r.chance(0.3))
    for (int k = 1; z0 + k * storey < ztop - 1.0; ++k) {
      const double zl = z0 + k * storey;
      if (rect_inside(sz, 0.02, smax - 0.02, zl, zl + 0.15)) proud_box(0.0, smax, zl, zl + 0.15, r.uniform(0.1, 0.2));
    }
  if (r.chance(0.35))
    for (int k = 1; z0 + k * storey + 1.2 < ztop - 0.5; ++k) {
      if (!r.chance(0.6)) continue;
      const double bw = r.uniform(2.0, 4.0), s0 = r.uniform(0.3, std::max(0.31, smax - bw - 0.3));
      const double zb = z0 + k * storey - 0.2;
      if (s0 + bw < smax && rect_inside(sz, s0, s0 + bw, zb, zb + 1.2))
        proud_box(s0, s0 + bw, zb, zb + 1.2, r.uniform(1.0, 1.5));
    }
  return scene.add_wall(std::move(w));
}

}  // namespace lodrefine::synth

namespace lodrefine::synth {

void add_street_clutter(StreetScene& scene, const Vec3& a, const Vec3& b, const Vec3& out, double z0, Rng& r) {
  const Vec3 along = (b - a).normalized();
  const double length = (b - a).norm();
  auto at = [&](double s, double dist, double z) {
    Vec3 p = a + s * along + dist * out;
    p.z() = z;
    return p;
  };
  for (double s = r.uniform(0, 3); s < length - 4.4; s += r.uniform(5.0, 6.5))  // parked cars at the kerb
    if (r.chance(0.5)) {
      const Vec3 half(r.uniform(2.0, 2.4), r.uniform(0.85, 0.95), r.uniform(0.7, 0.8));
      scene.add_box(at(s + half.x(), r.uniform(2.0, 3.0) + half.y(), z0 + 0.2 + half.z()), along, out, half, kClutter,
                    -1);
    }
  for (int k = r.integer(0, 1 + int(length / 12)); k > 0; --k) {  // people on the pavement
    const double h = r.uniform(1.6, 1.9);
    scene.add_box(at(r.uniform(0, length), r.uniform(0.5, 2.0), z0 + h / 2), along, out, Vec3(0.25, 0.18, h / 2),
                  kClutter, -1);
  }
  for (double s = r.uniform(0, 25); s < length; s += 25)  // lamp posts at the kerb
    if (r.chance(0.6)) scene.add_box(at(s, r.uniform(3.2, 3.8), z0 + 3), along, out, Vec3(0.08, 0.08, 3), kClutter, -1);
  for (int k = r.integer(0, 2); k > 0; --k) {  // trees: a trunk, a porous crown clear of the walls
    const double rad = r.uniform(1.5, 2.5), zc = z0 + r.uniform(5, 8), s = r.uniform(0, length);
    const double dist = std::max(r.uniform(3.0, 4.0), rad + 0.3);
    scene.add_box(at(s, dist, z0 + (zc - rad - z0) / 2), along, out, Vec3(0.15, 0.15, (zc - rad - z0) / 2), kClutter,
                  -1);
    scene.add_crown({at(s, dist, zc), rad, r.uniform(0.8, 1.5)});
  }
}

Vec3 Misregistration::apply(const Vec3& p) const {
  const double a = radians(heading_deg), c = std::cos(a), s = std::sin(a);
  const Vec3 q = p - pivot;
  return pivot + Vec3(c * q.x() - s * q.y(), s * q.x() + c * q.y(), q.z()) + shift;
}

Misregistration draw_misregistration(const VanOptions& o, const Vec3& pivot, Rng& r) {
  Misregistration m;
  const Vec2 d = r.unit2();
  const double size = r.uniform(0.25 * o.offset, o.offset);
  m.shift = Vec3(d.x() * size, d.y() * size, 0);
  m.heading_deg = r.uniform(-o.heading_deg, o.heading_deg);
  m.pivot = pivot;
  return m;
}

}  // namespace lodrefine::synth

namespace lodrefine::synth {

namespace {

// m: the first lane's distance from the facade, and the far lane's beyond it.
constexpr double kLaneMin = 4.5, kLaneMax = 7.0, kFarLaneMin = 2.5, kFarLaneMax = 3.5;
// m: the street is clear from this far in front of the facade.
constexpr double kPavement = 2.0;
constexpr double kRunOn = kVanRunOn;
const double kNewStreetCos = std::cos(radians(30.0));

struct FacadeGroup {
  Vec3 n;            // outward, horizontal
  double front = 0;  // max n . p over the group's vertices
  double area = 0;
};

// The street walls grouped by facing (within 30 degrees), largest first.
std::vector<FacadeGroup> facade_groups(const Mesh& truth, const std::vector<int>& faces) {
  std::vector<FacadeGroup> groups;
  for (int f : faces) {
    const auto poly = face_points(truth, truth.faces[std::size_t(f)]);
    const Vec3 nn = newell_normal(poly);
    const Vec3 n = Vec3(nn.x(), nn.y(), 0).normalized();
    auto g =
        std::find_if(groups.begin(), groups.end(), [&](const FacadeGroup& x) { return x.n.dot(n) > kNewStreetCos; });
    if (g == groups.end()) g = groups.insert(groups.end(), {n, -1e300, 0.0});
    g->area += polygon_area(poly);
    for (const auto& p : poly) g->front = std::max(g->front, g->n.dot(p));
  }
  std::stable_sort(groups.begin(), groups.end(), [](const auto& a, const auto& b) { return a.area > b.area; });
  return groups;
}

// Whether any vertex of the meshes stands in the street strip [front + kPavement, front + depth]
// in front of the facade, within the drive's extent along it.
bool street_blocked(const std::vector<const Mesh*>& meshes, const FacadeGroup& g, double s0, double s1, double depth) {
  const Vec3 u = along_wall(g.n);
  for (const Mesh* m : meshes)
    for (const auto& p : m->vertices) {
      const double d = g.n.dot(p) - g.front, s = u.dot(p);
      if (d > kPavement && d < depth && s > s0 && s < s1) return true;
    }
  return false;
}

// Boxes standing in for the neighbours past the street's ends (each end with a chance of 0.6).
void add_neighbour_boxes(StreetScene& scene, const FacadeGroup& g, double s0, double s1, double z0, Rng& r) {
  const Vec3 u = along_wall(g.n);
  for (double dir : {-1.0, 1.0}) {
    if (!r.chance(0.6)) continue;
    const double gap = r.chance(0.5) ? r.uniform(0.05, 0.8) : r.uniform(1.5, 4.0);
    const double len = r.uniform(4, 10), depth = r.uniform(6, 12), hgt = r.uniform(4, 12), off = r.uniform(-0.6, 0.6);
    const double s = (dir > 0 ? s1 + gap + len / 2 : s0 - gap - len / 2);
    Vec3 c = s * u + (g.front + off - depth / 2) * g.n;
    c.z() = z0 + hgt / 2;
    scene.add_box(c, u, g.n, Vec3(len / 2, depth / 2, hgt / 2), kNeighbour, -1);
  }
}

// The extent [s0, s1] of the building along the street of group g.
std::pair<double, double> along_street(const Mesh& truth, const FacadeGroup& g) {
  const Vec3 u = along_wall(g.n);
  double s0 = 1e300, s1 = -1e300;
  for (const auto& p : truth.vertices) s0 = std::min(s0, u.dot(p)), s1 = std::max(s1, u.dot(p));
  return {s0, s1};
}

}  // namespace

double van_drive_rays(const VanOptions& o, double length) {
  const double profiles = std::floor(length / (o.speed / o.profile_rate)) + 2;               // + the sum's rounding
  const double per_profile = std::floor((kHighestDeg - kLowestDeg) / o.angle_step_deg) + 2;  // + the last's rounding
  return profiles * 2 * per_profile;
}

double van_scan_rays(const Mesh& truth, const std::vector<int>& street_faces, const VanOptions& o) {
  double rays = 0;
  for (const FacadeGroup& g : facade_groups(truth, street_faces)) {
    const auto [s0, s1] = along_street(truth, g);
    rays += o.drives * van_drive_rays(o, s1 - s0 + 2 * kRunOn);
  }
  return rays;
}

void require_van_rays(double rays, const std::string& what) {
  if (rays <= kMaxVanRays) return;
  char buf[320];
  std::snprintf(buf, sizeof buf,
                ": the van would cast %.1f M rays, more than the %.0f M a building's scan may (memory and time "
                "grow with them): lower the profile rate or the drives, raise the speed or the angle step",
                rays / 1e6, kMaxVanRays / 1e6);
  throw InputError(what + buf);
}

VanScan van_scan(const Mesh& truth, const std::vector<int>& street_faces, double z0,
                 const std::vector<Mesh>& neighbours, const SynthOptions& o, Rng& r) {
  require_van_rays(van_scan_rays(truth, street_faces, o.van), "synth");
  StreetScene scene;
  std::vector<int> face_walls(truth.faces.size(), -1);
  for (int f : street_faces)
    if (o.nuisances)
      face_walls[std::size_t(f)] = add_relief(scene, face_points(truth, truth.faces[std::size_t(f)]), z0, 0, r);
  scene.add_mesh(truth, 0, true, face_walls);
  for (const Mesh& m : neighbours) scene.add_mesh(m, -1, false);
  std::vector<const Mesh*> solids{&truth};
  for (const Mesh& m : neighbours) solids.push_back(&m);

  VanScan out;
  out.spacing = o.van.speed / o.van.profile_rate;
  std::vector<std::pair<Drive, double>> lanes;  // the first drive of each street, and its facade's height
  const auto groups = facade_groups(truth, street_faces);
  for (std::size_t gi = 0; gi < groups.size(); ++gi) {
    const FacadeGroup& g = groups[gi];
    const Vec3 u = along_wall(g.n);
    const auto [s0, s1] = along_street(truth, g);
    bool seen = false;
    for (const auto& lane : lanes) seen |= lane.first.side.dot(-g.n) > kNewStreetCos;
    if (seen) continue;
    const double lane = r.uniform(kLaneMin, kLaneMax), far = lane + r.uniform(kFarLaneMin, kFarLaneMax);
    if (street_blocked(solids, g, s0 - kRunOn, s1 + kRunOn, far + 1.0) && gi > 0) continue;
    auto point = [&](double s, double d) {
      Vec3 p = s * u + (g.front + d) * g.n;
      p.z() = z0 + o.van.height;
      return p;
    };
    if (o.nuisances) {
      Vec3 a = point(s0 - kRunOn, 0), b = point(s1 + kRunOn, 0);
      a.z() = b.z() = z0;
      add_street_clutter(scene, a, b, g.n, z0, r);
      if (neighbours.empty()) add_neighbour_boxes(scene, g, s0, s1, z0, r);
    }
    lanes.push_back({Drive{point(s0 - kRunOn, lane), point(s1 + kRunOn, lane), -g.n}, far - lane});
  }
  // The street itself, under every lane.
  const Eigen::AlignedBox3d box = bounding_box(truth.vertices);
  const double reach = kRunOn + kLaneMax + kFarLaneMax + 10;
  scene.add_face(
      {Vec3(box.min().x() - reach, box.min().y() - reach, z0), Vec3(box.max().x() + reach, box.min().y() - reach, z0),
       Vec3(box.max().x() + reach, box.max().y() + reach, z0), Vec3(box.min().x() - reach, box.max().y() + reach, z0)},
      kGround, -1);

  const Vec3 pivot = 0.5 * (box.min() + box.max());
  for (const auto& [first, far_offset] : lanes)
    for (int k = 0; k < o.van.drives; ++k) {
      Drive d = first;
      if (k % 2 == 1) {  // back the other way, in the far lane
        std::swap(d.start, d.end);
        d.start -= far_offset * first.side, d.end -= far_offset * first.side;
      }
      const Misregistration m =
          k == 0 ? Misregistration{Vec3::Zero(), 0.0, pivot} : draw_misregistration(o.van, pivot, r);
      const int index = int(out.drives.size());
      for (const ScenePoint& sp : scene.scan(d, index, o.van, o.noise, r)) {
        out.pts.push_back(m.apply(sp.p));
        out.labels.push_back(sp.label);
        out.drive.push_back(index);
      }
      out.drives.push_back(d);
      out.misregistration.push_back(m);
    }
  return out;
}

}  // namespace lodrefine::synth
