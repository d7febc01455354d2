// Stage 5, selection, for the whole building (paper Sec. 3.2-3.4): see shell_selection.h.
#include "lodrefine/refine/shell_selection.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/topology.h"
#include "lodrefine/core/distance.h"
#include "lodrefine/core/matching.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/refine/objective.h"
#include "lodrefine/refine/shell_trace.h"
#include "occupancy.h"
#include "shell_checks.h"
#include "shell_describe.h"
#include "shell_mend.h"
#include "shell_supports.h"

namespace lodrefine {
namespace {

using detail::describe_candidates;
using detail::enclosing_changes;
using detail::face_flags;
using detail::FaceIndex;
using detail::FaceProps;
using detail::kSnapBack;
using detail::MendScope;
using detail::near_vertical;
using detail::nearest_closed_selection;
using detail::shell_problem;
using detail::snapped_to_start;
using detail::Supports;
std::vector<char> kept(const std::vector<char>& v, const std::vector<char>& keep) {
  std::vector<char> out;
  for (std::size_t f = 0; f < v.size(); ++f)
    if (keep[f]) out.push_back(v[f]);
  return out;
}

// How far in plan from the scan points the selection used a candidate may change (m). At least
// match_distance at its default (1.25 m: a matched wall lies at most that far from its points, and
// the roof strip its move re-cuts has corners on the old wall line); far below the 5 m at which
// RealData.ThreeDBagSeqMovedWall's roof was re-cut without evidence. The 0.75 m above
// match_distance is a margin no test or sweep has measured, and the value does not follow
// --match-distance. Also the spacing of step_volume_samples, so that its samples' reaches overlap.
constexpr double kEvidenceReach = 2.0;

// The scan points the selection used, in plan: built once per building, asked whether a point
// lies within kEvidenceReach of one.
class EvidenceReach {
 public:
  explicit EvidenceReach(const std::vector<Vec3>& evidence) : grid_(kEvidenceReach) {
    for (const auto& p : evidence) plan_.push_back(plan(p));
    for (int i = 0; i < int(plan_.size()); ++i) grid_.insert(plan_[i], i);
  }
  bool reaches(const Vec3& p) const {
    const Vec3 q = plan(p);
    return grid_.visit_near(q, [&](int i) { return (plan_[i] - q).norm() <= kEvidenceReach; });
  }

 private:
  static Vec3 plan(const Vec3& p) { return Vec3(p.x(), p.y(), 0.0); }
  std::vector<Vec3> plan_;
  PointGrid grid_;
};

// The candidates with a corner beyond the evidence: a change of one is a change the scan did not
// ask for, so they keep their starting-shell value.
std::vector<int> beyond_evidence(const CandidateSet& cs, const EvidenceReach& evidence) {
  std::vector<int> out;
  for (int f = 0; f < cs.size(); ++f)
    for (int v : cs.corners(f))
      if (!evidence.reaches(cs.vertices[v])) {
        out.push_back(f);
        break;
      }
  return out;
}

// Whether a vertex of `m` beyond kEvidenceReach (in plan) of every evidence point is not a
// starting-shell vertex: the arrangement's plane meets stand in for the model there, and where
// the scan says nothing the model must come out exactly as it went in.
bool moves_beyond_evidence(const Mesh& m, const Mesh& start, const EvidenceReach& evidence) {
  PointGrid same(kSnapBack);
  for (int i = 0; i < int(start.vertices.size()); ++i) same.insert(start.vertices[i], i);
  for (const Vec3& v : m.vertices) {
    if (evidence.reaches(v)) continue;
    if (!same.visit_near(v, [&](int i) { return start.vertices[i] == v; })) return true;
  }
  return false;
}

constexpr int kRetries = 2;

// A real building's program (thousands of columns) spends its work budget at the root: GLPK ends
// with its warm start though a selection far better exists (found with 300 times the budget). So
// the warm start is first improved where the scan asks for a change: each scanned plane's
// neighbourhood (the free candidates with a corner within kEvidenceReach of its points, in plan)
// is solved alone, every other candidate fixed at the incumbent, in turn; each such program is
// small, and its answer is at least as good as the incumbent it started from (which GLPK holds).
// Together they spend one work budget, shared evenly: the selection then costs at most twice it.
// A neighbourhood holding every free candidate is skipped: it is the whole program, solved next.
// Returns the improved incumbent and counts the neighbourhoods that changed it.
std::vector<char> improved_by_neighbourhoods(CandidateSet& cs, const SelectionProgram& pg, const Supports& s,
                                             const SelectionConfig& prm, int& improved) {
  std::vector<char> current = pg.warm;
  const auto scanned = std::count_if(s.points.begin(), s.points.end(), [](const auto& p) { return !p.empty(); });
  SelectionConfig share = prm;
  share.mip_work_limit = prm.mip_work_limit / double(std::max<std::ptrdiff_t>(1, scanned));
  const auto free_all = int(std::count(pg.fixed.begin(), pg.fixed.end(), -1));
  for (const auto& pts : s.points) {
    if (pts.empty()) continue;
    const EvidenceReach near(pts);
    SelectionProgram local = pg;
    local.warm = current;
    int free = 0;
    for (int f = 0; f < cs.size(); ++f) {
      if (local.fixed[f] >= 0) continue;
      bool reached = false;
      for (int v : cs.corners(f)) reached = reached || near.reaches(cs.vertices[v]);
      if (!reached) local.fixed[f] = int(current[f]);
      free += reached;
    }
    if (free == 0 || free == free_all) continue;  // none, or the whole program: solved next anyway
    if (!select_faces(cs, local, share).ok) continue;
    const std::vector<char> selected = selected_faces(cs);
    if (selected != current) ++improved;
    current = selected;
  }
  return current;
}

// A vertical wall's outline seen along its horizontal normal: (along the wall, height). A plane
// parallel to the wall (its scan plane) reads the same outline in it.
struct WallView {
  Vec3 u;
  explicit WallView(const Vec3& n) : u(along_wall(n).normalized()) {}
  Vec2 operator()(const Vec3& p) const { return {u.dot(p), p.z()}; }
};

// The supporting plane (other than `self`) carrying a wall's scan plane `plane` at the wall's
// centroid `at`: the nearest parallel one within merge_distance there (add_scan_planes gave the
// scan plane's points to it, or made it); -1 when none does.
int carrying_plane(const Supports& s, const Plane& plane, const Vec3& at, int self, const SelectionConfig& prm) {
  int best = -1;
  double best_d = prm.merge_distance;
  const Vec3 on = plane.project(at);
  for (int j = 0; j < int(s.planes.size()); ++j) {
    if (j == self || unoriented_angle_deg(s.planes[j].plane.n, plane.n) > prm.merge_angle_deg) continue;
    const double d = std::abs(s.planes[j].plane.distance(on));
    if (d <= best_d) best_d = d, best = j;
  }
  return best;
}

// `sel` with each outdated wall's candidates moved onto its scan plane: on the wall's supporting
// plane those within its outline off, on the plane carrying its scan plane those within the same
// outline on (by centroid). Not closed: the strips between the two planes are left to
// nearest_closed_selection. False when a wall's scan plane carries no supporting plane.
bool swap_onto_scan_planes(const CandidateSet& cs, const Mesh& start, const Supports& s, const MovePlan& outdated,
                           const SelectionConfig& prm, std::vector<char>& sel) {
  const std::vector<ModelSurface>& surfaces = outdated.surfaces;
  const auto support = cs.supports();
  const auto centroid = cs.centroids();
  for (const WallMove& mv : outdated.scan) {
    if (mv.surface < 0 || mv.surface >= int(surfaces.size())) return false;
    const ModelSurface& wall = surfaces[std::size_t(mv.surface)];
    const int from = s.face_plane[std::size_t(wall.faces.front())];
    const int to = carrying_plane(s, mv.plane, wall.centroid, from, prm);
    if (from < 0 || to < 0) return false;
    const WallView view(wall.plane.n);
    std::vector<std::vector<Vec2>> outline;
    for (int f : wall.faces) {
      outline.emplace_back();
      for (int v : start.faces[std::size_t(f)].v) outline.back().push_back(view(start.vertices[std::size_t(v)]));
    }
    for (int f = 0; f < cs.size(); ++f) {
      const int k = support[FaceIndex(f)];
      if (k != from && k != to) continue;
      const Vec2 c = view(centroid[FaceIndex(f)]);
      if (std::any_of(outline.begin(), outline.end(), [&](const auto& poly) { return point_in_polygon_2d(c, poly); }))
        sel[std::size_t(f)] = char(k == to);
    }
  }
  return true;
}

// Without a substitution the starting shell has its outdated walls where the model put them, and
// a real building's program spends its work budget at the root: GLPK ends on its warm start
// (City3D 08835: an upper storey set back over a ledge, whose move onto its scan folds the ledge's
// roof, so the substitution is refused; the selection kept the model, and refined it with 40
// times the work budget).
// So the warm start is built in the arrangement: `base` (the starting shell) with the walls on
// their scan planes, closed by the nearest closed selection; `base` itself when that fails or
// changes a candidate `pg` fixes.
std::vector<char> warm_with_walls_moved(CandidateSet& cs, const SelectionProgram& pg, const std::vector<char>& base,
                                        const Mesh& start, const Supports& s, const MovePlan& outdated,
                                        const SelectionConfig& prm) {
  std::vector<char> swapped = base;
  if (!swap_onto_scan_planes(cs, start, s, outdated, prm, swapped)) return base;
  const std::vector<char> closed = nearest_closed_selection(cs, swapped, prm);
  if (closed.empty()) return base;
  for (int f = 0; f < cs.size(); ++f)
    if (pg.fixed[std::size_t(f)] >= 0 && pg.fixed[std::size_t(f)] != int(closed[std::size_t(f)])) return base;
  return closed;
}

// Buildings with fewer supporting planes are cut over the whole region (every dev tile building:
// at most 31); local sections, which bound the large ones, changed a small real building's
// program enough to lose its refinement (RealData.ThreeDBagSeqMovedWall).
constexpr int kLocalSectionsFrom = 32;

// Why the selected shell cannot be written (empty when it can): it does not validate, it moves
// the model beyond the `evidence`, or a change encloses the supports' points (`scan_points`; those
// changes in `refused`). `changed`: per candidate, whether the selection differs from the start
// there; `warm`: whether the start was the warm start (enclosing changes are then fixed back
// alone). A valid shell is snapped onto the start where it still validates.
std::string shell_refusal(Mesh& shell, const Mesh& start, CandidateSet& cs, const std::vector<char>& changed, bool warm,
                          const EvidenceReach& evidence, const std::vector<Vec3>& scan_points, const RefineConfig& prm,
                          std::vector<int>& refused) {
  std::string problem = shell_problem(shell, prm.repair);
  const bool any = std::find(changed.begin(), changed.end(), 1) != changed.end();
  if (problem.empty()) {
    Mesh snapped = snapped_to_start(shell, start);
    if (shell_problem(snapped, prm.repair).empty()) shell = std::move(snapped);
    if (any && moves_beyond_evidence(shell, start, evidence))
      problem = "it moves the model where the scan shows nothing";
  }
  if (problem.empty() && any && warm) {
    refused = enclosing_changes(cs, changed, start, shell, scan_points, prm.plane);
    if (!refused.empty()) problem = "it encloses scan points (a surface seen through it)";
  }
  return problem;
}

// The supporting planes of a selection: the starting shell's (its slivers on larger faces'
// planes: add_start_planes), the scan's and the step walls, counted in `st` with the evidence they hold.
Supports supports_of(const Mesh& start, const PointCloud& cloud, const std::vector<ScanPlane>& planes,
                     const RefineConfig& prm, ShellSelectionStats& st) {
  Supports s;
  detail::add_start_planes(start, prm.repair.planarity_tolerance, s);
  detail::add_scan_planes(start, cloud, planes, prm, s);
  const int before_steps = int(s.planes.size());
  detail::add_step_walls(start, prm, s);
  st.step_walls = int(s.planes.size()) - before_steps;
  st.supporting_planes = int(s.planes.size());
  st.scan_planes_added = s.added;
  for (const auto& pts : s.points) st.evidence.insert(st.evidence.end(), pts.begin(), pts.end());
  return s;
}

// The program over the candidates: its costs (objective.h); with a `warm` start, it is the first
// incumbent and every candidate no evidence reaches is fixed to it.
SelectionProgram program_of(CandidateSet& cs, const FaceProps& props, const std::vector<char>& warm,
                            const SelectionConfig& prm) {
  SelectionProgram pg;
  set_selection_costs(cs, props.confidence, props.fit, prm, pg);
  if (!warm.empty()) {
    pg.warm = warm;
    for (int f = 0; f < cs.size(); ++f) pg.fixed.push_back(props.in_zone[FaceIndex(f)] ? -1 : int(warm[f]));
  }
  return pg;
}

// The candidates the program needs (with their FaceProps and the warm start on them): with a
// warm start, those fixed unselected (no support's evidence reaches them, the starting shell has
// none there) are pruned, and the program over the others is the same. Counted in `st`.
struct Pruned {
  CandidateSet cs;
  FaceProps props;
  std::vector<char> warm;
};
Pruned pruned(CandidateSet& all, const FaceProps& all_props, const std::vector<char>& all_warm,
              ShellSelectionStats& st) {
  std::vector<char> keep(all.size(), 1);
  if (!all_warm.empty())
    for (std::size_t f = 0; f < keep.size(); ++f) keep[f] = all_props.in_zone[FaceIndex(f)] || all_warm[f];
  CandidateSet cs = kept_candidates(all, keep);
  const FaceProps props = all_props.carried_to(cs.mesh, keep);
  std::vector<char> warm = all_warm.empty() ? all_warm : kept(all_warm, keep);
  st.candidates = cs.size();
  st.candidates_pruned = all.size() - st.candidates;
  st.edges = int(cs.edges.size());
  return {std::move(cs), props, std::move(warm)};
}

}  // namespace

// The selection. The start's slivers lie on the larger faces' planes they are within
// planarity_tolerance of (add_start_planes). The starting shell (mended where it does not close
// on the candidates) is GLPK's first incumbent (with the `outdated` walls on their scan planes:
// warm_with_walls_moved), and what no evidence reaches is fixed to it; without one everything is
// free. Each plane is cut to where its faces can be (its start faces and scan points, grown by
// twice the farthest a wall may move: a face reaches a moved neighbour, whose corner with the
// next moved wall lies that far again; once measured lost a real building's refinement), so a
// large building's program does not grow with the cube of its planes.
ShellSelection select_shell(const Mesh& start, const PointCloud& cloud, const std::vector<ScanPlane>& planes,
                            const RefineConfig& prm, const MovePlan& outdated) {
  const auto t0 = Clock::now();
  ShellSelection out;
  auto& st = out.stats;
  const Supports s = supports_of(start, cloud, planes, prm, st);

  const Region region = detail::building_region(start, s, prm.plane.facade_max_tilt_deg);
  const double reach = 2.0 * prm.scan_reach();
  CandidateSet all = build_candidates(
      s.planes, region,
      int(s.planes.size()) < kLocalSectionsFrom ? std::vector<Region>{} : detail::plane_reach(start, s, region, reach));
  if (all.capped) {
    out.reason = "too many candidate faces (over " + std::to_string(kMaxCandidates) + " from " +
                 std::to_string(s.planes.size()) + " planes)";
    st.seconds = seconds_since(t0);
    return out;
  }
  const FaceProps all_props = describe_candidates(all, start, s, prm);
  const std::vector<char> all_warm = nearest_closed_selection(all, face_flags(all, all_props.in_start), prm.selection);
  auto [cs, props, warm] = pruned(all, all_props, all_warm, st);

  SelectionProgram pg = program_of(cs, props, warm, prm.selection);
  auto finish = [&](const std::string& reason) {
    out.reason = reason;
    st.seconds = seconds_since(t0);
    return out;
  };
  // A candidate reaching beyond the evidence keeps its starting-shell value from the outset: any
  // selection changing one would be refused, so the program is the one the scan asks about.
  // A selection whose shell does not validate (two shells touching, faces meeting at a point)
  // is excluded: its changes from the starting shell are fixed back, and the program solved
  // again (at most kRetries times).
  const std::vector<char> base = warm.empty() ? face_flags(cs, props.in_start) : warm;
  std::vector<Vec3> reach_of = st.evidence;
  const std::vector<Vec3> swept = detail::step_volume_samples(start, s, prm, kEvidenceReach);
  reach_of.insert(reach_of.end(), swept.begin(), swept.end());
  const EvidenceReach evidence(reach_of);
  if (!warm.empty()) {
    for (int f : beyond_evidence(cs, evidence)) pg.fixed[f] = int(base[f]);
    if (!outdated.scan.empty()) pg.warm = warm_with_walls_moved(cs, pg, base, start, s, outdated, prm.selection);
    pg.warm = improved_by_neighbourhoods(cs, pg, s, prm.selection, st.neighbourhoods_improved);
  }
  std::string problem;
  for (int attempt = 0;; ++attempt) {
    st.selection = select_faces(cs, pg, prm.selection);
    const auto& sel = st.selection;
    if (!sel.ok) return finish("face selection " + sel.status_text());
    const std::vector<char> selected = selected_faces(cs);
    std::vector<char> changed(selected.size());
    for (std::size_t f = 0; f < changed.size(); ++f) changed[f] = selected[f] != base[f];
    st.candidates_changed = int(std::count(changed.begin(), changed.end(), 1));
    out.mesh = traced_shell(cs);
    out.mesh.id = start.id;
    st.faces_from_selection = int(out.mesh.faces.size());
    std::vector<int> refused;  // the changes to fix back (all of them, unless said)
    problem = shell_refusal(out.mesh, start, cs, changed, !warm.empty(), evidence, st.evidence, prm, refused);
    if (problem.empty() || st.candidates_changed == 0 || warm.empty() || attempt == kRetries) break;
    if (refused.empty())
      for (int f = 0; f < cs.size(); ++f)
        if (changed[f]) refused.push_back(f);
    for (int f : refused) pg.fixed[f] = int(base[f]);
    pg.warm = base;  // agrees with what is fixed back
  }
  if (st.candidates_changed == 0) {
    // The program chose its starting shell: it is written with the start's own faces, whose
    // vertices the arrangement's pieces only approximate (plane meets of a model that is planar
    // within tolerance; away from the scan a roof must not move by that).
    out.mesh = start;
    st.faces_from_selection = int(start.faces.size());
    out.ok = true;
    return finish(problem.empty() ? "" : "the starting shell was chosen (its pieces: " + problem + ")");
  }
  if (!problem.empty()) return finish("selected shell invalid: " + problem);
  out.ok = true;
  return finish("");
}

}  // namespace lodrefine
