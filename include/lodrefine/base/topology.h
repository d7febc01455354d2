// Mesh topology helpers, one home for the stages, the generator and evaluation: union-find,
// cleaning a face's index list, vertices lying inside a segment, a hash grid that welds points,
// edge maps and connected components.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <queue>
#include <unordered_map>
#include <utility>
#include <vector>

#include "lodrefine/base/types.h"

namespace lodrefine {

// ---------------------------------------------------------------------------------------------
// Union-find over 0..n-1 with path halving.
class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n);
  int find(int x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  // Joins the sets of a and b under b's root.
  void unite(int a, int b) { parent_[find(a)] = find(b); }
  // Puts root `child` under root `root`, for callers that choose which root survives.
  void link(int child, int root) { parent_[child] = root; }

 private:
  std::vector<int> parent_;
};

// ---------------------------------------------------------------------------------------------
// Face index lists

// Drops consecutive repeats of an index and, for a closed polygon, a last index equal to the
// first: {1, 1, 2, 3, 3, 1} -> {1, 2, 3}.
void drop_repeats(std::vector<int>& v);

// What counts as lying inside segment a-b: the projection parameter t strictly inside
// (t_margin, 1 - t_margin), the distance to the line below `tol` (`strict`) or at most `tol`,
// and, when end_clearance >= 0, farther than end_clearance from both ends.
struct SegmentRule {
  double tol = 0.0;
  bool strict = false;
  double t_margin = 0.0;
  double end_clearance = -1.0;
};

// t of p along a-b when p lies inside it by `rule`, else nullopt (also for a zero-length segment).
std::optional<double> inside_segment(const Vec3& a, const Vec3& b, const Vec3& p, const SegmentRule& rule);

// The vertices inside segment V[a]-V[b] by `rule`, ordered from a to b (ties by index). Only
// `candidates` are tried (all vertices when null); a, b and the vertices in `exclude` never count.
std::vector<int> vertices_on_segment(const std::vector<Vec3>& V, int a, int b, const SegmentRule& rule,
                                     const std::vector<int>* candidates = nullptr,
                                     const std::vector<int>* exclude = nullptr);

// ---------------------------------------------------------------------------------------------
// Hash grid

// A cell of a cubic grid, and its hash. The hash multiplies in unsigned arithmetic: it wraps
// instead of overflowing, whatever the coordinates' magnitude.
using GridKey = std::array<long long, 3>;
struct GridKeyHash {
  std::size_t operator()(const GridKey& k) const {
    return std::size_t(std::uint64_t(k[0]) * 73856093u ^ std::uint64_t(k[1]) * 19349663u ^
                       std::uint64_t(k[2]) * 83492791u);
  }
};

// Ids of points filed by the cubic cell of size `cell` they fall in.
class PointGrid {
 public:
  explicit PointGrid(double cell) : cell_(cell) {}
  GridKey key(const Vec3& p) const;
  void insert(const Vec3& p, int id) { cells_[key(p)].push_back(id); }
  // Calls fn(id) for every id in p's cell and the 26 around it (x outermost, then y, then z,
  // each from -1 to +1; a cell's ids in insertion order) until fn returns true. Returns
  // whether it did. Points within `cell` of p are all visited.
  template <class Fn>
  bool visit_near(const Vec3& p, Fn&& fn) const {
    const GridKey c = key(p);
    for (long long dx = -1; dx <= 1; ++dx)
      for (long long dy = -1; dy <= 1; ++dy)
        for (long long dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find({c[0] + dx, c[1] + dy, c[2] + dz});
          if (it == cells_.end()) continue;
          for (int id : it->second)
            if (fn(id)) return true;
        }
    return false;
  }

 private:
  double cell_;
  std::unordered_map<GridKey, std::vector<int>, GridKeyHash> cells_;
};

// Welds points within `tol` of an earlier one: add() returns the index of the first stored
// point (in PointGrid's visiting order) within `tol`, or stores p as a new point.
class PointWelder {
 public:
  explicit PointWelder(double tol) : tol_(tol), grid_(4 * tol) {}
  int add(const Vec3& p);
  const std::vector<Vec3>& points() const { return points_; }

 private:
  double tol_;
  PointGrid grid_;
  std::vector<Vec3> points_;
};

// ---------------------------------------------------------------------------------------------
// Edges and components

// Faces put in agreement over their adjacency, breadth first from each component's first face:
// adj[f] lists (neighbour, same) with `same` when both faces run their shared edge the same way.
// Each face's component and whether it must be reversed to agree with that first face; a
// conflict (a non-orientable component) is left to validation.
struct AgreeingParts {
  std::vector<int> part;
  std::vector<char> flip;
  int parts = 0;
};
template <class Adjacent>
AgreeingParts agreeing_parts(const std::vector<std::vector<Adjacent>>& adj) {
  AgreeingParts r{std::vector<int>(adj.size(), -1), std::vector<char>(adj.size(), 0), 0};
  for (std::size_t s = 0; s < adj.size(); ++s) {
    if (r.part[s] >= 0) continue;
    std::queue<int> q;
    q.push(int(s));
    r.part[s] = r.parts;
    while (!q.empty()) {
      const int f = q.front();
      q.pop();
      for (const auto& [g, same] : adj[std::size_t(f)]) {
        if (r.part[std::size_t(g)] >= 0) continue;
        r.part[std::size_t(g)] = r.parts;
        r.flip[std::size_t(g)] = char(r.flip[std::size_t(f)] ^ same);
        q.push(g);
      }
    }
    ++r.parts;
  }
  return r;
}

// Each undirected edge (lower vertex index first) with the faces using it, in face order;
// `forward` when the face runs from the lower to the higher vertex. A face's repeated
// consecutive vertex makes no edge.
struct EdgeUse {
  int face;
  bool forward;
};
using EdgeUses = std::map<std::pair<int, int>, std::vector<EdgeUse>>;
inline std::pair<int, int> edge_key(int a, int b) { return {std::min(a, b), std::max(a, b)}; }
EdgeUses edge_uses(const std::vector<Face>& faces);
// The same over the faces listed in `subset` only (EdgeUse::face still indexes `faces`).
EdgeUses edge_uses(const std::vector<Face>& faces, const std::vector<int>& subset);

// Number of edge-connected components of faces 0..face_count-1 (any edge, manifold or not).
int count_components(std::size_t face_count, const EdgeUses& uses);

}  // namespace lodrefine
