// Robustness against the broken files a city-wide batch meets (issue "bad input"): every case
// drives the real `lodrefine refine` binary on files written here and checks the contract:
//   - refused: non-zero exit, exactly one stderr line "lodrefine: error: ...", no output file
//     and no leftover temporary file;
//   - kept: exit 0, the repaired input written and valid, the report says "kept" and why;
//   - kept-invalid: exit 0, a model that is no solid written as read, the report says why;
//   - refined: exit 0, valid output, report "refined".
// Each case prints a row "| input | what lodrefine says | exit |"; running the suite in one
// process (lodrefine_app_tests --gtest_filter='BadInput*') prints the whole table at the end.
// The solver-fault tests drive select_faces() directly on synthetic hard/infeasible programs.
#include <gtest/gtest.h>

#include "support/ply_fixtures.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <random>
#include <set>
#include <sstream>
#include <tuple>

#include <nlohmann/json.hpp>

#include "lodrefine/base/files.h"
#include "lodrefine/city/refine_report.h"
#include "lodrefine/core/candidates.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/refine.h"
#include "lodrefine/core/selection.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/formats/ply.h"
#include "support/candidate_fixtures.h"

using namespace lodrefine;

// Validation at the parameter table's planarity tolerance.
const double kPlanarity = Params{}.planarity_tolerance;

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

const Vec3 kOrigin(85000.0, 447000.0, 0.0);

// ---------------------------------------------------------------------------------------------
// Files

std::string temp_dir(const std::string& name) {
  const fs::path dir = fs::path(testing::TempDir()) / ("lodrefine_bad_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

void write_text(const std::string& path, const std::string& content) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << content;
  ASSERT_TRUE(out.good()) << path;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4f", v);
  return buf;
}

// The coarse model: a 12 x 8 x 7 m box soup (one polygon per face, vertices repeated, CityGML
// groups), georeferenced, with the front wall 0.4 m too far out (y = -0.4 instead of 0).
const Vec3 kBox[8] = {{0, -0.4, 0}, {12, -0.4, 0}, {12, 8, 0}, {0, 8, 0},
                      {0, -0.4, 7}, {12, -0.4, 7}, {12, 8, 7}, {0, 8, 7}};
struct Quad {
  int v[4];
  const char* group;
};
const Quad kQuads[6] = {{{0, 3, 2, 1}, "GroundSurface"}, {{4, 5, 6, 7}, "RoofSurface"}, {{0, 1, 5, 4}, "WallSurface"},
                        {{1, 2, 6, 5}, "WallSurface"},   {{2, 3, 7, 6}, "WallSurface"}, {{3, 0, 4, 7}, "WallSurface"}};

// OBJ text of the listed faces of the box (each face its own 4 vertices).
std::string box_obj(const std::vector<int>& faces = {0, 1, 2, 3, 4, 5}, const std::string& extra = "") {
  std::string s = "# exported per building\no bldg_0001\n";
  int n = 0;
  for (int f : faces) {
    s += std::string("g ") + kQuads[f].group + "\n";
    for (int k : kQuads[f].v) {
      const Vec3 p = kBox[k] + kOrigin;
      s += "v " + fmt(p.x()) + " " + fmt(p.y()) + " " + fmt(p.z()) + "\n";
    }
    s += "f " + std::to_string(n + 1) + " " + std::to_string(n + 2) + " " + std::to_string(n + 3) + " " +
         std::to_string(n + 4) + "\n";
    n += 4;
  }
  return s + extra;
}

// MLS-like scan of the true front wall y = 0 (x 0.5..11.5, z 0.2..5, 5 cm grid, 1 cm noise)
// with street ground in front: the scan moves the model's front wall by 0.4 m.
std::vector<Vec3> wall_scan(unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<Vec3> pts;
  for (double x = 0.5; x <= 11.5; x += 0.05)
    for (double z = 0.2; z <= 5.0; z += 0.05) pts.push_back(Vec3(x, noise(rng), z) + kOrigin);
  for (double x = 0.5; x <= 11.5; x += 0.1)
    for (double y = -6.0; y < -0.3; y += 0.1) pts.push_back(Vec3(x, y, noise(rng)) + kOrigin);
  return pts;
}

std::string ply_header(const std::string& format, std::uint64_t count, const std::string& type = "double") {
  return "ply\nformat " + format + " 1.0\ncomment test\nelement vertex " + std::to_string(count) + "\nproperty " +
         type + " x\nproperty " + type + " y\nproperty " + type + " z\nend_header\n";
}

std::string ply_binary(const std::vector<Vec3>& pts, bool big_endian = false) {
  std::string s = ply_header(big_endian ? "binary_big_endian" : "binary_little_endian", pts.size());
  for (const auto& p : pts) put(s, p.x(), big_endian), put(s, p.y(), big_endian), put(s, p.z(), big_endian);
  return s;
}

std::string ply_ascii(const std::vector<Vec3>& pts) {
  std::string s = ply_header("ascii", pts.size());
  for (const auto& p : pts) s += fmt(p.x()) + " " + fmt(p.y()) + " " + fmt(p.z()) + "\n";
  return s;
}

// ---------------------------------------------------------------------------------------------
// Running the binary

struct CliRun {
  int exit = -1;
  std::string out, err;
  double seconds = 0;
};

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Runs the binary under `timeout`: a hang (exit 124, or 137 after the KILL grace) fails the
// case instead of the whole suite, and stops a runaway process before it eats the machine.
CliRun run_cli(const std::string& args, const std::string& dir, double timeout_seconds = 300) {
  const std::string out = dir + "/.stdout", err = dir + "/.stderr";
  const std::string cmd = "timeout -k 5 " + std::to_string(int(std::ceil(timeout_seconds))) + " " +
                          shell_quote(LODREFINE_BINARY) + " " + args + " >" + shell_quote(out) + " 2>" +
                          shell_quote(err);
  const auto t0 = std::chrono::steady_clock::now();
  const int st = std::system(cmd.c_str());
  CliRun r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.exit = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + (WIFSIGNALED(st) ? WTERMSIG(st) : 0);
  r.out = read_text(out);
  r.err = read_text(err);
  fs::remove(out);
  fs::remove(err);
  return r;
}

std::vector<std::string> lines(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string l; std::getline(ss, l);) out.push_back(l);
  return out;
}

// Files left in `dir` that look like an interrupted atomic write (".lodrefine-tmp-*", or an old
// "<name>.tmp.<pid>").
std::vector<std::string> temp_leftovers(const std::string& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : fs::recursive_directory_iterator(dir, ec))
    if (e.path().filename().string().find(".tmp") != std::string::npos ||
        e.path().filename().string().find("lodrefine-tmp") != std::string::npos)
      out.push_back(e.path().string());
  return out;
}

// The written model, checked by the project's own validator; empty string when valid.
std::string output_problem(const std::string& path) {
  try {
    const Mesh m = read_obj(path);
    const Validation v = validate_mesh(m, kPlanarity);
    return v.valid() ? "" : "invalid output: " + v.problem;
  } catch (const std::exception& e) {
    return std::string("unreadable output: ") + e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// The table

struct Row {
  std::string input, says;
  int exit;
};
std::vector<Row>& table() {
  static std::vector<Row> rows;
  return rows;
}

std::string cell(std::string s) {
  for (auto& c : s)
    if (c == '|' || c == '\n') c = c == '|' ? '/' : ' ';
  return s;
}

void add_row(const std::string& input, const std::string& says, int exit) {
  table().push_back({input, says, exit});
  std::cout << "| " << cell(input) << " | " << cell(says) << " | " << exit << " |" << std::endl;
}

class TablePrinter : public testing::Environment {
 public:
  void TearDown() override {
    if (table().size() < 2) return;  // one case per process under ctest: its row is printed already
    std::cout << "\n| input | what lodrefine says | exit code |\n| --- | --- | --- |\n";
    for (const auto& r : table())
      std::cout << "| " << cell(r.input) << " | " << cell(r.says) << " | " << r.exit << " |\n";
    std::cout << std::flush;
  }
};
const testing::Environment* const kTablePrinter = testing::AddGlobalTestEnvironment(new TablePrinter);

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

std::string valid_model() { return box_obj(); }
std::string valid_cloud() { return ply_binary(wall_scan()); }

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

std::vector<Case> cases() {
  std::vector<Case> c;
  const std::string box = valid_model();
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();

  // --- the good path
  c.push_back({"valid box + wall scan 0.4 m off (binary LE doubles)", both_valid, Expect::Refined});
  c.push_back(
      {"valid box + same scan as ASCII PLY", [](Paths& p) { cloud_is(p, ply_ascii(wall_scan())); }, Expect::Refined});
  c.push_back({"valid box + same scan as big-endian PLY", [](Paths& p) { cloud_is(p, ply_binary(wall_scan(), true)); },
               Expect::Refined});

  // --- malformed models
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

  // --- malformed clouds
  c.push_back({"cloud: empty file (0 bytes)", [](Paths& p) { cloud_is(p, ""); }, Expect::Error, "empty"});
  {
    // A LAZ (the fuzz seed: 6 points, one per chunk) cut inside its chunk table, and with a
    // header count beyond what its chunks hold.
    const std::string laz = read_text(std::string(LODREFINE_SOURCE_DIR) + "/tests/fuzz/corpus/fuzz_laz/v12_f0.laz");
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

  // --- paths
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

  // --- every input a fuzz target ever crashed on (tests/fuzz/regressions/<target>/), replayed
  // through the CLI: fuzz_obj inputs as the model, fuzz_ply inputs as the cloud, fuzz_refine
  // inputs split as the target splits them (its "tiny" flag becomes the same parameters).
  const fs::path reg = fs::path(LODREFINE_SOURCE_DIR) / "tests" / "fuzz" / "regressions";
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

  // --- solver limits through the CLI
  c.push_back({"valid input, --mip-time-limit 0.01",
               [](Paths& p) {
                 both_valid(p);
                 p.args = "--mip-time-limit 0.01";
               },
               Expect::Valid});
  return c;
}

std::string first_line(const std::string& s) { return s.substr(0, s.find('\n')); }

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
  p.model = p.dir + "/model.obj";
  p.cloud = p.dir + "/cloud.ply";
  p.out = p.dir + "/refined.obj";
  p.report = p.dir + "/report.json";
  k.make(p);
  const std::string model = p.model_arg.empty() ? p.model : p.model_arg;
  const std::string cloud = p.cloud_arg.empty() ? p.cloud : p.cloud_arg;
  const std::string out = p.out_arg.empty() ? p.out : p.out_arg;
  const CliRun r = run_cli("refine --model " + shell_quote(model) + " --cloud " + shell_quote(cloud) + " --out " +
                               shell_quote(out) + " --report " + shell_quote(p.report) + " " + p.args,
                           p.dir, k.max_seconds);
  SCOPED_TRACE(k.name + "\nstdout: " + r.out + "\nstderr: " + r.err);

  // Never a crash (signal / sanitizer abort) nor a hang.
  if (r.exit == 124 || r.exit == 137) {
    add_row(k.name, "HANG: killed after " + fmt(r.seconds) + " s", r.exit);
    FAIL() << "hang: still running after " << k.max_seconds << " s";
  }
  EXPECT_LT(r.exit, 128) << "killed by a signal";
  EXPECT_LT(r.seconds, k.max_seconds) << "too slow";
  EXPECT_TRUE(temp_leftovers(p.dir).empty()) << "temporary file left behind: " << temp_leftovers(p.dir)[0];

  json report;
  if (fs::exists(p.report)) {
    try {
      report = json::parse(read_text(p.report));
    } catch (const std::exception& e) {
      ADD_FAILURE() << "report is not JSON: " << e.what();
    }
  }
  const std::string outcome = report.is_object() ? report.value("outcome", std::string()) : std::string();

  const bool refused = r.exit != 0;
  if (refused) {
    const auto err = lines(r.err);
    EXPECT_EQ(err.size(), 1u) << "expected exactly one stderr line";
    EXPECT_EQ(r.err.rfind("lodrefine: error: ", 0), 0u) << "stderr must start with 'lodrefine: error: '";
    EXPECT_FALSE(fs::exists(out) && fs::is_regular_file(out)) << "a failed run left an output file";
    add_row(k.name, first_line(r.err), r.exit);
    EXPECT_TRUE(k.expect == Expect::Error || k.expect == Expect::ErrorOrValid) << "refused, expected success";
    if (k.expect == Expect::Error && !k.fragment.empty()) {
      EXPECT_NE(r.err.find(k.fragment), std::string::npos) << "message should mention '" << k.fragment << "'";
    }
    return;
  }

  // Success: a complete, valid building and a report that tells what was written.
  add_row(k.name, "exit 0, outcome: " + (outcome.empty() ? std::string("(no report)") : outcome), r.exit);
  EXPECT_NE(k.expect, Expect::Error) << "accepted, expected a refusal";
  EXPECT_TRUE(r.err.empty()) << "stderr on success";
  ASSERT_TRUE(fs::is_regular_file(out)) << "exit 0 but no output: the building was dropped";
  ASSERT_TRUE(report.is_object()) << "no report";
  EXPECT_EQ(report.value("written", std::string()), out);
  const std::string reason = report.value("reason", std::string());
  if (k.expect == Expect::KeptInvalid || outcome == "kept-invalid") {
    EXPECT_TRUE(k.expect == Expect::KeptInvalid || k.expect == Expect::ErrorOrValid) << outcome << ": " << reason;
    EXPECT_EQ(outcome, "kept-invalid");
    EXPECT_FALSE(reason.empty());
    if (!k.fragment.empty()) {
      EXPECT_NE(reason.find(k.fragment), std::string::npos) << reason;
    }
    EXPECT_EQ(read_obj(out).faces.size(), read_obj(p.model).faces.size()) << "kept-invalid is the input as read";
    return;
  }
  EXPECT_EQ(output_problem(out), "");
  EXPECT_TRUE(report["output_validation"].value("valid", false));
  if (k.expect == Expect::Refined) {
    EXPECT_EQ(outcome, "refined");
    const Mesh m = read_obj(out);
    double worst = 0;  // the front wall now lies on the scan (y = 0)
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
      ::execl(LODREFINE_BINARY, LODREFINE_BINARY, "refine", "--model", model.c_str(), "--cloud", cloud.c_str(), "--out",
              out.c_str(), static_cast<char*>(nullptr));
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

// ---------------------------------------------------------------------------------------------
// Library-level regressions of fuzz findings

// tests/fuzz/regressions/fuzz_obj/writer_huge_coordinate.obj: read_obj accepts any finite
// coordinate, so write_obj must print any finite coordinate readably.
TEST(BadInputRegression, ObjWriterRoundTripsHugeCoordinates) {
  // The writer prints any finite double readably; the reader refuses such a file in one line.
  const std::string dir = temp_dir("huge_coordinate");
  Mesh m;
  m.id = "huge";
  m.vertices = {{1e60, 0, 0}, {0, 1, 0}, {0, 0, -1.7e308}};
  Face f;
  f.v = {0, 1, 2};
  m.faces = {f};
  write_obj(dir + "/h.obj", m);
  std::ifstream in(dir + "/h.obj", std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (unsigned char c : text) EXPECT_TRUE(c == '\n' || (c >= 32 && c < 127)) << "byte " << int(c);
  EXPECT_GT(text.size(), 309u);  // -1.7e308 printed in full (309 digits)
  try {
    read_obj(dir + "/h.obj");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("beyond 1e9 m"), std::string::npos) << e.what();
  }
}

// tests/fuzz/regressions/fuzz_refine/glpk_duplicate_index_warped_ground: build_candidates
// produced an edge listing one face twice; select_faces put the column twice in one row and
// glp_load_matrix aborted the process ("duplicate indices not allowed"). Run in a child, so a
// regression kills the child, not the test binary.
TEST(BadInputRegression, FaceListedTwiceOnAnEdgeDoesNotAbortTheSolver) {
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::close(2);  // GLPK prints its error before aborting
    CandidateSet cs = fixtures::hand_built({0, 0}, {1.0, 1.0}, {{0, 0, 1}});
    const SelectionResult r = select_faces(cs, {-1.0, -1.0}, {0}, Params{});
    ::_exit(r.status == SolveStatus::NotRun ? 1 : 0);
  }
  int st = 0;
  ::waitpid(pid, &st, 0);
  EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0)
      << "select_faces killed the process (signal " << (WIFSIGNALED(st) ? WTERMSIG(st) : 0) << ")";
}

// ---------------------------------------------------------------------------------------------
// Solver faults: select_faces() on synthetic programs GLPK cannot solve.

// Random parity constraints (sum of 3 x's + outside = 2 y per edge) over many faces: GLPK's
// LP relaxation is trivially fractional and branch and bound explodes.
CandidateSet hard_program(int faces, int edges, unsigned seed, std::vector<double>& cost, std::vector<int>& outside) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick(0, faces - 1);
  std::vector<int> plane;
  std::vector<double> area;
  for (int f = 0; f < faces; ++f) {
    plane.push_back(f % 7);
    area.push_back(1.0 + f % 5);
    cost.push_back((f % 3) - 1.0);
  }
  std::vector<std::vector<int>> fans;
  for (int e = 0; e < edges; ++e) {
    std::vector<int> fan;
    while (fan.size() < 3) {
      const int f = pick(rng);
      if (std::find(fan.begin(), fan.end(), f) == fan.end()) fan.push_back(f);
    }
    fans.push_back(fan);
    outside.push_back(int(rng() % 2));
  }
  return fixtures::hand_built(plane, area, fans);
}

TEST(BadInputSolver, InfeasibleProgramIsReportedNotSelected) {
  // Face 0 alone on two edges: once with the outside surface (x0 + 1 = 2 y0 -> x0 = 1), once
  // without (x0 = 2 y1 -> x0 = 0). No selection satisfies both.
  CandidateSet cs = fixtures::hand_built({0}, {1.0}, {{0}, {0}});
  const SelectionResult r = select_faces(cs, {-1.0}, {1, 0}, Params{});
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.status_text(), "infeasible");
  EXPECT_EQ(selected_faces(cs), std::vector<char>(1, 0));
  add_row("select_faces: infeasible program", "ok=false, status '" + r.status_text() + "'", 0);
}

TEST(BadInputSolver, NoCandidatesIsReported) {
  CandidateSet none;
  const SelectionResult r = select_faces(none, {}, {}, Params{});
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.status_text(), "no candidates");
}

TEST(BadInputSolver, TimeLimitWithoutSolutionIsReported) {
  std::vector<double> cost;
  std::vector<int> outside;
  CandidateSet cs = hard_program(3000, 4000, 3, cost, outside);
  Params prm;
  prm.mip_time_limit = 0.01;
  const SelectionResult r = select_faces(cs, cost, outside, prm);
  EXPECT_NE(r.status_text().find("time limit"), std::string::npos) << r.status_text();
  if (!r.ok) {
    EXPECT_EQ(r.status_text(), "time limit (no solution)");
    EXPECT_EQ(selected_faces(cs), std::vector<char>(std::size_t(cs.size()), 0));
  } else {
    EXPECT_EQ(r.status_text(), "feasible (time limit)");
  }
  EXPECT_LT(r.seconds, 5.0) << "the time limit was not honoured";
  // The budget is an argument (what is left of mip_time_limit after an earlier solve), not a
  // mutated copy of the config: it rules whatever config.mip_time_limit says.
  SelectionConfig patient = prm;
  patient.mip_time_limit = 3600.0;
  SelectionProgram pg;
  pg.cost = cost;
  pg.outside = outside;
  const SelectionResult budget = select_faces(cs, pg, patient, 0.01);
  EXPECT_NE(budget.status_text().find("time limit"), std::string::npos) << budget.status_text();
  EXPECT_LT(budget.seconds, 5.0) << "the budget argument was not honoured";
  add_row("select_faces: 3000-face parity program, 10 ms limit",
          "ok=" + std::string(r.ok ? "true" : "false") + ", status '" + r.status_text() + "', " + fmt(r.seconds) + " s",
          0);
}

// A real, easy program: the arrangement of a cube's six planes in a larger region (54
// candidates); rewarding the pieces on the cube selects exactly its six faces.
CandidateSet cube_program(std::vector<double>& cost, std::vector<int>& outside) {
  std::vector<SupportPlane> planes;
  for (int k = 0; k < 3; ++k)
    for (double sign : {1.0, -1.0}) {
      SupportPlane sp;
      sp.plane = Plane(sign * Vec3::Unit(k), -1.0);
      sp.sem = k == 2 ? (sign > 0 ? Semantic::Roof : Semantic::Ground) : Semantic::Wall;
      planes.push_back(sp);
    }
  Region region;
  region.half = Vec3::Constant(2.0);
  CandidateSet cs = build_candidates(planes, region);
  for (int f = 0; f < cs.size(); ++f)
    cost.push_back(fixtures::centroid_of(cs, f).lpNorm<Eigen::Infinity>() <= 1.0 + 1e-9 ? -fixtures::area_of(cs, f)
                                                                                        : fixtures::area_of(cs, f));
  outside.assign(cs.edges.size(), 0);
  return cs;
}

TEST(BadInputSolver, OneMillisecondLimitFailsEvenAnEasyProgram) {
  std::vector<double> cost;
  std::vector<int> outside;
  CandidateSet cs = cube_program(cost, outside);
  ASSERT_GE(cs.size(), 6);
  const SelectionResult easy = select_faces(cs, cost, outside, Params{});
  ASSERT_TRUE(easy.ok) << easy.status_text();
  EXPECT_EQ(easy.status_text(), "optimal");
  const std::vector<char> chosen = selected_faces(cs);
  EXPECT_EQ(std::count(chosen.begin(), chosen.end(), 1), 6);
  // GLPK stops at its first time check when tm_lim <= 1 ms: a deterministic solver fault.
  Params prm;
  prm.mip_time_limit = 0.001;
  const SelectionResult r = select_faces(cs, cost, outside, prm);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.status_text(), "time limit (no solution)");
  const std::vector<char> none = selected_faces(cs);
  EXPECT_EQ(std::count(none.begin(), none.end(), 1), 0);
  add_row("select_faces: cube arrangement (" + std::to_string(cs.size()) + " candidates), 1 ms limit",
          "ok=false, status '" + r.status_text() + "' (30 s limit: '" + easy.status_text() + "')", 0);
}

// The whole pipeline under a starved solver: refine_building must write a valid shell, either
// the starting shell GLPK took as its incumbent ("feasible (time limit)" or better) or the
// repaired input with the solver status as the reason. The CLI half needs --mip-time-limit to
// accept 1 ms (params.h's minimum), and fails if that bound ever rises.
TEST(BadInputSolver, RefineUnderAStarvedSolverWritesAValidShell) {
  const std::string dir = temp_dir("solver_fallback");
  write_text(dir + "/m.obj", valid_model());
  const Mesh model = read_obj(dir + "/m.obj");
  PointCloud cloud;
  cloud.points = wall_scan();
  Params prm;
  prm.mip_time_limit = 0.001;
  const RefineResult r = refine_building(model, cloud, prm);
  const nlohmann::json report = refine_report(r);
  ASSERT_TRUE(r.valid) << report.dump(1);
  EXPECT_TRUE(validate_mesh(r.mesh, kPlanarity).valid());
  ASSERT_TRUE(report.contains("selection")) << report.dump(1);
  const std::string status = report["selection"].value("status", std::string());
  if (r.refined())
    EXPECT_TRUE(status == "optimal" || status == "feasible" || status == "feasible (time limit)") << status;
  else EXPECT_EQ(r.reason, "the selection found no valid shell: face selection " + status);
  add_row("refine_building, mip_time_limit 0.001", std::string("outcome '") + outcome_name(r.outcome) + "', " + status,
          0);

  // And through the CLI: exit 0, a valid shell written, the status in the report.
  write_text(dir + "/c.ply", valid_cloud());
  const CliRun cli =
      run_cli("refine --model " + shell_quote(dir + "/m.obj") + " --cloud " + shell_quote(dir + "/c.ply") + " --out " +
                  shell_quote(dir + "/r.obj") + " --report " + shell_quote(dir + "/r.json") + " --mip-time-limit 0.001",
              dir);
  EXPECT_EQ(cli.exit, 0) << cli.err;
  EXPECT_EQ(output_problem(dir + "/r.obj"), "");
  const json rep = json::parse(read_text(dir + "/r.json"));
  EXPECT_FALSE(rep["selection"].value("status", std::string()).empty()) << rep.dump(1);
  add_row("valid input, --mip-time-limit 0.001", first_line(cli.out), cli.exit);
}

// Issue 15, items 2, 13, 14 through the command line: untrusted city files and names.
TEST(BadInputSecurity, NonUtf8NamesAreWrittenWithReplacementCharacters) {
  const std::string dir = temp_dir("non_utf8");
  // refine --report with an OBJ object name holding bytes that are no UTF-8.
  write_text(dir + "/m.obj", "o bldg_\xff\xfe\n" + valid_model());
  write_text(dir + "/c.ply", valid_cloud());
  const CliRun r = run_cli("refine --model " + shell_quote(dir + "/m.obj") + " --cloud " + shell_quote(dir + "/c.ply") +
                               " --out " + shell_quote(dir + "/r.obj") + " --report " + shell_quote(dir + "/r.json"),
                           dir);
  EXPECT_EQ(r.exit, 0) << r.err;
  const json rep = json::parse(read_text(dir + "/r.json"));
  EXPECT_NE(rep.dump().find("bldg_\xEF\xBF\xBD\xEF\xBF\xBD"), std::string::npos) << rep.dump();
  // eval --dir over a run folder whose building folder name is no UTF-8.
  const std::string run = dir + "/run/b\xff";
  fs::create_directories(run);
  write_text(run + "/coarse.obj", valid_model());
  write_text(run + "/refined.obj", read_text(dir + "/r.obj"));
  write_text(run + "/cloud.ply", valid_cloud());
  const CliRun e =
      run_cli("eval --dir " + shell_quote(dir + "/run") + " --json " + shell_quote(dir + "/e.json") + " --jobs 1", dir);
  EXPECT_EQ(e.exit, 0) << e.err;
  EXPECT_EQ(e.err.find("json.exception"), std::string::npos) << e.err;
  EXPECT_NE(read_text(dir + "/e.json").find("b\xEF\xBF\xBD"), std::string::npos);
}

TEST(BadInputSecurity, CityFilesRefusedInOneLineNamingTheFile) {
  const std::string dir = temp_dir("city_refusals");
  write_text(dir + "/c.ply", valid_cloud());
  const std::string xxe =
      "<?xml version=\"1.0\"?>\n<!DOCTYPE CityModel [<!ENTITY e SYSTEM \"file:///etc/passwd\">]>\n"
      "<CityModel xmlns=\"http://www.opengis.net/citygml/2.0\"><gml:name>&e;</gml:name></CityModel>\n";
  const std::vector<std::pair<std::string, std::string>> files = {
      {"xxe.gml", xxe},
      {"overflow.city.json", R"({"type":"CityJSON","version":"2.0","CityObjects":{},"vertices":[[1e400,0,0]]})"},
      {"scale0.city.json",
       R"({"type":"CityJSON","version":"2.0","transform":{"scale":[1,1,0],"translate":[0,0,0]},"CityObjects":{},"vertices":[]})"},
      {"header.city.jsonl",
       R"({"type":"CityJSON","version":"2.0","transform":{"scale":"x"},"CityObjects":{},"vertices":[]})"
       "\n{\"type\":\"CityJSONFeature\",\"CityObjects\":{},\"vertices\":[]}\n"},
      {"deep.city.json", R"({"type":"CityJSON","version":"2.0","CityObjects":{},"vertices":[],"x":)" +
                             std::string(100000, '[') + std::string(100000, ']') + "}"},
      // A second "CityObjects" replaced the first (its buildings gone without a word).
      {"twice.city.json",
       R"({"type":"CityJSON","version":"2.0","CityObjects":{"A":{"type":"Building"}},"vertices":[],"CityObjects":{}})"},
      // Non-string "version" / "type": a raw json type_error, exit 1, after the crop.
      {"version.city.json", R"({"type":"CityJSON","version":2,"CityObjects":{},"vertices":[]})"},
      {"type.city.json", R"({"type":"CityJSON","version":"1.1","CityObjects":{"A":{"type":5}},"vertices":[]})"},
      {"feature.city.jsonl",
       R"({"type":"CityJSON","version":"2.0","transform":{"scale":[1,1,1],"translate":[0,0,0]},"CityObjects":{},"vertices":[]})"
       "\n{\"type\":5,\"CityObjects\":{},\"vertices\":[]}\n"},
      {"seqheader.city.jsonl", "{\"type\":5}\n{\"type\":\"CityJSONFeature\",\"CityObjects\":{},\"vertices\":[]}\n"},
      // 20,000 nested BuildingParts overflowed the CityGML module's stack (a crash, no line).
      {"deep.gml",
       [] {
         std::string s =
             "<?xml version=\"1.0\"?>\n<CityModel xmlns=\"http://www.opengis.net/citygml/2.0\" "
             "xmlns:bldg=\"http://www.opengis.net/citygml/building/2.0\"><cityObjectMember><bldg:Building>";
         for (int k = 0; k < 20000; ++k) s += "<bldg:consistsOfBuildingPart><bldg:BuildingPart>";
         for (int k = 0; k < 20000; ++k) s += "</bldg:BuildingPart></bldg:consistsOfBuildingPart>";
         return s + "</bldg:Building></cityObjectMember></CityModel>\n";
       }()},
  };
  for (const auto& [name, text] : files) {
    const std::string model = dir + "/" + name;
    write_text(model, text);
    const CliRun r = run_cli("refine --model " + shell_quote(model) + " --cloud " + shell_quote(dir + "/c.ply") +
                                 " --out " + shell_quote(dir + "/out.city.json"),
                             dir);
    EXPECT_EQ(r.exit, 2) << name << ": " << r.err;
    EXPECT_EQ(lines(r.err).size(), 1u) << r.err;
    EXPECT_EQ(r.err.rfind("lodrefine: error: " + model + ": ", 0), 0u) << r.err;
    EXPECT_EQ(r.err.find("root:"), std::string::npos) << r.err;  // nothing of /etc/passwd
    EXPECT_EQ(r.err.find("json.exception"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir + "/out.city.json")) << name;
    EXPECT_TRUE(temp_leftovers(dir).empty()) << name;
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Untrusted ids, paths and files (issue 15): outputs stay in the output folder, never replace an
// input or a file already there, temporaries are ours, and every building is accounted for.

namespace {

// A CityJSON 2.0 file: each id a copy of the box (MultiSurface, LoD 2.2); ids in `flat` get a
// geometry without any usable surface (rings of one repeated vertex).
std::string box_city(const std::vector<std::string>& ids, const std::vector<std::string>& flat = {}) {
  json doc = {{"type", "CityJSON"},
              {"version", "2.0"},
              {"transform", {{"scale", {0.001, 0.001, 0.001}}, {"translate", {kOrigin.x(), kOrigin.y(), kOrigin.z()}}}},
              {"CityObjects", json::object()},
              {"vertices", json::array()}};
  for (const Vec3& v : kBox)
    doc["vertices"].push_back({std::llround(v.x() * 1000), std::llround(v.y() * 1000), std::llround(v.z() * 1000)});
  json boundaries = json::array(), degenerate = json::array();
  for (const Quad& q : kQuads)
    boundaries.push_back({{q.v[0], q.v[1], q.v[2], q.v[3]}}), degenerate.push_back({{0, 0, 0}});
  for (const auto& id : ids) {
    const bool is_flat = std::find(flat.begin(), flat.end(), id) != flat.end();
    doc["CityObjects"][id] = {
        {"type", "Building"},
        {"geometry", {{{"type", "MultiSurface"}, {"lod", "2.2"}, {"boundaries", is_flat ? degenerate : boundaries}}}}};
  }
  return doc.dump();
}

std::vector<std::string> files_in(const std::string& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

void expect_one_error_line(const CliRun& r, const std::string& says) {
  EXPECT_EQ(r.exit, 2) << r.err;
  EXPECT_EQ(lines(r.err).size(), 1u) << r.err;
  EXPECT_EQ(r.err.rfind("lodrefine: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
}

}  // namespace

// A model named `...obj` (stem "..") must not make crop write into the parent of --out.
TEST(BadInputFiles, CropKeepsAModelNamedDotDotInsideOut) {
  const std::string dir = temp_dir("crop_dotdot");
  fs::create_directories(dir + "/models");
  write_text(dir + "/models/...obj", valid_model());
  write_text(dir + "/tile.ply", valid_cloud());
  const CliRun r = run_cli("crop --tile " + dir + "/tile.ply --models " + dir + "/models --out " + dir + "/run", dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(files_in(dir), (std::vector<std::string>{"models", "run", "tile.ply"})) << "wrote beside --out";
  const auto folders = files_in(dir + "/run");
  ASSERT_EQ(folders.size(), 1u);
  EXPECT_TRUE(is_safe_name(folders[0])) << folders[0];
  EXPECT_EQ(files_in(dir + "/run/" + folders[0]), (std::vector<std::string>{"cloud.ply", "coarse.obj"}));
  add_row("crop: model `...obj` (stem `..`)", "stays in --out, folder " + folders[0], r.exit);
}

// After an unreadable model is skipped, every building still gets its own model (the kept list
// and the model list used to drift apart by one).
TEST(BadInputFiles, CropPairsEachBuildingWithItsOwnModelAfterASkip) {
  const std::string dir = temp_dir("crop_skip");
  fs::create_directories(dir + "/models");
  write_text(dir + "/models/a.obj", "v 0 0\n");  // unreadable: skipped with a warning
  std::string b = valid_model(), c = valid_model();
  b.replace(b.find("o bldg_0001"), 11, "o B");
  c.replace(c.find("o bldg_0001"), 11, "o C");
  write_text(dir + "/models/b.obj", b);
  write_text(dir + "/models/c.obj", c);
  write_text(dir + "/tile.ply", valid_cloud());
  const CliRun r = run_cli("crop --tile " + dir + "/tile.ply --models " + dir + "/models --out " + dir + "/run", dir);
  EXPECT_EQ(r.exit, 1) << r.err;
  EXPECT_NE(r.err.find("skipping \"a\""), std::string::npos) << r.err;
  EXPECT_EQ(files_in(dir + "/run"), (std::vector<std::string>{"b", "c"}));
  EXPECT_EQ(read_text(dir + "/run/b/coarse.obj"), b);
  EXPECT_EQ(read_text(dir + "/run/c/coarse.obj"), c);
  add_row("crop: first model unreadable", "skipped; the others keep their own models", r.exit);
}

// A.obj and A/coarse.obj are two models for one building: refused, nothing written.
TEST(BadInputFiles, CropRefusesTwoModelsForOneBuilding) {
  const std::string dir = temp_dir("crop_twice");
  fs::create_directories(dir + "/models/A");
  write_text(dir + "/models/A.obj", valid_model());
  write_text(dir + "/models/A/coarse.obj", box_obj({0, 1, 2, 3, 4}));
  write_text(dir + "/tile.ply", valid_cloud());
  const CliRun r = run_cli("crop --tile " + dir + "/tile.ply --models " + dir + "/models --out " + dir + "/run", dir);
  expect_one_error_line(r, "two models for building \"A\"");
  EXPECT_FALSE(fs::exists(dir + "/run"));
  // The tile as an output of the crop (the run folder holding it) is refused too, the tile kept.
  fs::remove_all(dir + "/models/A");
  fs::create_directories(dir + "/run/A");
  write_text(dir + "/run/A/cloud.ply", valid_cloud());
  const CliRun t =
      run_cli("crop --tile " + dir + "/run/A/cloud.ply --models " + dir + "/models --out " + dir + "/run", dir);
  expect_one_error_line(t, "the tile would be overwritten");
  EXPECT_EQ(read_text(dir + "/run/A/cloud.ply"), valid_cloud());
  add_row("crop: A.obj and A/coarse.obj; tile inside --out", "refused: two models / tile would be overwritten", r.exit);
}

// convert: each building by name on stdout (written) or stderr (dropped), distinct safe file
// names that never replace a file already in --out-dir, the real id inside each model, ids of
// any length.
TEST(BadInputFiles, ConvertAccountsForEveryBuildingAndNeverOverwrites) {
  const std::string dir = temp_dir("convert_names");
  const std::string long_a(300, 'a'), long_b = std::string(299, 'a') + "b";
  const std::vector<std::string> ids = {"B 1", "B_1", "$(touch PWNED)", "-rf", long_a, long_b, "Flat roof"};
  json city = json::parse(box_city(ids, {"Flat roof"}));
  city["CityObjects"]["Only LoD1"] = {{"type", "Building"}, {"geometry", json::array()}};  // no LoD 2.x geometry
  write_text(dir + "/city.json", city.dump());
  const CliRun r = run_cli("convert --cityjson " + dir + "/city.json --out-dir " + dir + "/objs", dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/PWNED"));
  const auto names = files_in(dir + "/objs");
  ASSERT_EQ(names.size(), 6u) << r.out;
  std::set<std::string> read_ids;
  for (const auto& n : names) {
    EXPECT_TRUE(is_safe_name(n.substr(0, n.size() - 4))) << n;
    read_ids.insert(read_obj(dir + "/objs/" + n).id);
  }
  EXPECT_EQ(read_ids, std::set<std::string>(ids.begin(), ids.end() - 1)) << "the real ids, inside the models";
  EXPECT_EQ(lines(r.out).size(), 7u) << r.out;  // one line per written building, then the total
  EXPECT_NE(r.out.find(".obj <- \"B 1\""), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("Flat roof"), std::string::npos) << "the dropped building is named: " << r.err;
  EXPECT_NE(r.err.find("\"Only LoD1\" has no LoD 2.x geometry, skipped"), std::string::npos)
      << "the building without LoD 2 is named: " << r.err;
  // Again into the same folder: refused before anything is written, the files kept.
  const std::string before = read_text(dir + "/objs/B_1.obj");
  write_text(dir + "/objs/B_1.obj", "mine\n");
  const CliRun again = run_cli("convert --cityjson " + dir + "/city.json --out-dir " + dir + "/objs", dir);
  expect_one_error_line(again, "already exists");
  EXPECT_EQ(read_text(dir + "/objs/B_1.obj"), "mine\n");
  EXPECT_EQ(files_in(dir + "/objs"), names);
  add_row("convert: ids `B 1`/`B_1`, shell code, 300 bytes, no surface", "distinct safe names, ids kept, dropped named",
          r.exit);
}

// An output that is an input (any spelling of it) or the other output is refused before
// anything is read; the input is untouched.
TEST(BadInputFiles, RefineRefusesOutputsThatAreInputs) {
  const std::string dir = temp_dir("refine_same");
  fs::create_directories(dir + "/sub");
  const std::string model = dir + "/model.obj", cloud = dir + "/cloud.ply";
  write_text(model, valid_model());
  write_text(cloud, valid_cloud());
  fs::create_symlink(model, dir + "/link.obj");
  const std::string in = "refine --model " + model + " --cloud " + cloud;
  for (const std::string& outputs :
       {" --out " + model, " --out " + dir + "/link.obj", " --out " + dir + "/sub/../model.obj",
        " --out " + dir + "/r.obj --report " + cloud, " --out " + dir + "/r.obj --report " + dir + "/sub/../r.obj"}) {
    const CliRun r = run_cli(in + outputs, dir);
    expect_one_error_line(r, "--");
    EXPECT_LT(r.seconds, 5.0) << outputs;
    EXPECT_EQ(read_text(model), valid_model()) << outputs;
    EXPECT_EQ(read_text(cloud), valid_cloud()) << outputs;
    EXPECT_FALSE(fs::exists(dir + "/r.obj")) << outputs;
  }
  // A city file: --out the model.
  write_text(dir + "/city.json", box_city({"B"}));
  const CliRun c =
      run_cli("refine --model " + dir + "/city.json --cloud " + cloud + " --out " + dir + "/city.json", dir);
  expect_one_error_line(c, "is the --model file");
  EXPECT_EQ(read_text(dir + "/city.json"), box_city({"B"}));
  // --html, the city refine's review page, replaced the model, the cloud or the city file out.
  for (const auto& [outputs, says] : std::vector<std::pair<std::string, std::string>>{
           {" --out " + dir + "/r.json --html " + dir + "/city.json", "--html is the --model file"},
           {" --out " + dir + "/r.json --html " + cloud, "--html is the --cloud file"},
           {" --out " + dir + "/r.json --html " + dir + "/sub/../r.json", "--html is the --out file"},
           {" --out " + dir + "/r.json --report " + dir + "/h.html --html " + dir + "/h.html",
            "--html is the --report file"}}) {
    const CliRun h = run_cli("refine --model " + dir + "/city.json --cloud " + cloud + outputs, dir);
    expect_one_error_line(h, says);
    EXPECT_EQ(read_text(dir + "/city.json"), box_city({"B"})) << outputs;
    EXPECT_EQ(read_text(cloud), valid_cloud()) << outputs;
    EXPECT_FALSE(fs::exists(dir + "/r.json")) << outputs;
  }
  add_row("refine: --out/--report/--html = --model/--cloud or each other (links, ../)", "refused before reading",
          c.exit);
}

// eval's outputs replaced its inputs without a word (--json r.obj --refined r.obj).
TEST(BadInputFiles, EvalRefusesOutputsThatAreInputs) {
  const std::string dir = temp_dir("eval_same");
  const std::string model = dir + "/model.obj", refined = dir + "/refined.obj", cloud = dir + "/cloud.ply";
  write_text(model, valid_model());
  write_text(refined, valid_model());
  write_text(cloud, valid_cloud());
  const std::string in = "eval --original " + model + " --refined " + refined + " --cloud " + cloud;
  for (const auto& [outputs, says] : std::vector<std::pair<std::string, std::string>>{
           {" --json " + refined, "--json is the --refined file"},
           {" --csv " + dir + "/./model.obj", "--csv is the --original file"},
           {" --json " + cloud, "--json is the --cloud file"},
           {" --json " + dir + "/e.json --csv " + dir + "/e.json", "--csv is the --json file"}}) {
    const CliRun r = run_cli(in + outputs, dir);
    expect_one_error_line(r, says);
    EXPECT_EQ(read_text(model), valid_model()) << outputs;
    EXPECT_EQ(read_text(refined), valid_model()) << outputs;
    EXPECT_EQ(read_text(cloud), valid_cloud()) << outputs;
    EXPECT_FALSE(fs::exists(dir + "/e.json")) << outputs;
  }
  add_row("eval: --json/--csv/... = --original/--refined/--cloud or each other", "refused before reading", 2);
}

// A report never names a model that is not there; an output folder that takes no file is
// found before the work (single building and city file). /proc/self takes no new file, even for root.
TEST(BadInputFiles, UnwritableOutputFailsFirstAndLeavesNoReport) {
  const std::string dir = temp_dir("refine_unwritable");
  const std::string model = dir + "/model.obj", cloud = dir + "/cloud.ply";
  write_text(model, valid_model());
  write_text(cloud, valid_cloud());
  const CliRun r = run_cli("refine --model " + model + " --cloud " + cloud + " --out /proc/self/refined.obj --report " +
                               dir + "/report.json",
                           dir);
  expect_one_error_line(r, "cannot write /proc/self/refined.obj");
  EXPECT_FALSE(fs::exists(dir + "/report.json")) << "the report claims a model that was never written";
  write_text(dir + "/city.json", box_city({"B"}));
  const CliRun c =
      run_cli("refine --model " + dir + "/city.json --cloud " + cloud + " --out /proc/self/out.city.json", dir);
  expect_one_error_line(c, "cannot write /proc/self/out.city.json");
  EXPECT_EQ(c.out, "") << "refined before finding the output unwritable";
  EXPECT_TRUE(temp_leftovers(dir).empty());
  add_row("refine: --out in a folder that takes no file", "refused before refining; no report", r.exit);
}

// Devices and FIFOs are refused at once, not read for gigabytes (or forever).
TEST(BadInputFiles, DevZeroIsRefusedAtOnce) {
  const std::string dir = temp_dir("dev_zero");
  write_text(dir + "/model.obj", valid_model());
  write_text(dir + "/cloud.ply", valid_cloud());
  ASSERT_EQ(::mkfifo((dir + "/fifo").c_str(), 0600), 0);
  for (const std::string& args :
       {"--model /dev/zero --cloud " + dir + "/cloud.ply", "--model " + dir + "/model.obj --cloud /dev/zero",
        "--model " + dir + "/fifo --cloud " + dir + "/cloud.ply"}) {
    const CliRun r = run_cli("refine " + args + " --out " + dir + "/r.obj", dir, 60);
    expect_one_error_line(r, "not a regular file");
    EXPECT_LT(r.seconds, 5.0) << args;
  }
  add_row("refine --model /dev/zero (or a FIFO)", "refused at once: not a regular file", 2);
}

// A write that fails half-way (here a file size limit, as a full disk would) leaves no half run
// folder: crop and convert remove what they created.
TEST(BadInputFiles, FailedWriteLeavesNoHalfRunFolder) {
  const std::string dir = temp_dir("full_disk");
  fs::create_directories(dir + "/models");
  for (const char* id : {"a", "b", "c"}) write_text(dir + "/models/" + id + ".obj", valid_model());
  write_text(dir + "/tile.ply", valid_cloud());
  write_text(dir + "/city.json", box_city({"a", "b", "c"}));
  // SIGXFSZ ignored: a write beyond 64 KB fails with EFBIG, as on a full disk.
  auto limited = [&](const std::string& args) {
    return std::system(("cd " + shell_quote(dir) + " && sh -c \"trap '' XFSZ; ulimit -f 64; exec " +
                        shell_quote(LODREFINE_BINARY) + " " + args + "\" > /dev/null 2> err.txt")
                           .c_str());
  };
  EXPECT_NE(limited("crop --tile tile.ply --models models --out run"), 0);
  EXPECT_NE(read_text(dir + "/err.txt").find("lodrefine: error: "), std::string::npos) << read_text(dir + "/err.txt");
  EXPECT_FALSE(fs::exists(dir + "/run")) << "a half run folder is left";
  // convert: a model too big for the limit (many faces) after small ones.
  json doc = json::parse(box_city({"a", "b", "c"}));
  const json box = doc["CityObjects"]["c"]["geometry"][0]["boundaries"];
  json& big = doc["CityObjects"]["c"]["geometry"][0]["boundaries"];
  for (int k = 0; k < 800; ++k) big.insert(big.end(), box.begin(), box.end());  // ~100 KB of faces
  write_text(dir + "/city.json", doc.dump());
  EXPECT_NE(limited("convert --cityjson city.json --out-dir objs"), 0);
  EXPECT_FALSE(fs::exists(dir + "/objs")) << "half the models are left";
  EXPECT_TRUE(temp_leftovers(dir).empty());
  add_row("crop / convert hitting a full disk (file size limit)", "nothing half written left", 1);
}

// eval --svg-dir: one footprint file per building, whatever its id (the old per-character
// mapping gave `a b`, `a_b` and `a:b` one footprint_a_b.svg, written by two threads at once).
TEST(BadInputFiles, EvalFootprintsAreOneFilePerBuilding) {
  const std::string dir = temp_dir("eval_svg");
  for (const char* id : {"a b", "a_b", "a:b"}) {
    fs::create_directories(dir + "/run/" + id);
    write_text(dir + "/run/" + id + "/coarse.obj", valid_model());
    write_text(dir + "/run/" + id + "/refined.obj", valid_model());
    write_text(dir + "/run/" + id + "/cloud.ply", valid_cloud());
  }
  const CliRun r = run_cli("eval --dir " + dir + "/run --svg-dir " + dir + "/svg --jobs 3", dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  std::vector<std::string> footprints;
  for (const auto& f : files_in(dir + "/svg"))
    if (f.rfind("footprint_", 0) == 0) footprints.push_back(f);
  EXPECT_EQ(footprints.size(), 3u) << r.out;
  EXPECT_TRUE(temp_leftovers(dir).empty());
  add_row("eval --svg-dir: ids `a b`, `a_b`, `a:b`", "three footprint files", r.exit);
}

// ---------------------------------------------------------------------------------------------
// Memory running out (ulimit -v) while a CityGML file is read: the module's libraries initialise
// inside dlopen (an exception there ended in std::terminate, exit 134, with GnuTLS's own line),
// Xerces-C's panic called exit(-1) (exit 255, "Unknown reason"), and libcitygml / Xerces
// swallowed bad_alloc as "malformed XML" or a parse error (exit 2, the file blamed). Every
// limit around the least that works must give exit 0 with every building, or one line naming
// the file and saying what ran out, and nothing written.

namespace {

// `count` boxes as CityGML 2.0 buildings (lod2MultiSurface), ids b0, b1, ...
std::string box_citygml(int count) {
  std::string s =
      "<?xml version=\"1.0\"?>\n<CityModel xmlns=\"http://www.opengis.net/citygml/2.0\" "
      "xmlns:bldg=\"http://www.opengis.net/citygml/building/2.0\" xmlns:gml=\"http://www.opengis.net/gml\">\n";
  for (int b = 0; b < count; ++b) {
    s += "<cityObjectMember><bldg:Building gml:id=\"b" + std::to_string(b) +
         "\"><bldg:lod2MultiSurface><gml:MultiSurface>";
    for (const Quad& q : kQuads) {
      s += "<gml:surfaceMember><gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>";
      for (int k = 0; k <= 4; ++k) {
        const Vec3 v = kBox[q.v[k % 4]] + kOrigin + Vec3(20.0 * b, 0, 0);
        s += fmt(v.x()) + " " + fmt(v.y()) + " " + fmt(v.z()) + " ";
      }
      s += "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon></gml:surfaceMember>";
    }
    s += "</gml:MultiSurface></bldg:lod2MultiSurface></bldg:Building></cityObjectMember>\n";
  }
  return s + "</CityModel>\n";
}

// `lodrefine ARGS` with its address space limited to `kb` KB (stdout dropped).
CliRun run_limited(long kb, const std::string& args, const std::string& dir) {
  const std::string err = dir + "/.err";
  const std::string cmd =
      "timeout -k 5 120 sh -c " +
      shell_quote("ulimit -v " + std::to_string(kb) + "; exec " + shell_quote(LODREFINE_BINARY) + " " + args) +
      " >/dev/null 2>" + shell_quote(err);
  const int st = std::system(cmd.c_str());
  CliRun r;
  r.exit = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + (WIFSIGNALED(st) ? WTERMSIG(st) : 0);
  r.err = read_text(err);
  return r;
}

// Runs `lodrefine ARGS` under each address-space limit (KB). Where it fails for want of memory,
// it says one line, the file's name and that memory ran out reading it, exits 3 and leaves
// nothing at `out` (a file, or a folder with files). Returns how many limits failed.
int expect_named_out_of_memory(const std::vector<long>& limits_kb, const std::string& args, const std::string& file,
                               const std::string& out, const std::string& dir) {
  int failures = 0;
  for (long kb : limits_kb) {
    fs::remove_all(out);
    const CliRun r = run_limited(kb, args, dir);
    if (r.exit == 0) continue;  // enough memory after all
    ++failures;
    EXPECT_EQ(r.exit, 3) << kb << " KB: " << r.err;
    EXPECT_EQ(lines(r.err).size(), 1u) << kb << " KB: " << r.err;
    EXPECT_EQ(r.err, "lodrefine: error: " + file + ": out of memory reading the file\n") << kb << " KB";
    EXPECT_FALSE(fs::exists(out) && (!fs::is_directory(out) || !files_in(out).empty())) << kb << " KB";
  }
  return failures;
}

}  // namespace

TEST(BadInputMemory, CityGmlUnderAnAddressSpaceLimitFailsInOneLine) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "ASan reserves terabytes of address space: ulimit -v does not apply";
#endif
  const std::string dir = temp_dir("citygml_ulimit");
  const std::string model = dir + "/city.gml";
  constexpr int kBuildings = 3;
  write_text(model, box_citygml(kBuildings));
  auto convert_limited = [&](long kb) {
    fs::remove_all(dir + "/objs");
    return run_limited(kb, "convert --citygml " + shell_quote(model) + " --out-dir " + shell_quote(dir + "/objs"), dir);
  };
  // The least limit (in KB) that works, to within 64 KB. The address space jemalloc needs varies
  // by a few MB from run to run with where the kernel places its aligned mappings (measured: at
  // 2-6 MB above the least limit 1 run in 8 fails, none with address randomisation off), so a
  // limit is too small only when it fails twice, and the scan starts 8 MB below.
  auto works = [&](long kb) { return convert_limited(kb).exit == 0 || convert_limited(kb).exit == 0; };
  long lo = 16 * 1024, hi = 8 * 1024 * 1024;
  ASSERT_TRUE(works(hi)) << "8 GB of address space is not enough?";
  while (hi - lo > 64) {
    const long mid = (lo + hi) / 2;
    (works(mid) ? hi : lo) = mid;
  }
  int failures = 0;
  for (long kb = hi - 8000; kb <= hi + 200; kb += 200) {
    const CliRun r = convert_limited(kb);
    std::size_t written = 0;
    if (fs::exists(dir + "/objs")) written = files_in(dir + "/objs").size();
    if (r.exit == 0) {
      EXPECT_EQ(written, std::size_t(kBuildings)) << kb << " KB";
      continue;
    }
    ++failures;
    EXPECT_TRUE(r.exit >= 1 && r.exit <= 3) << kb << " KB: exit " << r.exit << ": " << r.err;
    EXPECT_EQ(lines(r.err).size(), 1u) << kb << " KB: " << r.err;
    EXPECT_EQ(r.err.rfind("lodrefine: error: " + model + ": ", 0), 0u) << kb << " KB: " << r.err;
    EXPECT_TRUE(r.err.find("out of memory") != std::string::npos ||
                r.err.find("failed to map segment") != std::string::npos ||  // dlopen's words for it
                r.err.find("Cannot allocate memory") != std::string::npos)
        << kb << " KB: what ran out is not said: " << r.err;
    EXPECT_EQ(written, 0u) << kb << " KB";
    EXPECT_TRUE(temp_leftovers(dir).empty()) << kb << " KB";
  }
  EXPECT_GT(failures, 10);  // the scan reached below the least limit
  add_row("convert: CityGML under ulimit -v (42 limits around the least)",
          "one line naming the file, or every building", failures > 0 ? 3 : 0);
}

// A CityJSON file too big for the limit: nlohmann::json's destructor allocates, so a parse
// running out of memory while an object grows threw again from a noexcept destructor
// (std::terminate, exit 134). Now one line naming the file, exit 3, nothing written.
TEST(BadInputMemory, CityJsonUnderAnAddressSpaceLimitFailsInOneLine) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "ASan reserves terabytes of address space: ulimit -v does not apply";
#endif
  const std::string dir = temp_dir("cityjson_ulimit");
  const std::string model = dir + "/big.city.json";
  json faces = json::array(), vertices = json::array();
  for (int i = 0; i < 300000; ++i) faces.push_back({{0, 1, 2}}), vertices.push_back({i, 2 * i, 3 * i});
  write_text(model, json{{"type", "CityJSON"},
                         {"version", "2.0"},
                         {"transform", {{"scale", {0.001, 0.001, 0.001}}, {"translate", {0, 0, 0}}}},
                         {"CityObjects",
                          {{"a",
                            {{"type", "Building"},
                             {"geometry", {{{"type", "MultiSurface"}, {"lod", "2.2"}, {"boundaries", faces}}}}}}}},
                         {"vertices", vertices}}
                        .dump());
  expect_named_out_of_memory({80000, 100000, 120000, 140000, 160000},
                             "convert --cityjson " + shell_quote(model) + " --out-dir " + shell_quote(dir + "/objs"),
                             model, dir + "/objs", dir);
  add_row("convert: 11 MB CityJSON under ulimit -v 80-160 MB", "one line naming the file, exit 3 (was an abort, 134)",
          3);
}

// A cloud too big for the limit: most of its memory is the points' vector, reserved from the
// header's count before a point is read; that reservation failed outside the reader's naming.
TEST(BadInputMemory, CloudUnderAnAddressSpaceLimitIsNamed) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "ASan reserves terabytes of address space: ulimit -v does not apply";
#endif
  const std::string dir = temp_dir("cloud_ulimit");
  const std::string cloud = dir + "/big.ply";
  PointCloud big;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  for (int i = 0; i < 6000000; ++i) big.points.emplace_back(u(rng), u(rng), u(rng));
  write_ply(cloud, big);
  big = PointCloud();
  const std::string model = std::string(LODREFINE_SOURCE_DIR) + "/data/samples/synth_gable_0001/coarse.obj";
  std::vector<long> limits;
  for (long kb = 90000; kb <= 200000; kb += 10000) limits.push_back(kb);
  const int failures = expect_named_out_of_memory(limits,
                                                  "refine --model " + shell_quote(model) + " --cloud " +
                                                      shell_quote(cloud) + " --out " + shell_quote(dir + "/r.obj"),
                                                  cloud, dir + "/r.obj", dir);
  EXPECT_GT(failures, 0);  // the scan reached below what the cloud needs
  fs::remove(cloud);
  add_row("refine: 144 MB PLY under ulimit -v 90-200 MB", "one line naming the cloud, exit 3", 3);
}

// Found by an attacker's review (2026-12-03): before its fix each input below crashed, hung,
// wrote outside --out, filled the memory, or was written back as garbage.

// std::regex recursed once per digit of a CityJSON 1.x CRS name: 50,000 digits overflowed the
// stack (SIGSEGV). Such a name is kept as it is.
TEST(BadInputAttack, HugeCrsNameIsKeptNotACrash) {
  const std::string dir = temp_dir("attack_crs");
  const std::string crs = "EPSG:" + std::string(50000, '1');
  json doc = json::parse(box_city({"a"}));
  doc["version"] = "1.1";
  doc["metadata"] = {{"referenceSystem", crs}};
  write_text(dir + "/city.json", doc.dump());
  write_text(dir + "/cloud.ply", valid_cloud());
  const CliRun r = run_cli(
      "refine --quiet --model " + dir + "/city.json --cloud " + dir + "/cloud.ply --out " + dir + "/out.city.json", dir,
      60);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(json::parse(read_text(dir + "/out.city.json"))["metadata"]["referenceSystem"], crs);
  add_row("CityJSON 1.1, CRS name of 50,000 digits", "refined; the name kept as it is", r.exit);
}

// convert opened its input without asking what it was: a FIFO blocked it, /dev/zero was read
// until the memory ran out. eval --dir did the same with a run folder's meta.json, report.json
// and FAILED marker.
TEST(BadInputAttack, FifosAndDevicesAreNeverRead) {
  const std::string dir = temp_dir("attack_fifo");
  ASSERT_EQ(::mkfifo((dir + "/fifo").c_str(), 0600), 0);
  for (const std::string& args :
       {"--cityjson " + dir + "/fifo", "--citygml " + dir + "/fifo", std::string("--cityjson /dev/zero")}) {
    const CliRun r = run_cli("convert " + args + " --out-dir " + dir + "/objs", dir, 30);
    expect_one_error_line(r, "not a regular file");
    EXPECT_LT(r.seconds, 5.0) << args;
  }
  const std::string b = dir + "/run/a";
  fs::create_directories(b);
  write_text(b + "/coarse.obj", valid_model());
  write_text(b + "/refined.obj", valid_model());
  write_text(b + "/truth.obj", valid_model());  // meta.json is read beside a truth
  write_text(b + "/cloud.ply", valid_cloud());
  for (const char* name : {"meta.json", "report.json"}) ASSERT_EQ(::mkfifo((b + "/" + name).c_str(), 0600), 0);
  fs::create_symlink("/dev/zero", b + "/FAILED");
  const CliRun r = run_cli("eval --quiet --dir " + dir + "/run --json " + dir + "/eval.json", dir, 30);
  EXPECT_LT(r.seconds, 10.0);
  EXPECT_NE(r.out.find("failed 1"), std::string::npos) << r.out << r.err;
  const json figures = json::parse(read_text(dir + "/eval.json"));
  EXPECT_EQ(figures["buildings"][0]["reason"], "failed (the FAILED marker is not a regular file)") << figures.dump();
  add_row("convert / eval --dir: FIFO or /dev/zero as an input file", "not read: refused, or the building failed", 2);
}

// With --out the --models folder, a building folder that is a symbolic link took crop's files
// wherever it pointed.
TEST(BadInputAttack, CropDoesNotWriteThroughASymlinkedBuildingFolder) {
  const std::string dir = temp_dir("attack_symlink");
  fs::create_directories(dir + "/run");
  fs::create_directories(dir + "/outside");
  write_text(dir + "/run/Y.obj", valid_model());
  fs::create_directory_symlink(dir + "/outside", dir + "/run/Y");
  write_text(dir + "/tile.ply", valid_cloud());
  const CliRun r =
      run_cli("crop --quiet --tile " + dir + "/tile.ply --models " + dir + "/run --out " + dir + "/run", dir);
  expect_one_error_line(r, "is a symbolic link");
  EXPECT_TRUE(files_in(dir + "/outside").empty());
  add_row("crop: a building folder in --out is a symlink", "refused; nothing written through it", r.exit);
}

// A transform.scale of 1e-15 wrapped the refined vertices to -9.2e18 (64-bit overflow) and the
// file was written with exit 0.
TEST(BadInputAttack, TransformScaleFinerThanANanometreIsRefused) {
  const std::string dir = temp_dir("attack_scale");
  json doc = json::parse(box_city({"a"}));
  doc["transform"]["scale"] = {1e-15, 1e-15, 1e-15};
  write_text(dir + "/city.json", doc.dump());
  write_text(dir + "/cloud.ply", valid_cloud());
  const CliRun r = run_cli(
      "refine --quiet --model " + dir + "/city.json --cloud " + dir + "/cloud.ply --out " + dir + "/out.city.json",
      dir);
  expect_one_error_line(r, "transform.scale has a factor below 1e-9 m");
  EXPECT_FALSE(fs::exists(dir + "/out.city.json"));
  add_row("CityJSON transform.scale 1e-15", "refused: the vertices written back would overflow", r.exit);
}

// A LAZ file of 150 KB announced 1e8 identical points: eval read them all and the city refine
// held them in its crops, until the memory ran out. Both are bounded now (--max-points,
// --max-crop-points), as the OBJ refine was.
TEST(BadInputAttack, PointLimitsBoundEvalAndTheCityRefine) {
  const std::string dir = temp_dir("attack_points");
  write_text(dir + "/model.obj", valid_model());
  write_text(dir + "/city.json", box_city({"a"}));
  write_text(dir + "/cloud.ply", valid_cloud());
  const std::string m = dir + "/model.obj", c = dir + "/cloud.ply";
  const CliRun e = run_cli("eval --original " + m + " --refined " + m + " --cloud " + c + " --max-points 10", dir);
  expect_one_error_line(e, "more than --max-points 10");
  const std::string b = dir + "/run/a";  // a run folder's clouds too
  fs::create_directories(b);
  for (const char* name : {"/coarse.obj", "/refined.obj"}) write_text(b + name, valid_model());
  write_text(b + "/cloud.ply", valid_cloud());
  const CliRun d = run_cli("eval --quiet --dir " + dir + "/run --max-points 10 --json " + dir + "/eval.json", dir);
  EXPECT_NE(d.out.find("failed 1"), std::string::npos) << d.out << d.err;
  EXPECT_NE(read_text(dir + "/eval.json").find("more than --max-points 10"), std::string::npos);
  const CliRun k =
      run_cli("crop --quiet --tile " + c + " --models " + dir + "/run --out " + dir + "/crops --max-points 10", dir);
  expect_one_error_line(k, "holds more than 10 points (--max-points)");
  EXPECT_FALSE(fs::exists(dir + "/crops"));
  const CliRun r = run_cli("refine --quiet --model " + dir + "/city.json --cloud " + c + " --out " + dir +
                               "/out.city.json --max-crop-points 10",
                           dir);
  expect_one_error_line(r, "hold more than 10 points (--max-crop-points)");
  EXPECT_FALSE(fs::exists(dir + "/out.city.json"));
  add_row("eval / city refine: more points than --max-points / --max-crop-points", "refused in one line", r.exit);
}

// The box with every edge cut into `pieces` collinear pieces (faces of 4 * pieces vertices).
std::string box_obj_with_collinear_vertices(int pieces) {
  std::string s = "o bldg_0001\n";
  int n = 0;
  for (const Quad& q : kQuads) {
    s += std::string("g ") + q.group + "\n";
    std::string face = "f";
    for (int e = 0; e < 4; ++e)
      for (int j = 0; j < pieces; ++j) {
        const Vec3 p = kOrigin + kBox[q.v[e]] + (kBox[q.v[(e + 1) % 4]] - kBox[q.v[e]]) * (double(j) / pieces);
        s += "v " + fmt(p.x()) + " " + fmt(p.y()) + " " + fmt(p.z()) + "\n";
        face += " " + std::to_string(++n);
      }
    s += face + "\n";
  }
  return s;
}

// A 1 MB OBJ whose faces hold thousands of collinear vertices made validation's
// self-intersection test (and eval's distances) run for minutes: such a model is no LoD2 building.
TEST(BadInputAttack, FacesOfThousandsOfVerticesAreRefusedAtOnce) {
  const std::string dir = temp_dir("attack_collinear");
  write_text(dir + "/model.obj", box_obj_with_collinear_vertices(300));
  write_text(dir + "/cloud.ply", valid_cloud());
  const std::string m = dir + "/model.obj";
  const CliRun r =
      run_cli("refine --model " + m + " --cloud " + dir + "/cloud.ply --out " + dir + "/out.obj", dir, 120);
  EXPECT_EQ(r.exit, 0) << r.err;
  EXPECT_NE(r.out.find("kept-invalid (face 0 has 1200 vertices, more than 1000"), std::string::npos) << r.out;
  EXPECT_LT(r.seconds, 10.0);
  const CliRun e = run_cli("eval --original " + m + " --refined " + m + " --cloud " + dir + "/cloud.ply", dir, 120);
  expect_one_error_line(e, "face 0 has 1200 vertices, more than 1000");
  EXPECT_LT(e.seconds, 10.0);
  add_row("OBJ whose faces hold 1,200 collinear vertices", "kept-invalid at once (eval: refused)", r.exit);
}

// Every error is one line whatever the input's bytes: a path, id or key quoted in a message with
// a newline or an escape code in it is shown escaped.
TEST(BadInputAttack, ErrorsQuotingControlCharactersStayOneLine) {
  const std::string dir = temp_dir("attack_lines");
  const std::string bad = dir + "/a\nlodrefine: error: injected\x1b[31m.obj";
  write_text(bad, "v 0 0 0\nnot obj\n");
  write_text(dir + "/cloud.ply", valid_cloud());
  for (const std::string& model : {bad, dir + "/missing\nline.obj"}) {
    const CliRun r = run_cli(
        "refine --model " + shell_quote(model) + " --cloud " + dir + "/cloud.ply --out " + dir + "/out.obj", dir);
    EXPECT_NE(r.exit, 0);
    EXPECT_EQ(lines(r.err).size(), 1u) << r.err;
    EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
  }
  add_row("a path holding a newline and an escape code", "one error line, escaped", 2);
}

// ---------------------------------------------------------------------------------------------
// Third pass (issue 36): gates that waved regressions through, outputs over a run's files, a CR
// in an outcome line.

namespace {

// A run folder of one building (the box, refined as itself) with its baseline written.
std::string run_with_baseline(const std::string& dir) {
  fs::create_directories(dir + "/run/a");
  for (const char* name : {"/coarse.obj", "/refined.obj"}) write_text(dir + "/run/a" + name, valid_model());
  write_text(dir + "/run/a/cloud.ply", valid_cloud());
  const CliRun w = run_cli("eval --quiet --dir " + dir + "/run --write-baseline " + dir + "/b.json", dir);
  EXPECT_EQ(w.exit, 0) << w.err;
  return dir + "/b.json";
}

}  // namespace

// CLI::Range lets NaN through (no comparison with it is true): `--tolerance nan` passed every
// regression. Every floating option of every command must be finite.
TEST(BadInputAttack, FloatingOptionsMustBeFinite) {
  const std::string dir = temp_dir("attack_nan");
  const std::string baseline = run_with_baseline(dir);
  for (const std::string value : {"nan", "NaN", "inf", "-inf", "1e400"}) {
    const CliRun r =
        run_cli("eval --quiet --dir " + dir + "/run --baseline " + baseline + " --tolerance " + value, dir);
    expect_one_error_line(r, "--tolerance");
    if (value.find_first_of("nN") == 0) {
      EXPECT_NE(r.err.find("must be a finite number"), std::string::npos) << r.err;
    }
  }
  write_text(dir + "/model.obj", valid_model());
  write_text(dir + "/cloud.ply", valid_cloud());
  const CliRun p = run_cli("refine --model " + dir + "/model.obj --cloud " + dir + "/cloud.ply --out " + dir +
                               "/out.obj --ransac-epsilon nan",
                           dir);
  expect_one_error_line(p, "--ransac-epsilon: must be a finite number, not nan");
  EXPECT_FALSE(fs::exists(dir + "/out.obj"));
  add_row("--tolerance nan, --ransac-epsilon nan (any floating option)", "refused in one line", p.exit);
}

// A baseline's counts are non-negative integers: -1 was read as 2^64 - 1, so a newly failed
// building passed. A value of the wrong kind is named in our words, not the JSON library's.
TEST(BadInputAttack, BaselineValuesOfTheWrongKindAreNamed) {
  const std::string dir = temp_dir("attack_baseline");
  const std::string baseline = run_with_baseline(dir);
  const json good = json::parse(read_text(baseline));
  const std::vector<std::tuple<std::string, json, std::string>> lies = {
      {"failed", -1, "\"failed\" must be a non-negative integer, not -1"},
      {"refined", -3, "\"refined\" must be a non-negative integer, not -3"},
      {"failed", "none", "\"failed\" must be a non-negative integer, not \"none\""},
      {"failed", 1.5, "\"failed\" must be a non-negative integer"},
      {"watertight_rate", json::array({1}), "\"watertight_rate\" must be a finite number, not [1]"},
      {"watertight_rate", 7, "\"watertight_rate\" must be a share from 0 to 1"},
      {"c2m_rmse", "x", "\"c2m_rmse\" must be a finite number"}};
  for (const auto& [key, value, says] : lies) {
    json b = good;
    b["pooled"][key] = value;
    write_text(dir + "/bad.json", b.dump());
    const CliRun r = run_cli("eval --quiet --dir " + dir + "/run --baseline " + dir + "/bad.json", dir);
    expect_one_error_line(r, says);
    EXPECT_EQ(r.err.find("json.exception"), std::string::npos) << r.err;
  }
  json b = good;
  b["buildings"][0]["facades_moved"] = -2;
  write_text(dir + "/bad.json", b.dump());
  expect_one_error_line(run_cli("eval --quiet --dir " + dir + "/run --baseline " + dir + "/bad.json", dir),
                        "building \"a\": \"facades_moved\" must be a non-negative integer");
  add_row("baseline with \"failed\": -1, \"none\", [1] ...", "refused, naming the key", 2);
}

// No output of `eval --dir` may be a file the run reads: `--json RUN/<id>/coarse.obj` replaced
// that building's model.
TEST(BadInputAttack, EvalOutputsNeverReplaceTheRunsFiles) {
  const std::string dir = temp_dir("attack_eval_run");
  run_with_baseline(dir);
  write_text(dir + "/run/a/report.json", "{}");
  for (const std::string option : {"--json", "--csv", "--html", "--junit", "--write-baseline"})
    for (const char* file : {"coarse.obj", "cloud.ply", "refined.obj", "report.json"}) {
      const std::string target = dir + "/run/a/" + file;
      const std::string before = read_text(target);
      const CliRun r = run_cli("eval --quiet --dir " + dir + "/run " + option + " " + target, dir);
      expect_one_error_line(r, option + " is the run's file; it would be overwritten");
      EXPECT_EQ(read_text(target), before) << option << " " << file;
    }
  add_row("eval --dir RUN --json RUN/<id>/coarse.obj (any output)", "refused before reading", 2);
}

// An outcome line is one line whatever the model's name holds: `o ok\rFAKE: refined` printed over
// the outcome in a terminal, and batch logs keep that line.
TEST(BadInputAttack, OutcomeLineEscapesCarriageReturns) {
  const std::string dir = temp_dir("attack_cr");
  std::string model = valid_model();
  model.replace(model.find("o bldg_0001"), 11, "o ok\rFAKE: refined (all good)");
  write_text(dir + "/model.obj", model);
  write_text(dir + "/cloud.ply", valid_cloud());
  const CliRun r =
      run_cli("refine --model " + dir + "/model.obj --cloud " + dir + "/cloud.ply --out " + dir + "/out.obj", dir);
  EXPECT_EQ(r.exit, 0) << r.err;
  EXPECT_EQ(r.out.find('\r'), std::string::npos) << r.out;
  EXPECT_EQ(r.out.rfind("ok\\rFAKE: refined (all good): ", 0), 0u) << r.out;
  add_row("OBJ name with a CR (`o ok\\rFAKE: refined`)", "escaped in the outcome line", r.exit);
}

// A baseline building's outcome and watertightness of the wrong kind were read as "failed" and
// false, so its regressions were never flagged: refused, naming the key.
TEST(BadInputAttack, BaselineBuildingValuesOfTheWrongKindAreNamed) {
  const std::string dir = temp_dir("attack_baseline_building");
  const std::string baseline = run_with_baseline(dir);
  const json good = json::parse(read_text(baseline));
  for (const auto& [key, value, says] : std::vector<std::tuple<std::string, json, std::string>>{
           {"outcome", json::array({"refined"}), "building \"a\": \"outcome\" must be a string, not [\"refined\"]"},
           {"watertight", 1, "building \"a\": \"watertight\" must be true or false, not 1"},
           {"reason", 7, "building \"a\": \"reason\" must be a string, not 7"}}) {
    json b = good;
    b["buildings"][0][key] = value;
    write_text(dir + "/bad.json", b.dump());
    expect_one_error_line(run_cli("eval --quiet --dir " + dir + "/run --baseline " + dir + "/bad.json", dir), says);
  }
  add_row("baseline building with \"outcome\": [\"refined\"], \"watertight\": 1", "refused, naming the key", 2);
}

// A run folder's report.json is the refine's, or anyone's: a reason of the wrong kind is a row's
// reason in our words (the JSON library's text reached the gate lines, the CSV and the JSON); an
// unknown report_version names it in at most 40 characters (3,000 made a 3,095-byte error line).
TEST(BadInputAttack, RunReportsOfTheWrongKindStayOurWords) {
  const std::string dir = temp_dir("attack_run_report");
  run_with_baseline(dir);
  write_text(dir + "/run/a/report.json", R"({"outcome":"kept","reason":5})");
  const CliRun r = run_cli("eval --quiet --dir " + dir + "/run --csv " + dir + "/t.csv", dir);
  EXPECT_EQ(r.exit, 0) << r.err;
  EXPECT_NE(read_text(dir + "/t.csv").find("report.json: \"\"reason\"\" is no text"), std::string::npos)
      << read_text(dir + "/t.csv");
  write_text(dir + "/run/a/report.json", R"({"outcome":"kept","seconds":5})");
  EXPECT_EQ(run_cli("eval --quiet --dir " + dir + "/run --csv " + dir + "/t.csv", dir).exit, 0);
  EXPECT_NE(read_text(dir + "/t.csv").find("unreadable report.json (a value of the wrong kind)"), std::string::npos)
      << read_text(dir + "/t.csv");
  EXPECT_EQ(read_text(dir + "/t.csv").find("json.exception"), std::string::npos);
  write_text(dir + "/run/a/report.json", "{\"report_version\":\"" + std::string(3000, '9') + "\"}");
  const CliRun v = run_cli("eval --quiet --dir " + dir + "/run", dir);
  expect_one_error_line(v, "is not one this lodrefine reads");
  EXPECT_LT(v.err.size(), 400u) << v.err.size();
  add_row("run folder report.json with \"reason\": 5 / a 3,000-character report_version", "our words, one short line",
          v.exit);
}

// With --out the --models folder, the hashed folder of `a b.obj` can be where the model
// `a_b--<hash>/coarse.obj` lies (that one then renamed): its model was replaced by the other's.
TEST(BadInputFiles, CropNeverWritesOverAnotherModel) {
  const std::string dir = temp_dir("crop_over_model");
  const std::string run = dir + "/run";
  fs::create_directories(run);
  write_text(run + "/a b.obj", valid_model());
  const std::string folder = safe_name("a b");
  ASSERT_NE(folder, "a b");
  fs::create_directories(run + "/" + folder);
  const std::string victim = "# the other building\n" + valid_model();
  write_text(run + "/" + folder + "/coarse.obj", victim);
  write_text(dir + "/tile.ply", valid_cloud());
  const CliRun r = run_cli("crop --quiet --tile " + dir + "/tile.ply --models " + run + " --out " + run, dir);
  expect_one_error_line(r, "would be overwritten by \"a b\"'s");
  EXPECT_EQ(read_text(run + "/" + folder + "/coarse.obj"), victim);
  EXPECT_FALSE(fs::exists(run + "/" + folder + "/cloud.ply"));
  add_row("crop --models R --out R where a hashed folder is another model's", "refused, nothing written", r.exit);
}
