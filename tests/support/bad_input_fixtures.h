// The bad-input suites (tests/app/test_bad_input_*.cpp, tests/refine/test_selection_bad_input.cpp):
// the box model and its wall scan as files, running the binary under a time limit, checking
// what it left behind, and the table of cases. Each case adds a row "| input | what lodrefine
// says | exit |"; a test binary run as one process (lodrefine_app_tests
// --gtest_filter='BadInput*') prints the whole table at the end.
#pragma once
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include <nlohmann/json.hpp>

#include "lodrefine/core/params.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/formats/obj.h"
#include "support/ply_fixtures.h"
#include "support/test_paths.h"

namespace lodrefine::bad_input {

namespace fs = std::filesystem;
using json = nlohmann::json;

// Validation at the parameter table's planarity tolerance.
inline const double kPlanarity = RefineConfig{}.repair.planarity_tolerance;

inline const Vec3 kOrigin(85000.0, 447000.0, 0.0);

// ---------------------------------------------------------------------------------------------
// Files

inline std::string temp_dir(const std::string& name) {
  const fs::path dir = fs::path(testing::TempDir()) / ("lodrefine_bad_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

inline void write_text(const std::string& path, const std::string& content) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << content;
  ASSERT_TRUE(out.good()) << path;
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4f", v);
  return buf;
}

// The coarse model: a 12 x 8 x 7 m box soup (one polygon per face, vertices repeated, CityGML
// groups), georeferenced, with the front wall 0.4 m too far out (y = -0.4 instead of 0).
inline const Vec3 kBox[8] = {{0, -0.4, 0}, {12, -0.4, 0}, {12, 8, 0}, {0, 8, 0},
                             {0, -0.4, 7}, {12, -0.4, 7}, {12, 8, 7}, {0, 8, 7}};
struct Quad {
  int v[4];
  const char* group;
};
inline const Quad kQuads[6] = {{{0, 3, 2, 1}, "GroundSurface"}, {{4, 5, 6, 7}, "RoofSurface"},
                               {{0, 1, 5, 4}, "WallSurface"},   {{1, 2, 6, 5}, "WallSurface"},
                               {{2, 3, 7, 6}, "WallSurface"},   {{3, 0, 4, 7}, "WallSurface"}};

// OBJ text of the listed faces of the box (each face its own 4 vertices).
inline std::string box_obj(const std::vector<int>& faces = {0, 1, 2, 3, 4, 5}, const std::string& extra = "") {
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
inline std::vector<Vec3> wall_scan(unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<Vec3> pts;
  for (double x = 0.5; x <= 11.5; x += 0.05)
    for (double z = 0.2; z <= 5.0; z += 0.05) pts.push_back(Vec3(x, noise(rng), z) + kOrigin);
  for (double x = 0.5; x <= 11.5; x += 0.1)
    for (double y = -6.0; y < -0.3; y += 0.1) pts.push_back(Vec3(x, y, noise(rng)) + kOrigin);
  return pts;
}

inline std::string ply_header(const std::string& format, std::uint64_t count, const std::string& type = "double") {
  return "ply\nformat " + format + " 1.0\ncomment test\nelement vertex " + std::to_string(count) + "\nproperty " +
         type + " x\nproperty " + type + " y\nproperty " + type + " z\nend_header\n";
}

inline std::string ply_binary(const std::vector<Vec3>& pts, bool big_endian = false) {
  std::string s = ply_header(big_endian ? "binary_big_endian" : "binary_little_endian", pts.size());
  for (const auto& p : pts) put(s, p.x(), big_endian), put(s, p.y(), big_endian), put(s, p.z(), big_endian);
  return s;
}

inline std::string ply_ascii(const std::vector<Vec3>& pts) {
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

inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Runs the binary under `timeout`: a hang (exit 124, or 137 after the KILL grace) fails the
// case instead of the whole suite, and stops a runaway process before it eats the machine.
inline CliRun run_cli(const std::string& args, const std::string& dir, double timeout_seconds = 300) {
  const std::string out = dir + "/.stdout", err = dir + "/.stderr";
  const std::string cmd = "timeout -k 5 " + std::to_string(int(std::ceil(timeout_seconds))) + " " +
                          shell_quote(test_paths::lodrefine_binary()) + " " + args + " >" + shell_quote(out) + " 2>" +
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

inline std::vector<std::string> lines(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string l; std::getline(ss, l);) out.push_back(l);
  return out;
}

// Files left in `dir` that look like an interrupted atomic write (".lodrefine-tmp-*", or an old
// "<name>.tmp.<pid>").
inline std::vector<std::string> temp_leftovers(const std::string& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : fs::recursive_directory_iterator(dir, ec))
    if (e.path().filename().string().find(".tmp") != std::string::npos ||
        e.path().filename().string().find("lodrefine-tmp") != std::string::npos)
      out.push_back(e.path().string());
  return out;
}

// The written model, checked by the project's own validator; empty string when valid.
inline std::string output_problem(const std::string& path) {
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
inline std::vector<Row>& table() {
  static std::vector<Row> rows;
  return rows;
}

inline std::string cell(std::string s) {
  for (auto& c : s)
    if (c == '|' || c == '\n') c = c == '|' ? '/' : ' ';
  return s;
}

inline void add_row(const std::string& input, const std::string& says, int exit) {
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
inline const testing::Environment* const kTablePrinter = testing::AddGlobalTestEnvironment(new TablePrinter);

inline std::string valid_model() { return box_obj(); }
inline std::string valid_cloud() { return ply_binary(wall_scan()); }

inline std::string first_line(const std::string& s) { return s.substr(0, s.find('\n')); }

// ---------------------------------------------------------------------------------------------
// City files and run folders

// A CityJSON 2.0 file: each id a copy of the box (MultiSurface, LoD 2.2); ids in `flat` get a
// geometry without any usable surface (rings of one repeated vertex).
inline std::string box_city(const std::vector<std::string>& ids, const std::vector<std::string>& flat = {}) {
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

// ---------------------------------------------------------------------------------------------
// Cloud folders (issue 47)

// A survey folder `<dir>/<name>`, made anew: a.ply and b.ply, the wall scan in two halves.
inline std::string survey_folder(const std::string& dir, const std::string& name) {
  const std::string tiles = dir + "/" + name;
  fs::remove_all(tiles);
  fs::create_directories(tiles);
  const std::vector<Vec3> scan = wall_scan();
  const auto half = scan.begin() + std::ptrdiff_t(scan.size() / 2);
  write_text(tiles + "/a.ply", ply_binary(std::vector<Vec3>(scan.begin(), half)));
  write_text(tiles + "/b.ply", ply_binary(std::vector<Vec3>(half, scan.end())));
  return tiles;
}

// An entry named as a cloud file among the tiles that is none, and what a refusal says of it.
struct BadTile {
  std::string name, says;
  void (*make)(const std::string& path);
};
inline std::vector<BadTile> bad_tiles() {
  return {{"c.laz", "c.laz: empty (0 bytes); a cloud file of the", [](const std::string& p) { write_text(p, ""); }},
          {"d.laz", "d.laz: a link to nothing", [](const std::string& p) { fs::create_symlink(p + ".gone", p); }},
          {"x.laz", "x.laz: a folder", [](const std::string& p) { fs::create_directory(p); }},
          // A LAS header cut after its signature: the reader's line, before any point is read.
          {"t.las", "t.las: ", [](const std::string& p) { write_text(p, "LASF" + std::string(40, '\0')); }}};
}

// A survey folder holding one bad tile beside a.ply and b.ply.
inline std::string survey_folder_with(const std::string& dir, const BadTile& bad) {
  const std::string tiles = survey_folder(dir, "tiles_" + bad.name);
  bad.make(tiles + "/" + bad.name);
  return tiles;
}

inline std::vector<std::string> files_in(const std::string& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

inline void expect_one_error_line(const CliRun& r, const std::string& says) {
  EXPECT_EQ(r.exit, 2) << r.err;
  EXPECT_EQ(lines(r.err).size(), 1u) << r.err;
  EXPECT_EQ(r.err.rfind("lodrefine: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
}

// Runs `command` + a survey folder holding each bad tile: refused in one line naming the tile,
// nothing at any of `written`. Then + a survey folder with a note beside the tiles: the run goes
// on and says on stdout it skipped the note. Returns that run (the folder: `<dir>/tiles`).
inline CliRun expect_bad_tiles_refused(const std::string& command, const std::string& dir,
                                       const std::vector<std::string>& written) {
  for (const BadTile& bad : bad_tiles()) {
    const std::string tiles = survey_folder_with(dir, bad);
    expect_one_error_line(run_cli(command + tiles, dir), tiles + "/" + bad.says);
    for (const std::string& path : written) EXPECT_FALSE(fs::exists(path)) << bad.name << ": " << path;
  }
  const std::string tiles = survey_folder(dir, "tiles");
  write_text(tiles + "/notes.txt", "drive 1, 2026-11-30\n");
  const CliRun r = run_cli(command + tiles, dir);
  EXPECT_EQ(r.exit, 0) << r.err;
  EXPECT_NE(r.out.find("skipped 1 entry of the cloud folders, no cloud files: " + tiles + "/notes.txt (not a PLY"),
            std::string::npos)
      << r.out;
  return r;
}

// `lodrefine ARGS` with its address space limited to `kb` KB (stdout dropped).
inline CliRun run_limited(long kb, const std::string& args, const std::string& dir) {
  const std::string err = dir + "/.err";
  const std::string cmd = "timeout -k 5 120 sh -c " +
                          shell_quote("ulimit -v " + std::to_string(kb) + "; exec " +
                                      shell_quote(test_paths::lodrefine_binary()) + " " + args) +
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
inline int expect_named_out_of_memory(const std::vector<long>& limits_kb, const std::string& args,
                                      const std::string& file, const std::string& out, const std::string& dir) {
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

}  // namespace lodrefine::bad_input
