// One progress line for long runs (city refine, crop, eval --dir, synth --tile), on stderr so
// that stdout stays what scripts parse. On a terminal the line is redrawn in place (carriage
// return, at once and then at most every `redraw` seconds); otherwise a plain line every `interval` seconds, and
// none at all for a run shorter than that. Exit codes and stdout are not touched.
#pragma once
#include <cstdint>
#include <functional>
#include <string>

namespace lodrefine {

class Progress {
 public:
  enum class Mode { Off, Terminal, Lines };
  using Clock = std::function<double()>;                 // seconds, monotonic
  using Sink = std::function<void(const std::string&)>;  // receives finished text (with \r / \n)

  // Off when `quiet`, Terminal when stderr is a TTY, Lines otherwise.
  static Mode mode_for_stderr(bool quiet);

  // `what` starts the line ("refine"), `unit` names what is counted ("buildings"); `total` may
  // be 0 (unknown: no percentage, no ETA). Default sink: stderr; default clock: steady_clock.
  Progress(std::string what, std::string unit, std::uint64_t total, Mode mode, Sink sink = {}, Clock clock = {},
           double interval = 10.0, double redraw = 0.2);
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  ~Progress();  // calls finish()

  // `done` so far, and a tally to append ("12 refined, 3 kept"). Prints only when due.
  void update(std::uint64_t done, const std::string& tally = "");
  // Prints the last figures when anything was printed before and they are newer (Terminal:
  // ends the line). Once.
  void finish();

  // "what: done/total unit (p %), rate/s, ETA t, tally" for `seconds` since the start (rate and
  // ETA from the first second on).
  static std::string format(const std::string& what, const std::string& unit, std::uint64_t done, std::uint64_t total,
                            double seconds, const std::string& tally);
  // 7 -> "7", 12345 -> "12.3 k", 16600000 -> "16.6 M": counts that stay readable.
  static std::string count_text(double n);
  // 42 -> "42 s", 605 -> "10 min 05 s", 7300 -> "2 h 01 min".
  static std::string duration_text(double seconds);

 private:
  void print(bool last);

  std::string what_, unit_;
  std::uint64_t total_;
  Mode mode_;
  Sink sink_;
  Clock clock_;
  double interval_, redraw_;
  double start_, last_print_;
  std::uint64_t done_ = 0;
  std::string tally_;
  bool printed_ = false, finished_ = false;
  bool pending_ = false;  // figures newer than the last line printed
};

}  // namespace lodrefine
