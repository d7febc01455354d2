// `lodrefine eval --dir` as a CI gate: a refined run, its baseline, the same run again (exit 0,
// every JUnit test case passing), then one refined model moved 0.3 m (exit 1, the building and
// the figure named, a JUnit failure for it), with a hostile building id in the run; JUnit read by
// python3's xml.etree. Gates files with unknown names are refused with one line.
#include <gtest/gtest.h>

#include <regex>

#include "support/batch_fixtures.h"

using namespace lodrefine::batch_fixtures;

namespace {

struct EvalRun {
  int exit = -1;
  std::string out, err;
};

EvalRun eval(const fs::path& run, const std::string& args) {
  EvalRun r;
  r.exit = shell(kBinary + " eval --dir " + shell_quoted(run) + " --jobs 2 " + args + " > " +
                 shell_quoted(run.parent_path() / "eval.out") + " 2> " + shell_quoted(run.parent_path() / "eval.err"));
  r.out = read_text(run.parent_path() / "eval.out");
  r.err = read_text(run.parent_path() / "eval.err");
  return r;
}

// "tests failures" of the JUnit file, then per test case its name (Python's ascii()) and whether
// it failed; an "error: ..." line when it is not well-formed.
std::string junit_summary(const fs::path& xml) {
  const fs::path out = xml.string() + ".txt";
  shell(
      "python3 -c \"import sys, xml.etree.ElementTree as E\ntry:\n r = E.parse(sys.argv[1]).getroot()\nexcept "
      "Exception as e:\n"
      " print('error:', e); sys.exit()\nc = r.findall('.//testcase')\nprint(len(c), len(r.findall('.//failure')))\n"
      "for t in c: print(ascii(t.get('name')), 'FAILED' if t.find('failure') is not None else 'passed')\" " +
      shell_quoted(xml) + " > " + shell_quoted(out) + " 2>&1");
  return read_text(out);
}

// Moves every vertex of an OBJ by dx along x.
void move_obj(const fs::path& obj, double dx) {
  std::istringstream in(read_text(obj));
  std::ostringstream out;
  out.precision(17);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("v ", 0) == 0) {
      std::istringstream v(line.substr(2));
      double x, y, z;
      v >> x >> y >> z;
      out << "v " << x + dx << ' ' << y << ' ' << z << '\n';
    } else {
      out << line << '\n';
    }
  }
  std::ofstream(obj, std::ios::binary) << out.str();
}

}  // namespace

TEST(EvalGate, BaselineThenAModelMovedFailsWithItsLine) {
  const fs::path dir = fresh_dir("gate"), run = dir / "run";
  fs::create_directories(run);
  make_tile(run, 3);
  ASSERT_EQ(shell(batch_command(run, "refined") + " > " + shell_quoted(dir / "batch.log") + " 2>&1"), 0)
      << read_text(dir / "batch.log");
  // A hostile id: markup, quotes, a control character and a byte that is not UTF-8.
  std::string first;
  std::vector<std::string> refined;
  for (const auto& e : fs::directory_iterator(run))
    if (fs::exists(e.path() / "report.json") &&
        json::parse(read_text(e.path() / "report.json")).value("outcome", "") == "refined")
      refined.push_back(e.path().filename().string());
  ASSERT_GE(refined.size(), 2u);
  std::sort(refined.begin(), refined.end());
  const std::string hostile = "<testcase name=\"x\"><script>&'\x01\xFF";
  fs::copy(run / refined[1], run / hostile, fs::copy_options::recursive);

  const EvalRun base = eval(run, "--write-baseline " + shell_quoted(dir / "base.json"));
  ASSERT_EQ(base.exit, 0) << base.err;
  const json b = json::parse(read_text(dir / "base.json"));
  EXPECT_EQ(b.at("version"), 1);
  ASSERT_EQ(b.at("buildings").size(), 4u);
  EXPECT_GT(b.at("buildings")[0].at("c2m_rmse").get<double>(), 0.0);

  // The same run: nothing worse, every test case passes.
  std::ofstream(dir / "gates.json")
      << R"({"_comment": "samples", "max_failed_buildings": 0, "min_watertight_rate": 1})";
  const EvalRun same = eval(run, "--baseline " + shell_quoted(dir / "base.json") + " --gates " +
                                     shell_quoted(dir / "gates.json") + " --junit " + shell_quoted(dir / "same.xml"));
  EXPECT_EQ(same.exit, 0) << same.out << same.err;
  EXPECT_NE(same.out.find("gate: 4 building(s), 0 new, 3 pooled check(s): passed"), std::string::npos) << same.out;
  const std::string pass = junit_summary(dir / "same.xml");
  if (pass.find("No module") != std::string::npos || pass.find("not found") != std::string::npos)
    GTEST_SKIP() << "python3 missing: " << pass;
  EXPECT_EQ(pass.rfind("7 0\n", 0), 0u) << pass;  // 4 buildings + baseline + 2 gates
  for (const std::string& id : refined) EXPECT_NE(pass.find("'" + id + "' passed"), std::string::npos) << pass;
  EXPECT_NE(pass.find("'<testcase name=\"x\"><script>&\\'\\ufffd\\ufffd' passed"), std::string::npos) << pass;

  // One refined model moved 0.3 m: its C2M grows; exit 1, one line naming it, a JUnit failure.
  move_obj(run / refined[0] / "refined.obj", 0.3);
  const EvalRun moved =
      eval(run, "--baseline " + shell_quoted(dir / "base.json") + " --junit " + shell_quoted(dir / "moved.xml"));
  EXPECT_EQ(moved.exit, 1) << moved.out << moved.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      moved.out, m,
      std::regex("regression: " + refined[0] + ": c2m_rmse (\\d+\\.\\d+) m -> (\\d+\\.\\d+) m \\(worse by")))
      << moved.out;
  EXPECT_LT(std::stod(m[1]), 0.05);
  EXPECT_GT(std::stod(m[2]), 0.15);
  for (const std::string& id : {refined[1], std::string("<testcase")})
    EXPECT_EQ(moved.out.find("regression: " + id), std::string::npos) << moved.out;
  const std::string fail = junit_summary(dir / "moved.xml");
  EXPECT_EQ(fail.rfind("5 2\n", 0), 0u) << fail;  // the building and the pooled baseline check
  EXPECT_NE(fail.find("'" + refined[0] + "' FAILED"), std::string::npos) << fail;
  EXPECT_NE(fail.find("'" + refined[1] + "' passed"), std::string::npos) << fail;
  const std::string xml = read_text(dir / "moved.xml");
  EXPECT_NE(xml.find("<failure message=\"" + refined[0] + ": c2m_rmse "), std::string::npos) << xml;
  EXPECT_EQ(xml.find("<script>"), std::string::npos);

  // A building gone: a failure; a gates file with an unknown name: one error line, exit 2.
  fs::remove_all(run / refined[1]);
  const EvalRun gone = eval(run, "--baseline " + shell_quoted(dir / "base.json"));
  EXPECT_EQ(gone.exit, 1);
  EXPECT_NE(gone.out.find("regression: " + refined[1] + ": missing from the run (baseline outcome refined)"),
            std::string::npos)
      << gone.out;
  std::ofstream(dir / "bad.json") << R"({"max_c2m": 0.1})";
  const EvalRun bad = eval(run, "--gates " + shell_quoted(dir / "bad.json"));
  EXPECT_EQ(bad.exit, 2);
  EXPECT_EQ(
      bad.err.rfind("lodrefine: error: " + (dir / "bad.json").string() + ": unknown gate \"max_c2m\" (known: ", 0), 0u)
      << bad.err;
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1);
  if (!HasFailure()) fs::remove_all(dir);
}
