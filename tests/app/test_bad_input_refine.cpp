// Robustness against the broken files a city-wide batch meets (issue "bad input"), `lodrefine
// refine` of one building: every case drives the real binary on files written here and checks
// the contract:
//   - refused: non-zero exit, exactly one stderr line "lodrefine: error: ...", no output file
//     and no leftover temporary file;
//   - kept: exit 0, the repaired input written and valid, the report says "kept" and why;
//   - kept-invalid: exit 0, a model that is no solid written as read, the report says why;
//   - refined: exit 0, valid output, report "refined".
// Each case prints a row "| input | what lodrefine says | exit |"; running the suite in one
// process (lodrefine_app_tests --gtest_filter='BadInput*') prints the whole table at the end.
// The other commands' bad input: test_bad_input_{refine_files,city,convert,crop,eval}.cpp; the
// selection solver's faults: tests/refine/test_selection_bad_input.cpp.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "lodrefine/base/geometry.h"
#include "lodrefine/formats/obj.h"
#include "support/bad_input_fixtures.h"
#include "support/test_paths.h"

using namespace lodrefine;
using namespace lodrefine::bad_input;

namespace {

// ---------------------------------------------------------------------------------------------
// Cases

enum class Expect {
  Error,         // refused with one error line, nothing written
  Kept,          // exit 0, repaired input written, report outcome "kept" (reason in "reason")
  KeptInvalid,   // exit 0, the input written as read, report outcome "kept-invalid"
  Refined,       // exit 0, report outcome "refined"
  Valid,         // exit 0, valid output, any outcome
  ErrorOrValid,  // either of the first (refused) or a valid written building
};

struct Paths {
  std::string dir, model, cloud, out, report;
  std::string args;                           // extra CLI arguments
  std::string model_arg, cloud_arg, out_arg;  // override the paths on the command line
};

struct Case {
  std::string name;  // the table's "input" column
  std::function<void(Paths&)> make;
  Expect expect;
  std::string fragment = {};  // must appear in the error line (Error) or the report's reason (Kept*), if set
  double max_seconds = 300;
};

void both_valid(Paths& p) {
  write_text(p.model, valid_model());
  write_text(p.cloud, valid_cloud());
}
void model_is(Paths& p, const std::string& obj) {
  write_text(p.model, obj);
  write_text(p.cloud, valid_cloud());
}
void cloud_is(Paths& p, const std::string& ply) {
  write_text(p.model, valid_model());
  write_text(p.cloud, ply);
}

std::vector<Vec3> shifted(std::vector<Vec3> pts, const Vec3& d) {
  for (auto& p : pts) p += d;
  return pts;
}

// The good path: a valid box and its wall scan in each PLY encoding.
void add_good_path(std::vector<Case>& c) {
  c.push_back({"valid box + wall scan 0.4 m off (binary LE doubles)", both_valid, Expect::Refined});
  c.push_back(
      {"valid box + same scan as ASCII PLY", [](Paths& p) { cloud_is(p, ply_ascii(wall_scan())); }, Expect::Refined});
  c.push_back({"valid box + same scan as big-endian PLY", [](Paths& p) { cloud_is(p, ply_binary(wall_scan(), true)); },
               Expect::Refined});
}

// Malformed models.
void add_model_cases(std::vector<Case>& c) {
  const std::string box = valid_model();
  c.push_back({"model: empty file (0 bytes)", [](Paths& p) { model_is(p, ""); }, Expect::Error, "empty"});
  c.push_back(
      {"model: only comments and blank lines", [](Paths& p) { model_is(p, "# nothing\n\n  \n"); }, Expect::Error});
  c.push_back({"model: truncated inside a vertex line",
               [box](Paths& p) { model_is(p, box.substr(0, box.find("v ", box.size() / 2) + 9)); }, Expect::Error});
  c.push_back({"model: truncated after the vertices (faces lost)",
               [box](Paths& p) {
                 std::string t;
                 for (const auto& l : lines(box))
                   if (l.rfind("f ", 0) != 0) t += l + "\n";
                 model_is(p, t);
               },
               Expect::Error, "no faces"});
  c.push_back({"model: NaN coordinate", [box](Paths& p) { model_is(p, "v nan 0 0\n" + box); }, Expect::Error});
  c.push_back({"model: Inf coordinate", [box](Paths& p) { model_is(p, "v 1 inf 0\n" + box); }, Expect::Error});
  c.push_back({"model: coordinate overflowing double (1e999)", [box](Paths& p) { model_is(p, "v 1e999 0 0\n" + box); },
               Expect::Error});
  c.push_back({"model: face index past the last vertex (f 1 2 99)",
               [box](Paths& p) { model_is(p, box + "f 1 2 99\n"); }, Expect::Error, "out of range"});
  c.push_back({"model: negative index before the first vertex (f -1 -2 -99)",
               [box](Paths& p) { model_is(p, box + "f -1 -2 -99\n"); }, Expect::Error, "out of range"});
  c.push_back({"model: face index 0", [box](Paths& p) { model_is(p, box + "f 0 1 2\n"); }, Expect::Error});
  c.push_back({"model: huge face index (f 1 2 99999999999999999999)",
               [box](Paths& p) { model_is(p, box + "f 1 2 99999999999999999999\n"); }, Expect::Error});
  c.push_back({"model: only faces with < 3 vertices", [](Paths& p) { model_is(p, "v 0 0 0\nv 1 0 0\nf 1 2\nf 1\n"); },
               Expect::Error, "no faces"});
  c.push_back({"model: valid box + extra 2-vertex face (skipped)", [box](Paths& p) { model_is(p, box + "f 1 2\n"); },
               Expect::Refined});
  c.push_back({"model: valid box + zero-area face (collinear vertices)",
               [box](Paths& p) {
                 const Vec3 a = kOrigin + Vec3(0, 8, 0), b = kOrigin + Vec3(6, 8, 0), d = kOrigin + Vec3(12, 8, 0);
                 model_is(p, box + "v " + fmt(a.x()) + " " + fmt(a.y()) + " 0\nv " + fmt(b.x()) + " " + fmt(b.y()) +
                                 " 0\nv " + fmt(d.x()) + " " + fmt(d.y()) + " 0\nf -3 -2 -1\n");
               },
               Expect::Refined});
  c.push_back(
      {"model: only zero-area faces",
       [](Paths& p) { model_is(p, "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3\nf 2 3 4\nf 1 2 4\nf 1 3 4\n"); },
       Expect::KeptInvalid, "usable faces"});
  c.push_back({"model: self-intersecting (bow-tie) front wall",
               [](Paths& p) {
                 std::string s = box_obj();
                 // front wall 0 1 5 4 -> 0 1 4 5: the quad crosses itself
                 const std::string front = "f 9 10 11 12\n";
                 s.replace(s.find(front), front.size(), "f 9 10 12 11\n");
                 model_is(p, s);
               },
               Expect::ErrorOrValid});
  c.push_back({"model: just the 4 walls (no roof, no ground)",
               [](Paths& p) {
                 model_is(p, box_obj({2, 3, 4, 5}));
               },
               Expect::ErrorOrValid});
  c.push_back({"model: just 2 walls",
               [](Paths& p) {
                 model_is(p, box_obj({2, 3}));
               },
               Expect::KeptInvalid, "not closable"});
  c.push_back({"model: a single triangle", [](Paths& p) { model_is(p, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"); },
               Expect::KeptInvalid, "usable faces"});
  c.push_back({"model: binary garbage",
               [](Paths& p) {
                 model_is(p, std::string("\x7f"
                                         "ELF\x02\x01\x01\0\0\0",
                                         10));
               },
               Expect::Error, "binary"});
  c.push_back({"model: a PLY file given as the model",
               [](Paths& p) {
                 model_is(p, ply_ascii({{0, 0, 0}}));
               },
               Expect::Error});
}

// Malformed cloud files: truncated, lying headers, unknown types and formats.
void add_cloud_file_cases(std::vector<Case>& c) {
  c.push_back({"cloud: empty file (0 bytes)", [](Paths& p) { cloud_is(p, ""); }, Expect::Error, "empty"});
  {
    // A LAZ (the fuzz seed: 6 points, one per chunk) cut inside its chunk table, and with a
    // header count beyond what its chunks hold.
    const std::string laz = read_text(test_paths::source_dir() + "/tests/fuzz/corpus/fuzz_laz/v12_f0.laz");
    c.push_back({"cloud: LAZ cut inside its chunk table",
                 [laz](Paths& p) { cloud_is(p, laz.substr(0, laz.size() - 6)); }, Expect::Error, "LAZ chunk"});
    c.push_back({"cloud: LAZ header count beyond its chunks",
                 [laz](Paths& p) {
                   std::string b = laz;
                   b[107] = 7;  // 7 points declared, 6 chunks of 1
                   cloud_is(p, b);
                 },
                 Expect::Error, "header declares 7 points but the LAZ chunks hold only 6"});
  }
  c.push_back({"cloud: header cut before end_header",
               [](Paths& p) { cloud_is(p, "ply\nformat binary_little_endian 1.0\nelement vertex 10\nproperty dou"); },
               Expect::Error});
  c.push_back({"cloud: binary data truncated mid-record",
               [](Paths& p) {
                 const std::string s = valid_cloud();
                 cloud_is(p, s.substr(0, s.size() - 13));
               },
               Expect::Error});
  c.push_back({"cloud: ASCII data truncated mid-line",
               [](Paths& p) {
                 const std::string s = ply_ascii(wall_scan());
                 cloud_is(p, s.substr(0, s.size() / 2));
               },
               Expect::Error});
  c.push_back({"cloud: header count 10x larger than the data",
               [](Paths& p) {
                 const auto pts = wall_scan();
                 std::string s = ply_binary(pts);
                 const std::string from = "element vertex " + std::to_string(pts.size()) + "\n";
                 s.replace(s.find(from), from.size(), "element vertex " + std::to_string(pts.size() * 10) + "\n");
                 cloud_is(p, s);
               },
               Expect::Error, "header declares"});
  c.push_back({"cloud: header count smaller than the data (trailing bytes)",
               [](Paths& p) {
                 const auto pts = wall_scan();
                 std::string s = ply_binary(pts);
                 const std::string from = "element vertex " + std::to_string(pts.size()) + "\n";
                 s.replace(s.find(from), from.size(), "element vertex " + std::to_string(pts.size() / 2) + "\n");
                 cloud_is(p, s);
               },
               Expect::Valid});
  c.push_back({"cloud: unknown property type (float128)",
               [](Paths& p) { cloud_is(p, ply_header("ascii", 1, "float128") + "1 2 3\n"); }, Expect::Error,
               "unknown property type"});
  c.push_back({"cloud: unknown format (binary_middle_endian)",
               [](Paths& p) { cloud_is(p, ply_header("binary_middle_endian", 1) + std::string(24, '\0')); },
               Expect::Error, "unknown format"});
  c.push_back({"cloud: header says big-endian, data is little-endian",
               [](Paths& p) {
                 std::string s = valid_cloud();
                 s.replace(s.find("binary_little_endian"), 20, "binary_big_endian");
                 cloud_is(p, s);
               },
               Expect::ErrorOrValid});
  c.push_back(
      {"cloud: no x property",
       [](Paths& p) {
         cloud_is(p, "ply\nformat ascii 1.0\nelement vertex 1\nproperty float y\nproperty float z\nend_header\n1 2\n");
       },
       Expect::Error, "no scalar property x"});
  c.push_back({"cloud: not a PLY (an OBJ)", [](Paths& p) { cloud_is(p, valid_model()); }, Expect::Error, "not a PLY"});
}

// Clouds whose file reads: non-finite, empty, far, clutter, duplicates, huge counts.
void add_cloud_content_cases(std::vector<Case>& c) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  c.push_back({"cloud: NaN coordinate (binary)",
               [nan](Paths& p) {
                 auto pts = wall_scan();
                 pts[pts.size() / 2].y() = nan;
                 cloud_is(p, ply_binary(pts));
               },
               Expect::Error, "non-finite"});
  c.push_back({"cloud: Inf coordinate (binary)",
               [inf](Paths& p) {
                 auto pts = wall_scan();
                 pts[7].z() = -inf;
                 cloud_is(p, ply_binary(pts));
               },
               Expect::Error, "non-finite"});
  c.push_back({"cloud: 'nan' in an ASCII PLY",
               [](Paths& p) { cloud_is(p, ply_header("ascii", 2) + "85001 447000 1\nnan 447000 2\n"); },
               Expect::Error});
  c.push_back({"cloud: 0 points (a crop the scan did not reach)", [](Paths& p) { cloud_is(p, ply_binary({})); },
               Expect::Kept, "no planes found"});
  c.push_back({"cloud: 1 point", [](Paths& p) { cloud_is(p, ply_binary({kOrigin + Vec3(6, 0, 2)})); }, Expect::Kept});
  c.push_back({"cloud: 10 points on the wall",
               [](Paths& p) {
                 std::vector<Vec3> pts;
                 for (int i = 0; i < 10; ++i) pts.push_back(kOrigin + Vec3(1 + i, 0, 1 + 0.3 * i));
                 cloud_is(p, ply_binary(pts));
               },
               Expect::Kept});
  c.push_back({"cloud: 10 km away from the model",
               [](Paths& p) { cloud_is(p, ply_binary(shifted(wall_scan(), Vec3(10000, 0, 0)))); }, Expect::Kept});
  c.push_back({"cloud: pure clutter (uniform random around the building)",
               [](Paths& p) {
                 std::mt19937 rng(5);
                 std::uniform_real_distribution<double> x(-2, 14), y(-3, 10), z(0, 9);
                 std::vector<Vec3> pts;
                 for (int i = 0; i < 6000; ++i) pts.push_back(kOrigin + Vec3(x(rng), y(rng), z(rng)));
                 cloud_is(p, ply_binary(pts));
               },
               Expect::Kept});
  c.push_back({"cloud: every point duplicated 3 times",
               [](Paths& p) {
                 std::vector<Vec3> pts;
                 for (const auto& q : wall_scan()) pts.insert(pts.end(), 3, q);
                 cloud_is(p, ply_binary(pts));
               },
               Expect::Valid});
  c.push_back({"cloud: 2000 copies of one point",
               [](Paths& p) { cloud_is(p, ply_binary(std::vector<Vec3>(2000, kOrigin + Vec3(6, 0, 2)))); },
               Expect::Kept, "", 30.0});
  c.push_back({"cloud: header claims 2^31 points, 1 KiB of data",
               [](Paths& p) { cloud_is(p, ply_header("binary_little_endian", 1ull << 31) + std::string(1024, '\0')); },
               Expect::Error, "header declares", 10.0});
  c.push_back({"cloud: 2 GiB file (sparse, 89M points of zeros)",
               [](Paths& p) {
                 const std::uint64_t n = ((1ull << 31) - 200) / 24;
                 cloud_is(p, ply_header("binary_little_endian", n));
                 const auto header = fs::file_size(p.cloud);
                 fs::resize_file(p.cloud, header + n * 24);  // a hole: nothing is written
               },
               Expect::Error, "max-points", 10.0});
  c.push_back({"cloud: header claims 2^64-1 points",
               [](Paths& p) {
                 cloud_is(p, ply_header("binary_little_endian", std::numeric_limits<std::uint64_t>::max()) +
                                 std::string(24, '\0'));
               },
               Expect::Error, "", 10.0});
  c.push_back({"cloud: header count above 2^64 (overflow)",
               [](Paths& p) {
                 cloud_is(p,
                          "ply\nformat ascii 1.0\nelement vertex 99999999999999999999999\nproperty float x\n"
                          "property float y\nproperty float z\nend_header\n1 2 3\n");
               },
               Expect::Error, "", 10.0});
}

// Paths that do not exist or cannot be written.
void add_path_cases(std::vector<Case>& c) {
  c.push_back({"model path does not exist",
               [](Paths& p) {
                 both_valid(p);
                 p.model_arg = p.dir + "/missing.obj";
               },
               Expect::Error});
  c.push_back({"cloud path does not exist",
               [](Paths& p) {
                 both_valid(p);
                 p.cloud_arg = p.dir + "/missing.ply";
               },
               Expect::Error});
  c.push_back({"model path is a directory",
               [](Paths& p) {
                 both_valid(p);
                 p.model_arg = p.dir;
               },
               Expect::Error});
  if (::geteuid() != 0)  // root reads anything
    c.push_back({"model file not readable (mode 000)",
                 [](Paths& p) {
                   both_valid(p);
                   ::chmod(p.model.c_str(), 0);
                 },
                 Expect::Error});
  c.push_back({"output path in a missing directory",
               [](Paths& p) {
                 both_valid(p);
                 p.out_arg = p.dir + "/no/such/dir/refined.obj";
               },
               Expect::Error});
  c.push_back({"output path is an existing directory",
               [](Paths& p) {
                 both_valid(p);
                 fs::create_directories(p.dir + "/outdir");
                 p.out_arg = p.dir + "/outdir";
               },
               Expect::Error});
  c.push_back({"report path in a missing directory",
               [](Paths& p) {
                 both_valid(p);
                 p.report = p.dir + "/no/such/dir/report.json";
               },
               Expect::Error});
}

// Every input a fuzz target ever crashed on, replayed through the CLI.
void add_fuzz_regressions(std::vector<Case>& c) {
  // Every input a fuzz target ever crashed on (tests/fuzz/regressions/<target>/), replayed
  // through the CLI: fuzz_obj inputs as the model, fuzz_ply inputs as the cloud, fuzz_refine
  // inputs split as the target splits them (its "tiny" flag becomes the same parameters).
  const fs::path reg = fs::path(test_paths::source_dir()) / "tests" / "fuzz" / "regressions";
  std::error_code ec;
  for (const char* target : {"fuzz_obj", "fuzz_ply", "fuzz_refine"}) {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(reg / target, ec))
      if (e.is_regular_file()) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
      const std::string t = target;
      c.push_back(
          {"fuzz regression " + t + "/" + f.filename().string(),
           [t, f](Paths& p) {
             const std::string bytes = read_text(f.string());
             if (t == "fuzz_obj") return model_is(p, bytes);
             if (t == "fuzz_ply") return cloud_is(p, bytes);
             if (bytes.size() < 3) return both_valid(p);
             const std::size_t rest = bytes.size() - 3;
             const std::size_t len =
                 (std::size_t(std::uint8_t(bytes[0])) | std::size_t(std::uint8_t(bytes[1])) << 8) % (rest + 1);
             write_text(p.model, bytes.substr(3, len));
             write_text(p.cloud, bytes.substr(3 + len));
             p.args = "--mip-time-limit 1";
             if (bytes[2] & 1)
               p.args += " --ransac-min-points 20 --min-plane-area 0.2 --normal-neighbors 6 --ransac-cluster-epsilon 1";
           },
           Expect::ErrorOrValid, "", 60.0});
    }
  }
}

// Solver limits through the CLI.
void add_solver_limits(std::vector<Case>& c) {
  c.push_back({"valid input, --mip-time-limit 0.01",
               [](Paths& p) {
                 both_valid(p);
                 p.args = "--mip-time-limit 0.01";
               },
               Expect::Valid});
}

// Every case, in a fixed order: the parameter index names a case in the test's name.
std::vector<Case> cases() {
  std::vector<Case> c;
  add_good_path(c);
  add_model_cases(c);
  add_cloud_file_cases(c);
  add_cloud_content_cases(c);
  add_path_cases(c);
  add_fuzz_regressions(c);
  add_solver_limits(c);
  return c;
}

// Runs `refine` on the case's files (made in p.dir); fills `out` with the output path passed.
CliRun run_case(const Case& k, Paths& p, std::string& out) {
  p.model = p.dir + "/model.obj";
  p.cloud = p.dir + "/cloud.ply";
  p.out = p.dir + "/refined.obj";
  p.report = p.dir + "/report.json";
  k.make(p);
  const std::string model = p.model_arg.empty() ? p.model : p.model_arg;
  const std::string cloud = p.cloud_arg.empty() ? p.cloud : p.cloud_arg;
  out = p.out_arg.empty() ? p.out : p.out_arg;
  return run_cli("refine --model " + shell_quote(model) + " --cloud " + shell_quote(cloud) + " --out " +
                     shell_quote(out) + " --report " + shell_quote(p.report) + " " + p.args,
                 p.dir, k.max_seconds);
}

// The report as JSON (null when there is none; a failure when it is no JSON).
json read_report(const std::string& path) {
  json report;
  if (fs::exists(path)) {
    try {
      report = json::parse(read_text(path));
    } catch (const std::exception& e) {
      ADD_FAILURE() << "report is not JSON: " << e.what();
    }
  }
  return report;
}

// A refusal: one line on stderr, no output, and a case that expects one.
void expect_refusal(const Case& k, const CliRun& r, const std::string& out) {
  const auto err = lines(r.err);
  EXPECT_EQ(err.size(), 1u) << "expected exactly one stderr line";
  EXPECT_EQ(r.err.rfind("lodrefine: error: ", 0), 0u) << "stderr must start with 'lodrefine: error: '";
  EXPECT_FALSE(fs::exists(out) && fs::is_regular_file(out)) << "a failed run left an output file";
  add_row(k.name, first_line(r.err), r.exit);
  EXPECT_TRUE(k.expect == Expect::Error || k.expect == Expect::ErrorOrValid) << "refused, expected success";
  if (k.expect == Expect::Error && !k.fragment.empty()) {
    EXPECT_NE(r.err.find(k.fragment), std::string::npos) << "message should mention '" << k.fragment << "'";
  }
}

// A valid output: refined with the front wall on the scan (y = 0), or kept, as the case expects.
void expect_valid_output(const Case& k, const std::string& out, const json& report) {
  const std::string outcome = report.value("outcome", std::string());
  const std::string reason = report.value("reason", std::string());
  EXPECT_EQ(output_problem(out), "");
  EXPECT_TRUE(report["output_validation"].value("valid", false));
  if (k.expect == Expect::Refined) {
    EXPECT_EQ(outcome, "refined");
    const Mesh m = read_obj(out);
    double worst = 0;
    for (const auto& f : m.faces) {
      if (f.sem != Semantic::Wall) continue;
      std::vector<Vec3> poly;
      for (int v : f.v) poly.push_back(m.vertices[v] - kOrigin);
      if (newell_normal(poly).normalized().y() > -0.9) continue;
      for (const auto& q : poly) worst = std::max(worst, std::abs(q.y()));
    }
    EXPECT_LT(worst, 0.03) << "front wall not moved onto the scan";
  }
  if (k.expect == Expect::Kept) {
    EXPECT_EQ(outcome, "kept") << reason;
    EXPECT_FALSE(report.value("refined", true));
    if (!k.fragment.empty()) {
      EXPECT_NE(reason.find(k.fragment), std::string::npos) << reason;
    }
  }
}

}  // namespace

class BadInput : public testing::TestWithParam<std::size_t> {};

TEST_P(BadInput, Contract) {
  static const std::vector<Case> all = cases();
  const Case& k = all[GetParam()];
  Paths p;
  p.dir = temp_dir("case_" + std::to_string(GetParam()));
  struct Cleanup {  // keep the files of a failed case for inspection
    std::string dir;
    ~Cleanup() {
      std::error_code ec;
      if (!testing::Test::HasFailure()) fs::remove_all(dir, ec);
    }
  } cleanup{p.dir};
  std::string out;
  const CliRun r = run_case(k, p, out);
  SCOPED_TRACE(k.name + "\nstdout: " + r.out + "\nstderr: " + r.err);

  // Never a crash (signal / sanitizer abort) nor a hang.
  if (r.exit == 124 || r.exit == 137) {
    add_row(k.name, "HANG: killed after " + fmt(r.seconds) + " s", r.exit);
    FAIL() << "hang: still running after " << k.max_seconds << " s";
  }
  EXPECT_LT(r.exit, 128) << "killed by a signal";
  EXPECT_LT(r.seconds, k.max_seconds) << "too slow";
  EXPECT_TRUE(temp_leftovers(p.dir).empty()) << "temporary file left behind: " << temp_leftovers(p.dir)[0];

  const json report = read_report(p.report);
  const std::string outcome = report.is_object() ? report.value("outcome", std::string()) : std::string();
  if (r.exit != 0) return expect_refusal(k, r, out);

  // Success: a complete, valid building and a report that tells what was written.
  add_row(k.name, "exit 0, outcome: " + (outcome.empty() ? std::string("(no report)") : outcome), r.exit);
  EXPECT_NE(k.expect, Expect::Error) << "accepted, expected a refusal";
  EXPECT_TRUE(r.err.empty()) << "stderr on success";
  ASSERT_TRUE(fs::is_regular_file(out)) << "exit 0 but no output: the building was dropped";
  ASSERT_TRUE(report.is_object()) << "no report";
  EXPECT_EQ(report.value("written", std::string()), out);
  if (k.expect == Expect::KeptInvalid || outcome == "kept-invalid") {
    const std::string reason = report.value("reason", std::string());
    EXPECT_TRUE(k.expect == Expect::KeptInvalid || k.expect == Expect::ErrorOrValid) << outcome << ": " << reason;
    EXPECT_EQ(outcome, "kept-invalid");
    EXPECT_FALSE(reason.empty());
    if (!k.fragment.empty()) {
      EXPECT_NE(reason.find(k.fragment), std::string::npos) << reason;
    }
    EXPECT_EQ(read_obj(out).faces.size(), read_obj(p.model).faces.size()) << "kept-invalid is the input as read";
    return;
  }
  expect_valid_output(k, out, report);
}

std::string case_name(const testing::TestParamInfo<std::size_t>& info) {
  static const std::vector<Case> all = cases();
  std::string s;
  for (char ch : all[info.param].name) {
    if (std::isalnum(static_cast<unsigned char>(ch))) s += ch;
    else if (!s.empty() && s.back() != '_') s += '_';
  }
  while (!s.empty() && s.back() == '_') s.pop_back();
  return std::to_string(info.param) + "_" + s.substr(0, 60);
}

INSTANTIATE_TEST_SUITE_P(Cases, BadInput, testing::Range<std::size_t>(0, cases().size()), case_name);

// ---------------------------------------------------------------------------------------------
// Atomic output under SIGKILL: whenever the process dies, the target path holds either the old
// content or a complete valid model, never a partial one.

TEST(BadInputAtomic, KillAtAnyTimeLeavesNoPartialModel) {
  const std::string dir = temp_dir("kill");
  const std::string model = dir + "/model.obj", cloud = dir + "/cloud.ply", out = dir + "/refined.obj";
  write_text(model, valid_model());
  write_text(cloud, valid_cloud());
  // First measure a whole run, then kill at fractions of it.
  const CliRun full = run_cli(
      "refine --model " + shell_quote(model) + " --cloud " + shell_quote(cloud) + " --out " + shell_quote(out), dir);
  ASSERT_EQ(full.exit, 0) << full.err;
  const std::string complete = read_text(out);
  std::string says;
  for (double frac : {0.05, 0.3, 0.6, 0.9, 0.97, 1.0}) {
    write_text(out, "old content\n");
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      const int devnull = ::open("/dev/null", O_WRONLY);
      ::dup2(devnull, 1), ::dup2(devnull, 2);
      ::execl(test_paths::lodrefine_binary().c_str(), test_paths::lodrefine_binary().c_str(), "refine", "--model",
              model.c_str(), "--cloud", cloud.c_str(), "--out", out.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    ::usleep(useconds_t(frac * full.seconds * 1e6));
    ::kill(pid, SIGKILL);
    int st = 0;
    ::waitpid(pid, &st, 0);
    const std::string now = read_text(out);
    EXPECT_TRUE(now == "old content\n" || now == complete) << "partial output after SIGKILL at " << frac;
    says += (now == complete ? "new " : "old ");
  }
  add_row("SIGKILL at 5..100% of a run (6 runs)", "target held old/new model: " + says, 0);
}
