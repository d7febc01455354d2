// Stage 1. The only translation unit with CGAL's shape detection: keep it that way, it is the
// slowest to compile.
#include "lodrefine/core/planes.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Random.h>
#include <CGAL/Shape_detection/Efficient_RANSAC.h>
#include <CGAL/pca_estimate_normals.h>
#include <CGAL/property_map.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <tuple>

// City files refine buildings on several threads: CGAL's default random generator must then be
// thread-local, which it is only with CGAL_HAS_THREADS.
#ifndef CGAL_HAS_THREADS
#error "lodrefine refines buildings on several threads: CGAL must be configured with CGAL_HAS_THREADS"
#endif

namespace lodrefine {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Vector = Kernel::Vector_3;
// Efficient RANSAC reorders its input: each point carries its index in the cloud.
using PointWithNormal = std::tuple<Point, Vector, int>;
using PointList = std::vector<PointWithNormal>;
using PointMap = CGAL::Nth_of_tuple_property_map<0, PointWithNormal>;
using NormalMap = CGAL::Nth_of_tuple_property_map<1, PointWithNormal>;
using Traits = CGAL::Shape_detection::Efficient_RANSAC_traits<Kernel, PointList, PointMap, NormalMap>;
using Ransac = CGAL::Shape_detection::Efficient_RANSAC<Traits>;
using RansacPlane = CGAL::Shape_detection::Plane<Traits>;

// RANSAC pieces of one facade are merged when their normals are within kMergeAngleDeg and each
// one's points lie on average within kMergeEpsilons RANSAC epsilons of the other's plane (one
// epsilon bounds an inlier; two allow for both planes' fitting error).
constexpr double kMergeAngleDeg = 2.0;
constexpr double kMergeEpsilons = 2.0;
// A cloud spanning fewer RANSAC epsilons than this has no planes to find.
constexpr double kMinExtentEpsilons = 10.0;
// Bits per axis of a voxel key (three in a 64-bit key).
constexpr int kVoxelKeyBits = 21;

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

ScanPlane describe(const std::vector<Vec3>& all, std::vector<int> inliers, const PlaneConfig& prm) {
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

// RANSAC's connectivity split one facade into pieces wherever a gap (a window column, an
// occluding tree) is wider than the cluster epsilon: the pieces of one plane are one surface.
std::vector<ScanPlane> merge_coplanar(std::vector<ScanPlane> planes, const std::vector<Vec3>& all,
                                      const PlaneConfig& prm) {
  const double tol = kMergeEpsilons * prm.ransac_epsilon;
  auto mean_distance = [&](const ScanPlane& a, const Plane& b) {
    double s = 0.0;
    for (int i : a.inliers) s += std::abs(b.distance(all[i]));
    return s / double(a.inliers.size());
  };
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t i = 0; i < planes.size() && !merged; ++i)
      for (std::size_t j = i + 1; j < planes.size() && !merged; ++j) {
        if (unoriented_angle_deg(planes[i].plane.n, planes[j].plane.n) > kMergeAngleDeg) continue;
        if (mean_distance(planes[j], planes[i].plane) > tol || mean_distance(planes[i], planes[j].plane) > tol)
          continue;
        std::vector<int> inl = planes[i].inliers;
        inl.insert(inl.end(), planes[j].inliers.begin(), planes[j].inliers.end());
        planes[i] = describe(all, std::move(inl), prm);
        planes.erase(planes.begin() + long(j));
        merged = true;
      }
  }
  return planes;
}

}  // namespace

std::vector<ScanPlane> detect_planes(const PointCloud& cloud, const PlaneConfig& prm) {
  std::vector<ScanPlane> result;
  const std::size_t n = cloud.points.size();
  if (n < std::size_t(std::max(prm.ransac_min_points, prm.normal_neighbors + 1))) return result;

  // Exact duplicates carry no shape and make RANSAC's octree loop forever (a cloud of one
  // repeated point hangs it): detect on distinct points, and only with a real extent.
  std::vector<int> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = int(i);
  auto less = [&](int a, int b) {
    const auto &p = cloud.points[a], &q = cloud.points[b];
    return std::tie(p.x(), p.y(), p.z()) < std::tie(q.x(), q.y(), q.z());
  };
  std::sort(order.begin(), order.end(), less);
  order.erase(std::unique(order.begin(), order.end(), [&](int a, int b) { return cloud.points[a] == cloud.points[b]; }),
              order.end());
  if (order.size() < std::size_t(std::max(prm.ransac_min_points, prm.normal_neighbors + 1))) return result;
  const Eigen::AlignedBox3d box = bounding_box(cloud.points, order);
  const Vec3 lo = box.min(), hi = box.max();
  if ((hi - lo).norm() < kMinExtentEpsilons * prm.ransac_epsilon) return result;
  std::sort(order.begin(), order.end());  // file order: keeps runs reproducible as before
  // Detection runs on one point per voxel (its cost grows with the points, not the facade
  // area); every point of a voxel whose representative a plane took, and that lies within
  // epsilon of that plane, is the plane's inlier.
  const double voxel = prm.detect_voxel;
  auto key = [&](const Vec3& p) -> std::uint64_t {
    if (voxel <= 0) return 0;
    const Vec3 q = (p - lo) / voxel;
    return (std::uint64_t(q.x()) << (2 * kVoxelKeyBits)) | (std::uint64_t(q.y()) << kVoxelKeyBits) |
           std::uint64_t(q.z());
  };
  std::vector<int> reps;  // indices into the cloud
  std::unordered_map<std::uint64_t, int> voxel_rep;
  if (voxel > 0 && ((hi - lo) / voxel).maxCoeff() < double(1 << kVoxelKeyBits)) {
    for (int i : order)
      if (voxel_rep.emplace(key(cloud.points[i]), int(reps.size())).second) reps.push_back(i);
  } else {
    reps = order;
  }
  if (reps.size() < std::size_t(std::max(prm.ransac_min_points, prm.normal_neighbors + 1))) return result;
  PointList pts;
  pts.reserve(reps.size());
  for (int i : reps) {
    const auto& p = cloud.points[i];
    pts.emplace_back(Point(p.x(), p.y(), p.z()), Vector(0, 0, 0), i);
  }
  CGAL::pca_estimate_normals<CGAL::Sequential_tag>(pts, prm.normal_neighbors,
                                                   CGAL::parameters::point_map(PointMap()).normal_map(NormalMap()));

  // Efficient RANSAC draws from CGAL's default generator: seed it for reproducible runs. The
  // generator is thread-local (CGAL_HAS_THREADS), so buildings refined at once do not share it.
  CGAL::get_default_random() = CGAL::Random(static_cast<unsigned>(prm.seed));
  Ransac ransac;
  ransac.set_input(pts);
  ransac.add_shape_factory<RansacPlane>();
  Ransac::Parameters rp;
  rp.probability = prm.ransac_probability;
  // min_points counts points of the full cloud: scaled to the voxel representatives.
  rp.min_points =
      std::max<std::size_t>(std::size_t(prm.normal_neighbors) + 1,
                            std::size_t(double(prm.ransac_min_points) * double(reps.size()) / double(order.size())));
  rp.epsilon = prm.ransac_epsilon;
  rp.cluster_epsilon = prm.ransac_cluster_epsilon;
  rp.normal_threshold = std::cos(radians(prm.ransac_normal_deg));
  ransac.detect(rp);

  // Efficient RANSAC reorders `pts`: a representative is found by its cloud index, not by k.
  std::unordered_map<int, int> rep_position;
  if (!voxel_rep.empty())
    for (int r = 0; r < int(reps.size()); ++r) rep_position.emplace(reps[r], r);
  std::vector<int> rep_shape(reps.size(), -1);
  int shape_id = 0;
  std::vector<std::vector<int>> shape_inliers;
  for (const auto& shape : ransac.shapes()) {
    std::vector<int> inl;
    for (std::size_t k : shape->indices_of_assigned_points()) {
      inl.push_back(std::get<2>(pts[k]));
      if (!voxel_rep.empty()) rep_shape[rep_position.at(std::get<2>(pts[k]))] = shape_id;
    }
    shape_inliers.push_back(std::move(inl));
    ++shape_id;
  }
  if (!voxel_rep.empty()) {
    // Back to the full cloud: each shape takes the points of its voxels near its plane.
    std::vector<Plane> fitted;
    for (const auto& inl : shape_inliers) {
      std::vector<Vec3> q;
      for (int i : inl) q.push_back(cloud.points[i]);
      fitted.push_back(q.size() >= 3 ? fit_plane(q) : Plane());
    }
    for (auto& inl : shape_inliers) inl.clear();
    for (int i = 0; i < int(n); ++i) {
      const auto it = voxel_rep.find(key(cloud.points[i]));
      if (it == voxel_rep.end()) continue;
      const int sh = rep_shape[it->second];
      if (sh >= 0 && std::abs(fitted[sh].distance(cloud.points[i])) <= prm.ransac_epsilon)
        shape_inliers[sh].push_back(i);
    }
  }
  for (auto& inl : shape_inliers) {
    if (inl.size() < 3) continue;
    ScanPlane sp = describe(cloud.points, std::move(inl), prm);
    if (sp.hull_area >= prm.min_plane_area) result.push_back(std::move(sp));
  }
  result = merge_coplanar(std::move(result), cloud.points, prm);
  // Largest first: later stages prefer well-supported planes on ties.
  std::stable_sort(result.begin(), result.end(),
                   [](const ScanPlane& a, const ScanPlane& b) { return a.inliers.size() > b.inliers.size(); });
  return result;
}

}  // namespace lodrefine
