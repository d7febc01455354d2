// Stages 3-4 for the whole building (paper Sec. 3.2-3.4): see shell_selection.h.
#include "lodrefine/core/shell_selection.h"

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
#include "lodrefine/core/confidence.h"
#include "lodrefine/core/distance.h"
#include "lodrefine/core/matching.h"
#include "lodrefine/core/shell_trace.h"
#include "lodrefine/core/validate.h"
#include "shell_supports.h"

namespace lodrefine {
namespace {

using detail::describe_candidates;
using detail::enclosing_changes;
using detail::FaceIndex;
using detail::FaceProps;
using detail::kCell;
using detail::near_vertical;
using detail::Supports;
// A sharp edge costs lambda_complexity * its length * this width (m): the complexity term in the
// coverage term's units (m²), independent of how large the region is.
constexpr double kSharpEdgeWidth = 0.25;

// A boolean face map of `cs` as 0/1 per candidate (a selection).
std::vector<char> face_flags(const CandidateSet& cs, const CandidateMap<bool>& map) {
  std::vector<char> out;
  for (auto f : cs.mesh.faces()) out.push_back(char(map[f]));
  return out;
}

std::vector<char> kept(const std::vector<char>& v, const std::vector<char>& keep) {
  std::vector<char> out;
  for (std::size_t f = 0; f < v.size(); ++f)
    if (keep[f]) out.push_back(v[f]);
  return out;
}

// Output vertices within this (m) of a starting-shell vertex are put back on it: the plane meets
// of the arrangement only approximate a model that is planar within tolerance, and where the
// selection changed nothing a roof must not move by that. Used only when the shell still
// validates after it.
constexpr double kSnapBack = 0.03;

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

// m: a changed candidate with a corner farther than this from every scan point the selection
// used, in plan, is a change the scan did not ask for (a roof re-cut far from every scanned
// facade): such candidates keep their starting-shell value. In plan, as the
// roof above a moved facade must follow it however high it is. A step's facade also reaches the
// volume between it and the start wall it replaces, however deep (detail::step_volume_samples).
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

// The starting shell as a selection of candidates: its faces are unions of candidates up to
// where its vertices sit off the planes' meets (a model within tolerance of its planes, planes
// merged within kSurfaceDistance), which leaves some edges used once or thrice. Those are
// mended by the nearest selection that closes: a small program over the candidates around each
// such edge (kMendRings edge-rings, more while it has no solution), the others fixed, each
// change costing its area; with `whole_last`, at last every candidate free. None of the local
// selections `excluded` is made (SelectionProgram::excluded). Empty when it cannot be mended.
constexpr int kMendRings = 2, kMendTries = 3;
constexpr int kRetries = 2;
struct MendScope {
  bool whole_last = false;   // at last, every candidate free
  double keep_weight = 1.0;  // a start candidate dropped costs this times its area, one added its area
};
std::vector<char> nearest_closed_selection(CandidateSet& cs, const std::vector<char>& in_start,
                                           const SelectionConfig& prm, const MendScope& scope = {},
                                           const std::vector<LocalSelection>& excluded = {}) {
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
    const auto area = cs.areas();
    for (int f = 0; f < cs.size(); ++f) {
      pg.cost.push_back(in_start[f] ? -scope.keep_weight * area[FaceIndex(f)] : area[FaceIndex(f)]);
      pg.fixed.push_back(near[f] ? -1 : int(in_start[f]));
    }
    pg.sharp_cost.assign(cs.edges.size(), 0.0);
    pg.excluded = excluded;
    SelectionConfig mend = prm;  // the costs are areas: weight 1
    mend.lambda_coverage = 1.0;
    const SelectionResult r = select_faces(cs, pg, mend);
    if (r.ok) return selected_faces(cs);
  }
  return {};
}

// A real building's program (thousands of columns) spends its work budget at the root: GLPK ends
// with its warm start though a selection far better exists (found with 300 times the budget). So
// the warm start is first improved where the scan asks for a change: each scanned plane's
// neighbourhood (the free candidates with a corner within kEvidenceReach of its points, in plan)
// is solved alone, every other candidate fixed at the incumbent, in turn; each such program is
// small, and its answer is at least as good as the incumbent it started from (which GLPK holds).
// Together they spend one work budget, shared evenly: the selection then costs at most twice it.
// Returns the improved incumbent and counts the neighbourhoods that changed it.
std::vector<char> improved_by_neighbourhoods(CandidateSet& cs, const SelectionProgram& pg, const Supports& s,
                                             const SelectionConfig& prm, int& improved) {
  std::vector<char> current = pg.warm;
  const auto scanned = std::count_if(s.points.begin(), s.points.end(), [](const auto& p) { return !p.empty(); });
  SelectionConfig share = prm;
  share.mip_work_limit = prm.mip_work_limit / double(std::max<std::ptrdiff_t>(1, scanned));
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
    if (free == 0) continue;
    if (!select_faces(cs, local, share).ok) continue;
    const std::vector<char> selected = selected_faces(cs);
    if (selected != current) ++improved;
    current = selected;
  }
  return current;
}

// Buildings with fewer supporting planes are cut over the whole region (every dev tile building:
// at most 31); local sections, which bound the large ones, changed a small real building's
// program enough to lose its refinement (RealData.ThreeDBagSeqMovedWall).
constexpr int kLocalSectionsFrom = 32;

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

// The supporting planes of a selection: the starting shell's (`sliver_tolerance`: see
// add_start_planes), the scan's and the step walls, counted in `st` with the evidence they hold.
Supports supports_of(const Mesh& start, const PointCloud& cloud, const std::vector<ScanPlane>& planes,
                     const RefineConfig& prm, double sliver_tolerance, ShellSelectionStats& st) {
  Supports s;
  detail::add_start_planes(start, sliver_tolerance, s);
  detail::add_scan_planes(start, cloud, planes, prm, s);
  const int before_steps = int(s.planes.size());
  detail::add_step_walls(start, prm, s);
  st.step_walls = int(s.planes.size()) - before_steps;
  st.supporting_planes = int(s.planes.size());
  st.scan_planes_added = s.added;
  for (const auto& pts : s.points) st.evidence.insert(st.evidence.end(), pts.begin(), pts.end());
  return s;
}

// The program over the candidates: coverage and data-fitting terms, sharp edges; with a `warm`
// start, it is the first incumbent and every candidate no evidence reaches is fixed to it.
SelectionProgram program_of(CandidateSet& cs, const FaceProps& props, const std::vector<char>& warm,
                            const SelectionConfig& prm) {
  SelectionProgram pg;
  const auto area = cs.areas();
  for (int f = 0; f < cs.size(); ++f) {
    pg.cost.push_back(coverage_cost(area[FaceIndex(f)], props.confidence[FaceIndex(f)], prm.tau_cov));
    pg.fit.push_back(props.fit[FaceIndex(f)]);
  }
  for (const auto& e : cs.edges) pg.sharp_cost.push_back(prm.lambda_complexity * cs.length(e) * kSharpEdgeWidth);
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

// The selection with the start's slivers on the planes they lie on within `sliver_tolerance`
// (negative: none); nothing when some are and the starting shell then cannot be expressed in the
// candidates (its pieces cannot be mended to close): select_shell then gives each sliver a plane
// of its own, as it is. The starting shell (mended where it does not close on the candidates) is
// GLPK's first incumbent, and what no evidence reaches is fixed to it; without one everything is
// free. Each plane is cut to where its faces can be (its start faces and scan points, grown by
// twice the farthest a wall may move: a face reaches a moved neighbour, whose corner with the next
// moved wall lies that far again; once measured lost a real building's refinement), so a large
// building's program does not grow with the cube of its planes.
std::optional<ShellSelection> select_shell_joining_slivers(const Mesh& start, const PointCloud& cloud,
                                                           const std::vector<ScanPlane>& planes,
                                                           const RefineConfig& prm, double sliver_tolerance) {
  const auto t0 = Clock::now();
  ShellSelection out;
  auto& st = out.stats;
  const Supports s = supports_of(start, cloud, planes, prm, sliver_tolerance, st);

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
  if (all_warm.empty() && s.slivers > 0) return std::nullopt;
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

// A soup's planes are cut over the whole region up to this many candidates (a local section
// can end a plane short of where a part closes); beyond, within kRebuildReach (m) of their own
// faces and open or overused edges, up to as many again: a larger program is refused (GLPK's
// root LP of 60,000 columns took seconds its work budget does not count: time, not work, ended
// it).
constexpr int kRebuildWholeRegion = 10000;
constexpr double kRebuildReach = 1.0;
// A covered candidate dropped costs this times what an uncovered one added costs (per m²): a
// missing wall is added whatever its size, and only what crosses another face is dropped.
constexpr double kKeepCover = 10.0;
// Spacing (m) of the samples the rebuild's distances are measured on, both ways; wider for a
// soup so large that it would take more than kMaxRebuildSamples (each face's grid spans its box).
constexpr double kRebuildSampling = 0.25;
constexpr double kMaxRebuildSamples = 250000;
// The most triangle-sample terms the winding numbers may take per building (each sample farther
// than the tolerance from the shell costs the soup's triangles); past it, a sample counts as
// uncovered: the rebuild is refused rather than slow (untrusted input).
constexpr double kMaxWindingTerms = 2e8;

// The selection of the candidates at each point where the traced `shell` is no 2-manifold
// (pinched_vertices): one the edge constraints allow that no solid is. Each is then excluded and
// the program solved again (a candidate added there or one dropped), at most kPinchRounds times.
constexpr int kPinchRounds = 4;
std::vector<LocalSelection> pinches(const CandidateSet& cs, const std::vector<char>& chosen, const Mesh& shell) {
  std::vector<LocalSelection> out;
  for (int v : pinched_vertices(shell)) {
    const Vec3& p = shell.vertices[std::size_t(v)];
    LocalSelection at;
    for (int f = 0; f < cs.size(); ++f) {
      const std::vector<int> corners = cs.corners(f);
      if (std::any_of(corners.begin(), corners.end(),
                      [&](int c) { return (cs.vertices[std::size_t(c)] - p).norm() < 1e-9; }))
        (chosen[f] ? at.selected : at.unselected).push_back(f);
    }
    if (!at.selected.empty()) out.push_back(std::move(at));
  }
  return out;
}

void set_selected(CandidateSet& cs, const std::vector<char>& chosen) {
  auto map = candidate_props::selected.add(cs.mesh);
  for (int f = 0; f < cs.size(); ++f) map[FaceIndex(f)] = chosen[f] != 0;
}

// The spacing of `m`'s samples: kRebuildSampling, or wider where its faces' boxes (bounded by
// their diagonals) would hold more than kMaxRebuildSamples.
double sample_spacing(const Mesh& m) {
  double box_area = 0.0;
  for (const Face& f : m.faces) box_area += bounding_box(face_points(m, f)).sizes().squaredNorm();
  return std::max(kRebuildSampling, std::sqrt(box_area / kMaxRebuildSamples));
}

// The samples of a face: a grid every `spacing`, and its vertices moved a hundredth of the way to
// its centroid (inside the face, off its neighbours).
std::vector<Vec3> face_samples(const Mesh& m, int f, double spacing) {
  std::vector<Vec3> pts = sample_faces(m, {f}, spacing);
  const std::vector<Vec3> corners = face_points(m, m.faces[std::size_t(f)]);
  const Vec3 c = polygon_centroid(corners);
  for (const Vec3& p : corners) pts.push_back(p + 0.01 * (c - p));
  return pts;
}

// The shell's area on the soup (samples within `tolerance` of it) and beside it (added), and the
// farthest a sample and a vertex lie from it.
void added_area(const Mesh& shell, const Mesh& soup, double tolerance, ShellRebuild& out) {
  const MeshDistance dist(soup);
  for (const Vec3& p : shell.vertices) out.corner_to_input = std::max(out.corner_to_input, dist.distance(p, false));
  const double spacing = sample_spacing(shell);
  for (int f = 0; f < int(shell.faces.size()); ++f)
    for (const Vec3& p : sample_faces(shell, {f}, spacing)) {
      const double d = dist.distance(p, false);
      out.output_to_input = std::max(out.output_to_input, d);
      (d <= tolerance ? out.area_kept : out.area_added) += spacing * spacing;
    }
}

// The generalized winding number (Jacobson, Kavan and Sorkine-Hornung 2013) of a soup's faces, as
// read (outward): about 1 inside what they enclose, 0 outside, fractional near a hole.
class Winding {
 public:
  explicit Winding(const Mesh& soup) {
    for_each_triangle(soup, [&](const Vec3& a, const Vec3& b, const Vec3& c, int f) { tris_.push_back({a, b, c, f}); });
  }
  std::size_t triangles() const { return tris_.size(); }
  // At `p`, of the faces other than `skip`.
  double without(int skip, const Vec3& p) const {
    double sum = 0.0;
    for (const Tri& t : tris_) {
      if (t.face == skip) continue;
      const Vec3 a = t.a - p, b = t.b - p, c = t.c - p;
      const double la = a.norm(), lb = b.norm(), lc = c.norm();
      sum += 2.0 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
    }
    return sum / (4.0 * kPi);
  }

 private:
  struct Tri {
    Vec3 a, b, c;
    int face;
  };
  std::vector<Tri> tris_;
};

// A soup face's point where the rest of the soup winds more than this has the soup's volume on
// both sides: a partition between two parts. An outer wall has it on one side only (about 1/2),
// a fin on neither (less than kFinWinding).
constexpr double kPartitionWinding = 0.75;
constexpr double kFinWinding = 0.25;

// The pieces of the soup's faces outside the shell with the soup's outside on both sides (its
// winding there, without their own face, below kFinWinding): a fin, such as a neighbour's wall
// standing above the roof. No solid holds one, so it goes beside the shell, as read: each soup
// face clipped to the candidates of its plane the selection left out, in the face's orientation,
// semantic and source.
Mesh fins_beside(const CandidateSet& cs, const Supports& s, const std::vector<char>& chosen, const Mesh& soup,
                 const Mesh& shell, const Winding& winding, double tolerance) {
  constexpr double kMinPiece = 1e-4;  // m²: smaller pieces are the clipping's slivers
  std::vector<std::vector<int>> left_out(cs.planes.size());
  const auto support = cs.supports();
  for (int f = 0; f < cs.size(); ++f)
    if (!chosen[f]) left_out[std::size_t(support[FaceIndex(f)])].push_back(f);
  const MeshDistance to_shell(shell);
  Mesh fins;
  fins.id = soup.id;
  for (int sf = 0; sf < int(soup.faces.size()); ++sf) {
    const int k = s.face_plane[std::size_t(sf)];
    if (k < 0) continue;
    const Plane& plane = cs.planes[std::size_t(k)].plane;
    const auto [u, v] = plane.basis();
    const Vec3 origin = -plane.d * plane.n;
    auto flat = [&](const std::vector<Vec3>& poly) {
      std::vector<Vec2> out;
      for (const Vec3& p : poly) out.emplace_back(u.dot(p - origin), v.dot(p - origin));
      return out;
    };
    const std::vector<Vec2> face = flat(face_points(soup, soup.faces[std::size_t(sf)]));
    for (int f : left_out[std::size_t(k)]) {
      const std::vector<Vec2> piece = polygon_clipped_to_convex(face, flat(cs.polygon(f)));
      if (std::abs(signed_area_2d(piece)) < kMinPiece) continue;
      std::vector<Vec3> corners;
      for (const Vec2& q : piece) corners.push_back(origin + q.x() * u + q.y() * v);
      const Vec3 c = polygon_centroid(corners);
      if (to_shell.distance(c, true) <= tolerance || std::abs(winding.without(sf, c)) >= kFinWinding) continue;
      Face out = soup.faces[std::size_t(sf)];
      out.v.clear();
      for (const Vec3& p : corners) {
        out.v.push_back(int(fins.vertices.size()));
        fins.vertices.push_back(p);
      }
      fins.faces.push_back(std::move(out));
    }
  }
  return snapped_to_start(fins, soup);
}

// The farthest a soup sample lies from the rebuilt `shell` and the `fins` beside it (m), over the
// samples they must cover: all but a partition between parts the shell joins (inside it, the
// soup's volume on both sides). An outer wall the shell swallows is no partition, and a fin not
// carried beside it leaves the soup uncovered too. `out` gets the areas (m²) of the samples
// farther than `tolerance` from the shell: on the fins (carried), the partitions' (dropped), the
// others (uncovered) and of those a fin's.
double uncovered(const Mesh& soup, const Mesh& shell, const Mesh& fins, const Winding& winding, double tolerance,
                 ShellRebuild& out) {
  const MeshDistance dist(shell);
  const std::optional<MeshDistance> to_fins =
      fins.faces.empty() ? std::nullopt : std::make_optional<MeshDistance>(fins);
  const double spacing = sample_spacing(soup), sample_area = spacing * spacing;
  out.sampling = spacing;
  double terms = 0.0, worst = 0.0;
  for (int f = 0; f < int(soup.faces.size()); ++f)
    for (const Vec3& p : face_samples(soup, f, spacing)) {
      const double d = dist.distance(p, true);
      if (std::abs(d) <= tolerance) {
        worst = std::max(worst, std::abs(d));
        continue;
      }
      if (to_fins) {
        const double d_fin = to_fins->distance(p, false);
        if (d_fin <= tolerance) {
          worst = std::max(worst, d_fin);
          out.area_carried += sample_area;
          continue;
        }
      }
      terms += double(winding.triangles());
      const double w = terms <= kMaxWindingTerms ? winding.without(f, p) : 0.5;  // past the budget: a wall
      if (d < 0.0 && w > kPartitionWinding) {
        out.area_dropped += sample_area;
        continue;
      }
      worst = std::max(worst, std::abs(d));
      out.area_uncovered += sample_area;
      if (std::abs(w) < kFinWinding) out.area_fins += sample_area;
    }
  return worst;
}

}  // namespace

ShellRebuild rebuild_shell(const Mesh& soup, const RefineConfig& prm) {
  ShellRebuild out;
  Supports s;
  detail::add_start_planes(soup, prm.repair.planarity_tolerance, s);
  if (!detail::carries_ground(soup, s)) {
    out.reason = "it has no ground face: the foot of its walls would be invented";
    return out;
  }
  detail::add_hole_planes(soup, s);
  out.planes_added = s.hole_planes;
  const Region region = detail::building_region(soup, s, prm.plane.facade_max_tilt_deg);
  CandidateSet cs = build_candidates(s.planes, region, {}, kRebuildWholeRegion);
  if (cs.capped) {
    std::vector<Vec3> open_ends;
    for (const auto& [key, uses] : edge_uses(soup.faces))
      if (uses.size() != 2) open_ends.insert(open_ends.end(), {soup.vertices[key.first], soup.vertices[key.second]});
    cs = build_candidates(s.planes, region, detail::plane_reach(soup, s, region, kRebuildReach, open_ends),
                          kRebuildWholeRegion);
  }
  if (cs.capped) {
    out.reason = "too many candidate faces (over " + std::to_string(kRebuildWholeRegion) + " from " +
                 std::to_string(s.planes.size()) + " planes)";
    return out;
  }
  const FaceProps props = describe_candidates(cs, soup, s, prm);
  const std::vector<char> cover = face_flags(cs, props.in_start);
  std::vector<char> chosen;
  std::vector<LocalSelection> excluded;
  for (int round = 0;; ++round) {
    chosen = nearest_closed_selection(cs, cover, prm.selection, {true, kKeepCover}, excluded);
    if (chosen.empty()) {
      out.reason = "its planes bound no closed shell";
      return out;
    }
    set_selected(cs, chosen);
    out.mesh = traced_shell(cs);
    out.mesh.id = soup.id;
    const std::string problem = shell_problem(out.mesh, prm.repair);
    if (problem.empty()) break;
    const std::vector<LocalSelection> more = pinches(cs, chosen, out.mesh);
    if (more.empty() || round == kPinchRounds) {
      out.reason = "the shell on its planes is invalid: " + problem;
      return out;
    }
    excluded.insert(excluded.end(), more.begin(), more.end());
  }
  for (int f = 0; f < cs.size(); ++f) out.candidates_changed += chosen[f] != cover[f];
  Mesh snapped = snapped_to_start(out.mesh, soup);
  if (shell_problem(snapped, prm.repair).empty()) out.mesh = std::move(snapped);
  const Winding winding(soup);
  out.fins = fins_beside(cs, s, chosen, soup, out.mesh, winding, prm.repair.weld_tolerance);
  out.input_to_output = uncovered(soup, out.mesh, out.fins, winding, prm.repair.weld_tolerance, out);
  added_area(out.mesh, soup, prm.repair.weld_tolerance, out);
  out.ok = true;
  return out;
}

ShellSelection select_shell(const Mesh& start, const PointCloud& cloud, const std::vector<ScanPlane>& planes,
                            const RefineConfig& prm) {
  if (auto joined = select_shell_joining_slivers(start, cloud, planes, prm, prm.repair.planarity_tolerance))
    return *joined;
  return *select_shell_joining_slivers(start, cloud, planes, prm, -1.0);  // no slivers: always a selection
}

}  // namespace lodrefine
