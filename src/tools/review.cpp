#include "lodrefine/tools/review.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <map>
#include <tuple>

#include <nlohmann/json.hpp>

#include "lodrefine/base/files.h"
#include "lodrefine/base/geometry.h"
#include "lodrefine/core/distance.h"
#include "lodrefine/eval/plots.h"
#include "lodrefine/refine/refine.h"

namespace lodrefine {
namespace {

using nlohmann::json;

// Points farther than this from the refined model (ground far off, trees, neighbours) are not
// shown: they say nothing about the building and would crowd its view.
constexpr double kViewPointDistance = 1.0;

std::string fmt(double v) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

json number_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
json number_or_null(const std::optional<double>& v) { return v ? number_or_null(*v) : json(nullptr); }

// Every `step`-th element so that at most `cap` remain.
template <typename T>
std::vector<T> thinned(const std::vector<T>& v, std::size_t cap) {
  if (cap == 0 || v.size() <= cap) return v;
  const std::size_t step = (v.size() + cap - 1) / cap;
  std::vector<T> out;
  for (std::size_t i = 0; i < v.size(); i += step) out.push_back(v[i]);
  return out;
}

// kept-invalid, kept, repaired, refined, untouched; then the worst fit after refinement first,
// unmeasured last.
std::vector<const CityReviewBuilding*> worst_first(const CityReview& r) {
  std::vector<const CityReviewBuilding*> order;
  for (const auto& b : r.buildings) order.push_back(&b);
  auto key = [](const CityReviewBuilding* b) {
    const int rank = b->outcome == Outcome::KeptInvalid ? 0
                     : b->outcome == Outcome::Kept      ? 1
                     : b->outcome == Outcome::Repaired  ? 2
                     : b->outcome == Outcome::Refined   ? 3
                                                        : 4;
    return std::make_tuple(rank, -b->fit_after.value_or(-1.0), b->id);
  };
  std::stable_sort(order.begin(), order.end(), [&](auto* a, auto* b) { return key(a) < key(b); });
  return order;
}

const json kColumns = json::array({{"id", "building"},
                                   {"outcome", "outcome"},
                                   {"reason", "reason"},
                                   {"points", "cloud points"},
                                   {"moved", "facades moved"},
                                   {"moved_max", "max move (m)"},
                                   {"moved_mean", "mean move (m)"},
                                   {"fit_before", "fit before (m)"},
                                   {"fit_after", "fit after (m)"}});

// A building's reason without its id, which the page shows beside it: a leading "building <id>: "
// or "<id>: " dropped (as line_id shows it), "building <id>" as "building", the id quoted (as
// shown_id quotes it, cut past 80 bytes) dropped.
std::string without_id(const std::string& id, std::string reason) {
  if (id.empty()) return reason;
  for (const std::string& lead : {"building " + line_id(id) + ": ", line_id(id) + ": "})
    if (reason.rfind(lead, 0) == 0) reason.erase(0, lead.size());
  for (const auto& [from, to] : {std::pair<std::string, std::string>{" '" + id + "'", ""},
                                 {" " + shown_id(id), ""},
                                 {"building " + id, "building"}})
    for (std::size_t at = reason.find(from); at != std::string::npos; at = reason.find(from, at + to.size()))
      reason.replace(at, from.size(), to);
  return reason;
}

json row(const CityReviewBuilding& b) {
  return {{"id", b.id},
          {"outcome", outcome_name(b.outcome)},
          {"reason", without_id(b.id, b.reason)},
          {"points", b.points},
          {"moved", b.facades_moved},
          {"moved_max", number_or_null(b.moved_max)},
          {"moved_mean", number_or_null(b.moved_mean)},
          {"fit_before", number_or_null(b.fit_before)},
          {"fit_after", number_or_null(b.fit_after)}};
}

std::string caption(const CityReviewBuilding& b) {
  std::string c = outcome_name(b.outcome) + std::string(", ") + std::to_string(b.facades_moved) +
                  " facade(s) moved (max " + fmt(b.moved_max) + " m), " + std::to_string(b.points) + " cloud points";
  if (b.fit_before) c += ", fit " + fmt(*b.fit_before) + " -> " + (b.fit_after ? fmt(*b.fit_after) : "-") + " m";
  return c;
}

// The check a kept building's reason names: its text (without_id) before any ':' or '(' with
// numbers as "N" (reasons carry the figures of the building, e.g. "... better (RMS 0.12 -> 0.15 m)").
std::string check_of(const std::string& id, const std::string& text) {
  const std::string reason = without_id(id, text);
  std::string key = reason.substr(0, std::min(reason.find(':'), reason.find('(')));
  std::string out;
  for (std::size_t i = 0; i < key.size(); ++i) {
    const bool digit =
        std::isdigit(static_cast<unsigned char>(key[i])) || (key[i] == '.' && !out.empty() && out.back() == 'N');
    if (!digit) out += key[i];
    else if (out.empty() || out.back() != 'N') out += 'N';
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out.empty() ? "(no reason)" : out;
}

// "checks that refused": kept and kept-invalid buildings counted by check_of(reason), most first.
std::string refusals_text(const CityReview& r) {
  std::map<std::string, std::size_t> count;
  for (const auto& b : r.buildings)
    if (b.outcome == Outcome::Kept || b.outcome == Outcome::KeptInvalid)
      ++count[outcome_name(b.outcome) + std::string(": ") + check_of(b.id, b.reason)];
  std::vector<std::pair<std::string, std::size_t>> sorted(count.begin(), count.end());
  std::stable_sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  std::string out = "\nchecks that refused (kept buildings by reason):\n";
  if (sorted.empty()) out += "  none\n";
  for (const auto& [check, n] : sorted) out += "  " + std::to_string(n) + "  " + check + "\n";
  return out;
}

}  // namespace

std::vector<std::vector<Vec2>> review_outline(const Mesh& model, const Vec3& origin) {
  std::vector<int> faces;
  for (std::size_t f = 0; f < model.faces.size(); ++f)
    if (model.faces[f].sem == Semantic::Ground) faces.push_back(int(f));
  if (faces.empty())
    for (std::size_t f = 0; f < model.faces.size(); ++f) faces.push_back(int(f));
  std::vector<std::vector<Vec2>> rings;
  for (int f : faces) {
    std::vector<Vec2> ring;
    for (int v : model.faces[std::size_t(f)].v) {
      if (v < 0 || std::size_t(v) >= model.vertices.size()) continue;
      const Vec3 p = model.vertices[std::size_t(v)] - origin;
      ring.emplace_back(p.x(), p.y());
    }
    if (ring.size() >= 3) rings.push_back(std::move(ring));
  }
  return rings;
}

BuildingView review_view(const std::string& id, const Mesh& coarse, const Mesh& refined,
                         const std::vector<Vec3>& points, std::size_t max_points) {
  const Vec3 origin = local_origin(coarse);
  const Mesh a = translated(coarse, -origin), b = translated(refined, -origin);
  // Distances of a first subsample only: a crop can hold millions of points.
  std::vector<Vec3> local = thinned(points, 8 * std::max<std::size_t>(1, max_points));
  for (auto& p : local) p -= origin;
  std::vector<Vec3> near;
  std::vector<double> d;
  if (!b.faces.empty() && !local.empty()) {
    const std::vector<double> all = cloud_to_mesh(b, local);
    for (std::size_t i = 0; i < local.size(); ++i)
      if (std::abs(all[i]) <= kViewPointDistance) near.push_back(local[i]), d.push_back(all[i]);
  }
  BuildingView v = make_building_view(id, a, b, near, d, max_points);
  v.footprint_svg = svg_footprint(a, b, thinned(near, max_points), id + ": coarse vs refined, scan points (XY)",
                                  std::min<std::size_t>(max_points, 1500));
  return v;
}

std::string city_review_html(const CityReview& r) {
  HtmlReport h;
  h.title = r.title;
  h.table1 = r.summary + refusals_text(r);
  h.summary_heading = "City summary";
  h.table_heading = "Buildings, worst first";
  h.views_legend =
      "Each refined and repaired building. Left: top view, coarse (blue, dashed) and written model (orange) "
      "over its scan points. Right: 3D, drag to turn, wheel to zoom; coarse blue (transparent), the written "
      "model's faces by where they come from (lodrefine_source: scan orange, model grey, added purple), "
      "scan points within 1 m coloured by their signed distance to it (blue -0.3 m, green 0, red +0.3 m). "
      "A click on a building of the map shows its view.";
  h.columns = kColumns;
  h.rows = json::array();
  for (const Outcome o : {Outcome::Refined, Outcome::Repaired, Outcome::KeptInvalid, Outcome::Kept, Outcome::Untouched})
    h.filter.push_back(outcome_name(o));
  h.filter_off = {outcome_name(Outcome::Untouched)};
  std::vector<MapOutline> map;
  for (const auto& b : r.buildings)
    map.push_back({b.id, b.outcome, b.outline, b.view ? "#" + view_anchor(b.id) : std::string()});
  h.map_svg = svg_district_map(map, "The district: a click on a refined or repaired building shows its 3D view");
  for (const CityReviewBuilding* b : worst_first(r)) {
    h.rows.push_back(row(*b));
    if (!b->view) continue;
    h.views.push_back(*b->view);
    h.views.back().id = b->id;
    h.views.back().caption = caption(*b);
    h.views.back().outcome = outcome_name(b->outcome);
  }
  return html_report(h);
}

}  // namespace lodrefine
