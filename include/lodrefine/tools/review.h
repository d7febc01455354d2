// The review page of a city refine (`refine --model CITY ... --html`): one self-contained page
// (html_report()'s machinery, three.js embedded) with the city summary, the buildings the cloud
// worst first (a filter by outcome; the untouched hidden at first), a 2D map of the district
// whose refined and repaired buildings link to their 3D view, coarse vs written over its scan
// points coloured by their distance to it, the written faces by provenance.
// Plain data in: the caller collects it while refining (only refined and repaired buildings
// carry a view).
#pragma once
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "lodrefine/base/types.h"
#include "lodrefine/core/outcome.h"
#include "lodrefine/tools/report.h"

namespace lodrefine {

struct CityReviewBuilding {
  std::string id;
  Outcome outcome = Outcome::Untouched;  // refined, repaired, kept, kept-invalid or untouched (no cloud points)
  std::string reason;                    // why kept
  std::size_t points = 0;                // cloud points in its crop
  std::size_t facades_moved = 0;
  double moved_max = std::nan(""), moved_mean = std::nan("");  // facade displacement (m), NaN if none moved
  std::optional<double> fit_before,
      fit_after;  // RMS distance of the scan points near the building, as the judge measured them (m)
  std::vector<std::vector<Vec2>> outline;  // XY rings in the district frame (review_outline())
  std::optional<BuildingView> view;        // refined and repaired buildings (review_view())
};

struct CityReview {
  std::string title;
  std::string summary;                        // preformatted: counts, the checks that refused, times
  std::vector<CityReviewBuilding> buildings;  // every building of the file, any order
};

// The XY outline of `model` for the district map: its ground faces (every face when none is
// labelled), minus `origin` (the district frame: any point near the city, e.g. the first
// building's local_origin()).
std::vector<std::vector<Vec2>> review_outline(const Mesh& model, const Vec3& origin);

// The 3D view of a refined building: both meshes and at most `max_points` of `points` (the
// building's crop, a regular subsample of those within 1 m of the refined model) coloured by
// their signed distance to `refined`, in a local frame; with its top view (svg_footprint()).
// Any common input frame (georeferenced is fine: moved to a local one first).
BuildingView review_view(const std::string& id, const Mesh& coarse, const Mesh& refined,
                         const std::vector<Vec3>& points, std::size_t max_points);

// The page. Ids, reasons and captions are escaped (ids may be hostile), reasons shown without
// the building's id; the table lists every building: kept-invalid, kept, repaired, refined, then
// untouched (hidden until its box of the filter is ticked), each by fit after refinement, worst
// first.
std::string city_review_html(const CityReview& review);

}  // namespace lodrefine
