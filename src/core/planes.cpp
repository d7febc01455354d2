// Stage 2, planes. The only translation unit with CGAL's shape detection: keep it that way, it is the
// slowest to compile.
#include "lodrefine/core/planes.h"
#include "wall_layers.h"

#include <CGAL/Eigen_diagonalize_traits.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Random.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Shape_detection/Efficient_RANSAC.h>
#include <CGAL/Shape_detection/Region_growing/Region_growing.h>
#include <CGAL/Shape_detection/Region_growing/Region_growing_on_point_set.h>
#include <CGAL/linear_least_squares_fitting_3.h>
#include <CGAL/property_map.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <tuple>
#include <unordered_map>

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
using KnnSearch = CGAL::Orthogonal_k_neighbor_search<CGAL::Search_traits_3<Kernel>>;
using KdTree = KnnSearch::Tree;

// RANSAC pieces of one facade are merged when their normals are within kMergeAngleDeg and each
// one's points lie on average within kMergeEpsilons RANSAC epsilons of the other's plane (one
// epsilon bounds an inlier; two allow for both planes' fitting error).
constexpr double kMergeAngleDeg = 2.0;
constexpr double kMergeEpsilons = 2.0;
// A cloud spanning fewer RANSAC epsilons than this has no planes to find.
constexpr double kMinExtentEpsilons = 10.0;
// Bits per axis of a voxel key (three in a 64-bit key).
constexpr int kVoxelKeyBits = 21;

using detail::describe_plane;

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
        planes[i] = describe_plane(all, std::move(inl), prm);
        planes.erase(planes.begin() + long(j));
        merged = true;
      }
  }
  return planes;
}

// The fewest points a cloud needs before detection is tried.
std::size_t min_cloud_points(const PlaneConfig& prm) {
  return std::size_t(std::max(prm.ransac_min_points, prm.normal_neighbors + 1));
}

// Whether a cloud of `distinct` distinct points can hold a plane: enough of them, spanning enough.
bool holds_planes(const PointCloud& cloud, std::size_t distinct, const PlaneConfig& prm) {
  return distinct >= min_cloud_points(prm) &&
         bounding_box(cloud.points).diagonal().norm() >= kMinExtentEpsilons * prm.ransac_epsilon;
}

// Exact duplicates carry no shape and make RANSAC's octree loop forever (a cloud of one repeated
// point hangs it). The cloud's distinct points in file order (which keeps runs reproducible), or
// none when they are too few or span too little to hold a plane.
std::vector<int> distinct_points(const PointCloud& cloud, const PlaneConfig& prm) {
  // Sorted with their indices, not as indices into the cloud: the comparisons read memory in
  // order. std::sort decides only by the comparisons, so the copies kept are the same as with
  // an index sort by the same key.
  struct Indexed {
    Vec3 p;
    int i;
  };
  std::vector<Indexed> sorted(cloud.points.size());
  for (std::size_t i = 0; i < sorted.size(); ++i) sorted[i] = {cloud.points[i], int(i)};
  std::sort(sorted.begin(), sorted.end(), [](const Indexed& a, const Indexed& b) {
    return std::tie(a.p.x(), a.p.y(), a.p.z()) < std::tie(b.p.x(), b.p.y(), b.p.z());
  });
  sorted.erase(std::unique(sorted.begin(), sorted.end(), [](const Indexed& a, const Indexed& b) { return a.p == b.p; }),
               sorted.end());
  if (!holds_planes(cloud, sorted.size(), prm)) return {};
  // Back to file order without a second sort.
  std::vector<char> kept(cloud.points.size(), 0);
  for (const auto& s : sorted) kept[std::size_t(s.i)] = 1;
  std::vector<int> order;
  order.reserve(sorted.size());
  for (std::size_t i = 0; i < kept.size(); ++i)
    if (kept[i]) order.push_back(int(i));
  return order;
}

// Voxel key -> position in reps, by open addressing: the region growing looks up the 26
// neighbours of every representative, where std::unordered_map's lookups cost more than the
// growing itself.
class VoxelIndex {
 public:
  void reserve(std::size_t n) {
    std::size_t capacity = 16;
    for (shift_ = 60; capacity < 2 * n; --shift_) capacity *= 2;
    keys_.assign(capacity, kEmpty);
    values_.assign(capacity, -1);
  }
  // The value of `key`, set to `value` when the key is new; and whether it was.
  std::pair<int, bool> emplace(std::uint64_t key, int value) {
    std::size_t i = slot(key);
    for (; keys_[i] != kEmpty; i = (i + 1) & (keys_.size() - 1))
      if (keys_[i] == key) return {values_[i], false};
    keys_[i] = key;
    values_[i] = value;
    return {value, true};
  }
  // The value of `key`, -1 when absent.
  int find(std::uint64_t key) const {
    if (keys_.empty()) return -1;
    for (std::size_t i = slot(key); keys_[i] != kEmpty; i = (i + 1) & (keys_.size() - 1))
      if (keys_[i] == key) return values_[i];
    return -1;
  }

 private:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t(0);  // no key: keys use 63 bits
  std::size_t slot(std::uint64_t key) const {                 // Fibonacci hashing: the high bits of key * 2^64/phi
    return std::size_t((key * 0x9E3779B97F4A7C15ull) >> shift_);
  }
  int shift_ = 60;  // 64 - log2 of the capacity
  std::vector<std::uint64_t> keys_;
  std::vector<int> values_;
};

// The cloud grouped by voxel, one representative point per voxel: detection's cost grows with
// the points, not with the facade area, so a dense scan is thinned to the voxel size before
// detection. The groups serve the take-back without a second hashing.
struct Thinning {
  Vec3 lo = Vec3::Zero();
  double size = 0.0;          // voxel edge (m); 0: no thinning
  std::vector<int> reps;      // cloud indices: each voxel's first point, voxels in file order
  std::vector<int> voxel_of;  // per cloud point, its voxel (position in reps)
  std::vector<int> first;     // voxel v holds members[first[v] .. first[v + 1])
  std::vector<int> members;   // cloud indices by voxel, copies of a point adjacent
  std::vector<char> copy;     // per member: an exact copy of the member before it
  std::size_t distinct = 0;   // points that are not copies

  bool thinned() const { return size > 0.0; }
  // The cloud indices of the points that are not copies, voxel by voxel.
  std::vector<int> non_copies() const {
    std::vector<int> out;
    out.reserve(distinct);
    for (std::size_t m = 0; m < members.size(); ++m)
      if (!copy[m]) out.push_back(members[m]);
    return out;
  }
  Eigen::Array3i cell(const Vec3& p) const { return ((p - lo) / size).array().floor().cast<int>(); }
  static std::uint64_t key(const Eigen::Array3i& c) {
    return (std::uint64_t(c.x()) << (2 * kVoxelKeyBits)) | (std::uint64_t(c.y()) << kVoxelKeyBits) |
           std::uint64_t(c.z());
  }
  // The voxel (position in reps) of cell c, or -1 when no point lies in it.
  int voxel_at(const Eigen::Array3i& c) const {
    if ((c < 0).any() || (c >= (1 << kVoxelKeyBits)).any()) return -1;
    return voxel_id.find(key(c));
  }

  VoxelIndex voxel_id;  // voxel key -> position in reps
};

// The voxel edge detection thins to: detect_voxel when set, none when 0, else (negative) the
// largest voxel at which a plane of min_plane_area still holds normal_neighbors + 1
// representatives, the fewest a thinned plane may have (detection_min_points). RANSAC's time
// grows with the representatives; the take-back and the PCA normals read the full cloud.
// ransac_cluster_epsilon / sqrt 2 (0.18 m, the voxel that kept RANSAC's connectivity as it was)
// spent 40 % of a real dev tile building's time here; sqrt(1 / 13) = 0.28 m scores the same on
// the dev tiles; at 0.4 m one real building had a wall fewer moved (truth facade 0.014 -> 0.060 m).
double detection_voxel(const PlaneConfig& prm) {
  if (prm.detect_voxel >= 0.0) return prm.detect_voxel;
  return std::sqrt(prm.min_plane_area / double(prm.normal_neighbors + 1));
}

// The cloud grouped by voxels of `voxel` (no thinning when 0 or when the grid would not fit the
// key). Copies of a point are found within their voxel, by sorting it.
Thinning thin_to_voxels(const PointCloud& cloud, double voxel) {
  Thinning t;
  const Eigen::AlignedBox3d box = bounding_box(cloud.points);
  if (voxel <= 0 || (box.diagonal() / voxel).maxCoeff() >= double((1 << kVoxelKeyBits) - 1)) return t;
  t.lo = box.min();
  t.size = voxel;
  const int n = int(cloud.points.size());
  t.voxel_of.resize(std::size_t(n));
  t.voxel_id.reserve(std::size_t(n));
  for (int i = 0; i < n; ++i) {
    const auto [v, added] = t.voxel_id.emplace(Thinning::key(t.cell(cloud.points[i])), int(t.reps.size()));
    if (added) t.reps.push_back(i);
    t.voxel_of[i] = v;
  }
  t.first.assign(t.reps.size() + 1, 0);
  for (int v : t.voxel_of) ++t.first[std::size_t(v) + 1];
  for (std::size_t v = 0; v < t.reps.size(); ++v) t.first[v + 1] += t.first[v];
  t.members.resize(std::size_t(n));
  std::vector<int> next(t.first.begin(), t.first.end() - 1);
  for (int i = 0; i < n; ++i) t.members[std::size_t(next[t.voxel_of[i]]++)] = i;
  t.copy.assign(std::size_t(n), 0);
  auto less = [&](int a, int b) {
    const auto &p = cloud.points[a], &q = cloud.points[b];
    return std::tie(p.x(), p.y(), p.z(), a) < std::tie(q.x(), q.y(), q.z(), b);
  };
  for (std::size_t v = 0; v < t.reps.size(); ++v) {
    std::sort(t.members.begin() + t.first[v], t.members.begin() + t.first[v + 1], less);
    for (int m = t.first[v] + 1; m < t.first[v + 1]; ++m)
      t.copy[std::size_t(m)] = cloud.points[t.members[m]] == cloud.points[t.members[m - 1]];
  }
  t.distinct = std::size_t(std::count(t.copy.begin(), t.copy.end(), 0));
  return t;
}

// The least inliers of a plane in the thinned cloud: ransac_min_points scaled by the share of
// points kept, so RANSAC's work per point stays that of the full cloud. Planes with fewer than
// ransac_min_points points after the take-back are dropped.
std::size_t detection_min_points(const Thinning& t, std::size_t distinct, const PlaneConfig& prm) {
  const double kept = double(t.reps.size()) / double(distinct);
  return std::max(std::size_t(prm.normal_neighbors) + 1, std::size_t(double(prm.ransac_min_points) * kept));
}

// Representatives of neighbouring voxels on a plane lie about a voxel diagonal apart: the thinned
// cloud's inliers are connected at that distance or ransac_cluster_epsilon, whichever is larger.
double detection_cluster_epsilon(const Thinning& t, const PlaneConfig& prm) {
  return std::max(prm.ransac_cluster_epsilon, std::sqrt(2.0) * t.size);
}

Vec3 to_vec(const Point& p) { return {p.x(), p.y(), p.z()}; }
Vec3 unit(const Vector& v) { return Vec3(v.x(), v.y(), v.z()).normalized(); }  // zero stays zero

// The representatives with their normals, PCA of their k nearest distinct points of the full
// cloud (a CGAL kd-tree over those): the same neighbourhoods as without thinning. Normals of the
// thinned cloud itself span several voxels and blur at a corner, where RANSAC then found a
// diagonal plane through the two walls' edges (topo dev tile, TOPO0014 at 0.1 m: 151 points, 25°
// off the front wall). Each point carries its cloud index (Efficient RANSAC reorders them) and
// its neighbourhood's planarity (CGAL's fitting quality, 1 - the least eigenvalue over the middle
// one), which orders the region growing's seeds.
struct Representatives {
  PointList pts;
  std::vector<double> planarity;
  // Thinned, for the growing: representative i's neighbourhood lies in voxels
  // knn_voxels[knn_first[i] .. knn_first[i + 1]).
  std::vector<int> knn_first{0}, knn_voxels;
};

Representatives representatives(const PointCloud& cloud, const Thinning& t, const PlaneConfig& prm) {
  Representatives r;
  r.pts.reserve(t.reps.size());
  r.planarity.reserve(t.reps.size());
  std::vector<Point> all;
  for (int i : t.thinned() ? t.non_copies() : t.reps)
    all.emplace_back(cloud.points[i].x(), cloud.points[i].y(), cloud.points[i].z());
  const KdTree tree(all.begin(), all.end());
  std::vector<Point> near;
  Kernel::Plane_3 fitted;
  Point centroid;
  for (int i : t.reps) {
    const Point p(cloud.points[i].x(), cloud.points[i].y(), cloud.points[i].z());
    near.clear();
    const KnnSearch search(tree, p, unsigned(prm.normal_neighbors), 0.0, true, KnnSearch::Distance(),
                           false);  // unsorted: the fit needs no order
    for (const auto& [q, d2] : search) near.push_back(q);
    if (t.thinned() && !prm.ransac) {  // the growing's neighbours
      for (const Point& q : near) r.knn_voxels.push_back(t.voxel_at(t.cell(to_vec(q))));
      r.knn_first.push_back(int(r.knn_voxels.size()));
    }
    // As CGAL::pca_estimate_normals fits each neighbourhood.
    const double quality =
        CGAL::linear_least_squares_fitting_3(near.begin(), near.end(), fitted, centroid, CGAL::Dimension_tag<0>(),
                                             Kernel(), CGAL::Eigen_diagonalize_traits<double, 3>());
    r.pts.emplace_back(p, fitted.orthogonal_vector(), i);
    r.planarity.push_back(std::isfinite(quality) ? quality : -1.0);
  }
  return r;
}

// The growing's neighbours of a representative: the representatives of the 26 voxels around and
// of the voxels holding its normal's neighbourhood (on a sparse scan a neighbour's voxel may lie
// two voxels away), within `reach` (RANSAC's cluster epsilon: the gap one shape may span).
struct VoxelNeighbours {
  const Representatives& r;
  const Thinning& t;
  double reach;
  void operator()(std::size_t i, std::vector<std::size_t>& out) const {
    const Point& p = std::get<0>(r.pts[i]);
    auto take = [&](int v) {
      if (v >= 0 && std::size_t(v) != i &&
          CGAL::squared_distance(p, std::get<0>(r.pts[std::size_t(v)])) <= reach * reach)
        out.push_back(std::size_t(v));
    };
    const Eigen::Array3i c = t.cell(to_vec(p));
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) take(t.voxel_at(c + Eigen::Array3i(dx, dy, dz)));
    for (int k = r.knn_first[i]; k < r.knn_first[i + 1]; ++k) take(r.knn_voxels[std::size_t(k)]);
  }
};

// A region of the growing (CGAL's RegionType): a point joins when within ransac_epsilon of the
// region's least-squares plane and its normal within ransac_normal_deg of the plane's, as a
// RANSAC inlier. The plane comes from running sums (a region only grows until the next seed):
// a refit costs the points added, where CGAL's Least_squares_plane_fit_region copies and refits
// the whole region at every step of the growing.
class PlaneRegion {
 public:
  PlaneRegion(const PointList& pts, std::size_t min_points, const PlaneConfig& prm)
      : pts_(pts),
        epsilon_(prm.ransac_epsilon),
        cos_normal_(std::cos(radians(prm.ransac_normal_deg))),
        min_points_(min_points) {}
  bool is_part_of_region(std::size_t, std::size_t q, const std::vector<std::size_t>&) const {
    return std::abs(n_.dot(to_vec(std::get<0>(pts_[q])) - origin_) - offset_) <= epsilon_ &&
           std::abs(unit(std::get<1>(pts_[q])).dot(n_)) >= cos_normal_;
  }
  bool is_valid_region(const std::vector<std::size_t>& r) const { return r.size() >= min_points_; }
  void update(const std::vector<std::size_t>& r) {
    if (r.size() == 1) {  // a new seed: its own normal until three points fit a plane
      origin_ = to_vec(std::get<0>(pts_[r[0]]));
      n_ = unit(std::get<1>(pts_[r[0]]));
      offset_ = 0.0;
      sum_.setZero();
      outer_.setZero();
      count_ = 0;
    }
    for (; count_ < r.size(); ++count_) {
      const Vec3 d = to_vec(std::get<0>(pts_[r[count_]])) - origin_;
      sum_ += d;
      outer_ += d * d.transpose();
    }
    if (count_ < 3) return;
    const Vec3 mean = sum_ / double(count_);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(outer_ / double(count_) - mean * mean.transpose());
    n_ = es.eigenvectors().col(0);
    offset_ = n_.dot(mean);
  }

 private:
  const PointList& pts_;
  double epsilon_, cos_normal_;
  std::size_t min_points_;
  Vec3 origin_ = Vec3::Zero(), n_ = Vec3::Zero(), sum_ = Vec3::Zero();  // origin_: the seed
  double offset_ = 0.0;
  Eigen::Matrix3d outer_ = Eigen::Matrix3d::Zero();
  std::size_t count_ = 0;
};

// Region growing on the representatives (CGAL's Region_growing): seeds from the most planar
// neighbourhood down, neighbours those of the voxels around (on an unthinned cloud, CGAL's
// sphere query) within the detection's cluster epsilon. Each region's inliers as cloud indices.
// On the dev tiles it finds the planes Efficient RANSAC finds, with their scores to the
// millimetre; it takes a quarter off plane detection's slowest buildings (RANSAC searching for
// the small planes among many points), little off the median one (the kNN normals dominate).
template <class Neighbours>
std::vector<std::vector<int>> grow(const Representatives& r, Neighbours& near, std::size_t min_points,
                                   const PlaneConfig& prm) {
  std::vector<std::size_t> seeds(r.pts.size());
  std::iota(seeds.begin(), seeds.end(), 0);
  std::stable_sort(seeds.begin(), seeds.end(),
                   [&](std::size_t a, std::size_t b) { return r.planarity[a] > r.planarity[b]; });
  PlaneRegion region(r.pts, min_points, prm);
  CGAL::Shape_detection::Region_growing<PointList, Neighbours, PlaneRegion,
                                        CGAL::Pointer_property_map<std::size_t>::type>
      growing(r.pts, near, region, CGAL::make_property_map(seeds));
  std::vector<std::vector<std::size_t>> regions;
  growing.detect(std::back_inserter(regions));
  std::vector<std::vector<int>> shapes;
  for (const auto& members : regions) {
    std::vector<int> inl;
    for (std::size_t k : members) inl.push_back(std::get<2>(r.pts[k]));
    shapes.push_back(std::move(inl));
  }
  return shapes;
}

std::vector<std::vector<int>> grown_shapes(const Representatives& r, const Thinning& t, std::size_t distinct,
                                           const PlaneConfig& prm) {
  const std::size_t min_points = detection_min_points(t, distinct, prm);
  const double reach = detection_cluster_epsilon(t, prm);
  if (t.thinned()) {
    VoxelNeighbours near{r, t, reach};
    return grow(r, near, min_points, prm);
  }
  CGAL::Shape_detection::Point_set::Sphere_neighbor_query<Kernel, PointList, PointMap> near(r.pts, reach);
  return grow(r, near, min_points, prm);
}

// Efficient RANSAC (the paper's, --ransac 1) on the representatives with their PCA normals: each
// shape's inliers as cloud indices, in CGAL's order of detection.
std::vector<std::vector<int>> ransac_shapes(Representatives r, const Thinning& t, std::size_t distinct,
                                            const PlaneConfig& prm) {
  PointList& pts = r.pts;
  // Efficient RANSAC draws from CGAL's default generator: seed it for reproducible runs. The
  // generator is thread-local (CGAL_HAS_THREADS), so buildings refined at once do not share it.
  CGAL::get_default_random() = CGAL::Random(static_cast<unsigned>(prm.seed));
  Ransac ransac;
  ransac.set_input(pts);
  ransac.add_shape_factory<RansacPlane>();
  Ransac::Parameters rp;
  rp.probability = prm.ransac_probability;
  rp.min_points = detection_min_points(t, distinct, prm);
  rp.epsilon = prm.ransac_epsilon;
  rp.cluster_epsilon = detection_cluster_epsilon(t, prm);
  rp.normal_threshold = std::cos(radians(prm.ransac_normal_deg));
  ransac.detect(rp);

  // Efficient RANSAC reorders `pts` ("the data in the input is reordered by detect()"): a point
  // is known by the cloud index it carries, not by its position.
  std::vector<std::vector<int>> shapes;
  for (const auto& shape : ransac.shapes()) {
    std::vector<int> inl;
    for (std::size_t k : shape->indices_of_assigned_points()) inl.push_back(std::get<2>(pts[k]));
    shapes.push_back(std::move(inl));
  }
  return shapes;
}

// The shapes other than `own` that took the representative of a voxel next to cell c (sorted,
// unique): where a corner voxel's points off its own plane may go.
std::vector<int> neighbouring_shapes(const Eigen::Array3i& c, int own, const Thinning& t,
                                     const std::vector<int>& rep_shape) {
  std::vector<int> out;
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        const int v = t.voxel_at(c + Eigen::Array3i(dx, dy, dz));
        const int s = v < 0 ? -1 : rep_shape[std::size_t(v)];
        if (s >= 0 && s != own) out.push_back(s);
      }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// Of `shapes`, the one whose plane lies nearest p within ransac_epsilon (ties: the lower); -1
// when none.
int nearest_shape(const Vec3& p, const std::vector<int>& shapes, const std::vector<Plane>& fitted,
                  const PlaneConfig& prm) {
  int best = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  for (int s : shapes) {  // ascending: a tie keeps the lower
    const double d = std::abs(fitted[std::size_t(s)].distance(p));
    if (d <= prm.ransac_epsilon && d < best_distance) best = s, best_distance = d;
  }
  return best;
}

// Back to the full cloud: every point (copies too) of a voxel whose representative a shape
// took goes to that shape when it lies within ransac_epsilon of the shape's plane (fitted on
// its representatives). A voxel at a corner holds points of two walls and its representative
// went to one: its points off that one's plane go to the nearest plane, within ransac_epsilon,
// of a shape that took a neighbouring voxel (on a box corner 0.28 m voxels otherwise lost a
// band of the ground plane: 7 % of its area). Voxels no shape took give back nothing: taking
// back from the neighbouring voxels for every point made supports larger than full
// detection's, and the selection then kept three topo dev tile buildings from their notch and
// bay walls (truth facade RMSE 0.084 -> 0.38 m).
std::vector<std::vector<int>> full_cloud_inliers(const PointCloud& cloud, const Thinning& t,
                                                 const std::vector<std::vector<int>>& shapes, const PlaneConfig& prm) {
  std::vector<int> rep_shape(t.reps.size(), -1);
  std::vector<Plane> fitted;
  for (int s = 0; s < int(shapes.size()); ++s) {
    std::vector<Vec3> q;
    for (int i : shapes[s]) {
      q.push_back(cloud.points[i]);
      rep_shape[t.voxel_of[i]] = s;
    }
    fitted.push_back(fit_plane(q));
  }
  std::vector<std::vector<int>> full(shapes.size());
  // Per voxel, its neighbours' shapes, looked up for its first point off its own plane.
  std::unordered_map<int, std::vector<int>> around;
  for (int i = 0; i < int(cloud.points.size()); ++i) {
    const Vec3& p = cloud.points[i];
    const int v = t.voxel_of[i], s = rep_shape[v];
    if (s < 0) continue;
    if (std::abs(fitted[s].distance(p)) <= prm.ransac_epsilon) {
      full[std::size_t(s)].push_back(i);
      continue;
    }
    auto it = around.find(v);
    if (it == around.end()) it = around.emplace(v, neighbouring_shapes(t.cell(p), s, t, rep_shape)).first;
    const int to = nearest_shape(p, it->second, fitted, prm);
    if (to >= 0) full[std::size_t(to)].push_back(i);
  }
  return full;
}

}  // namespace

std::vector<ScanPlane> detect_planes(const PointCloud& cloud, const PlaneConfig& prm) {
  std::vector<ScanPlane> result;
  if (cloud.points.size() < min_cloud_points(prm)) return result;
  Thinning thinning = thin_to_voxels(cloud, detection_voxel(prm));
  std::size_t distinct = thinning.distinct;
  if (!thinning.thinned()) {
    thinning.reps = distinct_points(cloud, prm);
    distinct = thinning.reps.size();
  } else if (!holds_planes(cloud, distinct, prm)) {
    return result;
  }
  if (thinning.reps.size() < std::size_t(prm.normal_neighbors) + 1) return result;
  Representatives reps = representatives(cloud, thinning, prm);
  std::vector<std::vector<int>> shapes = prm.ransac ? ransac_shapes(std::move(reps), thinning, distinct, prm)
                                                    : grown_shapes(reps, thinning, distinct, prm);
  if (thinning.thinned()) shapes = full_cloud_inliers(cloud, thinning, shapes, prm);
  for (auto& inl : shapes) {
    if (inl.size() < std::max<std::size_t>(3, std::size_t(prm.ransac_min_points))) continue;
    ScanPlane sp = describe_plane(cloud.points, std::move(inl), prm);
    if (sp.hull_area >= prm.min_plane_area) result.push_back(std::move(sp));
  }
  result = merge_coplanar(std::move(result), cloud.points, prm);
  result = detail::join_doubled_walls(std::move(result), cloud.points, prm);
  // Largest first: later stages prefer well-supported planes on ties.
  std::stable_sort(result.begin(), result.end(),
                   [](const ScanPlane& a, const ScanPlane& b) { return a.inliers.size() > b.inliers.size(); });
  return result;
}

}  // namespace lodrefine
