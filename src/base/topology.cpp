// Mesh topology helpers (see topology.h).
#include "lodrefine/base/topology.h"

#include <cmath>
#include <numeric>
#include <set>

namespace lodrefine {

DisjointSets::DisjointSets(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }

void drop_repeats(std::vector<int>& v) {
  v.erase(std::unique(v.begin(), v.end()), v.end());
  while (v.size() > 1 && v.front() == v.back()) v.pop_back();
}

std::optional<double> inside_segment(const Vec3& a, const Vec3& b, const Vec3& p, const SegmentRule& rule) {
  const Vec3 d = b - a;
  const double t = (p - a).dot(d) / d.squaredNorm();
  if (!(t > rule.t_margin && t < 1.0 - rule.t_margin)) return std::nullopt;  // also NaN
  const double off = (a + t * d - p).norm();
  if (rule.strict ? !(off < rule.tol) : !(off <= rule.tol)) return std::nullopt;
  if (rule.end_clearance >= 0 && ((p - a).norm() <= rule.end_clearance || (p - b).norm() <= rule.end_clearance))
    return std::nullopt;
  return t;
}

std::vector<int> vertices_on_segment(const std::vector<Vec3>& V, int a, int b, const SegmentRule& rule,
                                     const std::vector<int>* candidates, const std::vector<int>* exclude) {
  std::vector<std::pair<double, int>> hits;
  const auto consider = [&](int w) {
    if (w == a || w == b) return;
    const auto t = inside_segment(V[a], V[b], V[w], rule);
    // `exclude` (a face's ring) is searched only for the few hits: a ring of n vertices made
    // this n times slower per candidate, cubic over the ring (a face pinched 6000 times: minutes).
    if (t && !(exclude && std::find(exclude->begin(), exclude->end(), w) != exclude->end())) hits.emplace_back(*t, w);
  };
  if (candidates)
    for (int w : *candidates) consider(w);
  else
    for (int w = 0; w < int(V.size()); ++w) consider(w);
  std::sort(hits.begin(), hits.end());
  std::vector<int> out;
  out.reserve(hits.size());
  for (const auto& h : hits) out.push_back(h.second);
  return out;
}

GridKey PointGrid::key(const Vec3& p) const {
  return {(long long)std::floor(p.x() / cell_), (long long)std::floor(p.y() / cell_),
          (long long)std::floor(p.z() / cell_)};
}

int PointWelder::add(const Vec3& p) {
  int found = -1;
  grid_.visit_near(p, [&](int i) {
    if (!((points_[i] - p).norm() <= tol_)) return false;
    found = i;
    return true;
  });
  if (found >= 0) return found;
  points_.push_back(p);
  grid_.insert(p, int(points_.size()) - 1);
  return int(points_.size()) - 1;
}

namespace {

void add_face_edges(EdgeUses& uses, const std::vector<int>& v, int f) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    const int a = v[i], b = v[(i + 1) % v.size()];
    if (a != b) uses[edge_key(a, b)].push_back({f, a < b});
  }
}

}  // namespace

EdgeUses edge_uses(const std::vector<Face>& faces) {
  EdgeUses uses;
  for (std::size_t f = 0; f < faces.size(); ++f) add_face_edges(uses, faces[f].v, int(f));
  return uses;
}

EdgeUses edge_uses(const std::vector<Face>& faces, const std::vector<int>& subset) {
  EdgeUses uses;
  for (int f : subset) add_face_edges(uses, faces[f].v, f);
  return uses;
}

int count_components(std::size_t face_count, const EdgeUses& uses) {
  DisjointSets ds(face_count);
  for (const auto& entry : uses)
    for (const EdgeUse& u : entry.second) ds.unite(entry.second[0].face, u.face);
  std::set<int> roots;
  for (std::size_t f = 0; f < face_count; ++f) roots.insert(ds.find(int(f)));
  return int(roots.size());
}

}  // namespace lodrefine
