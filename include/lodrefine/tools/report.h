// The run report a person opens: one self-contained HTML page (no network needed to view it)
// with the pooled Table 1, the C2M plots, the per-building table and, per building shown, the
// footprint overlay and an interactive 3D view (three.js, embedded in the page).
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lodrefine/base/types.h"

namespace lodrefine {

// What the 3D view of one building shows, in a local frame (metres).
struct BuildingView {
  std::string id;
  std::string caption;          // e.g. "refined, 2 facades moved, C2M RMSE 0.41 -> 0.01 m"
  std::string footprint_svg;    // svg_footprint() of the building
  std::vector<float> original;  // triangles: x, y, z per corner
  std::vector<float> refined;   // idem (empty when nothing was written)
  // Per refined triangle: its face's Provenance (0 none, 1 model, 2 scan, 3 added); the view
  // colours the refined model by it when any is set.
  std::vector<unsigned char> sources;
  std::string outcome;        // the building's (outcome_name), for the page's filter; may be empty
  std::vector<float> points;  // scan points: x, y, z each
  std::vector<float> c2m;     // signed C2M of each point to the refined model (m)
};

// A view of `original` and `refined` (both local) with at most `max_points` of `points`, a
// regular subsample, each with its C2M distance `c2m[i]`.
BuildingView make_building_view(const std::string& id, const Mesh& original, const Mesh& refined,
                                const std::vector<Vec3>& points, const std::vector<double>& c2m,
                                std::size_t max_points);

struct HtmlReport {
  std::string title;
  std::string table1;  // the pooled figures, preformatted text
  std::string histogram_svg, boxplot_svg;
  std::string map_svg;  // full width below the plots, when set
  // Headings and the legend of the views (other pages, e.g. the city review, name them).
  std::string summary_heading = "Pooled figures (Table 1)", table_heading = "Buildings, worst first";
  std::string views_legend =
      "Left: top view, original (blue, dashed) and refined (orange) over the facade points. "
      "Right: 3D, drag to turn, wheel to zoom; original blue (transparent), refined orange, "
      "scan points coloured by their C2M distance to the refined model (blue -0.3 m, green "
      "0, red +0.3 m).";
  nlohmann::json columns;           // [[key, heading], ...] of the building table
  nlohmann::json rows;              // one object per building, worst first
  std::vector<BuildingView> views;  // the buildings shown in 3D (a subset of rows)
  // The filter by outcome above the table: a box per value of `filter` (the rows' "outcome"),
  // ticked unless in `filter_off`; unticked, its rows and views are hidden. None when empty.
  std::vector<std::string> filter, filter_off;
};

// The id of the element holding `id`'s view ("view-" and the id, every byte but ASCII letters,
// digits, '.' and '-' as "_" and two hex digits): a link "#" + view_anchor(id) reaches it whatever
// the id holds.
std::string view_anchor(const std::string& id);

// The page (ids, captions and cells escaped, JSON inside <script> made safe: "</", "<!--",
// U+2028/9 escaped, bytes that are not UTF-8 replaced); the embedded three.js ES module (three_module_js()) renders the
// views. After the first render of every view the <html> element gets data-rendered="<number of views>" and each
// canvas's page rectangle in data-rect; script errors go to data-errors (for headless tests).
std::string html_report(const HtmlReport& report);

// three.js (r160, MIT), compiled into the binary from third_party/three/ so the tool and its
// pages work offline.
const std::string& three_module_js();

}  // namespace lodrefine
