// Stage 4a (paper Sec. 3.3): candidate confidence from model and cloud references.
#include "lodrefine/core/confidence.h"

#include <algorithm>
#include <cmath>

namespace lodrefine {
namespace {

// Areas in ratios are at least this (m^2): a degenerate box or candidate divides by no zero.
constexpr double kMinArea = 1e-12;

// Coordinates of points in a plane's (u, v) basis around `origin`.
std::vector<Vec2> to_2d(const std::vector<Vec3>& pts, const Plane& pl, const Vec3& origin) {
  const auto [u, v] = pl.basis();
  std::vector<Vec2> out;
  out.reserve(pts.size());
  for (const auto& p : pts) out.emplace_back((p - origin).dot(u), (p - origin).dot(v));
  return out;
}

// Bounding-box overlap in the reference's plane: IoU, or the share of either box covered
// (the "bidirectional coverage ratio"), whichever is larger.
double box_overlap(const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
  const Eigen::AlignedBox2d ba = bounding_box(a), bb = bounding_box(b);
  const double w = std::min(ba.max().x(), bb.max().x()) - std::max(ba.min().x(), bb.min().x());
  const double h = std::min(ba.max().y(), bb.max().y()) - std::max(ba.min().y(), bb.min().y());
  if (w <= 0 || h <= 0) return 0.0;
  // Both boxes overlap with positive width and height here, so neither is empty.
  const double inter = w * h, ua = ba.volume(), ub = bb.volume();
  const double iou = inter / std::max(kMinArea, ua + ub - inter);
  return std::max({iou, inter / std::max(kMinArea, ua), inter / std::max(kMinArea, ub)});
}

double model_score(const std::vector<Vec3>& cand, const Plane& cplane, double carea, const ModelReference& ref,
                   const Plane& rplane, const ConfidenceConfig& prm) {
  if (unoriented_angle_deg(cplane.n, rplane.n) > prm.conf_angle_deg) return 0.0;
  double dmax = 0.0;
  for (const auto& p : cand) dmax = std::max(dmax, std::abs(rplane.distance(p)));
  if (dmax > prm.conf_model_distance) return 0.0;
  const Vec3 o = ref.polygon.front();
  const auto c2 = to_2d(cand, rplane, o);
  const auto r2 = to_2d(ref.polygon, rplane, o);
  if (box_overlap(c2, r2) < prm.conf_bbox_iou) return 0.0;
  return std::min(1.0, polygon_convex_intersection_area(r2, c2) / std::max(kMinArea, carea));
}

struct CloudInfo {
  Plane plane;
  std::vector<Vec3> points;
};

// A cloud reference seen from one candidate plane: passes the angle and distance filters or
// not, and if so the hull of its points projected on that plane (the same for every
// candidate of the plane, so computed once).
struct CloudView {
  bool valid = false;
  Vec3 origin = Vec3::Zero();
  std::vector<Vec2> hull;
};

CloudView view_cloud(const Plane& cplane, const CloudInfo& ref, const ConfidenceConfig& prm) {
  CloudView view;
  if (unoriented_angle_deg(cplane.n, ref.plane.n) > prm.conf_angle_deg) return view;
  double sum = 0.0, sum2 = 0.0;
  for (const auto& p : ref.points) {
    const double d = std::abs(cplane.distance(p));
    sum += d;
    sum2 += d * d;
  }
  const double n = double(ref.points.size());
  const double mean = sum / n, sd = std::sqrt(std::max(0.0, sum2 / n - mean * mean));
  if (mean > prm.conf_cloud_distance || sd > prm.conf_cloud_distance) return view;
  view.origin = cplane.project(ref.points.front());
  view.hull = convex_hull_2d(to_2d(ref.points, cplane, view.origin));
  view.valid = view.hull.size() >= 3;
  return view;
}

double cloud_score(const std::vector<Vec3>& cand, const Plane& cplane, double carea, const CloudView& view) {
  if (!view.valid) return 0.0;
  return std::min(
      1.0, polygon_convex_intersection_area(to_2d(cand, cplane, view.origin), view.hull) / std::max(kMinArea, carea));
}

}  // namespace

double coverage_cost(double area, double c, double tau) {
  return area * (1.0 / (1.0 + std::exp(-(1.0 - c) + (1.0 - tau))) - 0.5);
}

std::vector<Confidence> candidate_confidence(const CandidateSet& cs, const std::vector<ModelReference>& model,
                                             const std::vector<CloudReference>& cloud, const ConfidenceConfig& prm) {
  std::vector<Plane> model_planes;
  for (const auto& r : model) model_planes.push_back(polygon_plane(r.polygon));
  std::vector<CloudInfo> clouds;
  for (const auto& r : cloud)
    if (r.points.size() >= 3) clouds.push_back({fit_plane(r.points), r.points});

  std::vector<std::vector<CloudView>> views(cs.planes.size());
  for (std::size_t pl = 0; pl < cs.planes.size(); ++pl)
    for (const auto& c : clouds) views[pl].push_back(view_cloud(cs.planes[pl].plane, c, prm));

  const auto support = cs.supports();
  const auto areas = cs.areas();
  std::vector<Confidence> out(cs.size());
  for (int f = 0; f < cs.size(); ++f) {
    const auto poly = cs.polygon(f);
    const int k = support[CandidateFace(f)];
    const Plane& cp = cs.planes[k].plane;
    const double area = areas[CandidateFace(f)];
    for (int r = 0; r < int(model.size()); ++r) {
      const double s = model_score(poly, cp, area, model[r], model_planes[r], prm);
      if (s > out[f].value) out[f] = {s, r, -1};
    }
    for (int r = 0; r < int(clouds.size()); ++r) {
      const double s = cloud_score(poly, cp, area, views[k][r]);
      if (s > out[f].value) out[f] = {s, -1, r};
    }
  }
  return out;
}

}  // namespace lodrefine
