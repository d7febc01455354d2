// The progress line: its text, and when it prints (a clock and a sink injected, no waiting).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "lodrefine/city/progress.h"

using namespace lodrefine;

namespace {

// A progress line writing into `out` with time `now` (seconds) set by the test.
struct Rig {
  double now = 100.0;
  std::vector<std::string> out;
  Progress make(Progress::Mode mode, std::uint64_t total) {
    return Progress(
        "refine", "buildings", total, mode, [this](const std::string& s) { out.push_back(s); }, [this] { return now; },
        10.0, 0.2);
  }
};

}  // namespace

TEST(Progress, FormatsCountsRateEtaAndTally) {
  EXPECT_EQ(Progress::format("refine", "buildings", 120, 2000, 40.0, "100 refined, 15 kept, 5 kept-invalid"),
            "refine: 120/2000 buildings (6 %), 3.00/s, ETA 10 min 27 s, 100 refined, 15 kept, 5 kept-invalid");
  EXPECT_EQ(Progress::format("crop", "points", 8300000, 16600000, 10.0, ""),
            "crop: 8.3 M/16.6 M points (50 %), 830.0 k/s, ETA 10 s");
  // Unknown total: no percentage, no ETA; nothing done yet: no rate.
  EXPECT_EQ(Progress::format("eval", "buildings", 7, 0, 2.0, ""), "eval: 7 buildings, 3.50/s");
  EXPECT_EQ(Progress::format("eval", "buildings", 0, 10, 0.0, ""), "eval: 0/10 buildings (0 %)");
  EXPECT_EQ(Progress::format("eval", "buildings", 3, 10, 0.5, ""), "eval: 3/10 buildings (30 %)");
  EXPECT_EQ(Progress::format("eval", "buildings", 10, 10, 5.0, ""), "eval: 10/10 buildings (100 %), 2.00/s");
}

TEST(Progress, DurationAndCountTexts) {
  EXPECT_EQ(Progress::duration_text(42.4), "42 s");
  EXPECT_EQ(Progress::duration_text(605), "10 min 05 s");
  EXPECT_EQ(Progress::duration_text(7300), "2 h 01 min");
  EXPECT_EQ(Progress::count_text(9999), "9999");
  EXPECT_EQ(Progress::count_text(12345), "12.3 k");
  EXPECT_EQ(Progress::count_text(2.5e9), "2.5 G");
}

TEST(Progress, LinesModePrintsEveryIntervalAndALastLineOnlyAfterOne) {
  Rig rig;
  {
    Progress p = rig.make(Progress::Mode::Lines, 100);
    rig.now += 9.9;
    p.update(10);
    EXPECT_TRUE(rig.out.empty()) << "a line before the interval";
    rig.now += 0.2;
    p.update(11, "11 refined");
    ASSERT_EQ(rig.out.size(), 1u);
    EXPECT_EQ(rig.out[0], "refine: 11/100 buildings (11 %), 1.09/s, ETA 1 min 22 s, 11 refined\n");
    rig.now += 5;
    p.update(20);
    EXPECT_EQ(rig.out.size(), 1u);
    rig.now += 5.5;
    p.update(30);
    EXPECT_EQ(rig.out.size(), 2u);
    p.update(100);
  }  // the destructor finishes: the last figures
  ASSERT_EQ(rig.out.size(), 3u);
  EXPECT_EQ(rig.out[2].rfind("refine: 100/100 buildings (100 %)", 0), 0u) << rig.out[2];
  EXPECT_EQ(rig.out[2].back(), '\n');
}

TEST(Progress, FinishDoesNotRepeatTheLastLine) {
  Rig rig;
  Progress lines = rig.make(Progress::Mode::Lines, 5);
  rig.now += 11;
  lines.update(5);
  lines.finish();
  EXPECT_EQ(rig.out.size(), 1u) << "the figures printed last are not printed again";
  Progress tty = rig.make(Progress::Mode::Terminal, 5);
  tty.update(5);
  tty.finish();
  ASSERT_EQ(rig.out.size(), 3u);
  EXPECT_EQ(rig.out[2], "\n") << "the terminal line is only ended";
}

TEST(Progress, ShortRunPrintsNothing) {
  Rig rig;
  Progress p = rig.make(Progress::Mode::Lines, 3);
  rig.now += 1;
  p.update(3);
  p.finish();
  EXPECT_TRUE(rig.out.empty());
}

TEST(Progress, TerminalModeRedrawsInPlaceRateLimited) {
  Rig rig;
  Progress p = rig.make(Progress::Mode::Terminal, 40);
  rig.now += 0.1;
  p.update(1);
  ASSERT_EQ(rig.out.size(), 1u) << "the first figures at once";
  EXPECT_EQ(rig.out[0], "\rrefine: 1/40 buildings (2 %)\x1b[K") << "no rate within the first second";
  rig.now += 0.15;
  p.update(2);
  EXPECT_EQ(rig.out.size(), 1u) << "redrawn faster than every 0.2 s";
  rig.now += 1.75;
  p.update(8);
  ASSERT_EQ(rig.out.size(), 2u);
  EXPECT_EQ(rig.out[1], "\rrefine: 8/40 buildings (20 %), 4.00/s, ETA 8 s\x1b[K");
  p.update(9);
  EXPECT_EQ(rig.out.size(), 2u);
  p.finish();
  ASSERT_EQ(rig.out.size(), 3u);
  EXPECT_EQ(rig.out[2], "\rrefine: 9/40 buildings (22 %), 4.50/s, ETA 7 s\x1b[K\n")
      << "the finished line stays on the terminal";
  p.finish();
  EXPECT_EQ(rig.out.size(), 3u) << "finished once";
}

TEST(Progress, OffPrintsNothing) {
  Rig rig;
  Progress p = rig.make(Progress::Mode::Off, 4);
  for (int i = 0; i < 4; ++i) {
    rig.now += 100;
    p.update(i);
  }
  p.finish();
  EXPECT_TRUE(rig.out.empty());
  EXPECT_EQ(Progress::mode_for_stderr(true), Progress::Mode::Off);
}
