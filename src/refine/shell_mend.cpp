// A selection of candidates mended into the nearest closed one (shell_mend.h).
#include "shell_mend.h"

#include "lodrefine/refine/objective.h"

namespace lodrefine::detail {

// The starting shell as a selection of candidates: its faces are unions of candidates up to
// where its vertices sit off the planes' meets (a model within tolerance of its planes, planes
// merged within kSurfaceDistance), which leaves some edges used once or thrice. Those are
// mended by the nearest selection that closes: a small program over the candidates around each
// such edge (kMendRings edge-rings, more while it has no solution), the others fixed, each
// change costing its area; with `whole_last`, at last every candidate free. None of the local
// selections `excluded` is made (SelectionProgram::excluded). Empty when it cannot be mended.
constexpr int kMendRings = 2, kMendTries = 3;
std::vector<char> nearest_closed_selection(CandidateSet& cs, const std::vector<char>& in_start,
                                           const SelectionConfig& prm, const MendScope& scope,
                                           const std::vector<LocalSelection>& excluded) {
  if (excluded.empty() && every_edge_used_0_or_2(cs, in_start)) return in_start;
  std::vector<char> near(cs.size(), 0);
  for (const auto& x : excluded)
    for (const auto* set : {&x.selected, &x.unselected})
      for (int f : *set) near[f] = 1;
  for (const auto& e : cs.edges) {
    int n = 0;
    for (auto h : e) n += in_start[cs.face(h)];
    if (n != 0 && n != 2)
      for (auto h : e) near[cs.face(h)] = 1;
  }
  for (int attempt = 0; attempt < kMendTries + int(scope.whole_last); ++attempt) {
    if (attempt == kMendTries) near.assign(near.size(), 1);
    for (int ring = 0; ring < kMendRings; ++ring) {
      std::vector<char> grown = near;
      for (const auto& e : cs.edges) {
        bool touches = false;
        for (auto h : e) touches = touches || near[cs.face(h)];
        if (touches)
          for (auto h : e) grown[cs.face(h)] = 1;
      }
      near.swap(grown);
    }
    SelectionProgram pg;
    set_mend_costs(cs, in_start, scope.keep_weight, pg);
    for (int f = 0; f < cs.size(); ++f) pg.fixed.push_back(near[f] ? -1 : int(in_start[f]));
    pg.excluded = excluded;
    const SelectionResult r = select_faces(cs, pg, prm);
    if (r.ok) return selected_faces(cs);
  }
  return {};
}

// A boolean face map of `cs` as 0/1 per candidate (a selection).
std::vector<char> face_flags(const CandidateSet& cs, const CandidateMap<bool>& map) {
  std::vector<char> out;
  for (auto f : cs.mesh.faces()) out.push_back(char(map[f]));
  return out;
}

}  // namespace lodrefine::detail
