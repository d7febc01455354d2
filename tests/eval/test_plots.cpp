// The SVG plots: well-formed documents without NaN, a footprint with its points thinned to at most
// 5000, escaped captions and a scale bar.
#include <gtest/gtest.h>

#include "lodrefine/eval/plots.h"
#include "support/mesh_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;

TEST(Plots, SvgDocuments) {
  const std::vector<double> before = {-0.3, -0.1, 0.0, 0.2, 0.25, 1.5}, after = {-0.02, 0.0, 0.01, 0.03};
  for (const std::string& svg : {svg_histogram(before, after, "C2M"), svg_boxplot(before, after, "C2M")}) {
    EXPECT_EQ(svg.rfind("<svg", 0), 0u);
    EXPECT_NE(svg.find("</svg>"), std::string::npos);
    EXPECT_EQ(svg.find("nan"), std::string::npos);
  }
  std::vector<Vec3> pts(12000, Vec3(0.5, 0.0, 0.5));
  const std::string fp = svg_footprint(box({0, 0, 0}, {10, 8, 6}), box({0.2, 0, 0}, {10, 8, 6}), pts, "b & <1>");
  std::size_t circles = 0;
  for (std::size_t at = fp.find("<circle"); at != std::string::npos; at = fp.find("<circle", at + 1)) ++circles;
  EXPECT_LE(circles, 5000u);
  EXPECT_GE(circles, 4000u);
  EXPECT_NE(fp.find("b &amp; &lt;1&gt;"), std::string::npos);
  EXPECT_NE(fp.find(" m</text>"), std::string::npos);  // the scale bar
}
