// The refine report: RefineResult's trace as JSON (see refine_report.h).
#include "lodrefine/city/refine_report.h"

#include "lodrefine/version.h"

namespace lodrefine {
namespace {

using json = nlohmann::json;

json substitution_json(const RefineTrace::Substitution& s) {
  json j = {{"method", "substitution"}, {"walls", s.walls}, {"ok", s.ok}};
  if (!s.ok) {
    j["reason"] = s.reason;
  } else {
    j["moved_vertices"] = s.moved_vertices;
    j["max_vertex_move"] = s.max_vertex_move;
    j["split_faces"] = s.split_faces;
  }
  return j;
}

json step_json(const RefineTrace::Step& s) {
  json j = {{"scan_plane", s.scan_plane}, {"wall_faces", s.wall_faces}, {"moved_by", s.moved_by}, {"ok", s.ok}};
  if (!s.method.empty()) j["method"] = s.method;
  if (!s.ok) j["reason"] = s.reason;
  return j;
}

json selection_json(const ShellSelectionStats& st, const std::string& reason) {
  const SelectionResult& m = st.selection;
  json j = {{"status", m.status_text()},
            {"candidates", st.candidates},
            {"candidates_pruned", st.candidates_pruned},
            {"edges", st.edges},
            {"supporting_planes", st.supporting_planes},
            {"scan_planes_added", st.scan_planes_added},
            {"step_walls", st.step_walls},
            {"neighbourhoods_improved", st.neighbourhoods_improved},
            {"variables", m.variables},
            {"constraints", m.constraints},
            {"fixed_candidates", m.fixed},
            {"forced_candidates", m.forced},
            {"gap", m.gap},
            {"objective", m.objective},
            {"seconds", st.seconds},
            {"solver_seconds", m.seconds},
            {"work", m.work},
            {"faces_from_selection", st.faces_from_selection},
            {"candidates_changed", st.candidates_changed},
            {"warm_start", m.warm_text()}};
  if (!reason.empty()) j["reason"] = reason;
  return j;
}

json repair_json(const RepairReport& rr) {
  return {{"welded_vertices", rr.welded_vertices},
          {"removed_degenerate_faces", rr.removed_degenerate_faces},
          {"removed_duplicate_faces", rr.removed_duplicate_faces},
          {"split_t_junctions", rr.split_t_junctions},
          {"flipped_faces", rr.flipped_faces},
          {"filled_holes", rr.filled_holes},
          {"split_warped_faces", rr.split_warped_faces},
          {"notes", rr.notes}};
}

json rebuild_json(const ShellRebuild& rb, const std::string& why) {
  return {{"why", why},
          {"ok", rb.ok},
          {"reason", rb.reason},
          {"planes_added", rb.planes_added},
          {"area_added", rb.area_added},
          {"area_kept", rb.area_kept},
          {"area_dropped", rb.area_dropped},
          {"area_uncovered", rb.area_uncovered},
          {"area_fins", rb.area_fins},
          {"area_carried", rb.area_carried},
          {"fins", rb.fins.faces.size()},
          {"sampling", rb.sampling},
          {"candidates_changed", rb.candidates_changed},
          {"hausdorff_input_to_output", rb.input_to_output},
          {"hausdorff_output_to_input", rb.output_to_input},
          {"corner_to_input", rb.corner_to_input}};
}

json planes_json(const std::vector<ScanPlane>& planes) {
  json out = json::array();
  for (const auto& p : planes)
    out.push_back({{"normal", {p.plane.n.x(), p.plane.n.y(), p.plane.n.z()}},
                   {"d", p.plane.d},
                   {"inliers", p.inliers.size()},
                   {"rms", p.rms},
                   {"area", p.hull_area},
                   {"facade", p.facade},
                   {"doubled", p.doubled}});
  return out;
}

json matches_json(const RefineTrace::Matching& matching) {
  json matches = json::array();
  for (const auto& w : matching.walls) {
    const Match& m = w.match;
    matches.push_back({{"scan_plane", m.scan_plane},
                       {"surface", m.surface},
                       {"s_normal", m.s_normal},
                       {"d_centroid", m.d_centroid},
                       {"c_bbox", m.c_bbox},
                       {"s_match", m.s_match},
                       {"points", m.owned.size()},
                       {"deviation", w.deviation},
                       {"faces", w.faces}});
  }
  return matches;
}

json fit_json(const Judgement::Fit& f) {
  return json{{"points", f.points},
              {"better", f.better},
              {"worse", f.worse},
              {"rms_before", f.rms_before},
              {"rms_after", f.rms_after}};
}

json judgement_json(const Judgement& j) {
  json walls = json::array();
  for (const auto& w : j.walls) walls.push_back(fit_json(w));
  return {{"ok", j.ok},
          {"check", check_name(j.check)},
          {"detail", j.detail},
          {"building", fit_json(j.building)},
          {"walls", walls}};
}

}  // namespace

json validity_errors_json(const std::vector<ValidityError>& errors) {
  json out = json::array();
  for (const ValidityError& e : errors) {
    json j = {{"code", code_number(e.code)},
              {"description", code_name(e.code)},
              {"id", e.faces.empty() ? std::string() : "face=" + std::to_string(e.faces.front())},
              {"info", e.info}};
    if (!e.faces.empty()) j["faces"] = e.faces;
    out.push_back(std::move(j));
  }
  return out;
}

json city_outcome_json(const CityBuildingOutcome& b) {
  return {{"id", b.id},
          {"outcome", outcome_name(b.outcome)},
          {"reason", b.reason},
          {"facades_moved", b.facades_moved},
          {"refused_by", check_name(b.refused_by)},
          {"points", b.points},
          {"seconds", b.seconds},
          {"errors_before", validity_errors_json(b.errors_before)},
          {"errors_after", validity_errors_json(b.errors_after)}};
}

json validation_json(const Validation& v) {
  return {{"watertight", v.watertight()},
          {"valid", v.valid()},
          {"problem", v.problem},
          {"boundary_edges", v.boundary_edges},
          {"nonmanifold_edges", v.nonmanifold_edges},
          {"outward", v.outward},
          {"volume", v.volume},
          {"max_planarity_error", v.max_planarity_error},
          {"self_intersecting", v.self_intersecting},
          {"errors", validity_errors_json(v.errors)}};
}

json refine_report(const RefineResult& r) {
  const RefineTrace& t = r.trace;
  json rep;
  rep["report_version"] = kRefineReportVersion;
  rep["lodrefine_version"] = LODREFINE_VERSION;
  rep["id"] = t.id;
  rep["origin"] = {t.origin.x(), t.origin.y(), t.origin.z()};
  rep["outcome"] = outcome_name(r.outcome);
  rep["reason"] = r.reason;
  rep["refined"] = r.refined();
  rep["output_validation"] = validation_json(t.output_validation);
  rep["faces"] = t.faces;
  json seconds = json::object();
  for (const auto& [stage, s] : t.seconds) seconds[stage] = seconds.value(stage, 0.0) + s;  // a retry's laps add up
  rep["seconds"] = seconds;
  if (t.repair) rep["repair"] = repair_json(*t.repair);
  if (t.input_validation) rep["input_validation"] = validation_json(*t.input_validation);
  if (t.rebuild) rep["rebuild"] = rebuild_json(*t.rebuild, t.invalid_input);
  if (t.cloud) rep["cloud"] = {{"points", t.cloud->first}, {"points_near_model", t.cloud->second}};
  if (t.planes) rep["planes"] = planes_json(*t.planes);
  if (t.scan)
    rep["scan"] = {{"doubled_walls", t.scan->doubled_walls},
                   {"misregistration", t.scan->misregistration},
                   {"relief_planes", planes_json(t.scan->relief)},
                   {"relief_points", t.scan->relief_points},
                   {"relief_share", t.scan->relief_share},
                   {"wall_density", {{"min", t.scan->min_density}, {"max", t.scan->max_density}}}};
  if (t.matching) {
    rep["matches"] = matches_json(*t.matching);
    rep["rejected_matches"] = t.matching->rejected;
    rep["q_model"] = t.matching->q_model;
  }
  if (t.substitution) {
    json sub = substitution_json(*t.substitution);
    rep["substitution"] = sub;
  }
  if (t.replacements) {
    json steps = json::array();
    for (const auto& s : *t.replacements) steps.push_back(step_json(s));
    rep["replacements"] = steps;
    json facades = json::array();
    for (const auto& f : t.facades)
      facades.push_back({{"input_faces", f.input_faces},
                         {"evidence", f.evidence},
                         {"max_move", f.max_move},
                         {"mean_move", f.mean_move}});
    rep["facades"] = facades;
  }
  if (t.judgement) {
    rep["judgement"] = judgement_json(*t.judgement);
    if (t.corners_refused) rep["judgement"]["corners_refused"] = *t.corners_refused;
    if (!t.walls_refused.empty()) rep["judgement"]["walls_refused"] = t.walls_refused;
  }
  if (t.selection) rep["selection"] = selection_json(*t.selection, t.selection_reason);
  return rep;
}

json params_json(const RefineConfig& config) {
  json j = json::object();
  for_each_field(config, [&](const auto& field, auto value) { j[field.name] = value; });
  return j;
}

}  // namespace lodrefine
