// The simulated MLS crop (see scan.h).
#include "scan.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/topology.h"

namespace lodrefine::synth {

namespace {

int pick_weighted(const std::vector<double>& w, Rng& r) {
  const double total = std::accumulate(w.begin(), w.end(), 0.0);
  double x = r.uniform(0, total);
  for (std::size_t i = 0; i < w.size(); ++i)
    if ((x -= w[i]) < 0 && w[i] > 0) return int(i);
  for (std::size_t i = w.size(); i-- > 0;)
    if (w[i] > 0) return int(i);
  return -1;
}

// Walls of the truth sharing an edge with a chosen wall, not chosen themselves, at least 2 m long.
struct WallAdjacency {
  std::vector<int> wall_of;  // per face: index into walls, -1 for other faces
  EdgeUses edges;            // over the walls' faces

  WallAdjacency(const Mesh& m, const std::vector<WallInfo>& walls) : wall_of(m.faces.size(), -1) {
    std::vector<int> faces;
    for (std::size_t w = 0; w < walls.size(); ++w) wall_of[walls[w].face] = int(w), faces.push_back(walls[w].face);
    edges = edge_uses(m.faces, faces);
  }
  std::set<int> next_to(const std::vector<int>& chosen, const std::vector<WallInfo>& walls) const {
    std::set<int> cand;
    for (const auto& [e, uses] : edges)
      for (const EdgeUse& a : uses)
        if (std::count(chosen.begin(), chosen.end(), wall_of[a.face]))
          for (const EdgeUse& b : uses)
            if (!std::count(chosen.begin(), chosen.end(), wall_of[b.face]) && walls[wall_of[b.face]].length >= 2)
              cand.insert(wall_of[b.face]);
    return cand;
  }
};

}  // namespace

std::vector<int> choose_scanned(const Mesh& m, const std::vector<WallInfo>& walls, int k, Rng& r) {
  const WallAdjacency adjacency(m, walls);
  std::vector<double> weight;
  for (const auto& w : walls) weight.push_back(w.length >= 3 ? w.length : 0.0);
  std::vector<int> chosen{pick_weighted(weight, r)};
  while (int(chosen.size()) < k) {
    const std::set<int> cand = adjacency.next_to(chosen, walls);
    if (cand.empty()) break;
    chosen.push_back(*std::next(cand.begin(), r.integer(0, int(cand.size()) - 1)));
  }
  return chosen;  // indices into walls
}

std::vector<int> choose_street(const Mesh& m, const std::vector<WallInfo>& walls, const std::vector<int>& street,
                               Rng& r) {
  std::vector<int> chosen;
  for (int w = 0; w < int(walls.size()); ++w)
    if (std::count(street.begin(), street.end(), walls[w].line)) chosen.push_back(w);
  if (r.chance(0.4)) {  // the van turns a corner: one side wall too
    const std::set<int> cand = WallAdjacency(m, walls).next_to(chosen, walls);
    if (!cand.empty()) chosen.push_back(*std::next(cand.begin(), r.integer(0, int(cand.size()) - 1)));
  }
  return chosen;
}

namespace {

// A wall turned more than 45 degrees from the street is seen obliquely (street-facade types).
const double kFacingCos = std::cos(radians(45.0));
// m: how far along the street the van is from an oblique wall's point when it records it.
constexpr double kObliqueMin = 2.0, kObliqueMax = 8.0;
// m: the sight line's end is taken this far in front of the wall, off the footprint's edge.
constexpr double kClearOfWall = 0.01;

struct Sphere {
  Vec3 c;
  double r;
};

struct Box {  // oriented: axes u (along the wall), n (towards the street), z
  Vec3 c, u, n;
  Vec3 half;
};

struct Window {
  double s0, s1, z0, z1, depth;  // depth 0: glass (no return)
};

struct ScanWall {
  int face;
  Vec3 o, u, n;            // origin, along-wall axis, outward normal
  std::vector<Vec2> poly;  // (s, z)
  double smin, smax, zmin, zmax, zcut;
  std::vector<Window> windows;
  std::vector<Sphere> holes;  // occlusion blobs in (s, z, 0)
  // Set on walls the van sees only obliquely from the street (a recess's returns, a bay's
  // sides, a side wall at a corner): the street's side, the outward normal of the front.
  Vec3 street = Vec3::Zero();
  bool oblique() const { return !street.isZero(); }
};

ScanWall scan_wall(const Mesh& m, int face, double z0, Rng& r) {
  ScanWall w;
  w.face = face;
  const auto pts = face_points(m, m.faces[face]);
  const Vec2 n2 = xy(newell_normal(pts)).normalized();
  w.n = Vec3(n2.x(), n2.y(), 0);
  w.u = along_wall(w.n);
  w.o = Vec3(pts[0].x(), pts[0].y(), 0);
  w.smin = w.zmin = 1e300, w.smax = w.zmax = -1e300;
  for (const auto& p : pts) {
    w.poly.emplace_back((p - w.o).dot(w.u), p.z());
    w.smin = std::min(w.smin, w.poly.back().x()), w.smax = std::max(w.smax, w.poly.back().x());
    w.zmin = std::min(w.zmin, p.z()), w.zmax = std::max(w.zmax, p.z());
  }
  // Visible up to about the eave: the highest wall top at either end of the wall.
  double eave = z0;
  for (const auto& q : w.poly)
    if (q.x() < w.smin + 0.05 || q.x() > w.smax - 0.05) eave = std::max(eave, q.y());
  w.zcut = std::min(w.zmax, eave + r.uniform(-0.3, 0.8));
  return w;
}

bool inside_margin(const std::vector<Vec2>& poly, double s0, double s1, double z0, double z1, double m) {
  for (const Vec2& q : {Vec2(s0 - m, z0 - m), Vec2(s1 + m, z0 - m), Vec2(s1 + m, z1 + m), Vec2(s0 - m, z1 + m)})
    if (!point_in_polygon_2d(q, poly)) return false;
  return true;
}

// Storeys of windows 1-1.5 m wide; each is glass (no points) or a recess 8-25 cm deep.
void add_windows(ScanWall& w, double z0, Rng& r) {
  const double storey = r.uniform(2.8, 3.3), ww = r.uniform(1.0, 1.5), wh = r.uniform(1.2, 1.7);
  const double sill = r.uniform(0.8, 1.0), pitch = ww + r.uniform(1.0, 2.2), depth = r.uniform(0.08, 0.25);
  for (int k = 0;; ++k) {
    const double zb = z0 + k * storey + sill, zt = zb + wh;
    if (zt > w.zcut - 0.3) break;
    for (double s = w.smin + r.uniform(0.6, 1.2); s + ww < w.smax - 0.5; s += pitch) {
      if (!inside_margin(w.poly, s, s + ww, zb, zt, 0.25) || (k == 0 && r.chance(0.3))) continue;
      const double d = r.chance(0.4) ? 0.0 : std::clamp(depth + r.uniform(-0.03, 0.03), 0.08, 0.25);
      w.windows.push_back({s, s + ww, zb, zt, d});
    }
  }
}

void add_holes(ScanWall& w, Rng& r) {
  const int blobs = r.integer(1, 3);
  for (int b = 0; b < blobs; ++b) {
    const Vec3 c(r.uniform(w.smin, w.smax), r.uniform(w.zmin, w.zcut), 0);
    for (int k = r.integer(2, 4); k > 0; --k)
      w.holes.push_back({c + Vec3(r.uniform(-0.8, 0.8), r.uniform(-0.6, 0.6), 0), r.uniform(0.3, 0.9)});
  }
}

struct Scene {
  double z0 = 0;
  std::vector<Vec2> footprint;  // ground outline, for dropping clutter inside the building
  std::vector<ScanWall> walls;
  std::vector<Sphere> blockers;  // canopies, people
  std::vector<Box> cars;
  std::vector<Vec3> pts;
  std::vector<int> labels;
  double scanner_dist = 6, spacing = 0.05;

  // The walls the van drives along: clutter stands in front of these (all walls but the oblique).
  std::vector<const ScanWall*> street_walls() const {
    std::vector<const ScanWall*> out;
    for (const auto& w : walls)
      if (!w.oblique()) out.push_back(&w);
    if (out.empty())
      for (const auto& w : walls) out.push_back(&w);
    return out;
  }
};

// Whether the 2D sight line a-b crosses an edge of the building's footprint.
bool crosses_footprint(const Scene& sc, const Vec3& a, const Vec3& b) {
  const std::size_t n = sc.footprint.size();
  for (std::size_t i = 0; i < n; ++i)
    if (segments_cross(xy(a), xy(b), sc.footprint[i], sc.footprint[(i + 1) % n])) return true;
  return false;
}

bool ray_hits_sphere(const Vec3& a, const Vec3& b, const Sphere& s) {
  const Vec3 ab = b - a;
  const double t = std::clamp((s.c - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + t * ab - s.c).norm() < s.r;
}

bool ray_hits_box(const Vec3& a, const Vec3& b, const Box& bx) {
  const Vec3 axes[3] = {bx.u, bx.n, Vec3::UnitZ()};
  double t0 = 0, t1 = 1;
  for (int i = 0; i < 3; ++i) {
    const double pa = axes[i].dot(a - bx.c), d = axes[i].dot(b - a);
    if (std::abs(d) < 1e-12) {
      if (std::abs(pa) > bx.half[i]) return false;
      continue;
    }
    double ta = (-bx.half[i] - pa) / d, tb = (bx.half[i] - pa) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta), t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

bool occluded(const Scene& sc, const Vec3& from, const Vec3& to) {
  for (const auto& s : sc.blockers)
    if (ray_hits_sphere(from, to, s)) return true;
  for (const auto& b : sc.cars)
    if (ray_hits_box(from, to, b)) return true;
  return false;
}

double visible_area(const ScanWall& w, double z0) {
  const double h = 0.1;
  int n = 0;
  for (double s = w.smin + h / 2; s < w.smax; s += h)
    for (double z = z0 + h / 2; z < w.zcut; z += h) n += point_in_polygon_2d({s, z}, w.poly);
  return n * h * h;
}

// Jittered grid on the visible wall; windows, holes and clutter in the line of sight cut it.
void sample_facade(Scene& sc, const ScanWall& w, double noise, Rng& r) {
  const double h = sc.spacing;
  for (double s = w.smin + h / 2; s < w.smax; s += h)
    for (double z = sc.z0 + h / 2; z < w.zcut; z += h) {
      const double js = s + r.uniform(-0.35, 0.35) * h, jz = z + r.uniform(-0.35, 0.35) * h;
      if (jz > w.zcut || !point_in_polygon_2d({js, jz}, w.poly)) continue;
      bool hole = false;
      for (const auto& c : w.holes) hole |= (Vec2(js, jz) - c.c.head<2>()).norm() < c.r;
      double depth = 0;
      int label = w.face;
      for (const auto& win : w.windows)
        if (js > win.s0 && js < win.s1 && jz > win.z0 && jz < win.z1) {
          hole |= win.depth == 0;
          depth = win.depth;
          label = -1;
        }
      if (hole) continue;
      const Vec3 p = w.o + js * w.u + jz * Vec3::UnitZ() - depth * w.n;
      Vec3 scanner = w.o + js * w.u + sc.scanner_dist * w.n + (sc.z0 + 2.2) * Vec3::UnitZ();
      if (w.oblique()) {  // seen from the street a few metres along, through the recess's opening
        scanner = p + sc.scanner_dist * w.street + r.uniform(kObliqueMin, kObliqueMax) * w.n;
        scanner.z() = sc.z0 + 2.2;
        const Vec3 ray = (scanner - p).normalized();
        if (r.uniform() > ray.dot(w.n)) continue;                              // grazing beams return fewer points
        if (crosses_footprint(sc, p + kClearOfWall * w.n, scanner)) continue;  // the building hides it
      }
      if (occluded(sc, scanner, p)) continue;
      sc.pts.push_back(p + r.noise(noise) * w.n);
      sc.labels.push_back(label);
    }
}

// Clutter points: isotropic noise, nothing inside the building's footprint.
void push_clutter(Scene& sc, const Vec3& p, int label, double noise, Rng& r) {
  const Vec3 q = p + Vec3(r.noise(noise), r.noise(noise), r.noise(noise));
  if (point_in_polygon_2d(xy(q), sc.footprint)) return;
  sc.pts.push_back(q);
  sc.labels.push_back(label);
}

Vec3 street_point(const ScanWall& w, double s, double dist, double z) {
  return w.o + s * w.u + dist * w.n + z * Vec3::UnitZ();
}

// A canopy of a few overlapping spheres 1-4 m in front of a wall, on a trunk.
void add_tree(Scene& sc, const ScanWall& w, int budget, double noise, Rng& r) {
  const double R = r.uniform(1.0, 1.8);
  const Vec3 c = street_point(w, r.uniform(w.smin, w.smax), R + r.uniform(0.5, 2.2), sc.z0 + r.uniform(4, 7));
  std::vector<Sphere> blobs;
  for (int k = r.integer(3, 5); k > 0; --k) {
    Sphere s{c + Vec3(r.uniform(-0.8, 0.8), r.uniform(-0.8, 0.8), r.uniform(-0.5, 0.5)), R * r.uniform(0.6, 1.0)};
    s.c += std::max(0.0, 0.4 + s.r - (s.c - w.o).dot(w.n)) * w.n;  // keep clear of the wall
    blobs.push_back(s);
  }
  for (int i = 0; i < budget; ++i) {
    const Sphere& s = blobs[r.integer(0, int(blobs.size()) - 1)];
    const Vec3 d = r.unit3();
    if (d.dot(w.n) < -0.3) continue;  // the scanner sees the street side
    push_clutter(sc, s.c + d * s.r * (1 - 0.35 * r.uniform() * r.uniform()), -2, noise, r);
  }
  const double bottom = c.z() - R;
  for (int i = 0; i < budget / 10; ++i) {
    const Vec2 d = r.unit2();
    push_clutter(sc, Vec3(c.x() + 0.15 * d.x(), c.y() + 0.15 * d.y(), r.uniform(sc.z0, bottom)), -2, noise, r);
  }
  sc.blockers.insert(sc.blockers.end(), blobs.begin(), blobs.end());
}

// Points on the visible shell (street side, ends, top) of an oriented box.
void sample_box(Scene& sc, const Box& b, int budget, double noise, Rng& r) {
  const Vec3 ax[3] = {b.u, b.n, Vec3::UnitZ()};
  const double area[3] = {4 * b.half[1] * b.half[2], 4 * b.half[0] * b.half[2], 4 * b.half[0] * b.half[1]};
  // Visible faces: two ends (axis 0, both signs), street side (+n), top (+z).
  const std::pair<int, double> faces[4] = {{0, 1}, {0, -1}, {1, 1}, {2, 1}};
  double total = 0;
  for (const auto& [a, sgn] : faces) total += area[a];
  for (const auto& [a, sgn] : faces) {
    const int i = (a + 1) % 3, j = (a + 2) % 3;
    for (int k = int(budget * area[a] / total); k > 0; --k) {
      const Vec3 p =
          b.c + sgn * b.half[a] * ax[a] + r.uniform(-1, 1) * b.half[i] * ax[i] + r.uniform(-1, 1) * b.half[j] * ax[j];
      push_clutter(sc, p, -2, noise, r);
    }
  }
}

void add_car(Scene& sc, const ScanWall& w, int budget, double noise, Rng& r) {
  const Vec3 half(r.uniform(2.0, 2.4), r.uniform(0.85, 0.95), r.uniform(0.7, 0.8));
  const Vec3 c = street_point(w, r.uniform(w.smin, w.smax), r.uniform(2, 5) + half.y(), sc.z0 + 0.2 + half.z());
  const Box b{c, w.u, w.n, half};
  sample_box(sc, b, budget, noise, r);
  sc.cars.push_back(b);
}

void add_person(Scene& sc, const ScanWall& w, int budget, double noise, Rng& r) {
  const double height = r.uniform(1.6, 1.9), rad = r.uniform(0.18, 0.28);
  const Vec3 foot = street_point(w, r.uniform(w.smin, w.smax), r.uniform(1, 6), sc.z0);
  for (int i = 0; i < budget; ++i) {
    const Vec2 d = r.unit2();
    const double z = r.uniform(0, height), taper = z > height - 0.3 ? 0.5 : 1.0;
    push_clutter(sc, foot + Vec3(rad * taper * d.x(), rad * taper * d.y(), z), -2, noise, r);
  }
  sc.blockers.push_back({foot + Vec3(0, 0, height * 0.5), rad});
  sc.blockers.push_back({foot + Vec3(0, 0, height * 0.85), rad});
}

void add_street(Scene& sc, int budget, double noise, Rng& r) {
  double total = 0;
  const auto walls = sc.street_walls();
  for (const ScanWall* w : walls) total += w->smax - w->smin + 4;
  for (const ScanWall* w : walls)
    for (int k = int(budget * (w->smax - w->smin + 4) / total); k > 0; --k)
      push_clutter(sc, street_point(*w, r.uniform(w->smin - 2, w->smax + 2), r.uniform(0, 8), sc.z0), -3, noise, r);
}

// Whether the ground past a scanned facade's end (along `dir`), as deep behind the facade as a
// neighbour reaches, is clear of the building: not a concave corner, nor the end of a wall that
// stands forward of the rest of its facade (a setback's front line, a bay), where a neighbour
// would stand in front of the building's own walls.
bool open_end(const Scene& sc, const ScanWall& w, double end, double dir) {
  for (double along : {0.5, 2.0, 4.0, 8.0})
    for (double behind = 1.0; behind <= 6.0; behind += 1.0)
      if (point_in_polygon_2d(xy(street_point(w, end + along * dir, -behind, 0)), sc.footprint)) return false;
  return true;
}

// Pieces of the next building: a wall continuing past one end of a scanned facade (slightly
// offset) and/or the neighbour's side wall across a gap. Only at open ends (open_end).
void add_neighbour(Scene& sc, int budget, double noise, Rng& r) {
  std::vector<std::pair<const ScanWall*, double>> ends;  // wall, direction along u
  for (const ScanWall* w : sc.street_walls())
    for (double dir : {-1.0, 1.0})
      if (open_end(sc, *w, dir > 0 ? w->smax : w->smin, dir)) ends.emplace_back(w, dir);
  if (ends.empty()) return;
  const auto [w, dir] = ends[r.integer(0, int(ends.size()) - 1)];
  const double end = dir > 0 ? w->smax : w->smin;
  const int mode = r.integer(0, 2);  // 0 continuing, 1 perpendicular, 2 both
  const double hgt = r.uniform(4, 12), len = r.uniform(3, 8), off = r.uniform(-0.6, 0.6);
  const double gap = mode == 0 ? r.uniform(0.05, 0.8) : r.uniform(1.5, 4), depth = r.uniform(2, 6);
  const double a_cont = mode != 1 ? len * hgt : 0, a_perp = mode != 0 ? depth * hgt : 0;
  const int n_cont = int(budget * a_cont / (a_cont + a_perp)), n_perp = int(budget * a_perp / (a_cont + a_perp));
  for (int k = 0; k < n_cont; ++k)
    push_clutter(sc, street_point(*w, end + dir * (gap + r.uniform(0, len)), off, sc.z0 + r.uniform(0, hgt)), -4, noise,
                 r);
  for (int k = 0; k < n_perp; ++k)
    push_clutter(sc, street_point(*w, end + dir * gap, off - r.uniform(0, depth), sc.z0 + r.uniform(0, hgt)), -4, noise,
                 r);
}

void add_nuisances(Scene& sc, const SynthOptions& o, Rng& r) {
  const int T = o.target_points;
  const auto walls = sc.street_walls();
  auto wall = [&]() -> const ScanWall& { return *walls[r.integer(0, int(walls.size()) - 1)]; };
  for (int k = r.integer(0, 2); k > 0; --k) add_tree(sc, wall(), int(0.03 * T), o.noise, r);
  for (int k = r.integer(0, 2); k > 0; --k) add_car(sc, wall(), int(0.02 * T), o.noise, r);
  for (int k = r.integer(0, 3); k > 0; --k) add_person(sc, wall(), int(0.004 * T), o.noise, r);
  add_street(sc, int(0.15 * T), o.noise, r);
  add_neighbour(sc, int(0.08 * T), o.noise, r);
}

}  // namespace

std::vector<int> wall_faces(const std::vector<int>& chosen, const std::vector<WallInfo>& walls) {
  std::vector<int> faces;
  for (int w : chosen) faces.push_back(walls[w].face);
  return faces;
}

ScanResult simulate_scan(const Mesh& truth, const std::vector<int>& faces, double z0, const Vec2& street,
                         const SynthOptions& o, Rng& r) {
  Scene sc;
  sc.z0 = z0;
  sc.scanner_dist = r.uniform(7.5, 9);  // beyond the cars, inside the street strip
  for (const auto& f : truth.faces)
    if (f.sem == Semantic::Ground)
      for (int v : f.v) sc.footprint.push_back(xy(truth.vertices[v]));
  double area = 0;
  for (int f : faces) {
    sc.walls.push_back(scan_wall(truth, f, z0, r));
    if (!street.isZero() && sc.walls.back().n.head<2>().dot(street) < kFacingCos)
      sc.walls.back().street = Vec3(street.x(), street.y(), 0.0);
    area += visible_area(sc.walls.back(), z0);
  }
  sc.spacing = std::max(0.03, std::sqrt(area / std::max(1, o.target_points)));
  if (o.nuisances) {
    for (auto& w : sc.walls) add_windows(w, z0, r), add_holes(w, r);
    add_nuisances(sc, o, r);
  }
  // Facade points come after the clutter exists (it occludes them) but first in the cloud.
  std::vector<Vec3> clutter;
  std::vector<int> clutter_labels;
  std::swap(clutter, sc.pts), std::swap(clutter_labels, sc.labels);
  for (const auto& w : sc.walls) sample_facade(sc, w, o.noise, r);
  sc.pts.insert(sc.pts.end(), clutter.begin(), clutter.end());
  sc.labels.insert(sc.labels.end(), clutter_labels.begin(), clutter_labels.end());
  return {std::move(sc.pts), std::move(sc.labels), sc.spacing};
}

}  // namespace lodrefine::synth
