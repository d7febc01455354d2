// SVG figures of an evaluation, as plain text without dependencies: C2M histogram and boxplot
// before/after (the paper's Fig. 6c–e) and an XY footprint overlay per building (Fig. 5).
#pragma once
#include <string>
#include <vector>

#include "lodrefine/base/types.h"
#include "lodrefine/core/outcome.h"
#include "lodrefine/eval/histogram.h"

namespace lodrefine {

// Overlaid histograms of signed C2M distances (m) of the original (blue) and refined (orange)
// model, as percent of points per bin. `range` clips the x axis to ±range (0: the 99th
// percentile of |d| over both series, at least 0.1 m); the share beyond it is in the legend.
std::string svg_histogram(const std::vector<double>& before, const std::vector<double>& after, const std::string& title,
                          double range = 0.0, int bins = 60);
// The same from pooled histograms (a run's distances, not held): bars, range and the share
// beyond it to within the histogram's 0.1 mm bins.
std::string svg_histogram(const DistanceHistogram& before, const DistanceHistogram& after, const std::string& title,
                          double range = 0.0, int bins = 60);

// Tukey boxplots of signed C2M distances: box Q1–Q3, red median line, whiskers at the farthest
// value within 1.5 IQR of the box, mean as a cross; outliers are counted, not drawn.
std::string svg_boxplot(const std::vector<double>& before, const std::vector<double>& after, const std::string& title);
// The same from pooled histograms: quartiles, whiskers and the outlier count to one bin.
std::string svg_boxplot(const DistanceHistogram& before, const DistanceHistogram& after, const std::string& title);

// Top view (XY): outlines of the original (blue, dashed) and refined (orange) model — wall and
// ground faces, or every face if none is labelled — over the facade points (green, a regular
// subsample of at most `max_points`), with a scale bar in metres. Any common frame.
std::string svg_footprint(const Mesh& original, const Mesh& refined, const std::vector<Vec3>& facade_points,
                          const std::string& title, std::size_t max_points = 5000);

// One building of a district map: its XY outline rings (any common frame, metres) and outcome.
struct MapOutline {
  std::string id;
  Outcome outcome = Outcome::Untouched;  // refined, repaired, kept, kept-invalid, untouched; any other as kept-invalid
  std::vector<std::vector<Vec2>> rings;
  std::string link;  // where a click on it leads (its view on the same page: "#view-..."); none when empty
};

// Top view of a district, north up, about `width` pixels wide: each outline filled by its
// outcome (refined orange, repaired blue, kept yellow, kept-invalid red, untouched grey) with its id as tooltip,
// a legend with the counts and a scale bar. Ids are escaped.
std::string svg_district_map(const std::vector<MapOutline>& buildings, const std::string& title, double width = 1100);

}  // namespace lodrefine
