// The progress line (see progress.h).
#include "lodrefine/city/progress.h"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>

namespace lodrefine {
namespace {

constexpr double kMinRateSeconds = 1.0;

// Clears the rest of the terminal line after a redraw (a shorter line leaves no tail).
constexpr const char* kClearToEnd = "\x1b[K";

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string printf_text(const char* fmt, double a, double b = 0.0) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, a, b);
  return buf;
}

}  // namespace

Progress::Mode Progress::mode_for_stderr(bool quiet) {
  if (quiet) return Mode::Off;
  return ::isatty(STDERR_FILENO) ? Mode::Terminal : Mode::Lines;
}

Progress::Progress(std::string what, std::string unit, std::uint64_t total, Mode mode, Sink sink, Clock clock,
                   double interval, double redraw)
    : what_(std::move(what)),
      unit_(std::move(unit)),
      total_(total),
      mode_(mode),
      sink_(std::move(sink)),
      clock_(std::move(clock)),
      interval_(interval),
      redraw_(redraw) {
  if (!sink_)
    sink_ = [](const std::string& s) {
      std::fputs(s.c_str(), stderr);
      std::fflush(stderr);
    };
  if (!clock_) clock_ = steady_seconds;
  start_ = last_print_ = clock_();
}

Progress::~Progress() { finish(); }

std::string Progress::count_text(double n) {
  if (n < 1e4) return printf_text(n == std::floor(n) ? "%.0f" : "%.1f", n);
  if (n < 1e6) return printf_text("%.1f k", n / 1e3);
  if (n < 1e9) return printf_text("%.1f M", n / 1e6);
  return printf_text("%.1f G", n / 1e9);
}

std::string Progress::duration_text(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  if (s < 60) return printf_text("%.0f s", double(s));
  if (s < 3600) return printf_text("%.0f min %02.0f s", double(s / 60), double(s % 60));
  return printf_text("%.0f h %02.0f min", double(s / 3600), double(s / 60 % 60));
}

std::string Progress::format(const std::string& what, const std::string& unit, std::uint64_t done, std::uint64_t total,
                             double seconds, const std::string& tally) {
  std::string s = what + ": " + count_text(double(done));
  if (total > 0) s += "/" + count_text(double(total));
  s += " " + unit;
  if (total > 0) s += printf_text(" (%.0f %%)", 100.0 * double(std::min(done, total)) / double(total));
  // A rate over less than a second says little (and the first update may come at once).
  const double rate = seconds >= kMinRateSeconds ? double(done) / seconds : 0.0;
  if (rate > 0) {
    s += ", " + (rate < 10 ? printf_text("%.2f", rate) : count_text(std::round(rate))) + "/s";
    if (total > done) s += ", ETA " + duration_text(double(total - done) / rate);
  }
  if (!tally.empty()) s += ", " + tally;
  return s;
}

void Progress::update(std::uint64_t done, const std::string& tally) {
  if (mode_ == Mode::Off || finished_) return;
  done_ = done;
  tally_ = tally;
  const double now = clock_();
  // A terminal shows the line at once; a log gets its first line after an interval.
  const bool first = mode_ == Mode::Terminal && !printed_;
  if (!first && now - last_print_ < (mode_ == Mode::Terminal ? redraw_ : interval_)) {
    pending_ = true;
    return;
  }
  last_print_ = now;
  print(false);
}

void Progress::finish() {
  if (finished_) return;
  finished_ = true;
  if (mode_ == Mode::Off || !printed_) return;
  if (pending_) print(true);
  else if (mode_ == Mode::Terminal) sink_("\n");  // the line on screen is already the last one
}

void Progress::print(bool last) {
  const std::string line = format(what_, unit_, done_, total_, clock_() - start_, tally_);
  if (mode_ == Mode::Terminal) sink_("\r" + line + kClearToEnd + (last ? "\n" : ""));
  else sink_(line + "\n");
  printed_ = true;
  pending_ = false;
}

}  // namespace lodrefine
