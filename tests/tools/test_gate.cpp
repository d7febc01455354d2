// The regression gate: a baseline round trip, every kind of regression named with its old and new
// value, gates (unknown names refused), and JUnit XML that stays well-formed for hostile ids.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <functional>

#include "lodrefine/base/types.h"
#include "lodrefine/tools/gate.h"

using namespace lodrefine;

namespace {

BuildingFigures building(const std::string& id, Outcome outcome, double c2m) {
  BuildingFigures b;
  b.id = id;
  b.outcome = outcome;
  b.c2m_rmse = c2m;
  b.c2m_mae = c2m * 0.8;
  b.watertight = true;
  b.facades_moved = outcome == Outcome::Refined ? 2 : 0;
  return b;
}

RunFigures sample_run() {
  RunFigures r;
  r.buildings = {building("a", Outcome::Refined, 0.012), building("b", Outcome::Kept, 0.030),
                 building("c", Outcome::Refined, 0.020)};
  r.buildings[0].truth_facade_rmse = 0.010;
  r.refined = 2;
  r.watertight_rate = 1.0;
  r.c2m_rmse_original = 0.2;
  r.c2m_rmse = 0.021;
  r.c2m_mae = 0.017;
  r.truth_facade_rmse = 0.010;
  return r;
}

std::vector<std::string> texts(const GateVerdict& v) {
  std::vector<std::string> out;
  for (const auto& l : v.failures) out.push_back(l.text);
  return out;
}

// python3's xml.etree (a real parser) on `xml`: prints "tests failures" and one line per testcase.
std::string parse_with_python(const std::string& xml) {
  const std::string path = testing::TempDir() + "/lodrefine_gate_" + std::to_string(::getpid()) + ".xml";
  std::ofstream(path, std::ios::binary) << xml;
  const std::string cmd =
      "python3 -c \"import sys, xml.etree.ElementTree as E; r = E.parse(sys.argv[1]).getroot(); "
      "c = r.findall('.//testcase'); print(len(c), len(r.findall('.//failure'))); "
      "[print(ascii(t.get('name')), t.find('failure') is not None) for t in c]\" '" +
      path + "' 2>&1";
  std::string out;
  if (FILE* p = popen(cmd.c_str(), "r")) {
    char buf[4096];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
    pclose(p);
  }
  std::remove(path.c_str());
  return out;
}

}  // namespace

TEST(Gate, BaselineRoundTripsAndAnUnchangedRunPasses) {
  const RunFigures run = sample_run();
  const RunFigures back = read_baseline(baseline_json(run), "base.json");
  ASSERT_EQ(back.buildings.size(), 3u);
  EXPECT_EQ(back.buildings[0].id, "a");
  EXPECT_EQ(back.buildings[1].outcome, Outcome::Kept);
  EXPECT_DOUBLE_EQ(*back.buildings[0].truth_facade_rmse, 0.010);
  EXPECT_FALSE(back.buildings[1].truth_facade_rmse.has_value());
  EXPECT_EQ(back.buildings[0].facades_moved, 2u);
  EXPECT_DOUBLE_EQ(*back.c2m_rmse, 0.021);
  EXPECT_EQ(back.refined, 2u);
  const GateVerdict v = check_run(run, &back, nullptr, 0.005);
  EXPECT_FALSE(v.failed()) << texts(v).front();
  EXPECT_EQ(v.buildings, (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(v.pooled_checks, std::vector<std::string>{"baseline"});
}

TEST(Gate, IdsThatAreNotUtf8MatchTheBaselineTheyWrote) {
  RunFigures run = sample_run();
  run.buildings[1].id = "b\xFF\xC3";
  const RunFigures base = read_baseline(baseline_json(run), "base.json");
  EXPECT_EQ(base.buildings[1].id, "b\xEF\xBF\xBD\xEF\xBF\xBD");
  const GateVerdict v = check_run(run, &base, nullptr, 0.005);
  EXPECT_FALSE(v.failed()) << texts(v).front();
  EXPECT_TRUE(v.new_buildings.empty());
}

TEST(Gate, EachRegressionNamesBuildingFigureAndValues) {
  const RunFigures base = sample_run();
  RunFigures run = sample_run();
  run.buildings[0].c2m_rmse = 0.301;         // a: moved by 0.3 m
  run.buildings[2].outcome = Outcome::Kept;  // c: refined -> kept
  run.buildings[2].reason = "no facade matched";
  run.buildings[2].c2m_rmse = 0.5;                                 // not compared again: the outcome says it
  run.buildings[1].c2m_rmse = 0.034;                               // b: worse by 4 mm, within the tolerance
  run.buildings.push_back(building("d", Outcome::Refined, 0.01));  // new: listed, not failed
  run.buildings.erase(run.buildings.begin() + 1);                  // b gone
  const GateVerdict v = check_run(run, &base, nullptr, 0.005);
  const auto t = texts(v);
  ASSERT_EQ(t.size(), 3u) << ::testing::PrintToString(t);
  EXPECT_EQ(t[0], "a: c2m_rmse 0.0120 m -> 0.3010 m (worse by 0.2890 m, tolerance 0.0050 m)");
  EXPECT_EQ(v.failures[0].building, "a");
  EXPECT_EQ(v.failures[0].figure, "c2m_rmse");
  EXPECT_EQ(t[1], "c: outcome refined -> kept (no facade matched)");
  EXPECT_EQ(t[2], "b: missing from the run (baseline outcome kept)");
  EXPECT_EQ(v.new_buildings, std::vector<std::string>{"d"});
  EXPECT_EQ(v.buildings, (std::vector<std::string>{"a", "b", "c", "d"}));
  // Within the tolerance: b's 4 mm alone would pass.
  RunFigures small = sample_run();
  small.buildings[1].c2m_rmse = 0.034;
  EXPECT_FALSE(check_run(small, &base, nullptr, 0.005).failed());
  EXPECT_TRUE(check_run(small, &base, nullptr, 0.003).failed());
}

TEST(Gate, LostMeasuresWatertightnessAndPooledFiguresFail) {
  const RunFigures base = sample_run();
  RunFigures run = sample_run();
  run.buildings[0].truth_facade_rmse.reset();
  run.buildings[2].watertight = false;
  run.buildings[2].outcome = Outcome::Failed;
  run.failed = 1;
  run.watertight_rate = 2.0 / 3.0;
  run.c2m_rmse = 0.05;
  const auto t = texts(check_run(run, &base, nullptr, 0.005));
  ASSERT_EQ(t.size(), 5u) << ::testing::PrintToString(t);
  EXPECT_EQ(t[0], "a: truth_facade_rmse 0.0100 m -> not measured");
  EXPECT_EQ(t[1], "c: outcome refined -> failed");
  EXPECT_EQ(t[2], "pooled: c2m_rmse 0.0210 m -> 0.0500 m (worse by 0.0290 m, tolerance 0.0050 m)");
  EXPECT_EQ(t[3], "pooled: failed 0 -> 1");
  EXPECT_EQ(t[4], "pooled: watertight_rate 1.000 -> 0.667");
  EXPECT_LT(outcome_rank(Outcome::KeptInvalid), outcome_rank(Outcome::Kept));
  EXPECT_LT(outcome_rank(Outcome::Failed), outcome_rank(Outcome::KeptInvalid));
}

TEST(Gate, GatesBreachedPooledAndPerBuilding) {
  const Gates g = read_gates(R"({"_comment": "x", "max_c2m_rmse_refined": 0.02, "min_watertight_rate": 1,
      "max_failed_buildings": 0, "max_building_c2m_rmse_refined": 0.025, "max_truth_roof_rmse_refined": 0.05,
      "max_c2m_rmse_ratio": 0.5})",
                             "gates.json");
  ASSERT_EQ(g.size(), 6u);
  const GateVerdict v = check_run(sample_run(), nullptr, &g, 0.005);
  const auto t = texts(v);
  ASSERT_EQ(t.size(), 3u) << ::testing::PrintToString(t);  // the ratio 0.105 is within 0.5
  EXPECT_EQ(t[0], "b: max_building_c2m_rmse_refined 0.0300 > 0.0250");
  EXPECT_EQ(v.failures[0].building, "b");
  EXPECT_EQ(t[1], "pooled: max_c2m_rmse_refined 0.0210 > 0.0200");
  EXPECT_EQ(t[2], "pooled: max_truth_roof_rmse_refined not measured in this run");
  EXPECT_EQ(v.pooled_checks.size(), 5u);  // every gate but the per-building one
  RunFigures failing = sample_run();
  failing.failed = 2;
  EXPECT_EQ(texts(check_run(failing, nullptr, &g, 0.005))[2], "pooled: max_failed_buildings 2 > 0");
  const Gates ratio = {{"max_c2m_rmse_ratio", 0.1}};
  EXPECT_EQ(texts(check_run(sample_run(), nullptr, &ratio, 0.005)),
            std::vector<std::string>{"pooled: max_c2m_rmse_ratio 0.1050 > 0.1000"});
}

TEST(Gate, BadGateAndBaselineFilesAreOneLineErrors) {
  try {
    read_gates(R"({"max_c2m_rmse": 0.02})", "gates.json");
    FAIL() << "an unknown gate was accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("gates.json: unknown gate \"max_c2m_rmse\" (known: ", 0), 0u) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos);
  }
  EXPECT_THROW(read_gates(R"({"max_failed_buildings": "0"})", "g"), InputError);
  EXPECT_THROW(read_gates("[1]", "g"), InputError);
  EXPECT_THROW(read_gates("{", "g"), InputError);
  EXPECT_THROW(read_baseline("{}", "b"), InputError);
  EXPECT_THROW(read_baseline(R"({"format": "lodrefine-baseline", "version": 2})", "b"), InputError);
  EXPECT_THROW(read_baseline(R"({"format": "lodrefine-baseline", "version": 1, "pooled": {"failed": "x"}})", "b"),
               InputError);
  EXPECT_THROW(
      read_baseline(R"({"format": "lodrefine-baseline", "version": 1, "buildings": [{"id": "a"}, {"id": "a"}]})", "b"),
      InputError);
}

TEST(Gate, XmlEscapeKeepsOnlyWhatXml10Allows) {
  EXPECT_EQ(xml_escape("</testcase><script>\"'&"), "&lt;/testcase&gt;&lt;script&gt;&quot;&apos;&amp;");
  EXPECT_EQ(xml_escape("a\tb\nc\r"), "a&#9;b&#10;c&#13;");
  const std::string fffd = "\xEF\xBF\xBD";
  EXPECT_EQ(xml_escape(std::string("x\x01y\0z", 5)), "x" + fffd + "y" + fffd + "z");
  EXPECT_EQ(xml_escape("caf\xC3\xA9 \xE2\x80\xA8"), "caf\xC3\xA9 \xE2\x80\xA8");  // UTF-8 kept
  EXPECT_EQ(xml_escape("\xFF\xC3"), fffd + fffd);                                 // not UTF-8
  EXPECT_EQ(xml_escape("\xC0\xAF"), fffd + fffd);                                 // overlong "/"
  EXPECT_EQ(xml_escape("\xED\xA0\x80"), fffd + fffd + fffd);                      // a surrogate
  EXPECT_EQ(xml_escape("\xEF\xBF\xBE"), fffd);                                    // U+FFFE
  EXPECT_EQ(xml_escape("\xF0\x9F\x8F\xA0"), "\xF0\x9F\x8F\xA0");                  // beyond the BMP
}

TEST(Gate, JunitHasOneTestcasePerBuildingAndParsesWithHostileIds) {
  RunFigures base = sample_run();
  const std::string hostile = std::string("</testcase><script>alert(\"x\")</script>'\x01\xFF\n]]>");
  base.buildings.push_back(building(hostile, Outcome::Refined, 0.01));
  RunFigures run = base;
  run.buildings[3].c2m_rmse = 0.31;  // the hostile one regressed
  run.buildings.push_back(building("new", Outcome::Kept, 0.01));
  const Gates g = {{"max_failed_buildings", 0}};
  const GateVerdict v = check_run(run, &base, &g, 0.005);
  const std::string xml = junit_xml(v, "samples");
  EXPECT_EQ(xml.find("<script>"), std::string::npos);
  EXPECT_EQ(xml.find('\x01'), std::string::npos);
  EXPECT_NE(xml.find("<failure message=\"&lt;/testcase&gt;&lt;script&gt;alert(&quot;x&quot;)"), std::string::npos)
      << xml;
  EXPECT_NE(xml.find("<system-out>new building: not in the baseline</system-out>"), std::string::npos);
  const std::string parsed = parse_with_python(xml);
  if (parsed.find("No module") != std::string::npos || parsed.find("not found") != std::string::npos)
    GTEST_SKIP() << "python3 missing: " << parsed;
  // 5 buildings + the baseline and the one gate; one failure (the hostile building).
  EXPECT_EQ(parsed.rfind("7 1\n", 0), 0u) << parsed;
  EXPECT_NE(parsed.find("'new' False"), std::string::npos) << parsed;
  EXPECT_NE(parsed.find("'</testcase><script>alert(\"x\")</script>\\'\\ufffd\\ufffd\\n]]>' True"), std::string::npos)
      << parsed;
  EXPECT_NE(parsed.find("'max_failed_buildings' False"), std::string::npos) << parsed;
}

// Baselines and gates may come from other people. A value nested 100,000 arrays deep crashed
// eval (the parse kept it, the error message dumped it recursively); ids and keys holding a
// newline or an escape code broke the one error line.
TEST(GateFiles, DeepNestingAndControlCharactersFailInOneLine) {
  auto refusal = [](const std::function<void()>& read) {
    try {
      read();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  const std::string deep =
      R"({"format":"lodrefine-baseline","version":)" + std::string(100000, '[') + std::string(100000, ']') + "}";
  const std::string nested = refusal([&] { read_baseline(deep, "deep.json"); });
  EXPECT_NE(nested.find("nested deeper than"), std::string::npos) << nested.substr(0, 200);

  RunFigures run;
  run.buildings = {building("a\nlodrefine: error: injected", Outcome::Refined, 0.1)};
  run.buildings.push_back(run.buildings.front());
  const std::string twice = refusal([&] { read_baseline(baseline_json(run), "twice.json"); });
  EXPECT_NE(twice.find("listed twice"), std::string::npos) << twice;
  EXPECT_EQ(twice.find('\n'), std::string::npos) << twice;

  const std::string gate = refusal([] { read_gates("{\"bad\\ngate\\u001b[31m\": 1}", "gates.json"); });
  EXPECT_NE(gate.find("unknown gate"), std::string::npos) << gate;
  EXPECT_EQ(gate.find_first_of("\n\x1b"), std::string::npos) << gate;
}

// A gate line quotes ids and reasons from the run's reports and the baseline: their control
// characters are escaped, as a CR and escape codes printed "gate: … passed" over the verdict.
// An outcome is no quote: a baseline's is read as one lodrefine writes, any other text as failed.
TEST(Gate, LinesQuotingReportsAndBaselinesStayOneLine) {
  RunFigures run = sample_run();
  run.buildings[2].outcome = Outcome::Kept;
  run.buildings[2].reason = "judge\r\x1b[2K\ngate: 0 building(s): passed\x1b[8m";
  const RunFigures old = read_baseline(R"({"format": "lodrefine-baseline", "version": 1, "buildings": [
      {"id": "a", "outcome": "refined"}, {"id": "b", "outcome": "refined\r\u001b[2Kgate: all good\n"},
      {"id": "c", "outcome": "refined"}, {"id": "gone\rpassed", "outcome": "kept"}]})",
                                       "base.json");
  ASSERT_EQ(old.buildings.size(), 4u);
  EXPECT_EQ(old.buildings[1].outcome, Outcome::Failed);
  const GateVerdict v = check_run(run, &old, nullptr, 0.005);
  ASSERT_GE(v.failures.size(), 2u);
  for (const auto& l : v.failures) {
    EXPECT_EQ(l.text.find_first_of("\r\n\x1b"), std::string::npos) << l.text;
  }
  EXPECT_EQ(texts(v).front(), "c: outcome refined -> kept (judge\\r\\x1b[2K\\ngate: 0 building(s): passed\\x1b[8m)");
}
