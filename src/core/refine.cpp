// The pipeline (paper Sec. 3), as orchestration only: each stage's logic lives in its module.
#include "lodrefine/core/refine.h"

#include <chrono>
#include <cmath>
#include <optional>
#include <set>

#include "lodrefine/core/corners.h"
#include "lodrefine/core/distance.h"
#include "lodrefine/core/shell_selection.h"
#include "lodrefine/core/substitute.h"

namespace lodrefine {
namespace {


// m: local frames have their origin on this grid (the model's box minimum rounded down), so all
// computation runs on coordinates of a few hundred metres and reports show a readable origin.
constexpr double kOriginGrid = 100.0;
// A wall's position for "tried already" in the fallback: its centroid's squared norm in 1/this m²
// steps (the same wall re-found after another moved has the same position within rounding).
constexpr double kPositionSteps = 100.0;


// The cloud near the model, in its local frame (crops may carry whole streets): the model's
// box grown by the matching distance and the arrangement's region margins.
PointCloud cloud_near(const Mesh& local_model, const PointCloud& cloud, const Vec3& origin, const Params& prm) {
  const Eigen::AlignedBox3d box = bounding_box(local_model.vertices);
  const Vec3 pad = Vec3::Constant(prm.match_distance + prm.bbox_margin) + prm.bbox_expand * box.sizes();
  const Eigen::AlignedBox3d near(box.min() - pad, box.max() + pad);
  PointCloud local;
  for (const auto& p : cloud.points)
    if (near.contains(p - origin)) local.points.push_back(p - origin);
  return local;
}

// A moved wall for the report, on the mesh (and its surfaces) the move was made on.
RefineTrace::FacadeMove describe_move(const Mesh& mesh, const std::vector<ModelSurface>& surfaces,
                                      const WallMove& move, const char* evidence) {
  const ModelSurface& s = surfaces[move.surface];
  double mean = 0.0, n = 0.0;
  for (int f : s.faces)
    for (int v : mesh.faces[f].v) mean += std::abs(move.plane.distance(mesh.vertices[v])), n += 1.0;
  RefineTrace::FacadeMove d;
  for (int f : s.faces) d.input_faces.insert(mesh.faces[f].source);
  d.evidence = evidence;
  d.max_move = surface_deviation(mesh, s, move.plane);
  d.mean_move = n > 0 ? mean / n : 0.0;
  for (int f : s.faces) d.wall.polygons.push_back(face_points(mesh, mesh.faces[f]));
  d.wall.from = s.plane;
  d.wall.to = move.plane;
  d.wall.corner = d.evidence == "corner";
  return d;
}

// Substitution on `mesh`, merged and validated; `attempt` says what happened.
std::optional<Mesh> substitute_valid(const Mesh& mesh, const std::vector<ModelSurface>& surfaces,
                                     const std::vector<WallMove>& moves, const Params& prm,
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

// The starting shell's fallback: one wall at a time, the best-matching outdated one first, each
// by substitution, re-matching on the new model after each. Returns the model once any wall
// moved.
std::optional<Mesh> one_wall_at_a_time(const Mesh& start, const PointCloud& local, const std::vector<ScanPlane>& planes,
                                       const Params& prm, RefineTrace& trace) {
  // Each (scan plane, wall position) is tried once: a wall that would not move is not retried,
  // and the loop ends even when moves undo each other.
  const int max_steps = 4 * int(planes.size()) + 4;
  auto& steps = *trace.replacements;
  Mesh step_mesh = start;
  bool any = false;
  std::set<std::pair<int, long long>> tried;  // (scan plane, rounded wall position)
  auto position = [](const ModelSurface& s) { return (long long)std::llround(s.centroid.squaredNorm() * kPositionSteps); };
  for (int iter = 0; iter < max_steps; ++iter) {
    const auto ss = model_surfaces(step_mesh);
    const MatchResult mi = match_surfaces(step_mesh, ss, local, planes, prm);
    const Match* next = nullptr;
    for (const auto& m : mi.matches) {
      if (tried.count({m.scan_plane, position(ss[m.surface])}) ||
          surface_deviation(step_mesh, ss[m.surface], planes[m.scan_plane].plane) <= prm.change_tolerance)
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
    std::optional<Mesh> m = substitute_valid(step_mesh, ss, {{next->surface, plane}}, prm, attempt);
    step.ok = bool(m);
    if (!m) step.reason = attempt.reason;
    steps.push_back(step);
    if (m) {
      trace.facades.push_back(describe_move(step_mesh, ss, {next->surface, plane}, "scan"));
      step_mesh = std::move(*m);
      step_mesh.id = start.id;
      any = true;
    }
  }
  if (!any) return std::nullopt;
  return step_mesh;
}

}  // namespace

const char* outcome_name(Outcome outcome) {
  switch (outcome) {
    case Outcome::Refined: return "refined";
    case Outcome::Kept: return "kept";
    case Outcome::KeptInvalid: return "kept-invalid";
  }
  return "?";
}

// The starting shell: every outdated wall takes its scan plane at once, the model's topology
// kept (without the corner moves if those spoil it; else one wall at a time); none when no wall
// is outdated or none could be moved. Records the moves made in `trace.facades`.
std::optional<Mesh> starting_shell(const Mesh& current, const std::vector<ModelSurface>& surfaces,
                                   const std::vector<WallMove>& moves, const std::vector<CornerMove>& corners,
                                   const PointCloud& local, const std::vector<ScanPlane>& planes, const Params& prm,
                                   RefineTrace& trace) {
  std::vector<WallMove> all = moves;
  for (const auto& c : corners) all.push_back(c.move);
  std::optional<Mesh> refined;
  trace.substitution.reset();
  trace.substitution_without_corners.reset();
  if (!all.empty())
    refined = substitute_valid(current, surfaces, all, prm, trace.substitution.emplace(RefineTrace::Substitution{}));
  if (refined) {
    for (const auto& mv : moves) trace.facades.push_back(describe_move(current, surfaces, mv, "scan"));
    for (const auto& c : corners) trace.facades.push_back(describe_move(current, surfaces, c.move, "corner"));
  } else if (!corners.empty() && !moves.empty()) {
    refined = substitute_valid(current, surfaces, moves, prm,
                               trace.substitution_without_corners.emplace(RefineTrace::Substitution{}));
    if (refined)
      for (const auto& mv : moves) trace.facades.push_back(describe_move(current, surfaces, mv, "scan"));
  }
  trace.replacements.emplace();
  if (!refined && !all.empty()) refined = one_wall_at_a_time(current, local, planes, prm, trace);
  return refined;
}

Vec3 local_origin(const Mesh& model) {
  if (model.vertices.empty()) return Vec3::Zero();
  const Vec3 lo = bounding_box(model.vertices).min();
  if (!lo.allFinite()) return Vec3::Zero();
  return (lo / kOriginGrid).array().floor().matrix() * kOriginGrid;
}

RefineResult refine_building(const Mesh& model, const PointCloud& cloud, const Params& prm) {
  prm.validate();
  const auto t_start = Clock::now();
  RefineResult out;
  RefineTrace& trace = out.trace;
  trace.id = model.id;
  const Vec3 origin = local_origin(model);
  trace.origin = origin;
  auto t = Clock::now();
  auto lap = [&](const char* stage) {
    trace.seconds.emplace_back(stage, seconds_since(t));
    t = Clock::now();
  };
  auto finish = [&](Outcome outcome, const std::string& reason, const Mesh& local_mesh, bool single_shell = true) {
    out.outcome = outcome;
    out.reason = reason;
    trace.output_validation = validate_mesh(local_mesh, prm.planarity_tolerance, true, single_shell);
    out.valid = trace.output_validation.valid();
    trace.faces = local_mesh.faces.size();
    trace.seconds.emplace_back("total", seconds_since(t_start));
    out.mesh = translated(local_mesh, origin);
    out.mesh.id = model.id;
    return out;
  };

  // Repair the exported soup into a closed shell; a model that cannot be made one is written as
  // read (kept-invalid) with the reason.
  const Mesh local_model = translated(model, -origin);
  RepairReport rr;
  Mesh kept;
  try {
    kept = repair_input(local_model, prm, rr);
  } catch (const InputError& e) {
    lap("repair");
    return finish(Outcome::KeptInvalid, e.what(), local_model);
  }
  kept.id = model.id;
  trace.repair = rr;
  const Validation v0 = validate_mesh(kept, prm.planarity_tolerance);
  trace.input_validation = v0;
  lap("repair");
  if (!v0.valid() && v0.components > 1 && validate_mesh(kept, prm.planarity_tolerance, true, false).valid())
    // Several closed shells (a multi-part export): each valid, the building kept whole.
    return finish(Outcome::Kept, std::to_string(v0.components) + " separate closed shells: kept whole", kept, false);
  if (!v0.valid()) return finish(Outcome::KeptInvalid, "the input is no valid solid: " + v0.problem, local_model);
  Mesh current = merge_coplanar_faces(kept);
  current.id = model.id;

  // Planes of the scan near the model.
  const PointCloud local = cloud_near(current, cloud, origin, prm);
  trace.cloud = {cloud.points.size(), local.points.size()};
  const auto planes = detect_planes(local, prm);
  lap("planes");
  trace.planes = planes;
  if (planes.empty()) return finish(Outcome::Kept, "no planes found in the cloud near the model", kept);

  // Matching on the input: which walls the scan sees, where, and by which points; the outdated
  // ones move onto their planes, and unscanned walls at a scanned facade's end to where the
  // scan shows the corner.
  const auto surfaces = model_surfaces(current);
  const MatchResult mr = match_surfaces(current, surfaces, local, planes, prm);
  std::vector<WallMove> moves;
  std::vector<ScannedWall> scanned;
  RefineTrace::Matching& matching = trace.matching.emplace(RefineTrace::Matching{});
  for (const auto& m : mr.matches) {
    Plane pl = planes[m.scan_plane].plane;
    if (pl.n.dot(surfaces[m.surface].plane.n) < 0) pl = pl.flipped();
    scanned.push_back({m.surface, m.scan_plane, pl});
    const double dev = surface_deviation(current, surfaces[m.surface], pl);
    if (dev > prm.change_tolerance) moves.push_back({m.surface, pl, eave_follows_roof(current, surfaces, m, pl, local)});
    matching.walls.push_back({m, dev, surfaces[m.surface].faces});
  }
  matching.rejected = mr.rejected;
  matching.q_model = mr.q_model;
  const auto corners = corner_moves(current, surfaces, scanned, local, planes, prm);
  lap("matching");

  // Substitution, selection and the never-worse judge, first with the corners the scan's ends
  // show; the corners are the least certain evidence, so a refinement the judge refuses is tried
  // once more on the walls' own points alone.
  auto decide = [&](const std::vector<CornerMove>& with_corners) {
    trace.facades.clear();
    trace.judgement.reset();
    const std::optional<Mesh> start = starting_shell(current, surfaces, moves, with_corners, local, planes, prm, trace);
    lap("substitution");
    // The selection decides every face: the candidate arrangement over the starting shell's
    // planes and the scan's facades, the starting shell as GLPK's first incumbent.
    const ShellSelection chosen = select_shell(start ? *start : current, local, planes, prm);
    trace.selection = chosen.stats;
    trace.selection_reason = chosen.reason;
    lap("selection");
    if (!chosen.ok) return finish(Outcome::Kept, "the selection found no valid shell: " + chosen.reason, kept);
    if (!start && chosen.stats.candidates_changed == 0) {
      trace.facades.clear();
      return finish(Outcome::Kept, mr.matches.empty() ? "the selection kept the model (no wall matched a scan plane)"
                                                      : "the selection kept the model (the scan agrees with it)", kept);
    }
    // Never worse: on every scan point near the building, and on each moved wall's own points.
    std::vector<JudgedWall> moved;
    for (const auto& f : trace.facades) moved.push_back(f.wall);
    const Judgement& verdict = trace.judgement.emplace(judge_refinement(kept, chosen.mesh, moved, local, prm));
    if (!verdict.ok)
      return finish(Outcome::Kept, "not written: never worse, " + verdict.check + " check: " + verdict.detail, kept);
    return finish(Outcome::Refined, std::to_string(chosen.stats.faces_from_selection) + " face(s) selected, " +
                                        std::to_string(trace.facades.size()) + " wall(s) moved", chosen.mesh);
  };
  RefineResult result = decide(corners);
  if (!corners.empty() && trace.judgement && !trace.judgement->ok) {
    trace.corners_refused = trace.judgement->check + " check: " + trace.judgement->detail;
    trace.seconds.pop_back();  // the first attempt's total
    result = decide({});
  }
  return result;
}

}  // namespace lodrefine
