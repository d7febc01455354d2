// Headless Chromium for the tests of the HTML pages (run report, city review): the command line
// with software WebGL and a fixed viewport, and a decoder for its PNG screenshots.
#pragma once
#include <sys/wait.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace lodrefine::browser_fixtures {

namespace fs = std::filesystem;

inline std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

inline bool chromium_available() { return std::system("command -v chromium > /dev/null 2>&1") == 0; }

// Headless Chromium with software WebGL, a fixed viewport and its own profile folder.
inline std::string chromium(const fs::path& profile, int height) {
  return "timeout 120 chromium --headless --no-sandbox --disable-gpu-sandbox --enable-unsafe-swiftshader "
         "--use-angle=swiftshader --hide-scrollbars --force-device-scale-factor=1 --virtual-time-budget=20000 "
         "--user-data-dir=" +
         quoted(profile) + " --window-size=1400," + std::to_string(height) + " ";
}

// An 8-bit RGB/RGBA, non-interlaced PNG (what Chromium writes) as RGB rows.
struct Image {
  int width = 0, height = 0;
  std::vector<std::array<int, 3>> rgb;
  const std::array<int, 3>& at(int x, int y) const { return rgb[std::size_t(y) * std::size_t(width) + std::size_t(x)]; }
};

inline std::uint32_t be32(const unsigned char* p) {
  return (std::uint32_t(p[0]) << 24) | (p[1] << 16) | (p[2] << 8) | p[3];
}

inline Image decode_png(const std::string& file) {
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
  if (channels == 0 ||
      uncompress(raw.data(), &raw_len, reinterpret_cast<const Bytef*>(idat.data()), idat.size()) != Z_OK)
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

// The page after its scripts ran (--dump-dom): its text, the <html> start tag (where the pages
// note data-rendered and data-errors), Chromium's log and its console lines that are errors.
struct PageDump {
  int exit = -1;
  std::string page, root, log;
  std::vector<std::string> console_errors;
};

inline std::string file_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

inline PageDump dump_page(const fs::path& html, const fs::path& dir) {
  PageDump d;
  const int st = std::system((chromium(dir / "profile", 900) + "--enable-logging=stderr --v=0 --dump-dom " +
                              quoted(html) + " > " + quoted(dir / "dom.html") + " 2> " + quoted(dir / "chromium.log"))
                                 .c_str());
  d.exit = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  d.page = file_text(dir / "dom.html");
  d.log = file_text(dir / "chromium.log");
  std::smatch m;
  if (std::regex_search(d.page, m, std::regex("<html[^>]*>"))) d.root = m.str();
  std::istringstream lines(d.log);
  for (std::string line; std::getline(lines, line);)  // page console messages are CONSOLE lines
    if (line.find(":CONSOLE") != std::string::npos && line.find("ERROR") != std::string::npos)
      d.console_errors.push_back(line);
  return d;
}

// Shares of the pixels inside a canvas rectangle (3 px in from its border) that are drawn (not
// the white background), of the refined model's orange (its scan faces on the review page), of
// grey (the page's model faces: no other layer is grey; the coarse model is blue) and of purple
// (its added faces).
struct CanvasShares {
  double drawn = 0.0, orange = 0.0, grey = 0.0, purple = 0.0;
};

inline CanvasShares canvas_shares(const Image& img, int x0, int y0, int w, int h) {
  std::size_t drawn = 0, orange = 0, grey = 0, purple = 0, total = 0;
  for (int y = y0 + 3; y < y0 + h - 3; ++y)
    for (int x = x0 + 3; x < x0 + w - 3; ++x) {
      const auto& p = img.at(x, y);
      ++total;
      drawn += std::max({255 - p[0], 255 - p[1], 255 - p[2]}) > 30;
      orange += p[0] > 150 && p[1] > 60 && p[1] < 170 && p[2] < 90;
      grey += std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]}) < 12 && p[0] > 50 && p[0] < 210;
      purple += p[2] > p[1] + 50 && p[0] > p[1] + 30;
    }
  const double n = double(std::max<std::size_t>(1, total));
  return {double(drawn) / n, double(orange) / n, double(grey) / n, double(purple) / n};
}

}  // namespace lodrefine::browser_fixtures
