// An assembled shell checked before it is written (shell_checks.h).
#include "shell_checks.h"

#include <algorithm>
#include <unordered_map>

#include "lodrefine/base/topology.h"
#include "lodrefine/core/distance.h"
#include "lodrefine/core/matching.h"
#include "lodrefine/core/validate.h"

namespace lodrefine::detail {

namespace {

// A selection that puts solid where the scan saw through: points of the supporting planes
// (surfaces the scanner saw from outside) that end up deeper than kEnclosedDepth inside the
// shell, though not inside the start, would have been hidden by it. A neighbour's wall across a
// gap beyond the building's end became the front of a box filling the gap (the front wall's
// points behind it then inside): a change made of those. Deeper than a window recess or a
// moved wall's noise; as many as a plane needs (ransac_min_points).
constexpr double kEnclosedDepth = 0.5;

// The changed candidates in connected pieces (sharing an edge): each piece alone leaves every
// edge used 0 or 2 times, as the whole selection does.
std::vector<std::vector<int>> changed_pieces(const CandidateSet& cs, const std::vector<char>& changed) {
  DisjointSets sets(std::size_t(cs.size()));
  for (const auto& e : cs.edges) {
    int first = -1;
    for (auto h : e) {
      const int f = cs.face(h);
      if (!changed[f]) continue;
      if (first < 0) first = f;
      else sets.unite(f, first);
    }
  }
  std::unordered_map<int, int> piece_of_root;
  std::vector<std::vector<int>> pieces;
  for (int f = 0; f < cs.size(); ++f) {
    if (!changed[f]) continue;
    const auto [it, added] = piece_of_root.emplace(sets.find(f), int(pieces.size()));
    if (added) pieces.emplace_back();
    pieces[std::size_t(it->second)].push_back(f);
  }
  return pieces;
}

}  // namespace

// The changed candidates of the pieces that enclose scan points (see kEnclosedDepth): each
// newly enclosed point counts for the piece with the changed candidate nearest to it.
std::vector<int> enclosing_changes(const CandidateSet& cs, const std::vector<char>& changed, const Mesh& start,
                                   const Mesh& shell, const std::vector<Vec3>& evidence, const PlaneEvidence& prm) {
  const auto pieces = changed_pieces(cs, changed);
  if (pieces.empty()) return {};
  Mesh changes;  // the changed candidates as one polygon soup, face i of piece piece_of[i]
  std::vector<int> piece_of;
  Eigen::AlignedBox3d box;
  for (int k = 0; k < int(pieces.size()); ++k)
    for (int f : pieces[k]) {
      Face face;
      for (const Vec3& p : cs.polygon(f)) {
        face.v.push_back(int(changes.vertices.size()));
        changes.vertices.push_back(p);
        box.extend(p);
      }
      changes.faces.push_back(std::move(face));
      piece_of.push_back(k);
    }
  // A point newly enclosed lies inside the changed candidates' box or within kEnclosedDepth of
  // a removed one (the start's surface, by which it was less deep).
  box.extend(box.min() - Vec3::Constant(kEnclosedDepth + kSurfaceDistance));
  box.extend(box.max() + Vec3::Constant(kEnclosedDepth + kSurfaceDistance));
  std::vector<Vec3> enclosed;
  const MeshDistance to_shell(shell), to_start(start);
  for (const Vec3& p : evidence)
    if (box.contains(p) && to_shell.distance(p, true) < -kEnclosedDepth &&
        to_start.distance(p, true) >= -kEnclosedDepth)
      enclosed.push_back(p);
  if (int(enclosed.size()) < prm.ransac_min_points) return {};
  std::vector<int> count(pieces.size(), 0);
  for (const auto& n : MeshDistance(changes).nearest_all(enclosed)) ++count[piece_of[n.face]];
  std::vector<int> out;
  for (int k = 0; k < int(pieces.size()); ++k)
    if (count[k] >= prm.ransac_min_points) out.insert(out.end(), pieces[k].begin(), pieces[k].end());
  return out;
}

Mesh snapped_to_start(const Mesh& m, const Mesh& start) {
  PointGrid grid(kSnapBack);
  for (int i = 0; i < int(start.vertices.size()); ++i) grid.insert(start.vertices[i], i);
  Mesh out = m;
  out.vertices.clear();
  std::vector<int> index(m.vertices.size()), of_start(start.vertices.size(), -1);
  for (std::size_t k = 0; k < m.vertices.size(); ++k) {
    int best = -1;
    double best_d = kSnapBack;
    grid.visit_near(m.vertices[k], [&](int i) {
      const double d = (start.vertices[i] - m.vertices[k]).norm();
      if (d < best_d) best_d = d, best = i;
      return false;
    });
    int& slot = best >= 0 ? of_start[best] : index[k];  // vertices snapped to one start vertex become one
    if (best < 0 || slot < 0) {
      slot = int(out.vertices.size());
      out.vertices.push_back(best >= 0 ? start.vertices[best] : m.vertices[k]);
    }
    index[k] = slot;
  }
  out.faces.clear();
  for (Face f : m.faces) {
    for (int& v : f.v) v = index[v];
    drop_repeats(f.v);
    if (f.v.size() >= 3) out.faces.push_back(std::move(f));
  }
  return out;
}

// Why the assembled shell cannot be written, or empty: validate_mesh's problem, or a face that
// passes through one vertex twice (two pieces pinched together by the output weld or merge).
std::string shell_problem(const Mesh& m, const RepairConfig& prm) {
  const Validation v = validate_mesh(m, prm.planarity_tolerance);
  if (!v.valid()) return v.problem.empty() ? "invalid" : v.problem;
  for (const auto& f : m.faces) {
    std::vector<int> ids = f.v;
    std::sort(ids.begin(), ids.end());
    if (std::adjacent_find(ids.begin(), ids.end()) != ids.end()) return "a face repeats a vertex";
  }
  return "";
}

}  // namespace lodrefine::detail
