// Stage 4 (paper Sec. 3.2): candidate faces from pairwise plane intersections in a region.
#include "lodrefine/core/candidates.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "lodrefine/core/topology.h"

namespace lodrefine {
namespace {

// Tolerances of the arrangement, in the local frame (metres), where rounding is ~1e-12:
// Three planes whose pivoted solve meets a pivot below this are dependent: they share no point.
constexpr double kMeetMinPivot = 1e-12;
// A polygon vertex this close to a cutting plane lies on it (rounding of the plane meets).
constexpr double kOnCutPlane = 1e-9;
// Vertices this close are one (candidates.h): far above the meets' rounding, far below any
// feature of a building.
constexpr double kVertexWeld = 1e-6;
// A vertex splits another face's edge when within kVertexWeld of it and farther than this share
// of the edge from either end (nearer, it is that end).
constexpr double kEdgeEndShare = 1e-9;

}  // namespace

std::array<Plane, 6> Region::planes() const {
  std::array<Plane, 6> out;
  for (int k = 0; k < 3; ++k) {
    const Vec3 a = axes.col(k);
    out[2 * k] = Plane::through(center + half[k] * a, a);
    out[2 * k + 1] = Plane::through(center - half[k] * a, -a);
  }
  return out;
}

bool Region::contains(const Vec3& p, double tol) const {
  const Vec3 q = axes.transpose() * (p - center);
  return (q.cwiseAbs() - half).maxCoeff() <= tol;
}

Region Region::around(const std::vector<Vec3>& pts, double relative, double absolute) {
  const Eigen::AlignedBox3d box = bounding_box(pts);
  Region r;
  r.center = 0.5 * (box.min() + box.max());
  r.half = 0.5 * (box.max() - box.min()) * (1.0 + 2.0 * relative) + Vec3::Constant(absolute);
  return r;
}

std::vector<Vec3> CandidateSet::polygon(int f) const {
  std::vector<Vec3> pts;
  for (int i : faces[f].v) pts.push_back(vertices[i]);
  return pts;
}

namespace {

// A convex polygon under construction: vertex positions and, per edge i (v[i] -> v[i+1]), the
// id of the other plane whose intersection line carries it.
struct WorkPolygon {
  std::vector<Vec3> p;
  std::vector<int> line;
};

struct PlaneBank {
  std::vector<Plane> all;  // support planes, then the 6 region planes
  Vec3 meet3(int a, int b, int c, const Vec3& fallback) const {
    if (a < 0 || b < 0 || c < 0) return fallback;  // a side of the initial square
    std::array<int, 3> t{a, b, c};
    std::sort(t.begin(), t.end());  // same triple -> bit-identical point, whatever the caller
    const auto x = meet(all[t[0]], all[t[1]], all[t[2]], kMeetMinPivot);
    return x ? *x : fallback;
  }
};

// Splits `poly` (on plane `self`) by plane `cut`; returns the pieces on the negative and the
// positive side (either may be empty).
std::pair<WorkPolygon, WorkPolygon> split(const WorkPolygon& poly, int self, int cut, const PlaneBank& bank) {
  const Plane& pl = bank.all[cut];
  const int n = int(poly.p.size());
  std::vector<double> d(n);
  bool neg = false, pos = false;
  for (int i = 0; i < n; ++i) {
    d[i] = pl.distance(poly.p[i]);
    if (std::abs(d[i]) <= kOnCutPlane) d[i] = 0.0;
    neg |= d[i] < 0;
    pos |= d[i] > 0;
  }
  if (!pos) return {poly, {}};
  if (!neg) return {{}, poly};
  WorkPolygon lo, hi;
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    // Vertex i belongs to the sides it lies on; the edge i->j keeps its line on each side.
    if (d[i] <= 0) { lo.p.push_back(poly.p[i]); lo.line.push_back(poly.line[i]); }
    if (d[i] >= 0) { hi.p.push_back(poly.p[i]); hi.line.push_back(poly.line[i]); }
    if ((d[i] < 0 && d[j] > 0) || (d[i] > 0 && d[j] < 0)) {
      const double t = d[i] / (d[i] - d[j]);
      const Vec3 x = bank.meet3(self, poly.line[i], cut, poly.p[i] + t * (poly.p[j] - poly.p[i]));
      // The piece that continues along edge i->j after x keeps line[i]; the cut edge is `cut`.
      if (d[i] < 0) {
        lo.p.push_back(x); lo.line.push_back(cut);
        hi.p.push_back(x); hi.line.push_back(poly.line[i]);
      } else {
        hi.p.push_back(x); hi.line.push_back(cut);
        lo.p.push_back(x); lo.line.push_back(poly.line[i]);
      }
    }
    if (d[i] == 0.0) {
      // Leaving a vertex on the cut towards the other side: on this side the edge that leaves
      // it runs along the cut line.
      if (d[j] > 0) lo.line.back() = cut;
      if (d[j] < 0) hi.line.back() = cut;
    }
  }
  return {lo, hi};
}

// The plane's section of the region: a large square on the plane clipped by the 6 box planes.
WorkPolygon section(int self, const PlaneBank& bank, const Region& region, int first_box) {
  const Plane& pl = bank.all[self];
  const auto [u, v] = pl.basis();
  const Vec3 c = pl.project(region.center);
  const double r = 4.0 * region.half.norm() + 1.0;
  WorkPolygon w;
  w.p = {c - r * u - r * v, c + r * u - r * v, c + r * u + r * v, c - r * u + r * v};
  w.line = {-1, -1, -1, -1};
  for (int b = 0; b < 6 && w.p.size() >= 3; ++b) w = split(w, self, first_box + b, bank).first;
  return w;
}

}  // namespace

std::vector<Vec3> region_section(const Plane& plane, const Region& region) {
  PlaneBank bank;
  bank.all.push_back(plane);
  for (const auto& b : region.planes()) bank.all.push_back(b);
  WorkPolygon w = section(0, bank, region, 1);
  if (w.p.size() < 3) return {};
  if (newell_normal(w.p).dot(plane.n) < 0) std::reverse(w.p.begin(), w.p.end());
  return w.p;
}

CandidateSet build_candidates(const std::vector<SupportPlane>& planes, const Region& region, double min_area) {
  CandidateSet cs;
  cs.planes = planes;
  cs.region = region;
  PlaneBank bank;
  for (const auto& p : planes) bank.all.push_back(p.plane);
  const int first_box = int(bank.all.size());
  for (const auto& b : region.planes()) bank.all.push_back(b);

  PointWelder welder(kVertexWeld);
  for (int i = 0; i < int(planes.size()); ++i) {
    std::vector<WorkPolygon> pieces{section(i, bank, region, first_box)};
    if (pieces[0].p.size() < 3) continue;
    for (int j = 0; j < int(planes.size()); ++j) {
      if (j == i) continue;
      std::vector<WorkPolygon> next;
      for (const auto& w : pieces) {
        auto [lo, hi] = split(w, i, j, bank);
        if (lo.p.size() >= 3) next.push_back(std::move(lo));
        if (hi.p.size() >= 3) next.push_back(std::move(hi));
      }
      pieces.swap(next);
    }
    for (const auto& w : pieces) {
      if (polygon_area(w.p) < min_area) continue;
      Candidate c;
      c.plane = i;
      for (const auto& x : w.p) c.v.push_back(welder.add(x));
      drop_repeats(c.v);
      if (c.v.size() < 3) continue;
      std::vector<Vec3> poly;
      for (int id : c.v) poly.push_back(welder.points()[id]);
      if (newell_normal(poly).dot(planes[i].plane.n) < 0) std::reverse(c.v.begin(), c.v.end());
      c.area = polygon_area(poly);
      c.centroid = polygon_centroid(poly);
      cs.faces.push_back(std::move(c));
    }
  }
  cs.vertices = welder.points();

  // Where a vertex of one face lies inside another face's edge (several planes meeting at a
  // point along the line), split that edge so that adjacency is exact.
  for (auto& f : cs.faces) {
    std::vector<int> out;
    for (std::size_t k = 0; k < f.v.size(); ++k) {
      const int a = f.v[k], b = f.v[(k + 1) % f.v.size()];
      out.push_back(a);
      for (int x : vertices_on_segment(cs.vertices, a, b, SegmentRule{kVertexWeld, false, kEdgeEndShare})) out.push_back(x);
    }
    f.v = out;
  }

  std::map<std::pair<int, int>, int> edge_index;
  const auto box = region.planes();
  for (int f = 0; f < int(cs.faces.size()); ++f) {
    const auto& v = cs.faces[f].v;
    for (std::size_t k = 0; k < v.size(); ++k) {
      const int a = v[k], b = v[(k + 1) % v.size()];
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto [it, fresh] = edge_index.emplace(key, int(cs.edges.size()));
      if (fresh) {
        CandidateEdge e;
        e.a = key.first;
        e.b = key.second;
        e.length = (cs.vertices[a] - cs.vertices[b]).norm();
        for (int bp = 0; bp < 6; ++bp)
          if (std::abs(box[bp].distance(cs.vertices[a])) < kVertexWeld &&
              std::abs(box[bp].distance(cs.vertices[b])) < kVertexWeld)
            e.box_plane = bp;
        cs.edges.push_back(e);
      }
      cs.edges[it->second].faces.push_back(f);
    }
  }
  return cs;
}

}  // namespace lodrefine
