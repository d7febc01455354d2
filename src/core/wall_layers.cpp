// Stage 2, planes, besides the shape detection: the plane fitted to a point set; a wall seen twice by two
// drives is one plane midway; facade planes over only part of a wall's height are relief.
#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "lodrefine/base/geometry.h"
#include "lodrefine/core/planes.h"
#include "wall_layers.h"

namespace lodrefine {
namespace {

// Vertical least-squares plane: PCA of the horizontal coordinates only.
Plane fit_vertical_plane(const std::vector<Vec3>& pts) {
  Vec2 c = Vec2::Zero();
  for (const auto& p : pts) c += p.head<2>();
  c /= double(pts.size());
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const auto& p : pts) {
    const Vec2 q = p.head<2>() - c;
    cov += q * q.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov);
  const Vec2 n2 = es.eigenvectors().col(0);
  return Plane::through(Vec3(c.x(), c.y(), 0.0), Vec3(n2.x(), n2.y(), 0.0));
}

// A facade seen by two drives registered apart: the points near its plane and inside its
// extent, split in two layers by their signed distance (two-means, from the quartiles). The
// layers are two copies of one wall when each holds kMinLayerShare of the points or more, the
// density midway is below kMaxValley of either layer's (two peaks, not a thick or rough wall),
// and the copies overlap over kMinLayerSpan of the longer, along the wall and up it (one
// footprint: not a plinth, a balcony before the wall, or a facade stepping a few cm part-way),
// cell by cell (shared_cells: not a wall and its windows' panes set back in their reveals).
constexpr double kMinLayerShare = 0.2, kMaxValley = 0.4, kMinLayerSpan = 0.6;
// m, and the share of the sparser layer's cells the other must share (one footprint everywhere).
constexpr double kLayerCell = 0.5, kMinSharedCells = 0.7;
// Layers nearer than this many RANSAC epsilons are one thick plane to the detection anyway.
constexpr double kMinLayerGapEpsilons = 1.0;

struct Layers {
  double near = 0.0, far = 0.0;  // centres (signed distances)
  bool doubled = false;
};

// The 5th to 95th percentile of x.
std::pair<double, double> range_of(std::vector<double> x) {
  if (x.size() < 2) return {0.0, 0.0};
  const std::size_t lo = x.size() / 20, hi = x.size() - 1 - x.size() / 20;
  std::nth_element(x.begin(), x.begin() + long(lo), x.end());
  const double a = x[lo];
  std::nth_element(x.begin(), x.begin() + long(hi), x.end());
  return {a, x[hi]};
}

// Whether two ranges overlap over kMinLayerSpan of the longer: one footprint, not two halves.
bool same_extent(const std::pair<double, double>& a, const std::pair<double, double>& b) {
  const double overlap = std::min(a.second, b.second) - std::max(a.first, b.first);
  return overlap >= kMinLayerSpan * std::max(a.second - a.first, b.second - b.first);
}

// The share of the cells (kLayerCell square, in the wall) holding points of the sparser layer
// that hold points of the other too: a wall seen twice is two copies everywhere; a wall and its
// windows' panes set back behind it take turns.
double shared_cells(const std::vector<double>& d, const std::vector<Vec2>& uv, double mid) {
  std::set<std::pair<long long, long long>> near, far;
  for (std::size_t i = 0; i < d.size(); ++i)
    (d[i] < mid ? near : far)
        .emplace((long long)std::floor(uv[i].x() / kLayerCell), (long long)std::floor(uv[i].y() / kLayerCell));
  const auto& fewer = near.size() < far.size() ? near : far;
  const auto& more = near.size() < far.size() ? far : near;
  if (fewer.empty()) return 0.0;
  std::size_t both = 0;
  for (const auto& c : fewer) both += more.count(c);
  return double(both) / double(fewer.size());
}

Layers two_layers(const std::vector<double>& d, const std::vector<Vec2>& uv, double min_gap) {
  Layers out;
  if (d.size() < 20) return out;
  std::vector<double> sorted = d;
  std::sort(sorted.begin(), sorted.end());
  double a = sorted[sorted.size() / 4], b = sorted[3 * sorted.size() / 4];
  for (int it = 0; it < 30; ++it) {
    const double mid = 0.5 * (a + b);
    double sa = 0, sb = 0;
    std::size_t na = 0, nb = 0;
    for (double x : d) (x < mid ? (sa += x, ++na) : (sb += x, ++nb));
    if (na == 0 || nb == 0) return out;
    a = sa / double(na), b = sb / double(nb);
  }
  out.near = a, out.far = b;
  const double gap = b - a, mid = 0.5 * (a + b), half = gap / 6.0;
  if (gap < min_gap) return out;
  std::size_t peak_a = 0, peak_b = 0, valley = 0, na = 0;
  std::vector<double> ua, ub, za, zb;
  for (std::size_t i = 0; i < d.size(); ++i) {
    peak_a += std::abs(d[i] - a) <= half, peak_b += std::abs(d[i] - b) <= half, valley += std::abs(d[i] - mid) <= half;
    if (d[i] < mid) ++na, ua.push_back(uv[i].x()), za.push_back(uv[i].y());
    else ub.push_back(uv[i].x()), zb.push_back(uv[i].y());
  }
  const double share = double(std::min(na, d.size() - na)) / double(d.size());
  out.doubled = share >= kMinLayerShare && double(valley) < kMaxValley * double(std::min(peak_a, peak_b)) &&
                same_extent(range_of(ua), range_of(ub)) && same_extent(range_of(za), range_of(zb)) &&
                shared_cells(d, uv, mid) >= kMinSharedCells;
  return out;
}

}  // namespace

namespace detail {

// The scan plane fitted to `inliers` of `all` (wall_layers.h).
ScanPlane describe_plane(const std::vector<Vec3>& all, std::vector<int> inliers, const PlaneConfig& prm) {
  ScanPlane sp;
  sp.inliers = std::move(inliers);
  std::vector<Vec3> pts;
  pts.reserve(sp.inliers.size());
  for (int i : sp.inliers) pts.push_back(all[i]);
  sp.plane = fit_plane(pts);
  const double tilt = 90.0 - unoriented_angle_deg(sp.plane.n, Vec3::UnitZ());
  sp.facade = tilt <= prm.facade_max_tilt_deg;
  if (tilt <= prm.vertical_snap_deg) sp.plane = fit_vertical_plane(pts);
  double ss = 0.0;
  for (const auto& p : pts) {
    sp.centroid += p;
    ss += sp.plane.distance(p) * sp.plane.distance(p);
  }
  sp.centroid /= double(pts.size());
  sp.rms = std::sqrt(ss / double(pts.size()));
  const auto [u, v] = sp.plane.basis();
  std::vector<Vec2> uv;
  uv.reserve(pts.size());
  for (const auto& p : pts) uv.emplace_back((p - sp.centroid).dot(u), (p - sp.centroid).dot(v));
  sp.hull_area = std::abs(signed_area_2d(convex_hull_2d(std::move(uv))));
  return sp;
}

// Each facade, largest first, that two drives saw apart becomes one plane midway between its
// copies, holding both; the points it takes leave the other planes (the second copy's pieces),
// which are dropped when too few or too small remain.
std::vector<ScanPlane> join_doubled_walls(std::vector<ScanPlane> planes, const std::vector<Vec3>& all,
                                          const PlaneConfig& prm) {
  std::stable_sort(planes.begin(), planes.end(),
                   [](const ScanPlane& a, const ScanPlane& b) { return a.inliers.size() > b.inliers.size(); });
  std::vector<int> owner(all.size(), -1);
  for (int k = 0; k < int(planes.size()); ++k)
    for (int i : planes[std::size_t(k)].inliers) owner[std::size_t(i)] = k;
  std::vector<char> changed(planes.size(), 0), joined_already(planes.size(), 0);
  for (int k = 0; k < int(planes.size()); ++k) {
    ScanPlane& p = planes[std::size_t(k)];
    if (!p.facade || int(p.inliers.size()) < prm.ransac_min_points) continue;
    const auto [u, v] = p.plane.basis();
    Eigen::AlignedBox2d extent;
    for (int i : p.inliers) extent.extend(Vec2(u.dot(all[std::size_t(i)]), v.dot(all[std::size_t(i)])));
    std::vector<int> slab;
    std::vector<double> d;
    std::vector<Vec2> uv;
    for (int i = 0; i < int(all.size()); ++i) {
      const int o = owner[std::size_t(i)];
      // A roof's, the ground's, or a facade's already joined.
      if (o >= 0 && o != k && (!planes[std::size_t(o)].facade || joined_already[std::size_t(o)])) continue;
      const double dist = p.plane.distance(all[std::size_t(i)]);
      const Vec2 q(u.dot(all[std::size_t(i)]), v.dot(all[std::size_t(i)]));
      if (std::abs(dist) > kMaxDoubledWall || !extent.contains(q)) continue;
      slab.push_back(i), d.push_back(dist), uv.push_back(q);
    }
    const Layers layers = two_layers(d, uv, kMinLayerGapEpsilons * prm.ransac_epsilon);
    if (!layers.doubled) continue;
    for (int i : slab)
      if (owner[std::size_t(i)] != k && owner[std::size_t(i)] >= 0) changed[std::size_t(owner[std::size_t(i)])] = 1;
    for (int i : slab) owner[std::size_t(i)] = k;
    ScanPlane joined = detail::describe_plane(all, slab, prm);
    // Midway between the copies, whatever their point counts (the far lane's drive sees fewer).
    double near = 0, far = 0;
    std::size_t nn = 0, nf = 0;
    const double mid = 0.5 * (layers.near + layers.far);
    for (std::size_t j = 0; j < slab.size(); ++j) {
      const double x = joined.plane.distance(all[std::size_t(slab[j])]);
      (d[j] < mid ? (near += x, ++nn) : (far += x, ++nf));
    }
    joined.plane.d -= 0.5 * (near / double(nn) + far / double(nf));
    joined.doubled = layers.far - layers.near;
    double ss = 0;
    for (std::size_t j = 0; j < slab.size(); ++j) {
      const double x = d[j] - (d[j] < mid ? layers.near : layers.far);
      ss += x * x;
    }
    joined.rms = std::sqrt(ss / double(slab.size()));
    p = std::move(joined);
    changed[std::size_t(k)] = 0;
    joined_already[std::size_t(k)] = 1;
  }
  std::vector<ScanPlane> out;
  for (int k = 0; k < int(planes.size()); ++k) {
    ScanPlane& p = planes[std::size_t(k)];
    if (!changed[std::size_t(k)]) {
      out.push_back(std::move(p));
      continue;
    }
    std::vector<int> kept;
    for (int i : p.inliers)
      if (owner[std::size_t(i)] == k) kept.push_back(i);
    if (int(kept.size()) < std::max(3, prm.ransac_min_points)) continue;
    ScanPlane left = detail::describe_plane(all, std::move(kept), prm);
    if (left.hull_area >= prm.min_plane_area) out.push_back(std::move(left));
  }
  return out;
}

}  // namespace detail

void collapse_doubled_walls(PointCloud& cloud, const std::vector<ScanPlane>& planes) {
  for (const ScanPlane& p : planes) {
    if (p.doubled <= 0) continue;
    for (int i : p.inliers) {
      Vec3& q = cloud.points[std::size_t(i)];
      q -= std::copysign(0.5 * p.doubled, p.plane.distance(q)) * p.plane.n;
    }
  }
}

namespace {

// A model wall as the relief test sees it: its plane, horizontal direction, extent along it, and
// its foot and eave.
struct ModelWall {
  Plane plane;
  Vec3 u;
  double a, b, foot, eave;
};

std::vector<ModelWall> model_walls(const Mesh& model, double max_tilt_deg) {
  std::vector<ModelWall> out;
  for (const auto& f : model.faces) {
    const auto poly = face_points(model, f);
    if (poly.size() < 3) continue;
    const Plane pl = polygon_plane(poly);
    if (90.0 - unoriented_angle_deg(pl.n, Vec3::UnitZ()) > max_tilt_deg) continue;
    ModelWall w{pl, along_wall(pl.n).normalized(), 1e300, -1e300, 1e300, -1e300};
    for (const auto& p : poly) w.a = std::min(w.a, w.u.dot(p)), w.b = std::max(w.b, w.u.dot(p));
    for (const auto& p : poly) {
      w.foot = std::min(w.foot, p.z());
      const double t = w.u.dot(p);
      if (t < w.a + 0.05 || t > w.b - 0.05) w.eave = std::max(w.eave, p.z());
    }
    if (w.b - w.a > 0.1 && w.eave > w.foot + kHeightBin) out.push_back(w);
  }
  return out;
}

// Whether the plane's inliers beside the wall (within its extent along the street) stand as a
// wall does: the height bins they fill span kMinWallSpan of the wall's, from the lowest to the
// highest; nullopt when none stands beside it.
std::optional<bool> stands_as_wall(const ModelWall& w, const ScanPlane& p, const PointCloud& cloud) {
  const int bins = std::max(1, int(std::ceil((w.eave - w.foot) / kHeightBin)));
  int first = bins, last = -1;
  bool beside = false;
  for (int i : p.inliers) {
    const Vec3& q = cloud.points[std::size_t(i)];
    const double t = w.u.dot(q);
    if (t < w.a || t > w.b) continue;
    beside = true;
    const int bin = int(std::floor((q.z() - w.foot) / kHeightBin));
    if (bin >= 0 && bin < bins) first = std::min(first, bin), last = std::max(last, bin);
  }
  if (!beside) return std::nullopt;
  return last >= first && double(last - first + 1) >= kMinWallSpan * double(bins);
}

}  // namespace

std::vector<ScanPlane> without_relief(std::vector<ScanPlane> planes, const Mesh& model, const PointCloud& cloud,
                                      const PlaneConfig& prm, std::vector<ScanPlane>* relief) {
  const auto walls = model_walls(model, prm.facade_max_tilt_deg);
  std::vector<ScanPlane> out;
  for (auto& p : planes) {
    bool beside = false, wall = false;  // beside a parallel model wall, and standing as one there
    if (p.facade)
      for (const auto& w : walls)
        if (unoriented_angle_deg(w.plane.n, p.plane.n) <= prm.facade_max_tilt_deg &&
            std::abs(w.plane.distance(p.centroid)) <= kReliefDepth)
          if (const auto stands = stands_as_wall(w, p, cloud)) beside = true, wall = wall || *stands;
    if (!beside || wall) out.push_back(std::move(p));
    else if (relief) relief->push_back(std::move(p));
  }
  return out;
}

}  // namespace lodrefine
