// The HTML run report of a generated tile, opened in headless Chromium: it must load without
// script errors, render every 3D view (the page sets data-rendered), and a screenshot must show
// the model in the first 3D canvas. Skips when chromium is not installed (.ci/run installs it).
#include <gtest/gtest.h>
#include <zlib.h>

#include <array>
#include <regex>

#include "support/batch_fixtures.h"

using namespace lodrefine::batch_fixtures;

namespace {

bool chromium_available() { return shell("command -v chromium > /dev/null 2>&1") == 0; }

// Headless Chromium with software WebGL, a fixed viewport and its own profile folder.
std::string chromium(const fs::path& profile, int height) {
  return "timeout 120 chromium --headless --no-sandbox --disable-gpu-sandbox --enable-unsafe-swiftshader "
         "--use-angle=swiftshader --hide-scrollbars --force-device-scale-factor=1 --virtual-time-budget=20000 "
         "--user-data-dir=" + shell_quoted(profile) + " --window-size=1400," + std::to_string(height) + " ";
}

// An 8-bit RGB/RGBA, non-interlaced PNG (what Chromium writes) as RGB rows.
struct Image {
  int width = 0, height = 0;
  std::vector<std::array<int, 3>> rgb;
  const std::array<int, 3>& at(int x, int y) const { return rgb[std::size_t(y) * std::size_t(width) + std::size_t(x)]; }
};

std::uint32_t be32(const unsigned char* p) { return (std::uint32_t(p[0]) << 24) | (p[1] << 16) | (p[2] << 8) | p[3]; }

Image decode_png(const std::string& file) {
  Image img;
  const auto* d = reinterpret_cast<const unsigned char*>(file.data());
  if (file.size() < 8 || file.compare(1, 3, "PNG") != 0) return img;
  std::string idat;
  int channels = 0;
  for (std::size_t at = 8; at + 12 <= file.size();) {
    const std::uint32_t len = be32(d + at);
    const std::string type = file.substr(at + 4, 4);
    const unsigned char* body = d + at + 8;
    if (type == "IHDR") {
      img.width = int(be32(body)), img.height = int(be32(body + 4));
      if (body[8] != 8 || body[12] != 0 || (body[9] != 2 && body[9] != 6)) return {};
      channels = body[9] == 6 ? 4 : 3;
    } else if (type == "IDAT") {
      idat.append(reinterpret_cast<const char*>(body), len);
    }
    at += 12 + len;
  }
  const std::size_t stride = std::size_t(img.width) * std::size_t(channels);
  std::vector<unsigned char> raw((stride + 1) * std::size_t(img.height));
  uLongf raw_len = raw.size();
  if (channels == 0 || uncompress(raw.data(), &raw_len, reinterpret_cast<const Bytef*>(idat.data()), idat.size()) != Z_OK)
    return {};
  std::vector<unsigned char> prev(stride, 0), cur(stride);
  for (int y = 0; y < img.height; ++y) {
    const unsigned char* line = raw.data() + std::size_t(y) * (stride + 1);
    for (std::size_t i = 0; i < stride; ++i) {
      const int a = i >= std::size_t(channels) ? cur[i - std::size_t(channels)] : 0, b = prev[i],
                c = i >= std::size_t(channels) ? prev[i - std::size_t(channels)] : 0;
      int pred = 0;
      switch (line[0]) {
        case 1: pred = a; break;
        case 2: pred = b; break;
        case 3: pred = (a + b) / 2; break;
        case 4: {
          const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
          pred = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
          break;
        }
        default: break;
      }
      cur[i] = static_cast<unsigned char>(line[1 + i] + pred);
    }
    for (int x = 0; x < img.width; ++x) {
      const unsigned char* px = cur.data() + std::size_t(x) * std::size_t(channels);
      img.rgb.push_back({px[0], px[1], px[2]});
    }
    prev = cur;
  }
  return img;
}

TEST(Report, PageLoadsWithoutErrorsAndTheScreenshotShowsTheModel) {
  if (!chromium_available()) GTEST_SKIP() << "chromium not installed (Debian: chromium; .ci/run installs it)";
  const fs::path run = fresh_dir("report");
  make_tile(run, 4);
  // One building whose cloud cannot be read: a failed row, no view, and the page still works.
  std::string broken;
  for (const auto& e : fs::directory_iterator(run)) broken = std::max(broken, e.path().filename().string());
  std::ofstream(run / broken / "cloud.ply") << "ply\nformat ascii 1.0\nelement vertex 5\nend_header\n1 2\n";
  ASSERT_EQ(shell(batch_command(run) + " > " + shell_quoted(run / "batch.log") + " 2>&1"), 0) << read_text(run / "batch.log");
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

  const fs::path dom = run / "dom.html", log = run / "chromium.log", shot = run / "shot.png";
  ASSERT_EQ(shell(chromium(run / "profile", 900) + "--enable-logging=stderr --v=0 --dump-dom " +
                  shell_quoted(run / "report.html") + " > " + shell_quoted(dom) + " 2> " + shell_quoted(log)),
            0)
      << read_text(log);
  const std::string page = read_text(dom);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(page, m, std::regex("<html[^>]*>"))) << page.substr(0, 500);
  const std::string root = m.str();
  EXPECT_EQ(root.find("data-errors"), std::string::npos) << root;
  EXPECT_NE(root.find("data-rendered=\"3\""), std::string::npos) << root << "\n" << read_text(log);
  // Chromium logs page console messages as CONSOLE lines: none may be an error.
  std::istringstream lines(read_text(log));
  for (std::string line; std::getline(lines, line);)
    if (line.find(":CONSOLE") != std::string::npos)
      EXPECT_EQ(line.find("ERROR"), std::string::npos) << line;

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
  std::size_t drawn = 0, orange = 0, total = 0;
  for (int y = y0 + 3; y < y0 + h - 3; ++y)
    for (int x = x0 + 3; x < x0 + w - 3; ++x) {
      const auto& p = img.at(x, y);
      ++total;
      drawn += std::max({255 - p[0], 255 - p[1], 255 - p[2]}) > 30;  // not the white background
      orange += p[0] > 150 && p[1] > 60 && p[1] < 170 && p[2] < 90;   // the refined model's colour
    }
  std::printf("3D canvas %dx%d at (%d, %d): %.1f %% drawn, %.1f %% refined-model orange\n", w, h, x0, y0,
              100.0 * double(drawn) / double(total), 100.0 * double(orange) / double(total));
  EXPECT_GT(double(drawn) / double(total), 0.05) << "the 3D view looks empty";
  EXPECT_GT(double(orange) / double(total), 0.02) << "the refined model is not visible";
  // Outside the canvas, left of it, the page background is white.
  EXPECT_EQ(img.at(x0 - 5 > 0 ? x0 - 5 : 0, y0 + h / 2)[0] > 200, true);
  if (!HasFailure()) fs::remove_all(run);
}

}  // namespace
