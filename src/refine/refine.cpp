// The pipeline (paper Sec. 3), as orchestration only: each stage's logic lives in its module.
#include "lodrefine/refine/refine.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <set>

#include "lodrefine/core/corners.h"
#include "lodrefine/core/distance.h"
#include "lodrefine/core/move_plan.h"
#include "lodrefine/core/substitute.h"
#include "lodrefine/refine/provenance.h"
#include "lodrefine/refine/shell_rebuild.h"
#include "lodrefine/refine/shell_selection.h"

namespace lodrefine {
namespace {

// m: local frames have their origin on this grid (the model's box minimum rounded down), so all
// computation runs on coordinates of a few hundred metres and reports show a readable origin.
constexpr double kOriginGrid = 100.0;
// A wall's position for "tried already" in the fallback: its centroid's squared norm in 1/this m²
// steps (the same wall re-found after another moved has the same position within rounding).
constexpr double kPositionSteps = 100.0;

// What moved a wall: the scan's plane in front of it, or the scan's corner beside it.
enum class Evidence { Scan, Corner };

// A wall the starting shell moved, on the mesh (and its surfaces) the move was made on: handed to
// the judge in `moved` (scan_surface: SubstitutedWall's) and recorded in the trace's facades.
SubstitutedWall& add_moved(const Mesh& mesh, const std::vector<ModelSurface>& surfaces, const WallMove& move,
                           Evidence evidence, int scan_surface, std::vector<SubstitutedWall>& moved,
                           RefineTrace& trace) {
  const ModelSurface& s = surfaces[move.surface];
  RefineTrace::FacadeMove d;
  for (int f : s.faces) d.input_faces.insert(mesh.faces[f].source);
  d.evidence = evidence == Evidence::Corner ? "corner" : "scan";
  d.max_move = surface_deviation(mesh, s, move.plane);
  d.mean_move = surface_mean_deviation(mesh, s, move.plane);
  trace.facades.push_back(std::move(d));
  SubstitutedWall& w = moved.emplace_back();
  for (int f : s.faces) w.wall.polygons.push_back(face_points(mesh, mesh.faces[f]));
  w.wall.from = s.plane;
  w.wall.to = move.plane;
  w.wall.corner = evidence == Evidence::Corner;
  w.scan_surface = scan_surface;
  w.input_faces = trace.facades.back().input_faces;
  return w;
}

// Substitution on `mesh`, merged and validated; `attempt` says what happened.
std::optional<Mesh> substitute_valid(const Mesh& mesh, const std::vector<ModelSurface>& surfaces,
                                     const std::vector<WallMove>& moves, const RepairConfig& prm,
                                     RefineTrace::Substitution& attempt) {
  const SubstitutionResult sub = substitute_walls(mesh, surfaces, moves, prm.planarity_tolerance);
  attempt = {};
  attempt.walls = int(moves.size());
  if (!sub.ok) {
    attempt.reason = sub.reason;
    return std::nullopt;
  }
  Mesh m = merge_coplanar_faces(sub.mesh);
  const Validation vs = validate_mesh(m, prm.planarity_tolerance);
  if (!vs.valid()) {
    attempt.reason = "substituted shell invalid: " + vs.problem;
    return std::nullopt;
  }
  attempt.ok = true;
  attempt.moved_vertices = sub.moved_vertices;
  attempt.max_vertex_move = sub.max_vertex_move;
  attempt.split_faces = sub.split_faces;
  m.id = mesh.id;
  return m;
}

// Whether surface `s` of `mesh` holds a face descending from one of the input faces `faces`.
bool holds_any(const Mesh& mesh, const ModelSurface& s, const std::set<int>& faces) {
  return std::any_of(s.faces.begin(), s.faces.end(), [&](int f) { return faces.count(mesh.faces[f].source) > 0; });
}

// The starting shell's fallback: one wall at a time, the best-matching outdated one first, each
// by substitution, re-matching on the new model after each; a wall holding one of the
// `refused_faces` stays. Returns the model once any wall moved; the walls moved go to `moved`.
std::optional<Mesh> one_wall_at_a_time(const Mesh& start, const PointCloud& local, const std::vector<ScanPlane>& planes,
                                       const std::set<int>& refused_faces, const RefineConfig& prm,
                                       std::vector<SubstitutedWall>& moved, RefineTrace& trace) {
  // Each (scan plane, wall position) is tried once: a wall that would not move is not retried,
  // and the loop ends even when moves undo each other.
  const int max_steps = 4 * int(planes.size()) + 4;
  auto& steps = *trace.replacements;
  Mesh step_mesh = start;
  bool any = false;
  std::set<std::pair<int, long long>> tried;  // (scan plane, rounded wall position)
  auto position = [](const ModelSurface& s) {
    return (long long)std::llround(s.centroid.squaredNorm() * kPositionSteps);
  };
  for (int iter = 0; iter < max_steps; ++iter) {
    const auto ss = model_surfaces(step_mesh);
    const MatchResult mi = match_surfaces(step_mesh, ss, local, planes, prm.match);
    const Match* next = nullptr;
    for (const auto& m : mi.matches) {
      if (tried.count({m.scan_plane, position(ss[m.surface])}) || holds_any(step_mesh, ss[m.surface], refused_faces) ||
          surface_deviation(step_mesh, ss[m.surface], planes[m.scan_plane].plane) <= prm.match.change_tolerance)
        continue;
      if (next == nullptr || m.s_match > next->s_match) next = &m;
    }
    if (next == nullptr) break;
    const auto& surf = ss[next->surface];
    tried.insert({next->scan_plane, position(surf)});
    Plane plane = planes[next->scan_plane].plane;
    if (plane.n.dot(surf.plane.n) < 0) plane = plane.flipped();
    RefineTrace::Step step;
    step.scan_plane = next->scan_plane;
    step.wall_faces = surf.faces;
    step.moved_by = surface_deviation(step_mesh, surf, plane);
    step.method = "substitution";
    RefineTrace::Substitution attempt;
    std::optional<Mesh> m = substitute_valid(step_mesh, ss, {{next->surface, plane}}, prm.repair, attempt);
    step.ok = bool(m);
    if (!m) step.reason = attempt.reason;
    steps.push_back(step);
    if (m) {
      add_moved(step_mesh, ss, {next->surface, plane}, Evidence::Scan, -1, moved, trace);
      step_mesh = std::move(*m);
      step_mesh.id = start.id;
      any = true;
    }
  }
  if (!any) return std::nullopt;
  return step_mesh;
}

// What a rebuild mended, for the reason of a repaired building.
std::string rebuild_summary(const ShellRebuild& rb) {
  char buf[160];
  std::snprintf(buf, sizeof buf,
                "shell rebuilt on its planes (%.1f m² added, %.1f m² of partitions dropped, %d "
                "piece(s) changed)",
                rb.area_added, rb.area_dropped, rb.candidates_changed);
  std::string out = buf;
  if (!rb.fins.faces.empty()) {
    std::snprintf(buf, sizeof buf, ", %.1f m² of fins beside it (outside on both sides: no solid holds them)",
                  rb.area_carried);
    out += buf;
  }
  return out;
}

// One building's refinement under way: the result being filled, its local frame, the input as
// read in it, its rebuild's fins (when the input was rebuilt) and the stage timer.
class Refinement {
 public:
  Refinement(const Mesh& model, double planarity_tolerance) : planarity_tolerance_(planarity_tolerance) {
    out_.trace.id = model.id;
    origin_ = local_origin(model);
    out_.trace.origin = origin_;
    id_ = model.id;
    as_read_ = translated(model, -origin_);
  }
  const Vec3& origin() const { return origin_; }
  const Mesh& as_read() const { return as_read_; }  // the input in the local frame
  RefineTrace& trace() { return out_.trace; }
  // The input was no valid solid and was rebuilt on its planes (`summary`: rebuild_summary);
  // `fins` stand beside the shell.
  void rebuilt(Mesh fins, std::string summary) {
    fins_ = std::move(fins);
    rebuild_summary_ = std::move(summary);
  }
  const std::optional<Mesh>& fins() const { return fins_; }  // set once rebuilt
  // Records the time since the last lap as `stage`'s.
  void lap(RefineStage stage) {
    out_.trace.seconds.emplace_back(stage_name(stage), seconds_since(t_));
    t_ = Clock::now();
  }
  // The result: `local_mesh` validated, its outcome decided (decide_outcome: an output that does
  // not validate gives way to the input as read), written back in the input frame.
  RefineResult finish(Ending ending, const std::string& reason, const Mesh& local_mesh, bool single_shell = true) {
    RefineTrace& trace = out_.trace;
    trace.output_validation = validate_mesh(local_mesh, planarity_tolerance_, true, single_shell);
    const bool mended = fins_.has_value();
    out_.outcome = decide_outcome({ending, mended, trace.output_validation.valid()});
    out_.reason = ending == Ending::Kept && mended ? rebuild_summary_ + "; " + reason : reason;
    const bool refused = out_.outcome == Outcome::KeptInvalid && ending != Ending::AsRead;
    if (refused) {
      out_.reason += " (not valid: " + trace.output_validation.problem + ")";
      trace.output_validation = validate_mesh(as_read_, planarity_tolerance_, true, single_shell);
    }
    const Mesh& written = refused ? as_read_ : local_mesh;
    out_.valid = trace.output_validation.valid();
    trace.faces = written.faces.size();
    lap(RefineStage::Validation);
    trace.seconds.emplace_back("total", seconds_since(t_start_));
    out_.mesh = translated(written, origin_);
    out_.mesh.id = id_;
    if (fins_ && out_.outcome != Outcome::KeptInvalid) {
      out_.fins = translated(*fins_, origin_);
      out_.fins.id = id_;
    }
    if (out_.outcome == Outcome::Refined || out_.outcome == Outcome::Repaired) {  // written: each face says whence
      complete_provenance(out_.mesh);
      complete_provenance(out_.fins);
    }
    return out_;
  }

 private:
  RefineResult out_;
  Vec3 origin_;
  std::string id_;
  Mesh as_read_;
  std::optional<Mesh> fins_;
  std::string rebuild_summary_;
  double planarity_tolerance_;
  Clock::time_point t_start_ = Clock::now(), t_ = t_start_;
};

// Repairs the exported soup into a closed shell (`kept`). Returns the building's result when
// it ends here: several closed shells (a multi-part export) are each valid and kept whole; a
// soup that welding and orientation cannot make one valid solid is rebuilt on its planes
// (rebuild_shell), and written as read (kept-invalid) with the reason when that fails too or
// the rebuilt shell leaves the input's surfaces by more than weld_tolerance.
std::optional<RefineResult> repair_or_stop(const Mesh& local_model, const RefineConfig& cfg, Refinement& refinement,
                                           Mesh& kept) {
  RefineTrace& trace = refinement.trace();
  if (const std::string too_large = size_problem(local_model); !too_large.empty()) {
    refinement.lap(RefineStage::Repair);
    return refinement.finish(Ending::AsRead, too_large, local_model);
  }
  std::string invalid;
  try {
    RepairReport rr;
    kept = repair_input(local_model, cfg.repair, rr);
    kept.id = local_model.id;
    trace.repair = rr;
    const Validation v0 = validate_mesh(kept, cfg.repair.planarity_tolerance);
    trace.input_validation = v0;
    if (v0.valid()) {
      refinement.lap(RefineStage::Repair);
      return std::nullopt;
    }
    if (v0.components > 1 && validate_mesh(kept, cfg.repair.planarity_tolerance, true, false).valid()) {
      refinement.lap(RefineStage::Repair);
      return refinement.finish(Ending::Kept, std::to_string(v0.components) + " separate closed shells: kept whole",
                               kept, false);
    }
    invalid = "the input is no valid solid: " + v0.problem;
  } catch (const InputError& e) {
    invalid = e.what();
  }
  trace.invalid_input = invalid;
  ShellRebuild rb;
  try {
    rb = rebuild_shell(welded_soup(local_model, cfg.repair.weld_tolerance), cfg);
  } catch (const InputError& e) {
    rb.reason = e.what();
  }
  refinement.lap(RefineStage::Repair);
  if (rb.ok && rb.input_to_output <= cfg.repair.weld_tolerance && rb.corner_to_input > cfg.repair.weld_tolerance) {
    rb.ok = false;
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "its shell on its planes has a corner %.3f m off its faces (walls added only between its own edges)",
                  rb.corner_to_input);
    rb.reason = buf;
  }
  if (rb.ok && rb.input_to_output > cfg.repair.weld_tolerance) {
    rb.ok = false;
    char buf[160];
    if (rb.area_fins >= 0.5 * rb.area_uncovered)  // mostly a fin
      std::snprintf(buf, sizeof buf,
                    "%.1f m² of it is a fin (outside on both sides: no solid holds it); its shell on its planes "
                    "leaves its faces uncovered by up to %.3f m",
                    rb.area_fins, rb.input_to_output);
    else
      std::snprintf(buf, sizeof buf, "its shell on its planes leaves %.1f m² of its faces uncovered, by up to %.3f m",
                    rb.area_uncovered, rb.input_to_output);
    rb.reason = buf;
  }
  Mesh rebuilt = std::move(rb.mesh);
  rb.mesh = Mesh();  // the trace keeps the figures; the shell goes on as `kept`
  if (rb.ok) refinement.rebuilt(rb.fins, rebuild_summary(rb));
  trace.rebuild = rb;
  if (!rb.ok) return refinement.finish(Ending::AsRead, invalid + "; not rebuilt: " + rb.reason, local_model);
  kept = std::move(rebuilt);
  kept.id = local_model.id;
  return std::nullopt;
}

// The walls the scan sees, each on its scan plane (oriented like the wall), and of those the
// outdated ones (off their plane by more than change_tolerance) as the plan's scan moves (on
// plan.surfaces); recorded in the trace.
void outdated_walls(const Mesh& current, const MatchResult& mr, const std::vector<ScanPlane>& planes,
                    const PointCloud& local, const MatchConfig& cfg, RefineTrace& trace, MovePlan& plan,
                    std::vector<ScannedWall>& scanned) {
  const std::vector<ModelSurface>& surfaces = plan.surfaces;
  RefineTrace::Matching& matching = trace.matching.emplace(RefineTrace::Matching{});
  for (const auto& m : mr.matches) {
    Plane pl = planes[m.scan_plane].plane;
    if (pl.n.dot(surfaces[m.surface].plane.n) < 0) pl = pl.flipped();
    scanned.push_back({m.surface, m.scan_plane, pl});
    const double dev = surface_deviation(current, surfaces[m.surface], pl);
    if (dev > cfg.change_tolerance)
      plan.scan.push_back({m.surface, pl, eave_follows_roof(current, surfaces, m, pl, local)});
    matching.walls.push_back({m, dev, surfaces[m.surface].faces});
  }
  matching.rejected = mr.rejected;
  matching.q_model = mr.q_model;
}

// The starting shell: every move of the plan at once, the model's topology kept, else one wall at
// a time; none when no wall is outdated or none could be moved. The walls it moved go to
// plan.moved (and the trace's facades).
std::optional<Mesh> starting_shell(const Mesh& current, MovePlan& plan, const PointCloud& local,
                                   const std::vector<ScanPlane>& planes, const RefineConfig& prm, RefineTrace& trace) {
  plan.moved.clear();
  std::vector<WallMove> all = plan.scan;
  for (const auto& c : plan.corners) all.push_back(c.move);
  std::optional<Mesh> refined;
  if (!all.empty())
    refined = substitute_valid(current, plan.surfaces, all, prm.repair,
                               trace.substitution.emplace(RefineTrace::Substitution{}));
  if (refined) {
    for (const auto& mv : plan.scan)
      add_moved(current, plan.surfaces, mv, Evidence::Scan, mv.surface, plan.moved, trace);
    for (const auto& c : plan.corners)
      add_moved(current, plan.surfaces, c.move, Evidence::Corner, -1, plan.moved, trace).wall.flush_facade =
          c.flush_facade;
  }
  trace.replacements.emplace();
  if (!refined && !all.empty())
    refined = one_wall_at_a_time(current, local, planes, plan.refused_faces, prm, plan.moved, trace);
  return refined;
}

// Whether the fins stand on `shell` where they stood on `rebuilt`: every fin vertex within
// `tolerance` of the rebuilt shell is within it of `shell` (a refinement that moves the wall a fin
// stood on would leave it floating).
bool fins_stay_on(const Mesh& fins, const Mesh& rebuilt, const Mesh& shell, double tolerance) {
  if (fins.faces.empty()) return true;
  const MeshDistance before(rebuilt), after(shell);
  return std::all_of(fins.vertices.begin(), fins.vertices.end(), [&](const Vec3& p) {
    return before.distance(p, false) > tolerance || after.distance(p, false) <= tolerance;
  });
}

// The reason of a building the selection kept as it was.
std::string kept_by_selection(const ShellSelectionStats& stats, bool any_match) {
  if (!any_match) return "the selection kept the model (no wall matched a scan plane)";
  // A search stopped by its budget on its first incumbent says nothing of the scan.
  if (stats.selection.status == SolveStatus::FeasibleBudget)
    return "the selection kept the model (the work budget ended on the starting shell)";
  if (stats.selection.status == SolveStatus::FeasibleTimeLimit)
    return "the selection kept the model (the time limit ended on the starting shell)";
  return "the selection kept the model (the scan agrees with it)";
}

// The selection decides every face: the candidate arrangement over the starting shell's planes
// and the scan's facades, the starting shell as GLPK's first incumbent (without a substitution,
// with the plan's scan moves on their scan planes: select_shell's `outdated`). The result is
// written only when it is never worse, on every scan point near the building and on each wall
// the starting shell moved (plan.moved), on its own points (judge.h); `verdict` is the judge's,
// when it judged.
RefineResult select_and_judge(const Mesh& kept, const Mesh& current, const std::optional<Mesh>& refined, bool any_match,
                              const MovePlan& plan, const PointCloud& local, const std::vector<ScanPlane>& planes,
                              const RefineConfig& prm, Refinement& refinement, std::optional<Judgement>& verdict) {
  RefineTrace& trace = refinement.trace();
  const ShellSelection chosen =
      refined ? select_shell(*refined, local, planes, prm) : select_shell(current, local, planes, prm, plan);
  trace.selection = chosen.stats;
  trace.selection_reason = chosen.reason;
  refinement.lap(RefineStage::Selection);
  // A search that ends with no shell falls back to the best shell known: the substitution's.
  if (!chosen.ok && !refined)
    return refinement.finish(Ending::Kept, "the selection found no valid shell: " + chosen.reason, kept);
  const Mesh& shell = chosen.ok ? chosen.mesh : *refined;
  if (chosen.ok && !refined && chosen.stats.candidates_changed == 0) {
    trace.facades.clear();
    return refinement.finish(Ending::Kept, kept_by_selection(chosen.stats, any_match), kept);
  }
  verdict = judge_refinement(kept, shell, judged_walls(plan), local, prm.match, prm.plane, planes, prm.scan_reach());
  trace.judgement = verdict;
  refinement.lap(RefineStage::Judge);
  if (!verdict->ok) return refinement.finish(Ending::Kept, "not written: never worse, " + verdict->refusal(), kept);
  if (refinement.fins() && !fins_stay_on(*refinement.fins(), kept, shell, prm.repair.weld_tolerance))
    return refinement.finish(Ending::Kept, "not written: a fin beside the shell would stand apart from it", kept);
  const std::string moved_walls = std::to_string(plan.moved.size()) + " wall(s) moved";
  Mesh written = shell;
  measure_coverage(written, local, planes, prm);
  if (!chosen.ok)
    return refinement.finish(
        Ending::Refined, moved_walls + " by substitution (the selection found no valid shell: " + chosen.reason + ")",
        written);
  return refinement.finish(Ending::Refined,
                           std::to_string(chosen.stats.faces_from_selection) + " face(s) selected, " + moved_walls,
                           written);
}

}  // namespace

PointCloud cloud_near(const Mesh& local_model, const PointCloud& cloud, const Vec3& origin, const RefineConfig& prm) {
  const Eigen::AlignedBox3d box = bounding_box(local_model.vertices);
  const Vec3 pad = Vec3::Constant(prm.scan_reach()) + prm.selection.bbox_expand * box.sizes();
  const Eigen::AlignedBox3d near(box.min() - pad, box.max() + pad);
  PointCloud local;
  for (const auto& p : cloud.points)
    if (near.contains(p - origin)) local.points.push_back(p - origin);
  return local;
}

Vec3 local_origin(const Mesh& model) {
  if (model.vertices.empty()) return Vec3::Zero();
  const Vec3 lo = bounding_box(model.vertices).min();
  if (!lo.allFinite()) return Vec3::Zero();
  return (lo / kOriginGrid).array().floor().matrix() * kOriginGrid;
}

namespace {

// The scan's planes near the model, its doubled walls laid onto one plane in `local`, and the
// facade planes that are relief moved to `relief`.
std::vector<ScanPlane> scan_walls(const Mesh& model, PointCloud& local, const RefineConfig& prm,
                                  std::vector<ScanPlane>& relief) {
  auto planes = detect_planes(local, prm.plane);
  collapse_doubled_walls(local, planes);
  return without_relief(std::move(planes), model, local, prm.plane, &relief);
}

RefineTrace::Scan scan_summary(const std::vector<ScanPlane>& walls, const std::vector<ScanPlane>& relief,
                               std::size_t points) {
  RefineTrace::Scan s;
  std::vector<std::pair<double, std::size_t>> gaps;  // (distance, points), for the median
  std::size_t doubled_points = 0;
  for (const auto& p : walls) {
    if (p.doubled > 0)
      ++s.doubled_walls, gaps.emplace_back(p.doubled, p.inliers.size()), doubled_points += p.inliers.size();
    if (!p.facade || p.hull_area <= 0) continue;
    const double density = double(p.inliers.size()) / p.hull_area;
    s.min_density = s.min_density == 0 ? density : std::min(s.min_density, density);
    s.max_density = std::max(s.max_density, density);
  }
  std::sort(gaps.begin(), gaps.end());
  std::size_t seen = 0;
  for (const auto& [gap, n] : gaps)
    if ((seen += n) * 2 >= doubled_points) {
      s.misregistration = gap;
      break;
    }
  s.relief = relief;
  for (const auto& p : relief) s.relief_points += p.inliers.size();
  s.relief_share = points ? double(s.relief_points) / double(points) : 0.0;
  return s;
}

// Drops the move of the starting shell's wall `wall` (plan.moved; plan.surfaces are `current`'s)
// from the plan: its scan move, or for a wall the one-at-a-time fallback moved, its input faces,
// which the fallback then leaves where they are, and each scan move of a surface holding one.
// False when nothing is dropped (a corner move, or a wall dropped before).
bool drop_refused_wall(const Mesh& current, MovePlan& plan, int wall) {
  const SubstitutedWall& w = plan.moved[std::size_t(wall)];
  if (w.wall.corner) return false;
  const std::size_t refused = plan.refused_faces.size(), scan = plan.scan.size();
  if (w.scan_surface < 0) plan.refused_faces.insert(w.input_faces.begin(), w.input_faces.end());
  const std::set<int>& faces = plan.refused_faces;
  plan.scan.erase(std::remove_if(plan.scan.begin(), plan.scan.end(),
                                 [&](const WallMove& m) {
                                   return m.surface == w.scan_surface ||
                                          holds_any(current, plan.surfaces[m.surface], faces);
                                 }),
                  plan.scan.end());
  return plan.refused_faces.size() != refused || plan.scan.size() != scan;
}

}  // namespace

RefineResult refine_building(const Mesh& model, const PointCloud& cloud, const RefineConfig& prm) {
  prm.validate();
  Refinement refinement(model, prm.repair.planarity_tolerance);
  RefineTrace& trace = refinement.trace();
  Mesh kept;
  if (auto stopped = repair_or_stop(refinement.as_read(), prm, refinement, kept)) return *stopped;
  Mesh current = merge_coplanar_faces(kept);
  current.id = model.id;

  // Planes of the scan near the model: a wall seen twice is one, relief is no wall.
  PointCloud local = cloud_near(current, cloud, refinement.origin(), prm);
  trace.cloud = {cloud.points.size(), local.points.size()};
  std::vector<ScanPlane> relief;
  const auto planes = scan_walls(current, local, prm, relief);
  trace.scan = scan_summary(planes, relief, local.points.size());
  refinement.lap(RefineStage::Planes);
  trace.planes = planes;
  if (planes.empty()) return refinement.finish(Ending::Kept, "no planes found in the cloud near the model", kept);

  // Matching on the input: which walls the scan sees, where, and by which points; the outdated
  // ones move onto their planes, and unscanned walls at a scanned facade's end to where the
  // scan shows the corner. The plan carries them to the later stages (move_plan.h).
  MovePlan plan;
  plan.surfaces = model_surfaces(current);
  const MatchResult mr = match_surfaces(current, plan.surfaces, local, planes, prm.match);
  std::vector<ScannedWall> scanned;
  outdated_walls(current, mr, planes, local, prm.match, trace, plan, scanned);
  plan.corners = corner_moves(current, plan.surfaces, scanned, local, planes, prm.match, prm.plane);
  refinement.lap(RefineStage::Matching);

  // The corners are the least certain evidence: a refinement the judge refuses with them is
  // tried once more on the walls' own points alone.
  std::optional<Judgement> verdict;
  auto attempt = [&] {
    trace.facades.clear();
    trace.substitution.reset();
    const std::optional<Mesh> refined = starting_shell(current, plan, local, planes, prm, trace);
    refinement.lap(RefineStage::Substitution);
    return select_and_judge(kept, current, refined, !mr.matches.empty(), plan, local, planes, prm, refinement, verdict);
  };
  RefineResult result = attempt();
  auto refused = [&] { return verdict && !verdict->ok; };
  auto again = [&] {
    verdict.reset();
    trace.judgement.reset();
    trace.seconds.pop_back();  // the last attempt's total; its other laps add up in the report
    return attempt();
  };
  if (!plan.corners.empty() && refused()) {
    trace.corners_refused = verdict->refusal();
    plan.corners.clear();
    result = again();
  }
  // A scan move whose own wall the judge refuses (its points got farther, or it has none: a
  // plane matched that is not the wall's) says nothing of the other walls: it is dropped and the
  // building refined again on theirs.
  while (refused() && verdict->check == JudgeCheck::Wall && drop_refused_wall(current, plan, verdict->wall)) {
    trace.walls_refused.push_back(verdict->refusal());
    result = again();
  }
  return result;
}

}  // namespace lodrefine
