// Synthetic buildings with known truth (see synth.h).
//
// A building is a union of prism "parts". Each part's footprint is a cyclic list of shared
// footprint lines (so parts that touch stay glued when a line moves) and its roof is the lower
// envelope of a few planes z = a x + b y + c. Walls, roofs and ground are generated per part,
// then welded, T-junctions split, coplanar neighbours merged and redundant collinear vertices
// dropped, which gives one closed shell with shared vertices. The coarse model is the same
// construction after moving some footprint lines, so its roof planes are the truth's.
// Everything is built in the building's own frame and georeferenced at the end.
#include "lodrefine/synth/synth.h"

#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>
#include <random>
#include <set>

#include "lodrefine/core/geometry.h"
#include "lodrefine/core/topology.h"
#include "lodrefine/io/obj.h"
#include "lodrefine/io/ply.h"
#include "lodrefine/io/files.h"

namespace lodrefine {

namespace {

constexpr double kWeldTol = 1e-6;  // building frame, metres
// A vertex strictly inside a segment, closer than kWeldTol to it, lies on it.
constexpr SegmentRule kOnEdge{kWeldTol, true};
// Generated faces of one plane agree up to rounding: normals within this cosine, offsets within
// kWeldTol (building frame).
constexpr double kCoplanarCos = 1 - 1e-9;

// The footprint lines or roof planes do not describe a valid building (e.g. after extreme moves).
struct ShapeError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// ---------------------------------------------------------------------------------------------
// Random numbers. mt19937_64's sequence is fixed by the standard but the library distributions
// are not, so the mappings are our own: the shipped samples regenerate identically everywhere.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : g_(seed) {}
  double uniform() { return double(g_() >> 11) * (1.0 / 9007199254740992.0); }  // [0, 1)
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  int integer(int lo, int hi) { return lo + int(g_() % std::uint64_t(hi - lo + 1)); }  // inclusive
  bool chance(double p) { return uniform() < p; }
  double sign() { return chance(0.5) ? 1.0 : -1.0; }
  double normal() {  // Box-Muller
    double u = uniform();
    while (u <= 0.0) u = uniform();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * kPi * uniform());
  }
  // Truncated at 3.5 sigma so "within 4 sigma of the plane" holds for every point.
  double noise(double sigma) {
    double z = normal();
    while (std::abs(z) > 3.5) z = normal();
    return sigma * z;
  }
  Vec2 unit2() {
    const double a = uniform(0.0, 2.0 * kPi);
    return {std::cos(a), std::sin(a)};
  }
  Vec3 unit3() {
    Vec3 v(normal(), normal(), normal());
    return v.norm() > 1e-12 ? Vec3(v.normalized()) : Vec3(Vec3::UnitZ());
  }

 private:
  std::mt19937_64 g_;
};

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
Vec2 xy(const Vec3& p) { return p.head<2>(); }

// ---------------------------------------------------------------------------------------------
// Building description.

struct Line {
  Vec2 p, d;  // a point and a unit direction
};

struct RoofPlane {
  double a = 0, b = 0, c = 0;  // z = a x + b y + c
  double z(const Vec2& q) const { return a * q.x() + b * q.y() + c; }
};

struct Part {
  std::vector<int> lines;       // footprint lines, counter-clockwise seen from above
  std::vector<RoofPlane> roof;  // roof = min over these planes; >1 plane needs a convex footprint
};

struct Spec {
  std::vector<Line> lines;
  std::vector<Part> parts;
  double z0 = 0.0;  // ground level
};

struct Edge {
  Vec2 a, b;
  int line;
};

int add_line(Spec& s, const Vec2& a, const Vec2& b) {
  s.lines.push_back({a, (b - a).normalized()});
  return int(s.lines.size()) - 1;
}

// Lines of the axis-aligned rectangle [x0,x1]x[y0,y1], counter-clockwise from the bottom edge.
std::vector<int> rect_lines(Spec& s, double x0, double y0, double x1, double y1) {
  return {add_line(s, {x0, y0}, {x1, y0}), add_line(s, {x1, y0}, {x1, y1}), add_line(s, {x1, y1}, {x0, y1}),
          add_line(s, {x0, y1}, {x0, y0})};
}

RoofPlane flat_roof(double z) { return {0.0, 0.0, z}; }

// Plane at height z_at through `at`, rising with slope k in direction `up`.
RoofPlane sloped_roof(const Vec2& at, const Vec2& up, double z_at, double k) {
  const Vec2 g = k * up.normalized();
  return {g.x(), g.y(), z_at - g.dot(at)};
}

Vec2 intersect(const Line& a, const Line& b) {
  const double den = cross2(a.d, b.d);
  if (std::abs(den) < 1e-9) throw ShapeError("consecutive footprint lines are parallel");
  return a.p + (cross2(b.p - a.p, b.d) / den) * a.d;
}

std::vector<Vec2> footprint(const Spec& s, const Part& p) {
  const std::size_t n = p.lines.size();
  std::vector<Vec2> c(n);
  for (std::size_t k = 0; k < n; ++k) c[k] = intersect(s.lines[p.lines[k]], s.lines[p.lines[(k + 1) % n]]);
  return c;
}

std::vector<Edge> part_edges(const Spec& s, const Part& p) {
  const auto c = footprint(s, p);
  const std::size_t n = c.size();
  std::vector<Edge> e;
  for (std::size_t k = 0; k < n; ++k) e.push_back({c[k], c[(k + 1) % n], p.lines[(k + 1) % n]});
  return e;
}

bool segments_cross(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double d1 = cross2(b - a, c - a), d2 = cross2(b - a, d - a), d3 = cross2(d - c, a - c),
               d4 = cross2(d - c, b - c);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0));
}

// Counter-clockwise, not self-intersecting and not a sliver.
bool valid_footprint(const std::vector<Vec2>& poly) {
  const std::size_t n = poly.size();
  if (signed_area_2d(poly) < 4.0) return false;
  for (std::size_t i = 0; i < n; ++i) {
    if ((poly[(i + 1) % n] - poly[i]).norm() < 0.5) return false;
    for (std::size_t j = i + 2; j < n; ++j)
      if ((j + 1) % n != i && segments_cross(poly[i], poly[(i + 1) % n], poly[j], poly[(j + 1) % n])) return false;
  }
  return true;
}

bool convex_ccw(const std::vector<Vec2>& poly) {
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[(i + 1) % poly.size()];
    const Vec2& c = poly[(i + 2) % poly.size()];
    if (cross2(b - a, c - b) < -1e-9) return false;
  }
  return true;
}

double envelope(const std::vector<RoofPlane>& roof, const Vec2& q) {
  double z = std::numeric_limits<double>::infinity();
  for (const auto& r : roof) z = std::min(z, r.z(q));
  return z;
}

// Parameters strictly inside (t0, t1) where the roof envelope along a->b changes plane.
std::vector<double> kinks(const std::vector<RoofPlane>& roof, const Vec2& a, const Vec2& b, double t0, double t1) {
  std::vector<double> ts;
  for (std::size_t i = 0; i < roof.size(); ++i)
    for (std::size_t j = i + 1; j < roof.size(); ++j) {
      const double fi = roof[i].z(a), fj = roof[j].z(a);
      const double si = roof[i].z(b) - fi, sj = roof[j].z(b) - fj;
      if (std::abs(si - sj) < 1e-12) continue;
      const double t = (fj - fi) / (si - sj);
      if (t <= t0 + 1e-9 || t >= t1 - 1e-9) continue;
      const Vec2 q = a + t * (b - a);
      if (roof[i].z(q) <= envelope(roof, q) + 1e-9) ts.push_back(t);
    }
  std::sort(ts.begin(), ts.end());
  ts.erase(std::unique(ts.begin(), ts.end(), [](double x, double y) { return y - x < 1e-9; }), ts.end());
  return ts;
}

// ---------------------------------------------------------------------------------------------
// Faces of the union of parts.

struct RawFace {
  std::vector<Vec3> pts;
  Semantic sem;
  int line;  // footprint line of a wall, -1 otherwise
};

struct Cover {
  double t0, t1;
  int part;
};

// Stretches of edge e (as parameters of a->b) where another part lies on the other side.
std::vector<Cover> covers_of(const std::vector<std::vector<Edge>>& edges, int pi, const Edge& e) {
  std::vector<Cover> out;
  const Vec2 ab = e.b - e.a;
  auto param = [&](const Vec2& q) { return (q - e.a).dot(ab) / ab.squaredNorm(); };
  for (int qi = 0; qi < int(edges.size()); ++qi) {
    if (qi == pi) continue;
    for (const auto& f : edges[qi]) {
      if (f.line != e.line) continue;
      const double lo = std::max(0.0, std::min(param(f.a), param(f.b)));
      const double hi = std::min(1.0, std::max(param(f.a), param(f.b)));
      if (hi - lo > 1e-9) out.push_back({lo, hi, qi});
    }
  }
  return out;
}

// Profile of the roof envelope (or of the ground when roof is null) over [t0, t1] of a->b.
std::vector<Vec3> profile(const std::vector<RoofPlane>* roof, double z0, const Vec2& a, const Vec2& b, double t0,
                          double t1) {
  std::vector<double> ts{t0};
  if (roof) {
    const auto k = kinks(*roof, a, b, t0, t1);
    ts.insert(ts.end(), k.begin(), k.end());
  }
  ts.push_back(t1);
  std::vector<Vec3> out;
  for (double t : ts) {
    const Vec2 q = a + t * (b - a);
    out.emplace_back(q.x(), q.y(), roof ? envelope(*roof, q) : z0);
  }
  return out;
}

// Wall of edge e of part pi: the stretches where the part's roof is above whatever lies
// beyond the edge (ground, or a lower neighbouring part).
void add_walls(const Spec& s, const std::vector<std::vector<Edge>>& edges, int pi, const Edge& e,
               std::vector<RawFace>& out) {
  const auto covers = covers_of(edges, pi, e);
  std::vector<double> ts{0.0, 1.0};
  for (const auto& c : covers) ts.insert(ts.end(), {c.t0, c.t1});
  std::sort(ts.begin(), ts.end());
  const auto& above = s.parts[pi].roof;
  for (std::size_t i = 0; i + 1 < ts.size(); ++i) {
    const double t0 = ts[i], t1 = ts[i + 1], tm = 0.5 * (t0 + t1);
    if (t1 - t0 < 1e-9) continue;
    const std::vector<RoofPlane>* below = nullptr;
    for (const auto& c : covers)
      if (c.t0 < tm && tm < c.t1) below = &s.parts[c.part].roof;
    auto gap = [&](double t) {
      const Vec2 q = e.a + t * (e.b - e.a);
      return envelope(above, q) - (below ? envelope(*below, q) : s.z0);
    };
    std::vector<double> interior{tm};
    for (double t : kinks(above, e.a, e.b, t0, t1)) interior.push_back(t);
    if (below)
      for (double t : kinks(*below, e.a, e.b, t0, t1)) interior.push_back(t);
    double lo = std::min(gap(t0), gap(t1)), hi = std::max(gap(t0), gap(t1)), lo_in = gap(tm);
    for (double t : interior) lo_in = std::min(lo_in, gap(t)), hi = std::max(hi, gap(t));
    if (hi <= 1e-7) continue;  // the neighbour is at least as high: interior
    if (!below && std::min(lo, lo_in) < 0.5) throw ShapeError("roof comes within 0.5 m of the ground");
    if (lo < -1e-7 || lo_in <= 1e-7) throw ShapeError("roof profiles cross on a shared wall");
    RawFace f{profile(below, s.z0, e.a, e.b, t0, t1), Semantic::Wall, e.line};
    auto top = profile(&above, s.z0, e.a, e.b, t0, t1);
    f.pts.insert(f.pts.end(), top.rbegin(), top.rend());
    out.push_back(std::move(f));
  }
}

// Sutherland-Hodgman: keeps the part of a convex polygon where A x + B y + C <= 0.
std::vector<Vec2> clip(const std::vector<Vec2>& poly, double A, double B, double C) {
  auto f = [&](const Vec2& p) { return A * p.x() + B * p.y() + C; };
  std::vector<Vec2> out;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2& p = poly[i];
    const Vec2& q = poly[(i + 1) % poly.size()];
    const double fp = f(p), fq = f(q);
    if (fp <= 0) out.push_back(p);
    if ((fp <= 0) != (fq <= 0)) out.push_back(p + (q - p) * (fp / (fp - fq)));
  }
  return out;
}

// One roof face per plane: the footprint where that plane is the lowest.
void add_roofs(const Spec& s, const Part& p, std::vector<RawFace>& out) {
  const auto fp = footprint(s, p);
  if (p.roof.size() > 1 && !convex_ccw(fp)) throw ShapeError("multi-plane roof on a non-convex part");
  for (std::size_t i = 0; i < p.roof.size(); ++i) {
    std::vector<Vec2> region = fp;
    for (std::size_t j = 0; j < p.roof.size() && region.size() >= 3; ++j)
      if (j != i)
        region = clip(region, p.roof[i].a - p.roof[j].a, p.roof[i].b - p.roof[j].b, p.roof[i].c - p.roof[j].c);
    if (region.size() < 3 || std::abs(signed_area_2d(region)) < 1e-6) continue;
    RawFace f{{}, Semantic::Roof, -1};
    for (const auto& q : region) f.pts.emplace_back(q.x(), q.y(), p.roof[i].z(q));
    out.push_back(std::move(f));
  }
}

void add_ground(const Spec& s, const Part& p, std::vector<RawFace>& out) {
  const auto fp = footprint(s, p);
  RawFace f{{}, Semantic::Ground, -1};
  for (auto it = fp.rbegin(); it != fp.rend(); ++it) f.pts.emplace_back(it->x(), it->y(), s.z0);
  out.push_back(std::move(f));
}

// ---------------------------------------------------------------------------------------------
// Turning raw faces into one shell.

int weld(std::vector<Vec3>& verts, const Vec3& p) {
  for (std::size_t i = 0; i < verts.size(); ++i)
    if ((verts[i] - p).norm() < kWeldTol) return int(i);
  verts.push_back(p);
  return int(verts.size()) - 1;
}

// Inserts every vertex lying inside a face edge into that edge, so faces meet vertex to vertex.
void split_t_junctions(Mesh& m) {
  for (auto& f : m.faces) {
    std::vector<int> out;
    for (std::size_t i = 0; i < f.v.size(); ++i) {
      out.push_back(f.v[i]);
      const auto inside = vertices_on_segment(m.vertices, f.v[i], f.v[(i + 1) % f.v.size()], kOnEdge);
      out.insert(out.end(), inside.begin(), inside.end());
    }
    f.v = out;
  }
}

// The outline of a group of faces (shared edges cancel); nullopt unless it is one simple loop.
std::optional<std::vector<int>> outline(const Mesh& m, const std::vector<int>& group) {
  std::map<std::pair<int, int>, int> count;
  for (int fi : group) {
    const auto& v = m.faces[fi].v;
    for (std::size_t i = 0; i < v.size(); ++i) ++count[{v[i], v[(i + 1) % v.size()]}];
  }
  std::map<int, int> next;
  for (const auto& [e, c] : count) {
    const auto rev = count.find({e.second, e.first});
    if (rev != count.end() && rev->second > 0) continue;
    if (c != 1 || next.count(e.first)) return std::nullopt;
    next[e.first] = e.second;
  }
  if (next.empty()) return std::nullopt;
  std::vector<int> loop{next.begin()->first};
  while (true) {
    const auto it = next.find(loop.back());
    if (it == next.end()) return std::nullopt;
    if (it->second == loop.front()) break;
    loop.push_back(it->second);
    if (loop.size() > next.size()) return std::nullopt;
  }
  if (loop.size() != next.size()) return std::nullopt;
  return loop;
}

// Merges edge-adjacent coplanar faces of the same semantic (pieces of one wall, roofs of
// parts of equal height, the parts' grounds) into single polygons.
void merge_coplanar(Mesh& m) {
  const int nf = int(m.faces.size());
  std::vector<Plane> planes;
  for (const auto& f : m.faces) planes.push_back(polygon_plane(face_points(m, f)));
  DisjointSets sets(nf);
  for (const auto& [e, fs] : edge_uses(m.faces)) {
    if (fs.size() != 2) continue;
    const int f = fs[0].face, g = fs[1].face;
    if (m.faces[f].sem != m.faces[g].sem) continue;
    if (planes[f].n.dot(planes[g].n) < kCoplanarCos || std::abs(planes[f].d - planes[g].d) > kWeldTol) continue;
    sets.unite(f, g);
  }
  std::map<int, std::vector<int>> groups;
  for (int fi = 0; fi < nf; ++fi) groups[sets.find(fi)].push_back(fi);
  std::map<int, std::optional<std::vector<int>>> outlines;  // per group root; nullopt: keep members
  for (const auto& [root, g] : groups)
    if (g.size() > 1) outlines[root] = outline(m, g);
  std::vector<Face> faces;
  for (int fi = 0; fi < nf; ++fi) {
    const int root = sets.find(fi);
    const auto it = outlines.find(root);
    if (it == outlines.end() || !it->second)
      faces.push_back(m.faces[fi]);
    else if (groups[root].front() == fi)
      faces.push_back(Face{*it->second, m.faces[fi].sem, m.faces[fi].source});
  }
  m.faces = std::move(faces);
}

// Drops vertices that only continue a straight edge (two neighbours, collinear), then unused ones.
void drop_collinear_vertices(Mesh& m) {
  std::vector<std::set<int>> nb(m.vertices.size());
  for (const auto& f : m.faces)
    for (std::size_t i = 0; i < f.v.size(); ++i) {
      const int a = f.v[i], b = f.v[(i + 1) % f.v.size()];
      nb[a].insert(b);
      nb[b].insert(a);
    }
  std::vector<bool> drop(m.vertices.size(), false);
  for (std::size_t v = 0; v < nb.size(); ++v) {
    if (nb[v].size() != 2) continue;
    drop[v] = inside_segment(m.vertices[*nb[v].begin()], m.vertices[*nb[v].rbegin()], m.vertices[v], kOnEdge).has_value();
  }
  std::vector<int> remap(m.vertices.size(), -1);
  std::vector<Vec3> verts;
  for (auto& f : m.faces) {
    std::vector<int> kept;
    for (int v : f.v)
      if (!drop[v]) {
        if (remap[v] < 0) remap[v] = int(verts.size()), verts.push_back(m.vertices[v]);
        kept.push_back(remap[v]);
      }
    f.v = kept;
  }
  m.vertices = std::move(verts);
}

// The closed shell of a spec; Face::source holds the footprint line of each wall (-1 otherwise).
Mesh build_mesh(const Spec& s) {
  std::vector<std::vector<Edge>> edges;
  for (const auto& p : s.parts) {
    if (!valid_footprint(footprint(s, p))) throw ShapeError("a part's footprint folds over");
    edges.push_back(part_edges(s, p));
  }
  std::vector<RawFace> raw;
  for (int pi = 0; pi < int(s.parts.size()); ++pi)
    for (const auto& e : edges[pi]) add_walls(s, edges, pi, e, raw);
  for (const auto& p : s.parts) add_roofs(s, p, raw);
  for (const auto& p : s.parts) add_ground(s, p, raw);
  Mesh m;
  for (const auto& rf : raw) {
    Face f;
    for (const auto& p : rf.pts) f.v.push_back(weld(m.vertices, p));
    drop_repeats(f.v);
    f.sem = rf.sem;
    f.source = rf.line;
    if (f.v.size() >= 3) m.faces.push_back(std::move(f));
  }
  split_t_junctions(m);
  merge_coplanar(m);
  drop_collinear_vertices(m);
  return m;
}

// ---------------------------------------------------------------------------------------------
// Building types (building frame: metres, x/y axis-aligned where the type allows).

Spec single_part(std::vector<int> lines, std::vector<RoofPlane> roof, Spec s) {
  s.parts.push_back({std::move(lines), std::move(roof)});
  return s;
}

Spec flat_spec(Rng& r, double z0) {
  Spec s;
  s.z0 = z0;
  const double W = r.uniform(8, 30), D = r.uniform(6, std::min(W, 16.0));
  const auto lines = rect_lines(s, 0, 0, W, D);
  return single_part(lines, {flat_roof(z0 + r.uniform(3, 15))}, s);
}

Spec gable_spec(Rng& r, double z0, bool hip) {
  Spec s;
  s.z0 = z0;
  const double D = r.uniform(6, 12), W = D + r.uniform(hip ? 2.0 : 0.0, 12.0);
  const double eave = z0 + r.uniform(3, hip ? 8 : 9), k = std::tan(radians(r.uniform(25, hip ? 45 : 50)));
  const auto lines = rect_lines(s, 0, 0, W, D);
  std::vector<RoofPlane> roof{sloped_roof({0, 0}, {0, 1}, eave, k), sloped_roof({0, D}, {0, -1}, eave, k)};
  if (hip) {
    const double k2 = std::tan(std::atan(k) + radians(r.uniform(0, 15)));
    roof.push_back(sloped_roof({0, 0}, {1, 0}, eave, k2));
    roof.push_back(sloped_roof({W, 0}, {-1, 0}, eave, k2));
  }
  return single_part(lines, roof, s);
}

Spec shed_spec(Rng& r, double z0) {
  Spec s;
  s.z0 = z0;
  const double W = r.uniform(6, 20), D = r.uniform(6, 12);
  const auto lines = rect_lines(s, 0, 0, W, D);
  const double low = z0 + r.uniform(3, 8), k = std::tan(radians(r.uniform(8, 25)));
  return single_part(lines, {sloped_roof({0, 0}, {0, 1}, low, k)}, s);
}

// A tall block with a low annex behind it and sometimes a second one at its right side; annexes
// flush with the block's sides share its footprint line.
Spec stepped_spec(Rng& r, double z0) {
  Spec s;
  s.z0 = z0;
  const double W = r.uniform(10, 20), D = r.uniform(9, 14), hA = r.uniform(9, 15);
  const bool three = r.chance(0.5);
  const auto A = rect_lines(s, 0, 0, W, D);
  s.parts.push_back({A, {flat_roof(z0 + hA)}});
  // Annex B against the back (y = D).
  const double hB = r.uniform(3, 5.5), DB = r.uniform(4, 8);
  const double bx0 = r.chance(0.5) ? 0.0 : r.uniform(1, 3);
  double bx1 = bx0 + r.uniform(5, W - bx0);
  if (bx1 > W - 1) bx1 = W;
  const int bl = bx0 == 0.0 ? A[3] : add_line(s, {bx0, D + DB}, {bx0, D});
  const int br = bx1 == W ? A[1] : add_line(s, {bx1, D}, {bx1, D + DB});
  s.parts.push_back({{A[2], br, add_line(s, {bx1, D + DB}, {bx0, D + DB}), bl}, {flat_roof(z0 + hB)}});
  if (!three) return s;
  // Annex C against the right side (x = W), of a third height, clear of B.
  const double hC = r.uniform(hB + 1.2, hA - 2.0), WC = r.uniform(4, 8);
  const double cy0 = r.chance(0.5) ? 0.0 : r.uniform(1, 2.5), cy1 = r.uniform(cy0 + 4, D - 1.5);
  const int cb = cy0 == 0.0 ? A[0] : add_line(s, {W, cy0}, {W + WC, cy0});
  s.parts.push_back({{cb, add_line(s, {W + WC, cy0}, {W + WC, cy1}), add_line(s, {W + WC, cy1}, {W, cy1}), A[1]},
                     {flat_roof(z0 + hC)}});
  return s;
}

// L: a block and a wing along its left side sharing the left facade line; flat roof.
Spec lshape_spec(Rng& r, double z0) {
  Spec s;
  s.z0 = z0;
  const double W = r.uniform(10, 24), D1 = r.uniform(6, 10), W2 = r.uniform(5, W - 4), D2 = r.uniform(4, 10);
  const RoofPlane roof = flat_roof(z0 + r.uniform(3, 12));
  const int bottom = add_line(s, {0, 0}, {W, 0}), right = add_line(s, {W, 0}, {W, D1});
  const int mid = add_line(s, {W, D1}, {0, D1}), left = add_line(s, {0, D1 + D2}, {0, 0});
  s.parts.push_back({{bottom, right, mid, left}, {roof}});
  const int wr = add_line(s, {W2, D1}, {W2, D1 + D2}), wt = add_line(s, {W2, D1 + D2}, {0, D1 + D2});
  s.parts.push_back({{mid, wr, wt, left}, {roof}});
  return s;
}

// T: a stem part running through, with a wing on each side sharing the back facade line.
Spec tshape_spec(Rng& r, double z0) {
  Spec s;
  s.z0 = z0;
  const double W = r.uniform(14, 26), Ws = r.uniform(5, 9), Ls = r.uniform(4, 9), Dc = r.uniform(6, 10);
  const double x0 = std::clamp((W - Ws) / 2 + r.uniform(-2, 2), 2.5, W - Ws - 2.5), x1 = x0 + Ws, Dt = Ls + Dc;
  const RoofPlane roof = flat_roof(z0 + r.uniform(3, 12));
  const int top = add_line(s, {W, Dt}, {0, Dt});
  const int cl = add_line(s, {x0, Dt}, {x0, 0}), cr = add_line(s, {x1, 0}, {x1, Dt});
  s.parts.push_back({{add_line(s, {x0, 0}, {x1, 0}), cr, top, cl}, {roof}});
  s.parts.push_back({{add_line(s, {0, Ls}, {x0, Ls}), cl, top, add_line(s, {0, Dt}, {0, Ls})}, {roof}});
  s.parts.push_back({{add_line(s, {x1, Ls}, {W, Ls}), add_line(s, {W, Ls}, {W, Dt}), top, cr}, {roof}});
  return s;
}

// Convex trapezoid or chamfered pentagon with oblique corners; flat or mono-pitch roof.
Spec polygon_spec(Rng& r, double z0) {
  Spec s;
  s.z0 = z0;
  const double W = r.uniform(11, 22), D = r.uniform(7, 14);
  auto skew = [&] { return r.sign() * r.uniform(1.5, 3.5); };
  std::vector<Vec2> pts;
  if (r.chance(0.5)) {
    pts = {{0, 0}, {W, 0}, {W - skew(), D}, {skew(), D}};
  } else {
    const double c1 = r.uniform(2, 5), c2 = r.uniform(2, 5);
    pts = {{0, 0}, {W, 0}, {W, D - c1}, {W - c2, D}, {skew(), D}};
  }
  std::vector<int> lines;
  for (std::size_t i = 0; i < pts.size(); ++i) lines.push_back(add_line(s, pts[i], pts[(i + 1) % pts.size()]));
  const double h = z0 + r.uniform(3, 10);
  const RoofPlane roof =
      r.chance(0.5) ? flat_roof(h) : sloped_roof({0, 0}, {0, 1}, h, std::tan(radians(r.uniform(8, 20))));
  return single_part(lines, {roof}, s);
}

Spec make_spec(BuildingType t, Rng& r, double z0) {
  switch (t) {
    case BuildingType::Flat:
      return flat_spec(r, z0);
    case BuildingType::Gable:
      return gable_spec(r, z0, false);
    case BuildingType::Hip:
      return gable_spec(r, z0, true);
    case BuildingType::Shed:
      return shed_spec(r, z0);
    case BuildingType::Stepped:
      return stepped_spec(r, z0);
    case BuildingType::LShape:
      return lshape_spec(r, z0);
    case BuildingType::TShape:
      return tshape_spec(r, z0);
    case BuildingType::Polygon:
      return polygon_spec(r, z0);
  }
  throw std::logic_error("synth: unknown building type");
}

// ---------------------------------------------------------------------------------------------
// Walls: scanning and moving.

struct WallInfo {
  int face, line;
  Vec2 n;    // outward, horizontal
  Vec2 mid;  // middle of the wall's horizontal extent
  double length;
};

std::vector<WallInfo> wall_infos(const Mesh& m) {
  std::vector<WallInfo> out;
  for (int fi = 0; fi < int(m.faces.size()); ++fi) {
    const auto& f = m.faces[fi];
    if (f.sem != Semantic::Wall) continue;
    const auto pts = face_points(m, f);
    const Vec2 n = xy(newell_normal(pts)).normalized(), u(-n.y(), n.x());
    double lo = 1e300, hi = -1e300;
    for (const auto& p : pts) lo = std::min(lo, u.dot(xy(p))), hi = std::max(hi, u.dot(xy(p)));
    const Vec2 base = xy(pts[0]) - u * u.dot(xy(pts[0]));
    out.push_back({fi, f.source, n, base + u * (0.5 * (lo + hi)), hi - lo});
  }
  return out;
}

int pick_weighted(const std::vector<double>& w, Rng& r) {
  const double total = std::accumulate(w.begin(), w.end(), 0.0);
  double x = r.uniform(0, total);
  for (std::size_t i = 0; i < w.size(); ++i)
    if ((x -= w[i]) < 0 && w[i] > 0) return int(i);
  for (std::size_t i = w.size(); i-- > 0;)
    if (w[i] > 0) return int(i);
  return -1;
}

// A street-side run of 1..k adjacent walls, the first one picked by length.
std::vector<int> choose_scanned(const Mesh& m, const std::vector<WallInfo>& walls, int k, Rng& r) {
  std::vector<int> wall_of(m.faces.size(), -1), faces;
  for (std::size_t w = 0; w < walls.size(); ++w) wall_of[walls[w].face] = int(w), faces.push_back(walls[w].face);
  const auto edge_walls = edge_uses(m.faces, faces);
  std::vector<double> weight;
  for (const auto& w : walls) weight.push_back(w.length >= 3 ? w.length : 0.0);
  std::vector<int> chosen{pick_weighted(weight, r)};
  while (int(chosen.size()) < k) {
    std::set<int> cand;
    for (const auto& [e, uses] : edge_walls)
      for (const EdgeUse& a : uses)
        if (std::count(chosen.begin(), chosen.end(), wall_of[a.face]))
          for (const EdgeUse& b : uses)
            if (!std::count(chosen.begin(), chosen.end(), wall_of[b.face]) && walls[wall_of[b.face]].length >= 2)
              cand.insert(wall_of[b.face]);
    if (cand.empty()) break;
    chosen.push_back(*std::next(cand.begin(), r.integer(0, int(cand.size()) - 1)));
  }
  return chosen;  // indices into walls
}

void move_line(Line& l, const Vec2& pivot, const Vec2& n_out, double offset, double rot_deg) {
  const Eigen::Rotation2Dd R(radians(rot_deg));
  l.p = pivot + R * (l.p - pivot) + offset * (R * n_out);
  l.d = R * l.d;
}

MovedWall random_move(const SynthOptions& o, Rng& r) {
  MovedWall mv;
  const double mode = r.uniform();  // shift only / rotation only / both
  const bool shift = o.max_rotation_deg <= 0 || mode<0.85, rotate = o.max_rotation_deg> 0 && mode >= 0.45;
  if (shift) mv.offset = r.sign() * r.uniform(o.min_shift, o.max_shift);
  if (rotate) mv.rotation_deg = r.sign() * r.uniform(0.3 * o.max_rotation_deg, o.max_rotation_deg);
  return mv;
}

// Moves 1..3 facades: mostly scanned ones, now and then a scanned one stays right.
std::vector<MovedWall> move_facades(Spec& s, const std::vector<WallInfo>& walls, const std::vector<int>& scanned,
                                    const SynthOptions& o, Rng& r) {
  std::vector<int> pick;  // indices into walls
  for (int w : scanned)
    if (r.chance(0.75)) pick.push_back(w);
  std::vector<int> others;
  for (int w = 0; w < int(walls.size()); ++w)
    if (!std::count(scanned.begin(), scanned.end(), w) && walls[w].length >= 2) others.push_back(w);
  if (!others.empty() && (pick.empty() || r.chance(0.25))) pick.push_back(others[r.integer(0, int(others.size()) - 1)]);
  if (pick.empty()) pick.push_back(scanned.front());
  std::vector<MovedWall> moves;
  std::set<int> moved_lines;
  for (int w : pick) {
    const WallInfo& wi = walls[w];
    if (moves.size() >= 3 || !moved_lines.insert(wi.line).second) continue;
    MovedWall mv = random_move(o, r);
    for (const auto& x : walls)
      if (x.line == wi.line && x.face != wi.face) mv.truth_faces.push_back(x.face);
    mv.truth_faces.insert(mv.truth_faces.begin(), wi.face);
    mv.scanned = std::count(scanned.begin(), scanned.end(), w) > 0;
    move_line(s.lines[wi.line], wi.mid, wi.n, mv.offset, mv.rotation_deg);
    moves.push_back(mv);
  }
  return moves;
}

// ---------------------------------------------------------------------------------------------
// Coarse export: polygon soup with defects.

Mesh to_soup(const Mesh& m) {
  Mesh s;
  s.id = m.id;
  for (const auto& f : m.faces) {
    Face g{{}, f.sem, -1};
    for (int v : f.v) {
      g.v.push_back(int(s.vertices.size()));
      s.vertices.push_back(m.vertices[v]);
    }
    s.faces.push_back(std::move(g));
  }
  return s;
}

int random_face(const Mesh& m, Rng& r, bool roof_only) {
  std::vector<int> c;
  for (int i = 0; i < int(m.faces.size()); ++i)
    if (roof_only ? m.faces[i].sem == Semantic::Roof : m.faces[i].sem != Semantic::Ground) c.push_back(i);
  return c.empty() ? -1 : c[r.integer(0, int(c.size()) - 1)];
}

void copy_face(Mesh& s, int fi) {
  Face g = s.faces[fi];
  for (int& v : g.v) {
    s.vertices.push_back(s.vertices[v]);
    v = int(s.vertices.size()) - 1;
  }
  s.faces.push_back(std::move(g));
}

std::vector<std::string> add_defects(Mesh& s, Rng& r) {
  bool use[4];
  for (bool& u : use) u = r.chance(0.4);
  if (!(use[0] || use[1] || use[2] || use[3])) use[r.integer(0, 3)] = true;
  std::vector<std::string> log;
  if (use[0]) {
    s.faces.erase(
        std::remove_if(s.faces.begin(), s.faces.end(), [](const Face& f) { return f.sem == Semantic::Ground; }),
        s.faces.end());
    log.push_back("missing_ground");
  }
  if (int f = random_face(s, r, true); use[1] && f >= 0) {  // in-plane jitter keeps the face planar
    const auto [u, v] = polygon_plane(face_points(s, s.faces[f])).basis();
    for (int i : s.faces[f].v) {
      const Vec2 d = r.unit2() * r.uniform(0.001, 0.003);
      s.vertices[i] += d.x() * u + d.y() * v;
    }
    log.push_back("mm_gaps:" + std::to_string(f));
  }
  if (int f = random_face(s, r, false); use[2] && f >= 0) {
    std::reverse(s.faces[f].v.begin(), s.faces[f].v.end());
    log.push_back("reversed_face:" + std::to_string(f));
  }
  if (int f = random_face(s, r, false); use[3] && f >= 0) {
    copy_face(s, f);
    log.push_back("duplicate_face:" + std::to_string(f));
  }
  // Drawn last, so the defects above stay those of earlier versions for every seed.
  if (r.chance(0.5)) {  // every roof polygon's own copy of its corners a few mm off, some > 1 cm
    constexpr double kJitterMin = 0.002, kJitterMax = 0.013;
    for (const auto& f : s.faces)
      if (f.sem == Semantic::Roof)
        for (int i : f.v) {
          const Vec2 d = r.unit2() * r.uniform(kJitterMin, kJitterMax);
          s.vertices[i] += Vec3(d.x(), d.y(), r.uniform(-0.5, 0.5) * kJitterMin);
        }
    log.push_back("roof_jitter");
  }
  return log;
}

// ---------------------------------------------------------------------------------------------
// Simulated MLS crop (building frame).

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
};

ScanWall scan_wall(const Mesh& m, int face, double z0, Rng& r) {
  ScanWall w;
  w.face = face;
  const auto pts = face_points(m, m.faces[face]);
  const Vec2 n2 = xy(newell_normal(pts)).normalized();
  w.n = Vec3(n2.x(), n2.y(), 0);
  w.u = Vec3(-n2.y(), n2.x(), 0);
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
};

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
      const Vec3 scanner = w.o + js * w.u + sc.scanner_dist * w.n + (sc.z0 + 2.2) * Vec3::UnitZ();
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
  for (const auto& w : sc.walls) total += w.smax - w.smin + 4;
  for (const auto& w : sc.walls)
    for (int k = int(budget * (w.smax - w.smin + 4) / total); k > 0; --k)
      push_clutter(sc, street_point(w, r.uniform(w.smin - 2, w.smax + 2), r.uniform(0, 8), sc.z0), -3, noise, r);
}

// Pieces of the next building: a wall continuing past one end of a scanned facade (slightly
// offset) and/or the neighbour's side wall across a gap. Only at ends where the building does
// not continue itself (not at concave corners).
void add_neighbour(Scene& sc, int budget, double noise, Rng& r) {
  std::vector<std::pair<const ScanWall*, double>> ends;  // wall, direction along u
  for (const auto& w : sc.walls)
    for (double dir : {-1.0, 1.0}) {
      const double end = dir > 0 ? w.smax : w.smin;
      if (!point_in_polygon_2d(xy(street_point(w, end + 2 * dir, -1.0, 0)), sc.footprint)) ends.emplace_back(&w, dir);
    }
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
  auto wall = [&]() -> const ScanWall& { return sc.walls[r.integer(0, int(sc.walls.size()) - 1)]; };
  for (int k = r.integer(0, 2); k > 0; --k) add_tree(sc, wall(), int(0.03 * T), o.noise, r);
  for (int k = r.integer(0, 2); k > 0; --k) add_car(sc, wall(), int(0.02 * T), o.noise, r);
  for (int k = r.integer(0, 3); k > 0; --k) add_person(sc, wall(), int(0.004 * T), o.noise, r);
  add_street(sc, int(0.15 * T), o.noise, r);
  add_neighbour(sc, int(0.08 * T), o.noise, r);
}

std::vector<int> wall_faces(const std::vector<int>& chosen, const std::vector<WallInfo>& walls) {
  std::vector<int> faces;
  for (int w : chosen) faces.push_back(walls[w].face);
  return faces;
}

Scene simulate_scan(const Mesh& truth, const std::vector<int>& faces, double z0, const SynthOptions& o, Rng& r) {
  Scene sc;
  sc.z0 = z0;
  sc.scanner_dist = r.uniform(7.5, 9);  // beyond the cars, inside the street strip
  for (const auto& f : truth.faces)
    if (f.sem == Semantic::Ground)
      for (int v : f.v) sc.footprint.push_back(xy(truth.vertices[v]));
  double area = 0;
  for (int f : faces) {
    sc.walls.push_back(scan_wall(truth, f, z0, r));
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
  return sc;
}

// ---------------------------------------------------------------------------------------------
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

void check_options(const SynthOptions& o) {
  if (o.min_shift < 0 || o.max_shift < o.min_shift) throw InputError("synth: need 0 <= min_shift <= max_shift");
  if (o.max_shift > 3.0) throw InputError("synth: max_shift above 3 m would break the building's shape");
  if (o.max_rotation_deg < 0 || o.max_rotation_deg > 15) throw InputError("synth: max_rotation_deg must be in 0..15");
  if (o.noise < 0 || o.global_shift < 0) throw InputError("synth: noise and global_shift must be >= 0");
  if (o.target_points < 100) throw InputError("synth: target_points must be >= 100");
  if (o.scanned_facades < 0) throw InputError("synth: scanned_facades must be >= 0");
}

}  // namespace

// ---------------------------------------------------------------------------------------------

namespace {
// Every building type with its name, in the order `--type all` generates them.
constexpr std::pair<BuildingType, const char*> kBuildingTypes[] = {
    {BuildingType::Flat, "flat"},       {BuildingType::Gable, "gable"},   {BuildingType::Hip, "hip"},
    {BuildingType::Shed, "shed"},       {BuildingType::Stepped, "stepped"}, {BuildingType::LShape, "lshape"},
    {BuildingType::TShape, "tshape"}, {BuildingType::Polygon, "polygon"}};
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

SynthBuilding make_building(BuildingType type, std::uint64_t seed, const SynthOptions& opt) {
  check_options(opt);
  // One stream per stage, so --no-defects / --no-nuisances leave the other outputs unchanged.
  const std::uint64_t key = splitmix64(seed * 16 + std::uint64_t(type));
  Rng r(key), r_defects(splitmix64(key ^ 1)), r_scan(splitmix64(key ^ 2));
  SynthBuilding b;
  char id[64];
  std::snprintf(id, sizeof id, "synth_%s_%04llu", building_type_name(type), static_cast<unsigned long long>(seed));
  b.id = id;
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
  const int k = opt.scanned_facades > 0 ? opt.scanned_facades : r.integer(1, 3);
  const auto scanned = choose_scanned(truth, walls, k, r);
  b.scanned_truth_faces = wall_faces(scanned, walls);

  Mesh coarse_local;
  for (int attempt = 0;; ++attempt) {  // large moves can fold a part or sink an eave: redraw
    Spec moved = spec;
    b.moved_walls = move_facades(moved, walls, scanned, opt, r);
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

  Scene sc = simulate_scan(truth, b.scanned_truth_faces, z0, opt, r_scan);
  b.point_spacing = sc.spacing;
  for (const auto& p : sc.pts) b.cloud.points.push_back(frame.apply(p));
  b.point_label = std::move(sc.labels);

  b.truth = to_world(truth, frame, Vec3::Zero());
  b.truth.id = coarse.id = b.id;
  b.coarse = std::move(coarse);
  return b;
}

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
    by_label[l >= 0 ? "facade" : l == -1 ? "window_recess" : l == -2 ? "clutter" : l == -3 ? "ground" : "neighbour"]++;
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
        {"nuisances", o.nuisances}}},
      {"moved_walls", moved},
      {"coarse_shift", vec_json(b.coarse_shift)},
      {"defects", b.defects},
      {"scanned_truth_faces", b.scanned_truth_faces},
      {"point_spacing", b.point_spacing},
      {"point_labels",
       "cloud.ply property 'label': truth face index for facade points, -1 window recess, "
       "-2 clutter (trees, cars, people), -3 street ground, -4 neighbouring building"},
      {"counts",
       {{"truth_faces", b.truth.faces.size()},
        {"truth_vertices", b.truth.vertices.size()},
        {"coarse_faces", b.coarse.faces.size()},
        {"points", b.cloud.points.size()},
        {"points_by_label", by_label}}},
  };
}

}  // namespace

void write_synth_building(const std::string& dir, const SynthBuilding& b, bool with_cloud) {
  const std::filesystem::path out = std::filesystem::path(dir) / b.id;
  std::filesystem::create_directories(out);
  write_obj((out / "truth.obj").string(), b.truth);
  write_obj((out / "coarse.obj").string(), b.coarse);
  if (with_cloud) {
    const std::vector<float> labels(b.point_label.begin(), b.point_label.end());
    write_ply((out / "cloud.ply").string(), b.cloud, Vec3::Zero(), &labels, "label");
  }
  write_file_atomic((out / "meta.json").string(),
                    meta_json(b).dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "write_synth_tile writes the host's doubles as binary_little_endian"
#endif

std::uint64_t write_synth_tile(const std::string& dir, const std::string& tile_ply, int count, std::uint64_t first_seed,
                               double spacing, const SynthOptions& opt,
                               const std::function<void(const SynthBuilding&)>& progress) {
  std::string tmp;  // created exclusively beside the tile (a planted link is never followed)
  const int fd = create_temp_file(std::filesystem::path(tile_ply).parent_path().string(), tile_ply, tmp);
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(::fdopen(fd, "wb"), std::fclose);
  if (!f) {
    ::close(fd), std::remove(tmp.c_str());
    throw InputError("cannot write " + tile_ply + ": " + std::strerror(errno));
  }
  // The count is only known at the end: a fixed-width field, rewritten in place.
  constexpr int kCountWidth = 15;
  const std::string head = "ply\nformat binary_little_endian 1.0\ncomment lodrefine synth tile\nelement vertex ";
  const std::string tail = "\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
  auto header = [&](std::uint64_t n) {
    char num[32];
    std::snprintf(num, sizeof num, "%0*llu", kCountWidth, static_cast<unsigned long long>(n));
    return head + num + tail;
  };
  auto fail = [&] {
    const std::string reason = std::strerror(errno);
    f.reset();
    std::remove(tmp.c_str());
    throw InputError("cannot write " + tmp + ": " + reason);
  };
  auto put = [&](const void* data, std::size_t bytes) {
    if (std::fwrite(data, 1, bytes, f.get()) != bytes) fail();
  };
  put(header(0).data(), header(0).size());
  const auto types = all_building_types();
  const int columns = std::max(1, int(std::ceil(std::sqrt(double(count)))));
  std::uint64_t points = 0;
  for (int i = 0; i < count; ++i) {
    SynthBuilding b = make_building(types[std::size_t(i) % types.size()], first_seed + std::uint64_t(i), opt);
    // Onto its grid cell: a pure translation, so truth, model, scan and meta stay consistent.
    const Vec3 cell = opt.origin + Vec3(spacing * (i % columns), spacing * (i / columns), 0.0);
    const Vec3 shift(cell.x() - b.frame_origin.x(), cell.y() - b.frame_origin.y(), 0.0);
    b.truth = translated(std::move(b.truth), shift);
    b.coarse = translated(std::move(b.coarse), shift);
    for (auto& p : b.cloud.points) p += shift;
    b.frame_origin += shift;
    write_synth_building(dir, b, false);
    std::vector<double> xyz;
    xyz.reserve(3 * b.cloud.points.size());
    for (const auto& p : b.cloud.points) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
    put(xyz.data(), xyz.size() * sizeof(double));
    points += b.cloud.points.size();
    if (progress) progress(b);
  }
  if (std::fseek(f.get(), 0, SEEK_SET) != 0) fail();
  put(header(points).data(), header(points).size());
  if (std::fflush(f.get()) != 0 || ::fsync(::fileno(f.get())) != 0) fail();
  f.reset();
  std::filesystem::rename(tmp, tile_ply);
  return points;
}

}  // namespace lodrefine
