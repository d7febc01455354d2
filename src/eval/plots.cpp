#include "lodrefine/eval/plots.h"

#include "lodrefine/eval/eval.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace lodrefine {

namespace {

const char* const kBlue = "#1f77b4";
const char* const kOrange = "#ff7f0e";
const char* const kGreen = "#2ca02c";

std::string num(double x, int decimals = 2) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, x);
  return buf;
}

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '&') out += "&amp;";
    else if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

// Minimal SVG builder: just the elements the plots use.
class Svg {
 public:
  Svg(double w, double h) : w_(w), h_(h) {
    s_ << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << w << "\" height=\"" << h << "\" viewBox=\"0 0 " << w
       << ' ' << h << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
       << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  }
  void line(double x1, double y1, double x2, double y2, const std::string& style) {
    s_ << "<line x1=\"" << num(x1) << "\" y1=\"" << num(y1) << "\" x2=\"" << num(x2) << "\" y2=\"" << num(y2) << "\" "
       << style << "/>\n";
  }
  void rect(double x, double y, double w, double h, const std::string& style) {
    s_ << "<rect x=\"" << num(x) << "\" y=\"" << num(y) << "\" width=\"" << num(std::max(0.0, w)) << "\" height=\""
       << num(std::max(0.0, h)) << "\" " << style << "/>\n";
  }
  void text(double x, double y, const std::string& t, const std::string& style = "") {
    s_ << "<text x=\"" << num(x) << "\" y=\"" << num(y) << "\" " << style << ">" << escape(t) << "</text>\n";
  }
  void raw(const std::string& element) { s_ << element << '\n'; }
  void title(const std::string& t) { text(w_ / 2, 22, t, "text-anchor=\"middle\" font-size=\"15\""); }
  std::string str() { return s_.str() + "</svg>\n"; }

 private:
  double w_, h_;
  std::ostringstream s_;
};

// Tick spacing of 1, 2 or 5 × 10^k giving about `target` ticks over `span`.
double nice_step(double span, int target) {
  if (!(span > 0)) return 1.0;
  const double raw = span / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * mag >= raw) return m * mag;
  return 10 * mag;
}

int decimals_for(double step) { return std::max(0, int(std::ceil(-std::log10(step) - 1e-9))); }

// Plot area inside margins with a linear data-to-pixel mapping on both axes.
struct Frame {
  double left, top, width, height;
  double x0, x1, y0, y1;  // data range
  double px(double x) const { return left + (x - x0) / (x1 - x0) * width; }
  double py(double y) const { return top + height - (y - y0) / (y1 - y0) * height; }
};

void draw_axes(Svg& svg, const Frame& f, const std::string& xlabel, const std::string& ylabel, bool xticks) {
  const std::string grid = "stroke=\"#ddd\" stroke-width=\"1\"";
  const double ys = nice_step(f.y1 - f.y0, 6);
  for (double y = std::ceil(f.y0 / ys) * ys; y <= f.y1 + 1e-9 * ys; y += ys) {
    svg.line(f.left, f.py(y), f.left + f.width, f.py(y), grid);
    svg.text(f.left - 6, f.py(y) + 4, num(y, decimals_for(ys)), "text-anchor=\"end\"");
  }
  if (xticks) {
    const double xs = nice_step(f.x1 - f.x0, 8);
    for (double x = std::ceil(f.x0 / xs) * xs; x <= f.x1 + 1e-9 * xs; x += xs) {
      svg.line(f.px(x), f.top + f.height, f.px(x), f.top + f.height + 5, "stroke=\"black\"");
      svg.text(f.px(x), f.top + f.height + 18, num(x, decimals_for(xs)), "text-anchor=\"middle\"");
    }
  }
  svg.rect(f.left, f.top, f.width, f.height, "fill=\"none\" stroke=\"black\"");
  svg.text(f.left + f.width / 2, f.top + f.height + 38, xlabel, "text-anchor=\"middle\"");
  const double yc = f.top + f.height / 2;
  svg.text(f.left - 48, yc, ylabel,
           "text-anchor=\"middle\" transform=\"rotate(-90 " + num(f.left - 48) + ' ' + num(yc) + ")\"");
}

void legend_entry(Svg& svg, double x, double y, const std::string& color, const std::string& label) {
  svg.rect(x, y - 10, 14, 10, "fill=\"" + color + "\" fill-opacity=\"0.6\" stroke=\"" + color + "\"");
  svg.text(x + 20, y, label);
}

// Histogram half-width: the 99th percentile of |d| (`q`) rounded up to a nice value, >= 0.1 m.
double nice_range(double q) {
  if (!(q > 0)) return 0.1;
  const double step = nice_step(q, 4);
  return std::max(0.1, std::ceil(q / step) * step);
}

double auto_range(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> all;
  for (double x : a) all.push_back(std::abs(x));
  for (double x : b) all.push_back(std::abs(x));
  return nice_range(percentile(all, 0.99));
}

// One series of the histogram plot: percent of points per bin over [-range, range], the percent
// outside, the count and the RMSE.
struct HistogramSeries {
  std::vector<double> shares;
  double outside = 0, rmse = 0;
  std::uint64_t n = 0;
};

HistogramSeries histogram_series(const std::vector<double>& d, double range, int bins) {
  HistogramSeries s;
  s.shares.assign(std::size_t(bins), 0.0);
  std::size_t out = 0;
  for (double x : d) {
    const int b = int(std::floor((x + range) / (2 * range) * bins));
    if (b < 0 || b >= bins) ++out;
    else s.shares[std::size_t(b)] += 1;
  }
  s.n = d.size();
  const double n = double(std::max<std::size_t>(1, d.size()));
  for (double& v : s.shares) v *= 100.0 / n;
  s.outside = 100.0 * double(out) / n;
  s.rmse = summarize_distances(d).rmse;
  return s;
}

// The same from a pooled histogram (each fine bin counted in the plot bin of its centre).
HistogramSeries histogram_series(const DistanceHistogram& d, double range, int bins) {
  HistogramSeries s;
  s.shares.assign(std::size_t(bins), 0.0);
  const double bw = 2 * range / bins, n = double(std::max<std::uint64_t>(1, d.count()));
  std::uint64_t inside = 0;
  for (int i = 0; i < bins; ++i) {
    const std::uint64_t c = d.count_between(-range + i * bw, i + 1 == bins ? range : -range + (i + 1) * bw);
    inside += c;
    s.shares[std::size_t(i)] = 100.0 * double(c) / n;
  }
  s.n = d.count();
  s.outside = 100.0 * double(d.count() - inside) / n;
  s.rmse = d.stats().rmse;
  return s;
}

std::string draw_histogram(const HistogramSeries& hb, const HistogramSeries& ha, const std::string& title, double range,
                           int bins) {
  const double top = std::max(*std::max_element(hb.shares.begin(), hb.shares.end()),
                              *std::max_element(ha.shares.begin(), ha.shares.end()));
  Svg svg(760, 440);
  svg.title(title);
  const Frame f{80, 40, 650, 330, -range, range, 0.0, std::max(1.0, top * 1.08)};
  draw_axes(svg, f, "signed C2M distance (m)", "points (%)", true);
  const double bw = 2 * range / bins;
  auto bars = [&](const std::vector<double>& h, const char* color) {
    for (int i = 0; i < bins; ++i) {
      const double x = -range + i * bw;
      svg.rect(
          f.px(x), f.py(h[std::size_t(i)]), f.px(x + bw) - f.px(x), f.py(0) - f.py(h[std::size_t(i)]),
          std::string("fill=\"") + color + "\" fill-opacity=\"0.5\" stroke=\"" + color + "\" stroke-width=\"0.5\"");
    }
  };
  bars(hb.shares, kBlue);
  bars(ha.shares, kOrange);
  svg.line(f.px(0), f.top, f.px(0), f.top + f.height, "stroke=\"#555\" stroke-dasharray=\"4 3\"");
  auto label = [&](const char* name, const HistogramSeries& h) {
    return std::string(name) + ": n=" + std::to_string(h.n) + ", RMSE " + num(h.rmse, 3) + " m, " + num(h.outside, 1) +
           "% beyond ±" + num(range, 2) + " m";
  };
  legend_entry(svg, f.left + 10, f.top + 18, kBlue, label("original", hb));
  legend_entry(svg, f.left + 10, f.top + 36, kOrange, label("refined", ha));
  return svg.str();
}

}  // namespace

std::string svg_histogram(const std::vector<double>& before, const std::vector<double>& after, const std::string& title,
                          double range, int bins) {
  if (!(range > 0)) range = auto_range(before, after);
  bins = std::max(1, bins);
  return draw_histogram(histogram_series(before, range, bins), histogram_series(after, range, bins), title, range,
                        bins);
}

std::string svg_histogram(const DistanceHistogram& before, const DistanceHistogram& after, const std::string& title,
                          double range, int bins) {
  if (!(range > 0)) {
    DistanceHistogram both = before;
    both.merge(after);
    range = nice_range(both.abs_quantile(0.99));
  }
  bins = std::max(1, bins);
  return draw_histogram(histogram_series(before, range, bins), histogram_series(after, range, bins), title, range,
                        bins);
}

namespace {

struct BoxStats {
  double q1 = 0, median = 0, q3 = 0, lo = 0, hi = 0, mean = 0;
  std::uint64_t outliers = 0, n = 0;
};

BoxStats box_stats(std::vector<double> d) {
  BoxStats b;
  b.n = d.size();
  if (d.empty()) return b;
  b.q1 = percentile(d, 0.25), b.median = percentile(d, 0.5), b.q3 = percentile(d, 0.75);
  const double iqr = b.q3 - b.q1, fence_lo = b.q1 - 1.5 * iqr, fence_hi = b.q3 + 1.5 * iqr;
  b.lo = b.q1, b.hi = b.q3;
  double sum = 0;
  for (double x : d) {
    sum += x;
    if (x < fence_lo || x > fence_hi) ++b.outliers;
    else b.lo = std::min(b.lo, x), b.hi = std::max(b.hi, x);
  }
  b.mean = sum / double(d.size());
  return b;
}

// The same from a pooled histogram: quartiles, whiskers and outliers to one bin, the mean exact.
BoxStats box_stats(const DistanceHistogram& d) {
  BoxStats b;
  b.n = d.count();
  if (d.count() == 0) return b;
  b.q1 = d.quantile(0.25), b.median = d.quantile(0.5), b.q3 = d.quantile(0.75);
  const double iqr = b.q3 - b.q1, fence_lo = b.q1 - 1.5 * iqr, fence_hi = b.q3 + 1.5 * iqr;
  const double lo = d.lowest_in(fence_lo, fence_hi), hi = d.highest_in(fence_lo, fence_hi);
  b.lo = std::isfinite(lo) ? std::min(lo, b.q1) : b.q1;
  b.hi = std::isfinite(hi) ? std::max(hi, b.q3) : b.q3;
  b.outliers = d.count() - d.count_between(fence_lo, std::nextafter(fence_hi, HUGE_VAL));
  b.mean = d.mean();
  return b;
}

void draw_box(Svg& svg, const Frame& f, double cx, const BoxStats& b, const char* color) {
  const double hw = 50;
  const std::string stroke = std::string("stroke=\"") + color + "\" stroke-width=\"1.5\"";
  svg.line(cx, f.py(b.lo), cx, f.py(b.q1), stroke);
  svg.line(cx, f.py(b.q3), cx, f.py(b.hi), stroke);
  svg.line(cx - hw / 2, f.py(b.lo), cx + hw / 2, f.py(b.lo), stroke);
  svg.line(cx - hw / 2, f.py(b.hi), cx + hw / 2, f.py(b.hi), stroke);
  svg.rect(cx - hw, f.py(b.q3), 2 * hw, f.py(b.q1) - f.py(b.q3),
           std::string("fill=\"") + color + "\" fill-opacity=\"0.35\" " + stroke);
  svg.line(cx - hw, f.py(b.median), cx + hw, f.py(b.median), "stroke=\"red\" stroke-width=\"2\"");
  const double my = f.py(b.mean);
  svg.line(cx - 5, my - 5, cx + 5, my + 5, "stroke=\"black\"");
  svg.line(cx - 5, my + 5, cx + 5, my - 5, "stroke=\"black\"");
}

std::string draw_boxplot(const BoxStats& bb, const BoxStats& ba, const std::string& title) {
  double lo = std::min({bb.lo, ba.lo, 0.0}), hi = std::max({bb.hi, ba.hi, 0.0});
  const double pad = std::max(0.02, 0.08 * (hi - lo));
  Svg svg(520, 460);
  svg.title(title);
  const Frame f{90, 40, 400, 350, 0.0, 1.0, lo - pad, hi + pad};
  draw_axes(svg, f, "", "signed C2M distance (m)", false);
  svg.line(f.left, f.py(0), f.left + f.width, f.py(0), "stroke=\"#555\" stroke-dasharray=\"4 3\"");
  const double c1 = f.left + f.width * 0.28, c2 = f.left + f.width * 0.72;
  draw_box(svg, f, c1, bb, kBlue);
  draw_box(svg, f, c2, ba, kOrange);
  auto caption = [&](double cx, const char* name, const BoxStats& b) {
    svg.text(cx, f.top + f.height + 20, name, "text-anchor=\"middle\"");
    const std::string small = "text-anchor=\"middle\" font-size=\"10\"";
    svg.text(cx, f.top + f.height + 34, "median " + num(b.median, 3) + " m, IQR " + num(b.q3 - b.q1, 3) + " m", small);
    svg.text(cx, f.top + f.height + 47, std::to_string(b.outliers) + " of " + std::to_string(b.n) + " beyond whiskers",
             small);
  };
  caption(c1, "original", bb);
  caption(c2, "refined", ba);
  return svg.str();
}

}  // namespace

std::string svg_boxplot(const std::vector<double>& before, const std::vector<double>& after, const std::string& title) {
  return draw_boxplot(box_stats(before), box_stats(after), title);
}

std::string svg_boxplot(const DistanceHistogram& before, const DistanceHistogram& after, const std::string& title) {
  return draw_boxplot(box_stats(before), box_stats(after), title);
}

namespace {

std::vector<int> outline_faces(const Mesh& m) {
  std::vector<int> faces;
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    if (m.faces[f].sem == Semantic::Wall || m.faces[f].sem == Semantic::Ground) faces.push_back(int(f));
  if (faces.empty())
    for (std::size_t f = 0; f < m.faces.size(); ++f) faces.push_back(int(f));
  return faces;
}

// Map from the XY extent of the data to a square-pixel canvas, north up.
struct TopView {
  double minx, maxy, scale, left, top;
  double px(const Vec3& p) const { return left + (p.x() - minx) * scale; }
  double py(const Vec3& p) const { return top + (maxy - p.y()) * scale; }
};

std::string outline_path(const Mesh& m, const TopView& v, const char* color, const std::string& extra) {
  std::ostringstream d;
  for (int f : outline_faces(m)) {
    const auto& idx = m.faces[std::size_t(f)].v;
    for (std::size_t i = 0; i < idx.size(); ++i) {
      const Vec3& p = m.vertices.at(std::size_t(idx[i]));
      d << (i == 0 ? 'M' : 'L') << num(v.px(p)) << ' ' << num(v.py(p)) << ' ';
    }
    d << "Z ";
  }
  return "<path d=\"" + d.str() + "\" fill=\"none\" stroke=\"" + color + "\" stroke-width=\"1.2\" " + extra +
         " stroke-linejoin=\"round\"/>";
}

// Largest 1, 2 or 5 × 10^k not above x (scale bar lengths).
double nice_floor(double x) {
  const double mag = std::pow(10.0, std::floor(std::log10(x)));
  for (double m : {5.0, 2.0})
    if (m * mag <= x) return m * mag;
  return mag;
}

void scale_bar(Svg& svg, const TopView& v, double span_m, double x, double y) {
  const double len = nice_floor(span_m / 5);
  const double w = len * v.scale;
  svg.rect(x, y - 6, w / 2, 6, "fill=\"black\"");
  svg.rect(x + w / 2, y - 6, w / 2, 6, "fill=\"white\" stroke=\"black\"");
  svg.text(x, y + 14, "0", "text-anchor=\"middle\" font-size=\"11\"");
  svg.text(x + w, y + 14, num(len, decimals_for(len)) + " m", "text-anchor=\"middle\" font-size=\"11\"");
}

}  // namespace

std::string svg_footprint(const Mesh& original, const Mesh& refined, const std::vector<Vec3>& facade_points,
                          const std::string& title, std::size_t max_points) {
  double minx = std::numeric_limits<double>::max(), miny = minx, maxx = -minx, maxy = -minx;
  auto extend = [&](const Vec3& p) {
    minx = std::min(minx, p.x()), maxx = std::max(maxx, p.x());
    miny = std::min(miny, p.y()), maxy = std::max(maxy, p.y());
  };
  for (const auto* m : {&original, &refined})
    for (const auto& p : m->vertices) extend(p);
  for (const auto& p : facade_points) extend(p);
  if (minx > maxx) minx = maxx = miny = maxy = 0;
  const double span = std::max({maxx - minx, maxy - miny, 1.0});
  const double margin = 40, header = 60, footer = 50;
  const TopView v{minx, maxy, 700 / span, margin, header};
  const double w = std::max(620.0, (maxx - minx) * v.scale + 2 * margin);
  const double plot_h = (maxy - miny) * v.scale;
  Svg svg(w, header + plot_h + footer);
  svg.title(title);
  legend_entry(svg, margin, 46, kBlue, "original");
  legend_entry(svg, margin + 100, 46, kOrange, "refined");
  legend_entry(
      svg, margin + 200, 46, kGreen,
      "facade points (" + std::to_string(facade_points.size()) + ", at most " + std::to_string(max_points) + " drawn)");

  const std::size_t cap = std::max<std::size_t>(1, max_points);
  const std::size_t stride = std::max<std::size_t>(1, (facade_points.size() + cap - 1) / cap);
  std::ostringstream dots;
  dots << "<g fill=\"" << kGreen << "\">";
  for (std::size_t i = 0; i < facade_points.size(); i += stride)
    dots << "<circle cx=\"" << num(v.px(facade_points[i])) << "\" cy=\"" << num(v.py(facade_points[i]))
         << "\" r=\"1.2\"/>";
  dots << "</g>";
  svg.raw(dots.str());
  svg.raw(outline_path(original, v, kBlue, "stroke-dasharray=\"6 3\""));
  svg.raw(outline_path(refined, v, kOrange, ""));
  scale_bar(svg, v, span, margin, header + plot_h + 28);
  return svg.str();
}

std::string svg_district_map(const std::vector<MapOutline>& buildings, const std::string& title, double width) {
  double minx = std::numeric_limits<double>::max(), miny = minx, maxx = -minx, maxy = -minx;
  for (const auto& b : buildings)
    for (const auto& ring : b.rings)
      for (const Vec2& p : ring) {
        if (!p.allFinite()) continue;
        minx = std::min(minx, p.x()), maxx = std::max(maxx, p.x());
        miny = std::min(miny, p.y()), maxy = std::max(maxy, p.y());
      }
  if (minx > maxx) minx = maxx = miny = maxy = 0;
  const double span = std::max({maxx - minx, maxy - miny, 1.0});
  const double margin = 30, header = 60, footer = 50;
  const TopView v{minx, maxy, (width - 2 * margin) / span, margin, header};
  const double plot_h = (maxy - miny) * v.scale;
  Svg svg(width, header + plot_h + footer);
  svg.title(title);
  const std::pair<Outcome, const char*> styles[] = {{Outcome::Refined, kOrange},
                                                    {Outcome::Repaired, "#1f77b4"},
                                                    {Outcome::Kept, "#e6c229"},
                                                    {Outcome::KeptInvalid, "#d62728"},
                                                    {Outcome::Untouched, "#bbbbbb"}};
  auto colour_of = [&](Outcome outcome) {
    for (const auto& [name, colour] : styles)
      if (outcome == name) return colour;
    return styles[3].second;
  };
  double x = margin;
  for (const auto& [name, colour] : styles) {
    const auto n = std::count_if(buildings.begin(), buildings.end(), [&, name = name](const MapOutline& b) {
      return colour_of(b.outcome) == colour_of(name);
    });
    const std::string label = std::string(outcome_name(name)) + " (" + std::to_string(n) + ")";
    legend_entry(svg, x, 46, colour, label);
    x += 40 + 7.0 * double(label.size());
  }
  for (const auto& b : buildings) {
    std::ostringstream d;
    for (const auto& ring : b.rings) {
      for (std::size_t i = 0; i < ring.size(); ++i) {
        const Vec3 p(ring[i].x(), ring[i].y(), 0.0);
        d << (i == 0 ? 'M' : 'L') << num(v.px(p)) << ' ' << num(v.py(p)) << ' ';
      }
      if (!ring.empty()) d << "Z ";
    }
    const std::string colour = colour_of(b.outcome);
    std::string path = "<path d=\"" + d.str() + "\" fill=\"" + colour +
                       "\" fill-opacity=\"0.75\" stroke=\"#555\" "
                       "stroke-width=\"0.6\"><title>" +
                       escape(b.id + ": " + outcome_name(b.outcome)) + "</title></path>";
    if (!b.link.empty()) path = "<a href=\"" + escape(b.link) + "\">" + path + "</a>";
    svg.raw(path);
  }
  scale_bar(svg, v, span, margin, header + plot_h + 28);
  return svg.str();
}

}  // namespace lodrefine
