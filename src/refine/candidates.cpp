// Stage 5, selection (paper Sec. 3.2): candidate faces from pairwise plane intersections in a region.
#include "lodrefine/refine/candidates.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "lodrefine/base/topology.h"

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
// A vertex inside an edge of a face on plane P lies within kVertexWeld of that edge, hence of
// P up to the rounding of the plane meets: 100x the weld is a wide margin for that rounding.
constexpr double kPlaneReach = 100 * kVertexWeld;

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

CandidateMap<int> CandidateSet::supports() const { return candidate_props::support.get(mesh); }
CandidateMap<double> CandidateSet::areas() const { return candidate_props::area.get(mesh); }
CandidateMap<Vec3> CandidateSet::centroids() const { return candidate_props::centroid.get(mesh); }

std::vector<int> CandidateSet::corners(int f) const {
  std::vector<int> out;
  if (f >= size()) return out;
  const auto point = candidate_props::point.get(mesh);
  for (auto h : CGAL::halfedges_around_face(mesh.halfedge(CandidateMesh::Face_index(f)), mesh))
    out.push_back(point[mesh.source(h)]);
  return out;
}

std::vector<Vec3> CandidateSet::polygon(int f) const {
  std::vector<Vec3> pts;
  for (int i : corners(f)) pts.push_back(vertices[i]);
  return pts;
}

std::pair<int, int> CandidateSet::ends(const CandidateEdge& e) const {
  const auto point = candidate_props::point.get(mesh);
  const int s = point[mesh.source(e.front())], t = point[mesh.target(e.front())];
  return {std::min(s, t), std::max(s, t)};
}

double CandidateSet::length(const CandidateEdge& e) const {
  const auto [a, b] = ends(e);
  return (vertices[a] - vertices[b]).norm();
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
    if (d[i] <= 0) {
      lo.p.push_back(poly.p[i]);
      lo.line.push_back(poly.line[i]);
    }
    if (d[i] >= 0) {
      hi.p.push_back(poly.p[i]);
      hi.line.push_back(poly.line[i]);
    }
    if ((d[i] < 0 && d[j] > 0) || (d[i] > 0 && d[j] < 0)) {
      const double t = d[i] / (d[i] - d[j]);
      const Vec3 x = bank.meet3(self, poly.line[i], cut, poly.p[i] + t * (poly.p[j] - poly.p[i]));
      // The piece that continues along edge i->j after x keeps line[i]; the cut edge is `cut`.
      if (d[i] < 0) {
        lo.p.push_back(x);
        lo.line.push_back(cut);
        hi.p.push_back(x);
        hi.line.push_back(poly.line[i]);
      } else {
        hi.p.push_back(x);
        hi.line.push_back(cut);
        lo.p.push_back(x);
        lo.line.push_back(poly.line[i]);
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

// The plane's section of the region: a large square on the plane clipped by the 6 box planes,
// then by those of the local box planes (first_local.. +5; -1: none) that cut into the region
// (`inside[b]`).
WorkPolygon section(int self, const PlaneBank& bank, const Region& region, int first_box, int first_local = -1,
                    const std::array<bool, 6>& inside = {}) {
  const Plane& pl = bank.all[self];
  const auto [u, v] = pl.basis();
  const Vec3 c = pl.project(region.center);
  const double r = 4.0 * region.half.norm() + 1.0;
  WorkPolygon w;
  w.p = {c - r * u - r * v, c + r * u - r * v, c + r * u + r * v, c - r * u + r * v};
  w.line = {-1, -1, -1, -1};
  for (int b = 0; b < 6 && w.p.size() >= 3; ++b) w = split(w, self, first_box + b, bank).first;
  for (int b = 0; first_local >= 0 && b < 6 && w.p.size() >= 3; ++b)
    if (inside[b]) w = split(w, self, first_local + b, bank).first;
  return w;
}

// A plane's local box in the region's frame (coordinates along region.axes), cut to the region.
struct LocalBox {
  Vec3 lo, hi;
  bool meets(const LocalBox& o) const {
    return (lo.array() <= o.hi.array() + kVertexWeld).all() && (o.lo.array() <= hi.array() + kVertexWeld).all();
  }
};
LocalBox local_box(const Region& region, const Region* reach) {
  const Vec3 c = region.axes.transpose() * region.center;
  LocalBox b{c - region.half, c + region.half};
  if (reach == nullptr) return b;
  const Vec3 rc = region.axes.transpose() * reach->center;
  b.lo = b.lo.cwiseMax(rc - reach->half);
  b.hi = b.hi.cwiseMin(rc + reach->half);
  return b;
}
// Its 6 planes in Region::planes() order (+axis, -axis per axis), and which cut into the region.
std::array<Plane, 6> local_planes(const Region& region, const LocalBox& b, std::array<bool, 6>& inside) {
  const Vec3 c = region.axes.transpose() * region.center;
  std::array<Plane, 6> out;
  for (int k = 0; k < 3; ++k) {
    const Vec3 a = region.axes.col(k);
    out[2 * k] = Plane::through(region.axes * c + (b.hi[k] - c[k]) * a, a);
    out[2 * k + 1] = Plane::through(region.axes * c + (b.lo[k] - c[k]) * a, -a);
    inside[2 * k] = b.hi[k] < c[k] + region.half[k] - kOnCutPlane;
    inside[2 * k + 1] = b.lo[k] > c[k] - region.half[k] + kOnCutPlane;
  }
  return out;
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

namespace {

// What a piece carries into its face's maps.
struct Piece {
  int plane = -1;
  double area = 0.0;
  Vec3 centroid = Vec3::Zero();
};

// The pieces as faces of `cs.mesh`, one component per supporting plane (`corners[f]`: piece f's
// corners in `cs.vertices`, its plane pieces[f].plane; pieces come plane by plane). A piece the
// component cannot take (it would make the component non-manifold: overlapping slivers, a corner
// repeated) becomes a component of its own; the fans are by point, so its edges still count.
// Returns per face the halfedge that leaves its first corner.
std::vector<CandidateHalfedge> build_mesh(CandidateSet& cs, const std::vector<Piece>& pieces,
                                          const std::vector<std::vector<int>>& corners) {
  auto support = candidate_props::support.add(cs.mesh);
  auto area = candidate_props::area.add(cs.mesh);
  auto centroid = candidate_props::centroid.add(cs.mesh);
  auto point = candidate_props::point.add(cs.mesh);
  std::vector<CandidateMesh::Vertex_index> of_point(cs.vertices.size());
  std::vector<int> plane_of_vertex(cs.vertices.size(), -1);
  std::vector<CandidateHalfedge> first;
  auto new_vertex = [&](int id) {
    const Vec3& x = cs.vertices[id];
    const auto v = cs.mesh.add_vertex(CandidateMesh::Point(x.x(), x.y(), x.z()));
    point[v] = id;
    return v;
  };
  for (int f = 0; f < int(corners.size()); ++f) {
    const int k = pieces[f].plane;
    std::vector<CandidateMesh::Vertex_index> vs;
    for (int id : corners[f]) {
      if (plane_of_vertex[id] != k) of_point[id] = new_vertex(id), plane_of_vertex[id] = k;
      vs.push_back(of_point[id]);
    }
    auto face = cs.mesh.add_face(vs);
    if (face == CandidateMesh::null_face()) {
      for (auto& v : vs) v = new_vertex(point[v]);
      face = cs.mesh.add_face(vs);
    }
    support[face] = k;
    area[face] = pieces[f].area;
    centroid[face] = pieces[f].centroid;
    first.push_back(cs.mesh.halfedge(vs[0], vs[1]));
  }
  return first;
}

// The fans (CGAL's extract_adjacency): every halfedge of a face, by the points at its ends; the
// edges in order of their first appearance (faces in order, each from its first corner,
// `first`), the halfedges of each in face order.
void build_fans(CandidateSet& cs, const std::vector<CandidateHalfedge>& first) {
  const auto point = candidate_props::point.get(cs.mesh);
  struct Side {
    int a, b;
    CandidateHalfedge h;
  };
  std::vector<Side> sides;  // by order of appearance
  for (const auto h0 : first)
    for (auto h : CGAL::halfedges_around_face(h0, cs.mesh)) {
      const int s = point[cs.mesh.source(h)], t = point[cs.mesh.target(h)];
      sides.push_back({std::min(s, t), std::max(s, t), h});
    }
  std::vector<int> by_end(sides.size());
  std::iota(by_end.begin(), by_end.end(), 0);
  std::stable_sort(by_end.begin(), by_end.end(), [&](int x, int y) {
    return std::tie(sides[x].a, sides[x].b, x) < std::tie(sides[y].a, sides[y].b, y);
  });
  std::vector<std::pair<int, CandidateEdge>> fans;  // first appearance, fan
  for (std::size_t i = 0; i < by_end.size();) {
    const Side& s = sides[by_end[i]];
    CandidateEdge e;
    int appears = by_end[i];
    for (; i < by_end.size() && sides[by_end[i]].a == s.a && sides[by_end[i]].b == s.b; ++i) {
      e.push_back(sides[by_end[i]].h);
      appears = std::min(appears, by_end[i]);
    }
    std::stable_sort(e.begin(), e.end(), [&](auto x, auto y) { return cs.face(x) < cs.face(y); });
    fans.emplace_back(appears, std::move(e));
  }
  std::sort(fans.begin(), fans.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  for (auto& [appears, e] : fans) cs.edges.push_back(std::move(e));
}

// Per support plane, the vertices within kPlaneReach of it, by x: an edge's inside vertices
// are among those within its x range (a plane of a large building holds thousands of vertices).
struct PlaneVertices {
  std::vector<int> ids;   // ascending x
  std::vector<double> x;  // their x

  // The vertices whose x lies within `tol` of segment a-b's x range.
  std::vector<int> near_segment(const Vec3& a, const Vec3& b, double tol) const {
    const auto lo = std::lower_bound(x.begin(), x.end(), std::min(a.x(), b.x()) - tol);
    const auto hi = std::upper_bound(lo, x.end(), std::max(a.x(), b.x()) + tol);
    return {ids.begin() + (lo - x.begin()), ids.begin() + (hi - x.begin())};
  }
};

std::vector<PlaneVertices> vertices_on_planes(const std::vector<Vec3>& V, const std::vector<SupportPlane>& planes) {
  std::vector<PlaneVertices> on(planes.size());
  for (std::size_t i = 0; i < planes.size(); ++i) {
    for (int w = 0; w < int(V.size()); ++w)
      if (std::abs(planes[i].plane.distance(V[w])) <= kPlaneReach) on[i].ids.push_back(w);
    std::sort(on[i].ids.begin(), on[i].ids.end(), [&](int u, int w) { return V[u].x() < V[w].x(); });
    for (int w : on[i].ids) on[i].x.push_back(V[w].x());
  }
  return on;
}

// Where a vertex of one face lies inside another face's edge (several planes meeting at a point
// along the line), that edge is split so that adjacency is exact. Such a vertex lies on the
// face's plane, so only that plane's vertices are tried: trying every vertex for every edge took
// minutes on a large building (thousands of faces).
void split_edges_at_vertices(const std::vector<Vec3>& vertices, const std::vector<SupportPlane>& planes,
                             const std::vector<Piece>& pieces, std::vector<std::vector<int>>& corners) {
  const auto on_plane = vertices_on_planes(vertices, planes);
  for (std::size_t f = 0; f < corners.size(); ++f) {
    auto& v = corners[f];
    std::vector<int> out;
    for (std::size_t k = 0; k < v.size(); ++k) {
      const int a = v[k], b = v[(k + 1) % v.size()];
      out.push_back(a);
      const std::vector<int> near = on_plane[pieces[f].plane].near_segment(vertices[a], vertices[b], kVertexWeld);
      for (int x : vertices_on_segment(vertices, a, b, SegmentRule{kVertexWeld, false, kEdgeEndShare}, &near))
        out.push_back(x);
    }
    v = out;
  }
}

}  // namespace

CandidateSet build_candidates(const std::vector<SupportPlane>& planes, const Region& region, double min_area) {
  return build_candidates(planes, region, {}, std::numeric_limits<int>::max(), min_area);
}

CandidateSet build_candidates(const std::vector<SupportPlane>& planes, const Region& region,
                              const std::vector<Region>& reach, int max_candidates, double min_area) {
  CandidateSet cs;
  cs.planes = planes;
  cs.region = region;
  PlaneBank bank;
  for (const auto& p : planes) bank.all.push_back(p.plane);
  const int first_box = int(bank.all.size());
  for (const auto& b : region.planes()) bank.all.push_back(b);
  // Per plane, its local box and (when given) its 6 planes, after the region's in the bank.
  const int first_local = int(bank.all.size());
  std::vector<LocalBox> boxes;
  std::vector<std::array<bool, 6>> inside(planes.size());
  for (std::size_t i = 0; i < planes.size(); ++i) {
    boxes.push_back(local_box(region, reach.empty() ? nullptr : &reach[i]));
    for (const auto& b : local_planes(region, boxes[i], inside[i])) bank.all.push_back(b);
  }

  PointWelder welder(kVertexWeld);
  std::vector<Piece> kept;
  std::vector<std::vector<int>> corners;  // per piece, in `welder`
  auto over_cap = [&](std::size_t pieces) { return corners.size() + pieces > std::size_t(max_candidates); };
  for (int i = 0; i < int(planes.size()); ++i) {
    const bool local = !reach.empty();
    std::vector<WorkPolygon> pieces{section(i, bank, region, first_box, local ? first_local + 6 * i : -1, inside[i])};
    if (pieces[0].p.size() < 3) continue;
    for (int j = 0; j < int(planes.size()); ++j) {
      if (j == i || !boxes[i].meets(boxes[j])) continue;
      std::vector<WorkPolygon> next;
      for (const auto& w : pieces) {
        auto [lo, hi] = split(w, i, j, bank);
        if (lo.p.size() >= 3) next.push_back(std::move(lo));
        if (hi.p.size() >= 3) next.push_back(std::move(hi));
      }
      pieces.swap(next);
      if (over_cap(pieces.size())) {
        CandidateSet capped;
        capped.planes = planes;
        capped.region = region;
        capped.capped = true;
        return capped;
      }
    }
    for (const auto& w : pieces) {
      if (polygon_area(w.p) < min_area) continue;
      Piece c;
      c.plane = i;
      std::vector<int> v;
      for (const auto& x : w.p) v.push_back(welder.add(x));
      drop_repeats(v);
      if (v.size() < 3) continue;
      std::vector<Vec3> poly;
      for (int id : v) poly.push_back(welder.points()[id]);
      if (newell_normal(poly).dot(planes[i].plane.n) < 0) std::reverse(v.begin(), v.end());
      c.area = polygon_area(poly);
      c.centroid = polygon_centroid(poly);
      kept.push_back(c);
      corners.push_back(std::move(v));
    }
  }
  cs.vertices = welder.points();

  split_edges_at_vertices(cs.vertices, planes, kept, corners);
  build_fans(cs, build_mesh(cs, kept, corners));
  return cs;
}

CandidateSet kept_candidates(const CandidateSet& cs, const std::vector<char>& keep) {
  CandidateSet out;
  out.planes = cs.planes;
  out.region = cs.region;
  out.vertices = cs.vertices;
  const auto support = cs.supports();
  const auto area = cs.areas();
  const auto centroid = cs.centroids();
  std::vector<int> index(cs.size(), -1);
  std::vector<Piece> pieces;
  std::vector<std::vector<int>> corners;
  for (int f = 0; f < cs.size(); ++f) {
    if (!keep[f]) continue;
    index[f] = int(pieces.size());
    const CandidateFace fi(f);
    pieces.push_back({support[fi], area[fi], centroid[fi]});
    corners.push_back(cs.corners(f));
  }
  const std::vector<CandidateHalfedge> first = build_mesh(out, pieces, corners);
  // A kept face's k-th halfedge from its face's halfedge (where corners() starts) is the k-th of
  // its copy from the copy's first corner.
  std::vector<CandidateHalfedge> copy(cs.mesh.number_of_halfedges());
  for (int f = 0; f < cs.size(); ++f) {
    if (index[f] < 0) continue;
    const CandidateHalfedge h0 = cs.mesh.halfedge(CandidateFace(f));
    CandidateHalfedge h = h0, g = first[std::size_t(index[f])];
    do {
      copy[std::size_t(h)] = g;
      h = cs.mesh.next(h);
      g = out.mesh.next(g);
    } while (h != h0);
  }
  for (const auto& e : cs.edges) {
    CandidateEdge k;
    for (auto h : e)
      if (index[cs.face(h)] >= 0) k.push_back(copy[std::size_t(h)]);
    if (!k.empty()) out.edges.push_back(std::move(k));
  }
  return out;
}

}  // namespace lodrefine
