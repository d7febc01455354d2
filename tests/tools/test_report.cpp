// The HTML run report of a generated tile, opened in headless Chromium: it must load without
// script errors, render every 3D view (the page sets data-rendered), and a screenshot must show
// the model in the first 3D canvas. Skips when chromium is not installed (.ci/run installs it).
#include <gtest/gtest.h>
#include <regex>

#include "support/batch_fixtures.h"
#include "support/browser_fixtures.h"

using namespace lodrefine::batch_fixtures;
using namespace lodrefine::browser_fixtures;

namespace {

TEST(Report, PageLoadsWithoutErrorsAndTheScreenshotShowsTheModel) {
  if (!chromium_available()) GTEST_SKIP() << "chromium not installed (Debian: chromium; .ci/run installs it)";
  const fs::path run = fresh_dir("report");
  make_tile(run, 4);
  // One building whose cloud cannot be read: a failed row, no view, and the page still works.
  std::string broken;
  for (const auto& e : fs::directory_iterator(run)) broken = std::max(broken, e.path().filename().string());
  std::ofstream(run / broken / "cloud.ply") << "ply\nformat ascii 1.0\nelement vertex 5\nend_header\n1 2\n";
  ASSERT_EQ(shell(batch_command(run) + " > " + shell_quoted(run / "batch.log") + " 2>&1"), 0)
      << read_text(run / "batch.log");
  const std::string html = read_text(run / "report.html");
  ASSERT_FALSE(html.empty());
  // Self-contained: nothing fetched from anywhere.
  EXPECT_EQ(html.find("src=\"http"), std::string::npos);
  EXPECT_EQ(html.find("href=\"http"), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_NE(html.find("<svg"), std::string::npos) << "plots and footprints are inline SVG";
  const std::string reason = read_text(run / broken / "FAILED");
  ASSERT_FALSE(reason.empty());
  const auto failed_row = html.find("<tr class=\"failed\"><td>" + broken + "</td><td>failed</td>");
  EXPECT_NE(failed_row, std::string::npos) << "the failed building heads the table";
  EXPECT_LT(failed_row, html.find("<tr class=\"refined\">"));
  EXPECT_EQ(html.find("id=\"view-" + broken + "\""), std::string::npos) << "no view of unreadable inputs";

  const fs::path shot = run / "shot.png";
  const PageDump d = dump_page(run / "report.html", run);
  ASSERT_EQ(d.exit, 0) << d.log;
  const std::string& page = d.page;
  std::smatch m;
  ASSERT_FALSE(d.root.empty()) << page.substr(0, 500);
  EXPECT_EQ(d.root.find("data-errors"), std::string::npos) << d.root;
  EXPECT_NE(d.root.find("data-rendered=\"3\""), std::string::npos) << d.root << "\n" << d.log;
  for (const std::string& line : d.console_errors) ADD_FAILURE() << line;

  // The first 3D canvas, where the page says it is; then its pixels in a screenshot.
  ASSERT_TRUE(std::regex_search(page, m, std::regex("data-rect=\"(\\d+),(\\d+),(\\d+),(\\d+)\""))) << "no canvas rect";
  const int x0 = std::stoi(m[1]), y0 = std::stoi(m[2]), w = std::stoi(m[3]), h = std::stoi(m[4]);
  ASSERT_GT(w, 100);
  ASSERT_GT(h, 100);
  ASSERT_EQ(shell(chromium(run / "profile", y0 + h + 40) + "--screenshot=" + shell_quoted(shot) + " " +
                  shell_quoted(run / "report.html") + " > /dev/null 2>&1"),
            0);
  const Image img = decode_png(read_text(shot));
  ASSERT_GE(img.width, x0 + w);
  ASSERT_GE(img.height, y0 + h);
  const CanvasShares c = canvas_shares(img, x0, y0, w, h);
  std::printf("3D canvas %dx%d at (%d, %d): %.1f %% drawn, %.1f %% refined-model orange\n", w, h, x0, y0,
              100.0 * c.drawn, 100.0 * c.orange);
  EXPECT_GT(c.drawn, 0.05) << "the 3D view looks empty";
  EXPECT_GT(c.orange, 0.02) << "the refined model is not visible";
  // Outside the canvas, left of it, the page background is white.
  EXPECT_EQ(img.at(x0 - 5 > 0 ? x0 - 5 : 0, y0 + h / 2)[0] > 200, true);
  if (!HasFailure()) fs::remove_all(run);
}

}  // namespace
