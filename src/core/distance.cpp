// Point-to-mesh distances on a CGAL AABB tree. The only CGAL-heavy unit the distance needs.
#include "lodrefine/core/distance.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include "lodrefine/base/files.h"
#include "lodrefine/base/geometry.h"

namespace lodrefine {
namespace {

using K = CGAL::Simple_cartesian<double>;
using CgalTriangles = std::vector<K::Triangle_3>;
using Primitive = CGAL::AABB_triangle_primitive<K, CgalTriangles::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

// Triangles whose nearest point is this much farther than the nearest one still count as
// touching it (double rounding in a local frame is ~1e-13 m).
constexpr double kTieTolerance = 1e-7;
constexpr double kMinTriangleArea = 1e-12;
// Slack for the rounding of the bounds that keep a triangle in a search (m, far above it).
constexpr double kRounding = 1e-9;
// The cells of a batch of queries (m) and the most a batch's grid holds.
constexpr double kBatchCell = 1.0;
constexpr double kMaxCells = 1 << 22;
// Meshes of at most this many triangles are searched without the tree (faster for so few).
constexpr std::size_t kFewTriangles = 128;

K::Point_3 to_cgal(const Vec3& p) { return {p.x(), p.y(), p.z()}; }

// Nearest point of a triangle to p (Ericson, Real-Time Collision Detection 5.1.5) and where it
// lies: at a corner (0 a, 1 b, 2 c), on an edge or inside.
enum : int { kOnEdge = 3, kInside = 4 };
struct Closest {
  Vec3 q;
  int at;
};

Closest closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {a, 0};
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {b, 1};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return {a + ab * (d1 / (d1 - d3)), kOnEdge};
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {c, 2};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return {a + ac * (d2 / (d2 - d6)), kOnEdge};
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return {b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))), kOnEdge};
  const double denom = 1.0 / (va + vb + vc);
  return {a + ab * (vb * denom) + ac * (vc * denom), kInside};
}

double corner_angle(const Vec3& at, const Vec3& u, const Vec3& w) {
  const Vec3 e1 = (u - at).normalized(), e2 = (w - at).normalized();
  return std::acos(std::clamp(e1.dot(e2), -1.0, 1.0));
}

// The angle the triangle subtends around its nearest point: 2π inside, π on an edge, the
// corner angle at a vertex.
double angle_at(const Closest& c, const Vec3& a, const Vec3& b, const Vec3& t) {
  switch (c.at) {
    case 0: return corner_angle(a, b, t);
    case 1: return corner_angle(b, t, a);
    case 2: return corner_angle(t, a, b);
    case kOnEdge: return kPi;
  }
  return 2 * kPi;
}

// AABB tree over a mesh's triangles, in a frame shifted to the mesh's first vertex so that
// georeferenced inputs keep their precision.
class SurfaceIndex {
 public:
  explicit SurfaceIndex(const Mesh& mesh) {
    if (!mesh.vertices.empty()) origin_ = mesh.vertices.front().array().floor().matrix();
    for_each_triangle(mesh, [&](const Vec3& a, const Vec3& b, const Vec3& c, int face) {
      Tri t{a - origin_, b - origin_, c - origin_, Vec3::Zero(), face};
      const Vec3 n = (t.b - t.a).cross(t.c - t.a);
      if (0.5 * n.norm() < kMinTriangleArea) return;
      t.n = n.normalized();
      tris_.push_back(t);
      cgal_.emplace_back(to_cgal(t.a), to_cgal(t.b), to_cgal(t.c));
    });
    if (tris_.empty()) throw InputError("mesh " + shown_id(mesh.id) + " has no non-degenerate face");
    tree_.insert(cgal_.cbegin(), cgal_.cend());
    tree_.build();
    tree_.accelerate_distance_queries();
  }
  SurfaceIndex(const SurfaceIndex&) = delete;  // the tree points into cgal_
  SurfaceIndex& operator=(const SurfaceIndex&) = delete;

  using Nearest = MeshDistance::Nearest;

  Nearest nearest(const Vec3& world, bool want_sign) const { return nearest_local(world - origin_, want_sign); }
  double distance(const Vec3& world, bool want_sign) const { return distance_local(world - origin_, want_sign); }

  // The nearest distance for many points at once, and the face nearest() reports: the points
  // fall into cubic cells of kBatchCell, and each cell keeps only the triangles that can be nearest
  // (or tie) anywhere in it.
  std::vector<Nearest> nearest_all(const std::vector<Vec3>& world) const {
    std::vector<Vec3> local;
    local.reserve(world.size());
    for (const auto& w : world) local.push_back(w - origin_);
    CellCandidates cells(*this, local);
    std::vector<Nearest> out;
    out.reserve(world.size());
    std::vector<double> scratch;
    for (const auto& p : local) {
      const std::vector<std::size_t>* candidates = cells.of(p);
      out.push_back(candidates ? nearest_of(p, *candidates, scratch) : nearest_local(p, false));
    }
    return out;
  }

 private:
  struct Tri {
    Vec3 a, b, c, n;
    int face;
  };

  // The AABB tree's nearest triangle to p (an index into tris_).
  std::size_t tree_nearest(const Vec3& p) const {
    return std::size_t(tree_.closest_point_and_primitive(to_cgal(p)).second - cgal_.cbegin());
  }

  // nearest() in the index's frame: the distance to the tree's nearest triangle (signed by the
  // pseudonormal there), the face by nearest_of's rule among the triangles tied with it.
  Nearest nearest_local(const Vec3& p, bool want_sign) const {
    const std::size_t i = tree_nearest(p);
    std::vector<double> scratch;
    Nearest n = nearest_of(p, within(p, i, kTieTolerance), scratch);
    if (want_sign && n.distance != 0.0) {
      const Closest c = closest_on_triangle(p, tris_[i].a, tris_[i].b, tris_[i].c);
      n.distance *= sign_at(p, c, i);
    }
    return n;
  }

  // The distance alone, without the face's tie search.
  double distance_local(const Vec3& p, bool want_sign) const {
    const std::size_t i = tree_nearest(p);
    const Closest c = closest_on_triangle(p, tris_[i].a, tris_[i].b, tris_[i].c);
    const double d = (p - c.q).norm();
    return !want_sign || d == 0.0 ? d : sign_at(p, c, i) * d;
  }

  double distance_to(const Vec3& p, std::size_t t) const {
    return (p - closest_on_triangle(p, tris_[t].a, tris_[t].b, tris_[t].c).q).norm();
  }

  // The triangles within `slack` of the nearest one to p, ascending: on a small mesh all are
  // measured, else the tree's nearest triangle bounds the nearest distance and those in the box
  // of that reach are measured (a Sphere_3 query would miss the triangles wholly inside it).
  std::vector<std::size_t> within(const Vec3& p, double slack) const { return within(p, tree_nearest(p), slack); }
  // The same, with the tree's nearest triangle to p already found.
  std::vector<std::size_t> within(const Vec3& p, std::size_t nearest, double slack) const {
    std::vector<std::size_t> near;
    if (tris_.size() <= kFewTriangles) {
      near.resize(tris_.size());
      for (std::size_t t = 0; t < near.size(); ++t) near[t] = t;
    } else {
      const double r = distance_to(p, nearest) + slack + kRounding;
      std::vector<Primitive::Id> in_box;
      tree_.all_intersected_primitives(CGAL::Bbox_3(p.x() - r, p.y() - r, p.z() - r, p.x() + r, p.y() + r, p.z() + r),
                                       std::back_inserter(in_box));
      for (const auto& id : in_box) near.push_back(std::size_t(id - cgal_.cbegin()));
      std::sort(near.begin(), near.end());
    }
    std::vector<double> d(near.size());
    for (std::size_t k = 0; k < near.size(); ++k) d[k] = distance_to(p, near[k]);
    const double reach = *std::min_element(d.begin(), d.end()) + slack;
    std::vector<std::size_t> out;
    for (std::size_t k = 0; k < near.size(); ++k)
      if (d[k] <= reach) out.push_back(near[k]);
    return out;
  }

  // The nearest distance among `candidates` (triangles holding every one within kTieTolerance of
  // the nearest) and its face. Where several triangles lie within kTieTolerance (a point nearest
  // an edge or a vertex), the one whose plane lies nearest the point: a street point beyond a
  // wall's foot goes to the ground, a point of a flush neighbour's facade beyond a wall's end
  // to that wall. Ties of that go to the first candidate (the lowest triangle).
  Nearest nearest_of(const Vec3& p, const std::vector<std::size_t>& candidates, std::vector<double>& d) const {
    if (d.size() < candidates.size()) d.resize(candidates.size());
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      d[k] = distance_to(p, candidates[k]);
      nearest = std::min(nearest, d[k]);
    }
    std::size_t best = 0;
    double off_plane = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      if (!(d[k] <= nearest + kTieTolerance)) continue;
      const Tri& t = tris_[candidates[k]];
      const double off = std::abs(t.n.dot(p - t.a));
      if (off < off_plane) off_plane = off, best = k;
    }
    return {nearest, tris_[candidates[best]].face};
  }

  // Per cell of kBatchCell, the triangles that can lie within kTieTolerance of the nearest one for
  // some point of the cell: from its centre m (half diagonal h) the nearest triangle is at U,
  // so every point of the cell has one within U + h, and a triangle farther than U + 2h from m
  // is farther than that from every point of the cell.
  class CellCandidates {
   public:
    // A grid over the points' bounding box; none when it would hold more than kMaxCells cells.
    CellCandidates(const SurfaceIndex& index, const std::vector<Vec3>& points) : index_(index) {
      if (points.empty()) return;
      const Eigen::AlignedBox3d box = bounding_box(points);
      if (!box.min().allFinite() || !box.max().allFinite()) return;
      lo_ = (box.min() / kBatchCell).array().floor().matrix();
      const Eigen::Array3d n = (box.max() / kBatchCell).array().floor() - lo_.array() + 1.0;
      if (n.prod() > kMaxCells) return;
      n_ = n.cast<long long>();
      slot_.assign(std::size_t(n.prod()), -1);
    }
    // Null for a point outside the grid.
    const std::vector<std::size_t>* of(const Vec3& p) {
      const Eigen::Array3d c = (p / kBatchCell).array().floor() - lo_.array();
      if (slot_.empty() || !(c >= 0.0).all() || !(c < n_.cast<double>()).all()) return nullptr;
      const std::size_t cell = std::size_t((c.z() * double(n_.y()) + c.y()) * double(n_.x()) + c.x());
      if (slot_[cell] < 0) {
        slot_[cell] = int(lists_.size());
        lists_.push_back(candidates((lo_ + c.matrix() + Vec3::Constant(0.5)) * kBatchCell));
      }
      return &lists_[std::size_t(slot_[cell])];
    }

   private:
    std::vector<std::size_t> candidates(const Vec3& m) const {
      const double h = 0.5 * std::sqrt(3.0) * kBatchCell + kRounding;
      return index_.within(m, 2 * h + kTieTolerance + kRounding);
    }
    const SurfaceIndex& index_;
    Vec3 lo_ = Vec3::Zero();  // the grid's first cell (in cells)
    Eigen::Array<long long, 3, 1> n_ = Eigen::Array<long long, 3, 1>::Zero();
    std::vector<int> slot_;  // per cell of the grid, its list (-1: not yet found)
    std::deque<std::vector<std::size_t>> lists_;
  };

  // Inside a face the face normal decides. On an edge or vertex, the angle-weighted pseudonormal
  // of every triangle touching the nearest point decides (Bærentzen & Aanæs 2005): correct on a
  // closed surface whatever the triangulation, where a single adjacent normal can be wrong.
  double sign_at(const Vec3& p, const Closest& c, std::size_t i) const {
    const double own = tris_[i].n.dot(p - c.q);
    if (c.at == kInside) return own >= 0 ? 1.0 : -1.0;
    const double r = (p - c.q).norm() + kTieTolerance;
    std::vector<Primitive::Id> touching;
    tree_.all_intersected_primitives(K::Sphere_3(to_cgal(p), r * r), std::back_inserter(touching));
    double s = 0.0;
    for (const auto& id : touching) {
      const Tri& t = tris_[std::size_t(id - cgal_.cbegin())];
      const Closest ct = closest_on_triangle(p, t.a, t.b, t.c);
      if ((p - ct.q).norm() <= r) s += angle_at(ct, t.a, t.b, t.c) * t.n.dot(p - ct.q);
    }
    if (s == 0.0) s = own;
    return s >= 0 ? 1.0 : -1.0;
  }

  Vec3 origin_ = Vec3::Zero();
  std::vector<Tri> tris_;
  CgalTriangles cgal_;
  Tree tree_;
};

}  // namespace

struct MeshDistance::Index : SurfaceIndex {
  using SurfaceIndex::SurfaceIndex;
};

MeshDistance::MeshDistance(const Mesh& mesh) : index_(std::make_unique<Index>(mesh)) {}
MeshDistance::~MeshDistance() = default;

MeshDistance::Nearest MeshDistance::nearest(const Vec3& point, bool signed_distance) const {
  return index_->nearest(point, signed_distance);
}

double MeshDistance::distance(const Vec3& point, bool signed_distance) const {
  return index_->distance(point, signed_distance);
}

std::vector<MeshDistance::Nearest> MeshDistance::nearest_all(const std::vector<Vec3>& points) const {
  return index_->nearest_all(points);
}

namespace {

std::vector<double> distances(const Mesh& mesh, const std::vector<Vec3>& points, bool want_sign) {
  const MeshDistance index(mesh);
  std::vector<double> d(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) d[i] = index.distance(points[i], want_sign);
  return d;
}

}  // namespace

// Unlike unsigned_distances, a mesh without faces is refused even for no points.
std::vector<double> cloud_to_mesh(const Mesh& mesh, const std::vector<Vec3>& points) {
  return distances(mesh, points, true);
}

std::vector<double> unsigned_distances(const Mesh& mesh, const std::vector<Vec3>& pts) {
  if (pts.empty()) return {};
  return distances(mesh, pts, false);
}

double rms_distance(const Mesh& mesh, const std::vector<Vec3>& pts) {
  if (pts.empty()) return 0.0;
  double s = 0.0;
  for (double d : cloud_to_mesh(mesh, pts)) s += d * d;
  return std::sqrt(s / double(pts.size()));
}

std::vector<Vec3> sample_faces(const Mesh& mesh, const std::vector<int>& faces, double spacing) {
  std::vector<Vec3> out;
  for (int f : faces) {
    std::vector<Vec3> poly;
    for (int v : mesh.faces.at(f).v) poly.push_back(mesh.vertices.at(v));
    if (poly.size() < 3 || polygon_area(poly) <= 0) continue;
    const auto [u, v] = polygon_plane(poly).basis();
    std::vector<Vec2> p2;
    for (const auto& p : poly) p2.emplace_back((p - poly[0]).dot(u), (p - poly[0]).dot(v));
    const Eigen::AlignedBox2d box = bounding_box(p2);
    const Vec2 lo = box.min(), hi = box.max();
    const std::size_t before = out.size();
    for (double x = lo.x() + 0.5 * spacing; x < hi.x(); x += spacing)
      for (double y = lo.y() + 0.5 * spacing; y < hi.y(); y += spacing)
        if (point_in_polygon_2d(Vec2(x, y), p2)) out.push_back(poly[0] + x * u + y * v);
    if (out.size() == before) out.push_back(polygon_centroid(poly));
  }
  return out;
}

}  // namespace lodrefine
