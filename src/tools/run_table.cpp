// What `lodrefine eval` writes of evaluated buildings: Table 1, the tile table (JSON, CSV), the
// HTML page's rows and views, and the gate's figures.
#include "lodrefine/tools/run_table.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <tuple>

#include "lodrefine/version.h"

namespace lodrefine {
namespace {

using nlohmann::json;

std::string fmt(double v, int decimals = 3) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// printf onto the end of `out`.
void appendf(std::string& out, const char* format, ...) __attribute__((format(printf, 2, 3)));
void appendf(std::string& out, const char* format, ...) {
  va_list args, copy;
  va_start(args, format);
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  if (n > 0) {
    const std::size_t at = out.size();
    out.resize(at + std::size_t(n) + 1);
    std::vsnprintf(&out[at], std::size_t(n) + 1, format, args);
    out.resize(at + std::size_t(n));
  }
  va_end(args);
}

json stats_json(const std::optional<DistanceStats>& s) {
  if (!s) return nullptr;
  return {{"count", s->count}, {"rmse", s->rmse},     {"mae", s->mae}, {"mean", s->mean},
          {"std", s->std},     {"median", s->median}, {"p95", s->p95}, {"max_abs", s->max_abs}};
}

json number_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json point_json(const Vec3& p) { return {p.x(), p.y(), p.z()}; }

// The row's outcome as written: its name, "" without a refine record.
const char* outcome_text(const RunRow& r) { return r.outcome ? outcome_name(*r.outcome) : ""; }

json moved_json(const RunRow& r) {
  const MovedSummary m = summarize_moved(r.moved);
  json list = json::array();
  for (const auto& f : r.moved) list.push_back({{"surface", f.surface}, {"displacement", f.displacement}});
  return {{"count", m.count}, {"max", number_or_null(m.max)}, {"mean", number_or_null(m.mean)}, {"facades", list}};
}

json row_json(const RunRow& r) {
  const BuildingEval& e = r.eval;
  json j = {
      {"id", e.id},
      {"status", e.ok() ? "ok" : "failed"},
      {"error", e.error},
      {"outcome", outcome_text(r)},
      {"reason", r.reason},
      {"facades_moved", moved_json(r)},
      {"refine_seconds", number_or_null(r.refine_seconds)},
      {"facade_points", e.facade_points},
      {"c2m",
       {{"original", stats_json(e.before)}, {"refined", stats_json(e.ok() ? std::optional(e.after) : std::nullopt)}}},
      {"delta_d", number_or_null(e.delta_d)},
      {"watertight", {{"original", e.watertight_before}, {"refined", e.watertight_after}}},
      {"centroids",
       {{"mls", point_json(e.c_mls + r.origin)},
        {"original", point_json(e.c_init + r.origin)},
        {"refined", e.ok() ? point_json(e.c_ref + r.origin) : json(nullptr)}}}};
  if (!r.truth_faces_source.empty())
    j["truth"] = {
        {"scanned_faces", e.scanned_truth_faces},
        {"scanned_faces_from", r.truth_faces_source},
        {"facade", {{"original", stats_json(e.truth_facade_before)}, {"refined", stats_json(e.truth_facade_after)}}},
        {"roof", {{"original", stats_json(e.truth_roof_before)}, {"refined", stats_json(e.truth_roof_after)}}}};
  if (!r.refine_outcome.empty()) j["refine_outcome"] = r.refine_outcome;
  if (!r.selection.empty()) j["selection"] = r.selection;
  return j;
}

json totals_json(const RunTotals& t) {
  return {{"outcomes", t.outcomes},
          {"facades_moved",
           {{"count", t.moved.count}, {"max", number_or_null(t.moved.max)}, {"mean", number_or_null(t.moved.mean)}}},
          {"refine_seconds_total", t.refine_seconds}};
}

json pooled_json(const PooledEval& p) {
  return {
      {"buildings", p.buildings},
      {"failed", p.failed},
      {"evaluated", p.evaluated},
      {"pooled_over_points",
       {{"c2m", {{"original", stats_json(p.before)}, {"refined", stats_json(p.after)}}},
        {"truth_facade",
         {{"original", stats_json(p.truth_facade_before)}, {"refined", stats_json(p.truth_facade_after)}}},
        {"truth_roof", {{"original", stats_json(p.truth_roof_before)}, {"refined", stats_json(p.truth_roof_after)}}}}},
      {"mean_of_buildings",
       {{"c2m", {{"original", stats_json(p.mean_before)}, {"refined", stats_json(p.mean_after)}}}}},
      {"delta_d", {{"mean", p.delta_d_mean}, {"median", p.delta_d_median}}},
      {"watertight_rate", {{"original", p.watertight_rate_before}, {"refined", p.watertight_rate_after}}},
      {"truth_buildings", p.truth_buildings}};
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string csv_stats(const std::optional<DistanceStats>& s) {
  if (!s) return ",,,,,";
  return fmt(s->rmse, 4) + ',' + fmt(s->mae, 4) + ',' + fmt(s->mean, 4) + ',' + fmt(s->std, 4) + ',' +
         fmt(s->median, 4) + ',' + fmt(s->p95, 4);
}

std::string csv_rmse(const std::optional<DistanceStats>& s) { return s ? fmt(s->rmse, 4) : std::string(); }

std::string csv_optional(double v) { return std::isfinite(v) ? fmt(v, 4) : std::string(); }

std::string csv_line(const RunRow& r) {
  const BuildingEval& e = r.eval;
  const bool measured = e.facade_points > 0;
  const MovedSummary m = summarize_moved(r.moved);
  return csv_field(e.id) + ',' + outcome_text(r) + ',' + csv_field(r.reason) + ',' + std::to_string(m.count) + ',' +
         csv_optional(m.max) + ',' + csv_optional(m.mean) + ',' + (e.watertight_before ? "1" : "0") + ',' +
         (e.ok() && e.watertight_after ? "1" : "0") + ',' + csv_optional(r.refine_seconds) + ',' +
         std::to_string(e.facade_points) + ',' + csv_stats(measured ? std::optional(e.before) : std::nullopt) + ',' +
         csv_stats(measured && e.ok() ? std::optional(e.after) : std::nullopt) + ',' + csv_optional(e.delta_d) + ',' +
         csv_rmse(e.truth_facade_before) + ',' + csv_rmse(e.truth_facade_after) + ',' + csv_rmse(e.truth_roof_before) +
         ',' + csv_rmse(e.truth_roof_after) + ',' + csv_field(r.refine_outcome) + ',' + csv_field(r.selection) + '\n';
}

}  // namespace

MovedSummary summarize_moved(const std::vector<MovedFacade>& moved) {
  MovedSummary m;
  m.count = moved.size();
  if (moved.empty()) return m;
  m.max = m.mean = 0.0;
  for (const auto& f : moved) m.max = std::max(m.max, f.displacement), m.mean += f.displacement;
  m.mean /= double(moved.size());
  return m;
}

RunTotals run_totals(const std::vector<RunRow>& rows) {
  RunTotals t;
  std::vector<MovedFacade> all;
  for (const RunRow& r : rows) {
    ++t.outcomes[outcome_text(r)];
    all.insert(all.end(), r.moved.begin(), r.moved.end());
    if (std::isfinite(r.refine_seconds)) t.refine_seconds += r.refine_seconds;
  }
  t.moved = summarize_moved(all);
  return t;
}

std::vector<const RunRow*> worst_first(const std::vector<RunRow>& rows) {
  std::vector<const RunRow*> order;
  for (const RunRow& r : rows) order.push_back(&r);
  auto key = [](const RunRow* r) {
    const BuildingEval& e = r->eval;
    const int rank = !e.ok() ? 0 : !e.watertight_after ? 1 : 2;
    const double rmse = e.ok() && e.facade_points > 0 ? e.after.rmse : -1.0;
    return std::make_tuple(rank, -rmse, e.id);
  };
  std::stable_sort(order.begin(), order.end(), [&](const RunRow* a, const RunRow* b) { return key(a) < key(b); });
  return order;
}

std::string table1_text(const PooledEval& p, bool batch) {
  std::string out;
  appendf(out, "buildings: %zu (evaluated %zu, failed %zu), facade points: %zu\n\n", p.buildings, p.evaluated, p.failed,
          p.before.count);
  appendf(out, "%-28s %10s %10s", "", "Original", "Refined");
  if (batch) appendf(out, "   %12s %12s", "Orig (mean)", "Ref (mean)");
  out += '\n';
  auto line = [&](const char* name, double a, double b, double ma, double mb) {
    appendf(out, "%-28s %10s %10s", name, fmt(a).c_str(), fmt(b).c_str());
    if (batch) appendf(out, "   %12s %12s", fmt(ma).c_str(), fmt(mb).c_str());
    out += '\n';
  };
  const double nan = std::nan("");
  using Field = double DistanceStats::*;
  const std::pair<const char*, Field> c2m_rows[] = {
      {"C2M RMSE (m)", &DistanceStats::rmse},     {"C2M MAE (m)", &DistanceStats::mae},
      {"C2M Mean (m)", &DistanceStats::mean},     {"C2M Std (m)", &DistanceStats::std},
      {"C2M median (m)", &DistanceStats::median}, {"C2M p95 |d| (m)", &DistanceStats::p95}};
  auto get = [&](const DistanceStats& s, Field f) { return s.count ? s.*f : nan; };  // "-" when nothing measured
  for (const auto& [name, f] : c2m_rows)
    line(name, get(p.before, f), get(p.after, f), get(p.mean_before, f), get(p.mean_after, f));
  line("Centroid offset red. (m)", nan, p.evaluated ? p.delta_d_mean : nan, nan, nan);
  appendf(out, "%-28s %10.0f %10.0f\n", "Watertight rate (%)", 100 * p.watertight_rate_before,
          100 * p.watertight_rate_after);
  auto rmse = [&](const std::optional<DistanceStats>& s) { return s ? s->rmse : nan; };
  line("Truth facade RMSE (m)", rmse(p.truth_facade_before), rmse(p.truth_facade_after), nan, nan);
  line("Truth roof RMSE (m)", rmse(p.truth_roof_before), rmse(p.truth_roof_after), nan, nan);
  return out;
}

std::string totals_text(const RunTotals& t) {
  std::string others;  // the outcomes besides the three always shown, when counted
  for (Outcome o : {Outcome::Repaired, Outcome::KeptInvalid, Outcome::Untouched}) {
    const auto it = t.outcomes.find(outcome_name(o));
    if (it != t.outcomes.end() && it->second > 0) appendf(others, ", %s %zu", outcome_name(o), it->second);
  }
  std::string out;
  appendf(out,
          "\noutcomes: refined %zu, kept %zu, failed %zu%s; facades moved %zu (max %s m, mean %s m); refine %.1f s in "
          "all\n",
          t.outcomes.at("refined"), t.outcomes.at("kept"), t.outcomes.at("failed"), others.c_str(), t.moved.count,
          fmt(t.moved.max).c_str(), fmt(t.moved.mean).c_str(), t.refine_seconds);
  return out;
}

json run_json(const std::vector<const RunRow*>& order, const PooledEval& pooled, const RunTotals& totals,
              const json& params, const std::string& run_dir) {
  json j = {{"lodrefine_version", LODREFINE_VERSION},
            {"pooled", pooled_json(pooled)},
            {"buildings", json::array()},
            {"params", params}};
  j["pooled"].update(totals_json(totals));
  for (const RunRow* r : order) j["buildings"].push_back(row_json(*r));
  if (!run_dir.empty()) j["run_dir"] = run_dir;
  return j;
}

std::string csv_text(const std::vector<const RunRow*>& order) {
  std::string out =
      "id,outcome,reason,facades_moved,displacement_max,displacement_mean,watertight_original,watertight_refined,"
      "refine_seconds,facade_points,"
      "c2m_rmse_original,c2m_mae_original,c2m_mean_original,c2m_std_original,c2m_median_original,c2m_p95_original,"
      "c2m_rmse_refined,c2m_mae_refined,c2m_mean_refined,c2m_std_refined,c2m_median_refined,c2m_p95_refined,"
      "delta_d,truth_facade_rmse_original,truth_facade_rmse_refined,truth_roof_rmse_original,truth_roof_rmse_refined,"
      "refine_outcome,selection\n";
  for (const RunRow* r : order) out += csv_line(*r);
  return out;
}

const json& html_columns() {
  static const json columns = json::array({{"id", "building"},
                                           {"outcome", "outcome"},
                                           {"reason", "reason"},
                                           {"selection", "selection"},
                                           {"moved", "facades moved"},
                                           {"moved_max", "max move (m)"},
                                           {"moved_mean", "mean move (m)"},
                                           {"c2m_before", "C2M RMSE before (m)"},
                                           {"c2m_after", "C2M RMSE after (m)"},
                                           {"watertight", "watertight"},
                                           {"seconds", "refine (s)"}});
  return columns;
}

json html_row(const RunRow& r) {
  const BuildingEval& e = r.eval;
  const MovedSummary m = summarize_moved(r.moved);
  const bool measured = e.facade_points > 0;
  return {{"id", e.id},
          {"outcome", outcome_text(r)},
          {"reason", r.reason},
          {"selection", r.selection},
          {"moved", m.count},
          {"moved_max", number_or_null(m.max)},
          {"moved_mean", number_or_null(m.mean)},
          {"c2m_before", measured ? json(e.before.rmse) : json()},
          {"c2m_after", measured && e.ok() ? json(e.after.rmse) : json()},
          {"watertight", e.ok() && e.watertight_after},
          {"seconds", number_or_null(r.refine_seconds)}};
}

BuildingView html_view(const RunRow& r, const RefineConfig& params) {
  std::string refined_error;
  const LocalBuilding b = read_local(r.files, r.origin, refined_error);
  // A run drops each building's per-point series once pooled: the few shown are measured again
  // (the same points and distances: the evaluation is deterministic).
  const BuildingEval e = r.eval.facade_points > 0 && r.eval.facade_index.empty()
                             ? evaluate_building(b.original, b.refined, b.cloud, nullptr, params)
                             : r.eval;
  const std::vector<double>& c2m = e.ok() ? e.c2m_after : e.c2m_before;
  constexpr std::size_t kViewPoints = 4000;       // per building: enough to see the facades, keeps the page small
  constexpr std::size_t kFootprintPoints = 1500;  // idem for the top view
  BuildingView v = make_building_view(e.id, b.original, b.refined, facade_points(e, b.cloud), c2m, kViewPoints);
  v.footprint_svg = building_footprint_svg(e, b, kFootprintPoints);
  v.caption =
      outcome_text(r) + (r.reason.empty() ? "" : " (" + r.reason + ")") + ", " + std::to_string(r.moved.size()) +
      " facade(s) moved" +
      (e.facade_points ? ", C2M RMSE " + fmt(e.before.rmse) + " -> " + (e.ok() ? fmt(e.after.rmse) : "-") + " m" : "");
  return v;
}

BuildingFigures building_figures(const RunRow& r) {
  const BuildingEval& e = r.eval;
  BuildingFigures b;
  b.id = e.id;
  b.outcome = r.outcome.value_or(Outcome::Failed);  // a run's rows all have one
  b.reason = r.reason;
  if (e.ok() && e.facade_points > 0) b.c2m_rmse = e.after.rmse, b.c2m_mae = e.after.mae;
  if (e.ok() && e.truth_facade_after) b.truth_facade_rmse = e.truth_facade_after->rmse;
  if (e.ok() && e.truth_roof_after) b.truth_roof_rmse = e.truth_roof_after->rmse;
  b.watertight = e.ok() && e.watertight_after;
  const MovedSummary m = summarize_moved(r.moved);
  b.facades_moved = m.count;
  if (std::isfinite(m.max)) b.moved_max = m.max;
  return b;
}

RunFigures run_figures(const std::vector<RunRow>& rows, const PooledEval& p) {
  RunFigures run;
  for (const RunRow& r : rows) run.buildings.push_back(building_figures(r));
  run.failed = p.failed;
  run.refined = std::size_t(
      std::count_if(rows.begin(), rows.end(), [](const RunRow& r) { return r.outcome == Outcome::Refined; }));
  run.watertight_rate = p.watertight_rate_after;
  if (p.before.count) run.c2m_rmse_original = p.before.rmse;
  if (p.after.count) run.c2m_rmse = p.after.rmse, run.c2m_mae = p.after.mae;
  if (p.truth_facade_after) run.truth_facade_rmse = p.truth_facade_after->rmse;
  if (p.truth_roof_after) run.truth_roof_rmse = p.truth_roof_after->rmse;
  return run;
}

}  // namespace lodrefine
