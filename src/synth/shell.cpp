// From a Spec to one closed shell (see shapes.h): walls, roofs and ground per part, then the
// core's repair (weld, T-junctions) and coplanar merge (which drops the vertices that only
// continue a straight edge).
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "lodrefine/base/geometry.h"
#include "lodrefine/core/repair.h"
#include "shapes.h"

namespace lodrefine::synth {

namespace {

constexpr double kWeldTol = 1e-6;  // building frame, metres
// Generated faces of one plane agree up to rounding; distinct planes of a building differ by
// degrees, so the core's merge runs with tolerances far below those of a refined model.
constexpr double kCoplanarAngleDeg = 0.01;
constexpr double kMinPartArea = 1.0;  // m^2: a part's footprint below this has folded

struct Edge {
  Vec2 a, b;
  int line;
};

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

// Counter-clockwise, not self-intersecting and not a sliver (a bay's part is 1.5 m^2 and up).
bool valid_footprint(const std::vector<Vec2>& poly) {
  const std::size_t n = poly.size();
  if (signed_area_2d(poly) < kMinPartArea) return false;
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

}  // namespace

int add_line(Spec& s, const Vec2& a, const Vec2& b) {
  s.lines.push_back({a, (b - a).normalized()});
  return int(s.lines.size()) - 1;
}

std::vector<int> rect_lines(Spec& s, double x0, double y0, double x1, double y1) {
  return {add_line(s, {x0, y0}, {x1, y0}), add_line(s, {x1, y0}, {x1, y1}), add_line(s, {x1, y1}, {x0, y1}),
          add_line(s, {x0, y1}, {x0, y0})};
}

RoofPlane flat_roof(double z) { return {0.0, 0.0, z}; }

RoofPlane sloped_roof(const Vec2& at, const Vec2& up, double z_at, double k) {
  const Vec2 g = k * up.normalized();
  return {g.x(), g.y(), z_at - g.dot(at)};
}

bool segments_cross(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double d1 = cross2(b - a, c - a), d2 = cross2(b - a, d - a), d3 = cross2(d - c, a - c),
               d4 = cross2(d - c, b - c);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0));
}

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
  // Every raw face with its own corners, then the core's repair: weld, T-junctions, orientation.
  Mesh soup;
  for (const auto& rf : raw) {
    Face f{{}, rf.sem, rf.line};
    for (const auto& p : rf.pts) f.v.push_back(int(soup.vertices.size())), soup.vertices.push_back(p);
    soup.faces.push_back(std::move(f));
  }
  RepairReport report;
  Mesh m;
  try {
    m = repair_model(soup, kWeldTol, &report);
  } catch (const InputError& e) {
    throw ShapeError(std::string("the parts do not close: ") + e.what());
  }
  // The raw faces are outward and meet edge to edge: a filled hole or a flipped face is a bug here.
  if (report.filled_holes > 0 || report.flipped_faces > 0)
    throw std::logic_error("synth: the generated faces left a hole or ran against their neighbours");
  return merge_coplanar_faces(m, kCoplanarAngleDeg, kWeldTol);
}

}  // namespace lodrefine::synth
