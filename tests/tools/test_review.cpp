// The review page of a city refine: hostile ids escaped in the HTML and inside the <script> JSON,
// the table worst first without the untouched buildings, the refusals counted; and the page of a
// refine of Rotterdam Delfshaven (853 buildings, a scan of three with one wall 0.4 m off, one of
// them with a hostile id) loads in headless Chromium with every refined building rendered.
#include <gtest/gtest.h>

#include <random>
#include <regex>

#include <nlohmann/json.hpp>

#include "lodrefine/base/geometry.h"
#include "lodrefine/formats/cityjson.h"
#include "lodrefine/formats/ply.h"
#include "lodrefine/tools/review.h"
#include "support/batch_fixtures.h"
#include "support/browser_fixtures.h"
#include "support/mesh_fixtures.h"
#include "support/realdata.h"
#include "support/scan_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::batch_fixtures;
using namespace lodrefine::browser_fixtures;

namespace {

const std::string kHostile = "</script><script>document.title='pwned'</script>\"'<!--\xE2\x80\xA8&";

CityReviewBuilding reviewed(const std::string& id, Outcome outcome, double fit_after, double x) {
  CityReviewBuilding b;
  b.id = id;
  b.outcome = outcome;
  b.reason = outcome == Outcome::Refined ? "" : "the refinement does not fit the scan better (RMS 0.1 -> 0.2 m)";
  b.fit_before = 0.2;
  b.fit_after = fit_after;
  const Mesh m = fixtures::box({x, 0, 0}, {x + 8, 6, 5});
  b.outline = review_outline(m, Vec3::Zero());
  if (outcome == Outcome::Refined || outcome == Outcome::Repaired) {
    Mesh written = fixtures::box({x + 0.3, 0, 0}, {x + 8, 6, 5});
    for (Face& f : written.faces) f.provenance = f.sem == Semantic::Wall ? Provenance::Scan : Provenance::Model;
    b.view = review_view(id, m, written, {}, 100);
  }
  return b;
}

}  // namespace

TEST(Review, HostileIdsEscapedAndTableWorstFirst) {
  CityReview r;
  r.title = "city <b>";
  r.summary = "2 refined";
  r.buildings = {reviewed("good", Outcome::Refined, 0.01, 0), reviewed(kHostile, Outcome::Refined, 0.05, 20),
                 reviewed("k1", Outcome::Kept, 0.3, 40), reviewed("k2", Outcome::Kept, 0.3, 60),
                 reviewed("u", Outcome::Untouched, 0, 80)};
  r.buildings[3].reason = "no wall matched a scan plane";
  for (const std::string id : {"i1", "i2"}) {
    r.buildings.push_back(reviewed(id, Outcome::KeptInvalid, 0.3, 100));
    r.buildings.back().reason = "building " + id + ": not closable: 2 non-manifold edges (more than two faces)";
  }
  const std::string h = city_review_html(r);
  // Only "</" and "<!--" can end or bend a script element: escaped, in the HTML as in the JSON.
  EXPECT_EQ(h.find("</script><script>document"), std::string::npos);
  EXPECT_EQ(h.find("<script>document"), h.find("\\u003c/script><script>document") + 14);
  EXPECT_EQ(h.find("<b>"), std::string::npos);
  EXPECT_NE(h.find("&lt;/script&gt;&lt;script&gt;document.title="), std::string::npos);
  const auto json_at = h.find("id=\"lodrefine-views\">");
  ASSERT_NE(json_at, std::string::npos);
  const std::string views = h.substr(json_at, h.find("</script>", json_at) - json_at);
  EXPECT_NE(views.find("\\u003c/script><script>document.title='pwned'\\u003c/script>\\\"'\\u003c!--\\u2028&"),
            std::string::npos)
      << views.substr(0, 400);
  // Worst first: kept before refined, the worse fit first; untouched buildings are not listed.
  const auto k1 = h.find("<td>k1</td>"), bad = h.find("<td><a href=\"#" + view_anchor(kHostile) + "\">&lt;/script"),
             good = h.find("<td><a href=\"#view-good\">good</a></td>");
  EXPECT_EQ(view_anchor(kHostile).find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_-."), std::string::npos)
      << view_anchor(kHostile);
  ASSERT_NE(k1, std::string::npos);
  ASSERT_NE(bad, std::string::npos);
  ASSERT_NE(good, std::string::npos);
  EXPECT_LT(k1, bad);
  EXPECT_LT(bad, good);
  // Untouched buildings are listed last, hidden until their box of the filter is ticked.
  EXPECT_NE(h.find("<tr class=\"untouched\" data-outcome=\"untouched\" hidden><td>u</td>"), std::string::npos);
  EXPECT_NE(h.find("<input type=\"checkbox\" data-outcome=\"untouched\"> untouched (1)"), std::string::npos);
  EXPECT_NE(h.find("<input type=\"checkbox\" data-outcome=\"kept\" checked> kept (2)"), std::string::npos);
  // The reason without the id the row shows beside it.
  EXPECT_NE(h.find("<td>i1</td><td>kept-invalid</td><td>not closable: 2 non-manifold edges"), std::string::npos);
  EXPECT_NE(h.find("id=\"view-good\" data-outcome=\"refined\""), std::string::npos);
  // The written faces by source, one per triangle (a box: ground and roof the model's, 8 wall
  // triangles the scan's).
  EXPECT_NE(h.find("\"sources\":[1,1,1,1,2,2,2,2,2,2,2,2]"), std::string::npos) << h.substr(h.find("\"sources\""), 80);
  EXPECT_EQ(h.find("id=\"view-k1\""), std::string::npos) << "only refined buildings get a view";
  // The refusals by check, numbers folded.
  EXPECT_NE(h.find("1  kept: the refinement does not fit the scan better"), std::string::npos);
  EXPECT_NE(h.find("1  kept: no wall matched a scan plane"), std::string::npos);
  EXPECT_NE(h.find("2  kept-invalid: not closable\n"), std::string::npos) << h.substr(h.find("checks that"), 300);
  // The map: every building outlined, refined ones linked to their view.
  EXPECT_NE(h.find("<a href=\"#view-good\"><path"), std::string::npos);
  EXPECT_NE(h.find("<title>u: untouched</title>"), std::string::npos);
}

namespace {

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
  return s;
}

// Drives the page in Chromium after its views rendered, noting in <html> data attributes what a
// reader would see: where the view of the map's link `first` lies before and after a click on its
// outline; the rows shown per outcome before and after unticking "refined"; then a click on
// `second`'s outline (its view hidden by the filter now) and whether its view is shown.
std::string page_driver(const std::string& first, const std::string& second) {
  const std::string script = R"js(<script>
(() => {
  const el = document.documentElement, outcomes = ['refined', 'repaired', 'kept', 'untouched'];
  const shown = () => outcomes.map(o => o + ':' +
      [...document.querySelectorAll('tr[data-outcome="' + o + '"]')].filter(r => !r.hidden).length).join(' ');
  const click = id => document.querySelector('.map a[href="#' + id + '"] path')
      .dispatchEvent(new MouseEvent('click', {bubbles: true, cancelable: true, view: window}));
  const top = id => Math.round(document.getElementById(id).getBoundingClientRect().top);
  const step = () => {
    if (el.dataset.rendered === undefined) return setTimeout(step, 50);
    el.dataset.topBefore = top(FIRST);
    click(FIRST);
    setTimeout(() => {
      el.dataset.hash = location.hash;
      el.dataset.topAfter = top(FIRST);
      el.dataset.scrolled = Math.round(scrollY);
      el.dataset.rowsBefore = shown();
      document.querySelector('.filter input[data-outcome="refined"]').click();
      el.dataset.rowsAfter = shown();
      el.dataset.refinedViewsHidden = [...document.querySelectorAll('section[data-outcome="refined"]')]
          .every(s => s.hidden);
      click(SECOND);
      setTimeout(() => {
        el.dataset.hash2 = location.hash;
        el.dataset.secondShown = !document.getElementById(SECOND).hidden;
        el.dataset.top2 = top(SECOND);
      }, 300);
    }, 300);
  };
  step();
})();
</script>)js";
  return replaced(replaced(script, "FIRST", "'" + first + "'"), "SECOND", "'" + second + "'");
}

// A data attribute of the dumped <html> start tag.
std::string attribute(const std::string& root, const std::string& name) {
  std::smatch m;
  return std::regex_search(root, m, std::regex(name + "=\"([^\"]*)\"")) ? m.str(1) : "(absent)";
}

}  // namespace

// The page for deciding, in headless Chromium: unticking an outcome hides its rows and views; a
// click on a building of the map scrolls to its 3D view, and shows it when the filter hid it.
TEST(Review, FilterAndMapClickThroughInChromium) {
  if (!chromium_available()) GTEST_SKIP() << "chromium not installed (Debian: chromium; .ci/run installs it)";
  const fs::path dir = fresh_dir("review_filter");
  CityReview r;
  r.title = "filter";
  r.summary = "4 buildings";
  r.buildings = {reviewed("rep", Outcome::Repaired, 0.02, 0), reviewed("good", Outcome::Refined, 0.01, 20),
                 reviewed(kHostile, Outcome::Refined, 0.03, 40), reviewed("k1", Outcome::Kept, 0.3, 60),
                 reviewed("u", Outcome::Untouched, 0, 80)};
  const std::string first = view_anchor(kHostile), second = view_anchor("good");
  std::string html = city_review_html(r);
  html.insert(html.rfind("</body>"), page_driver(first, second));
  std::ofstream(dir / "review.html") << html;

  const PageDump d = dump_page(dir / "review.html", dir);
  ASSERT_EQ(d.exit, 0) << d.log;
  EXPECT_EQ(d.root.find("data-errors"), std::string::npos) << d.root;
  EXPECT_EQ(attribute(d.root, "data-rendered"), "3") << d.root;
  EXPECT_EQ(attribute(d.root, "data-rows-before"), "refined:2 repaired:1 kept:1 untouched:0");
  EXPECT_EQ(attribute(d.root, "data-rows-after"), "refined:0 repaired:1 kept:1 untouched:0");
  EXPECT_EQ(attribute(d.root, "data-refined-views-hidden"), "true");
  // The click on the hostile id's outline scrolls its view into the window; the click on good's
  // shows its view the filter hid, in the window.
  EXPECT_EQ(attribute(d.root, "data-hash"), "#" + first);
  EXPECT_GT(std::stoi(attribute(d.root, "data-scrolled")), 0);
  const int before = std::stoi(attribute(d.root, "data-top-before")),
            after = std::stoi(attribute(d.root, "data-top-after"));
  EXPECT_GT(before, 900) << "below the window before the click";
  EXPECT_GE(after, 0);
  EXPECT_LT(after, 450) << "before the click at " << before;
  EXPECT_EQ(attribute(d.root, "data-hash2"), "#" + second);
  EXPECT_EQ(attribute(d.root, "data-second-shown"), "true");
  EXPECT_GE(std::stoi(attribute(d.root, "data-top2")), 0);
  EXPECT_LT(std::stoi(attribute(d.root, "data-top2")), 450);
  for (const std::string& line : d.console_errors) ADD_FAILURE() << line;
  if (!HasFailure()) fs::remove_all(dir);
}

TEST(Review, ViewKeepsOnlyPointsNearTheRefinedModelAndCapsThem) {
  const Mesh coarse = fixtures::box({100000, 400000, 0}, {100008, 400006, 5});
  const Mesh refined = fixtures::box({100000.3, 400000, 0}, {100008, 400006, 5});
  std::vector<Vec3> points;
  for (int i = 0; i < 5000; ++i) points.emplace_back(100000.3, 400000 + 6.0 * i / 5000, 0.5 + 4.0 * (i % 7) / 7);
  for (int i = 0; i < 5000; ++i) points.emplace_back(100030, 400000, 1);  // a neighbour far off
  const BuildingView v = review_view("b", coarse, refined, points, 800);
  ASSERT_FALSE(v.c2m.empty());
  EXPECT_LE(v.c2m.size(), 800u);
  EXPECT_EQ(v.points.size(), 3 * v.c2m.size());
  for (float d : v.c2m) EXPECT_LT(std::abs(d), 0.02);
  for (std::size_t i = 0; i < v.points.size(); i += 3) EXPECT_LT(std::abs(v.points[i]), 1.0f) << "a local frame";
}

namespace {

// Every written building's canvas (data-rect in the dumped `page`), in one screenshot tall enough
// for all of them: drawn, and the written model visible in its colours by source.
void expect_canvases_show_their_models(const std::string& page, const fs::path& dir, std::size_t viewed) {
  std::vector<std::array<int, 4>> rects;
  const std::regex rect("data-rect=\"(\\d+),(\\d+),(\\d+),(\\d+)\"");
  for (auto it = std::sregex_iterator(page.begin(), page.end(), rect); it != std::sregex_iterator(); ++it)
    rects.push_back({std::stoi((*it)[1]), std::stoi((*it)[2]), std::stoi((*it)[3]), std::stoi((*it)[4])});
  ASSERT_EQ(rects.size(), viewed);
  int bottom = 0;
  for (const auto& r : rects) bottom = std::max(bottom, r[1] + r[3]);
  const fs::path shot = dir / "shot.png";
  ASSERT_EQ(shell(chromium(dir / "profile", bottom + 40) + "--screenshot=" + shell_quoted(shot) + " " +
                  shell_quoted(dir / "review.html") + " > /dev/null 2>&1"),
            0);
  const Image img = decode_png(read_text(shot));
  for (const auto& [x0, y0, w, h] : rects) {
    ASSERT_GT(w, 100);
    ASSERT_GE(img.width, x0 + w);
    ASSERT_GE(img.height, y0 + h);
    const CanvasShares c = canvas_shares(img, x0, y0, w, h);
    std::printf("3D canvas at (%d, %d): %.1f %% drawn, %.1f %% scan orange, %.1f %% model grey, %.1f %% added purple\n",
                x0, y0, 100.0 * c.drawn, 100.0 * c.orange, 100.0 * c.grey, 100.0 * c.purple);
    EXPECT_GT(c.drawn, 0.05) << "a 3D view looks empty";
    // The written model in its colours by source: the moved wall may face away from the camera,
    // the model's faces (roof, the walls the scan confirms) or the added ones (a hole the repair
    // closed) are in view.
    EXPECT_GT(c.orange + c.grey + c.purple, 0.05) << "a refined model is not visible";
  }
}

// The page's view data (`html`): each of the `viewed` views colours its faces by source, every one
// with scan faces (the moved wall) and the model's (its roof).
void expect_views_coloured_by_source(const std::string& html, std::size_t viewed) {
  const auto data_at = html.find("id=\"lodrefine-views\">");
  ASSERT_NE(data_at, std::string::npos);
  const std::size_t json_at = html.find('>', data_at) + 1;
  const json views = json::parse(html.substr(json_at, html.find("</script>", json_at) - json_at));
  ASSERT_EQ(views.size(), viewed);
  for (const json& v : views) {
    const std::vector<int> sources = v.value("sources", std::vector<int>());
    EXPECT_NE(std::count(sources.begin(), sources.end(), int(Provenance::Scan)), 0) << v["id"];
    EXPECT_NE(std::count(sources.begin(), sources.end(), int(Provenance::Model)), 0) << v["id"];
  }
}

}  // namespace

TEST(Review, DelfshavenRefinePageRendersEveryRefinedBuilding) {
  REQUIRE_REALDATA("val3dity/data/rotterdam/3-20-DELFSHAVEN.city.json");
  if (!chromium_available()) GTEST_SKIP() << "chromium not installed (Debian: chromium; .ci/run installs it)";
  const fs::path dir = fresh_dir("review");
  // The city with one scanned building renamed to a hostile id.
  const CityJsonFile city = read_cityjson(data_path.string());
  std::mt19937 rng(3);
  PointCloud cloud;
  std::vector<std::string> scanned;
  for (const auto& b : city.buildings) {
    if (scanned.size() == 3) break;
    if (b.mesh.faces.size() < 6 || b.mesh.faces.size() > 14) continue;
    std::size_t largest = 0;
    double area = 0;
    for (std::size_t k = 0; k < b.mesh.faces.size(); ++k)
      if (b.mesh.faces[k].sem == Semantic::Wall && polygon_area(face_points(b.mesh, b.mesh.faces[k])) > area)
        area = polygon_area(face_points(b.mesh, b.mesh.faces[k])), largest = k;
    if (area < 40) continue;
    for (std::size_t k = 0; k < b.mesh.faces.size(); ++k)
      if (b.mesh.faces[k].sem == Semantic::Wall)
        fixtures::sample_face(face_points(b.mesh, b.mesh.faces[k]), k == largest ? 0.4 : 0.0, 0.1, rng, cloud);
    scanned.push_back(b.mesh.id);
  }
  ASSERT_EQ(scanned.size(), 3u);
  write_ply((dir / "scan.ply").string(), cloud);
  nlohmann::ordered_json doc = nlohmann::ordered_json::parse(read_text(data_path));
  // Would mark the page if it ever ran.
  const std::string hostile = "</script><img src=x onerror=\"document.documentElement.dataset.pwned=1\">'";
  doc["CityObjects"][hostile] = doc["CityObjects"][scanned[1]];
  doc["CityObjects"].erase(scanned[1]);
  std::ofstream(dir / "city.json") << doc.dump();

  ASSERT_EQ(shell(kBinary + " refine --model " + shell_quoted(dir / "city.json") + " --cloud " +
                  shell_quoted(dir / "scan.ply") + " --out " + shell_quoted(dir / "out.city.json") + " --report " +
                  shell_quoted(dir / "report.json") + " --html " + shell_quoted(dir / "review.html") + " > " +
                  shell_quoted(dir / "refine.log") + " 2>&1"),
            0)
      << read_text(dir / "refine.log");
  const json rep = json::parse(read_text(dir / "report.json"));
  std::vector<std::string> refined;
  std::size_t viewed = 0;  // refined and repaired buildings have a view
  for (const auto& o : rep["outcomes"]) {
    if (o["outcome"] == "refined") refined.push_back(o["id"]);
    viewed += o["outcome"] == "refined" || o["outcome"] == "repaired";
  }
  ASSERT_GE(refined.size(), 1u) << rep.dump(1);
  const std::string html = read_text(dir / "review.html");
  EXPECT_EQ(html.find("</script><img"), std::string::npos);
  EXPECT_EQ(html.find("src=\"http"), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_NE(html.find("853 building(s): " + std::to_string(refined.size()) + " refined"), std::string::npos);
  EXPECT_NE(html.find(std::to_string(rep["untouched"].get<int>()) + " untouched"), std::string::npos);

  const PageDump d = dump_page(dir / "review.html", dir);
  ASSERT_EQ(d.exit, 0) << d.log;
  const std::string& page = d.page;
  ASSERT_FALSE(d.root.empty()) << page.substr(0, 500);
  EXPECT_EQ(d.root.find("data-errors"), std::string::npos) << d.root;
  EXPECT_EQ(d.root.find("data-pwned"), std::string::npos) << "the hostile id ran";
  EXPECT_NE(d.root.find("data-rendered=\"" + std::to_string(viewed) + "\""), std::string::npos) << d.root << "\n"
                                                                                                << d.log;
  for (const std::string& line : d.console_errors) ADD_FAILURE() << line;

  expect_canvases_show_their_models(page, dir, viewed);
  expect_views_coloured_by_source(html, viewed);
  if (!HasFailure()) fs::remove_all(dir);
}

TEST(Review, HtmlNeedsACityFileAndAWritableFolder) {
  const fs::path dir = fresh_dir("review_bad");
  const std::string sample = (kSource / "data" / "samples" / "synth_gable_0001").string();
  const std::string refine = kBinary + " refine --model " + shell_quoted(sample + "/coarse.obj") + " --cloud " +
                             shell_quoted(sample + "/cloud.ply") + " --out " + shell_quoted(dir / "r.obj");
  EXPECT_EQ(shell(refine + " --html " + shell_quoted(dir / "r.html") + " > /dev/null 2> " + shell_quoted(dir / "err")),
            2);
  EXPECT_NE(read_text(dir / "err")
                .find("lodrefine: error: " + sample +
                      "/coarse.obj: --html (the review page of a city refine) applies to "
                      "a city file as --model"),
            std::string::npos)
      << read_text(dir / "err");
  EXPECT_FALSE(fs::exists(dir / "r.obj"));
  EXPECT_EQ(
      shell(refine + " --html " + shell_quoted(dir / "no" / "r.html") + " > /dev/null 2> " + shell_quoted(dir / "err")),
      2);
  EXPECT_NE(read_text(dir / "err").find("output directory"), std::string::npos) << read_text(dir / "err");
  if (!HasFailure()) fs::remove_all(dir);
}
