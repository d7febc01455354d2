// A guard for inputs that once made a stage run for minutes (cubic splits, entity expansion):
// the test fails when the stage takes longer than kHangGuardSeconds. It is not a speed target
// (benchmarks print speed figures), so the bound is wide enough for a loaded 2-core machine or a
// sanitizer build, and still far below the minutes the blow-up took.
#pragma once
#include <chrono>

namespace lodrefine::fixtures {

inline constexpr double kHangGuardSeconds = 30.0;

// Seconds of steady_clock since t0.
inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace lodrefine::fixtures
