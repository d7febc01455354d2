// Bad input to `lodrefine refine` beyond the one-building contract of test_bad_input_refine.cpp:
// names and paths that are no text, outputs that are inputs or cannot be written, devices and
// FIFOs, a cloud too big for the memory, faces of thousands of vertices, control characters in
// messages and outcome lines (issues 15 and 36, the attack review of 2026-12-03).
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "lodrefine/formats/ply.h"
#include "support/bad_input_fixtures.h"
#include "support/test_paths.h"

using namespace lodrefine;
using namespace lodrefine::bad_input;

// Issue 15, items 2, 13, 14 through the command line: untrusted names.
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

// An OBJ object name of 100,000 bytes, of bytes that are no UTF-8, or on a model of degenerate faces
// (its reason names the building too): refine's one result line stays short, and no raw byte of
// the name reaches the terminal. A plain name is shown as it is.
TEST(BadInputSecurity, AHostileObjectNameIsCutOnTheResultLine) {
  const std::string dir = temp_dir("hostile_name");
  write_text(dir + "/c.ply", valid_cloud());
  const std::string huge(100000, 'A');
  const std::string degenerate = "v 0 0 0\nv 0 0 0\nv 0 0 0\ng WallSurface\nf 1 2 3\n";
  for (const auto& [name, body] : {std::pair{huge, valid_model()}, std::pair{huge, degenerate},
                                   std::pair{std::string(200, '\xff'), valid_model()}}) {
    write_text(dir + "/m.obj", "o " + name + "\n" + body);
    fs::remove(dir + "/r.obj");
    const CliRun r = run_cli("refine --model " + shell_quote(dir + "/m.obj") + " --cloud " +
                                 shell_quote(dir + "/c.ply") + " --out " + shell_quote(dir + "/r.obj"),
                             dir);
    ASSERT_EQ(r.exit, 0) << r.err.substr(0, 300);
    ASSERT_EQ(lines(r.out).size(), 1u);
    EXPECT_LT(r.out.size(), 1000u) << r.out.substr(0, 300);  // the id twice, cut, on a degenerate model
    EXPECT_NE(r.out.find("bytes)"), std::string::npos) << r.out.substr(0, 300);
    EXPECT_EQ(r.out.find('\xff'), std::string::npos);
  }
  write_text(dir + "/m.obj", valid_model());
  fs::remove(dir + "/r.obj");
  const CliRun plain = run_cli("refine --model " + shell_quote(dir + "/m.obj") + " --cloud " +
                                   shell_quote(dir + "/c.ply") + " --out " + shell_quote(dir + "/r.obj"),
                               dir);
  EXPECT_EQ(plain.out.rfind("bldg_0001: ", 0), 0u) << plain.out;
}

// ---------------------------------------------------------------------------------------------
// Untrusted ids, paths and files (issue 15): outputs stay in the output folder, never replace an
// input or a file already there, temporaries are ours, and every building is accounted for.

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

// ---------------------------------------------------------------------------------------------
// Memory running out (ulimit -v): see test_bad_input_convert.cpp for the city files.

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
  const std::string model = test_paths::source_dir() + "/data/samples/synth_gable_0001/coarse.obj";
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

// ---------------------------------------------------------------------------------------------
// Found by an attacker's review (2026-12-03): before its fix each input below crashed, hung,
// wrote outside --out, filled the memory, or was written back as garbage.

namespace {

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

}  // namespace

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

// Third pass (issue 36).

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
  // No plain name: shown quoted, its CR escaped (line_id).
  EXPECT_EQ(r.out.rfind("\"ok\\rFAKE: refined (all good)\": ", 0), 0u) << r.out;
  add_row("OBJ name with a CR (`o ok\\rFAKE: refined`)", "escaped in the outcome line", r.exit);
}

// Fourth pass (issue 47).

// The options of a city file's refine were refused with an OBJ model for --html, --building and
// --lod, but --repair-all, --jobs and --max-crop-points were taken and ignored without a word:
// each is refused by name now, nothing written, and --help groups them under city files.
TEST(BadInputAttack, CityOnlyOptionsAreRefusedWithAnObjModel) {
  const std::string dir = temp_dir("attack_city_only");
  write_text(dir + "/model.obj", valid_model());
  write_text(dir + "/cloud.ply", valid_cloud());
  const std::string refine = "refine --model " + dir + "/model.obj --cloud " + dir + "/cloud.ply --out " + dir +
                             "/out.obj --report " + dir + "/out.json";
  for (const std::string& option : std::vector<std::string>{"--repair-all", "--jobs 2", "--max-crop-points 10",
                                                            "--html " + dir + "/p.html", "--building a", "--lod 2.2"}) {
    const CliRun r = run_cli(refine + " " + option, dir);
    expect_one_error_line(r, dir + "/model.obj: " + option.substr(0, option.find(' ')) + " (");
    EXPECT_NE(r.err.find(") applies to a city file as --model (CityJSON, CityJSONSeq, CityGML), not to an OBJ"),
              std::string::npos)
        << r.err;
    for (const char* out : {"/out.obj", "/out.json", "/p.html"}) EXPECT_FALSE(fs::exists(dir + out)) << option;
  }
  const CliRun help = run_cli("refine --help", dir);
  const std::size_t group = help.out.find("City files (a city file as --model; refused with an OBJ)");
  ASSERT_NE(group, std::string::npos) << help.out;
  for (const char* option : {"--repair-all", "--jobs", "--max-crop-points", "--html", "--building", "--lod"})
    EXPECT_GT(help.out.find(std::string("  ") + option, group), group) << option << "\n" << help.out;
  EXPECT_EQ(run_cli(refine, dir).exit, 0);
  add_row("refine an OBJ with --repair-all, --jobs or --max-crop-points", "refused by name, as --html", 2);
}

// A cloud folder left out the tiles it could not read without a word (issue 47): the run went
// on with a.ply and b.ply only, exit 0. Each such entry refuses the run in one line naming it,
// nothing written, for a city file and an OBJ alike; a file that is no cloud by name or content
// is skipped, on stdout and in the report's cloud.files with why.
TEST(BadInputAttack, RefineRefusesACloudFolderWithATileItCannotRead) {
  const std::string dir = temp_dir("attack_tiles_refine");
  write_text(dir + "/model.obj", valid_model());
  write_text(dir + "/city.json", box_city({"B"}));
  expect_bad_tiles_refused("refine --quiet --model " + dir + "/city.json --out " + dir + "/out.city.json --cloud ", dir,
                           {dir + "/out.city.json"});
  const CliRun r = expect_bad_tiles_refused(
      "refine --model " + dir + "/model.obj --out " + dir + "/out.obj --report " + dir + "/out.json --cloud ", dir,
      {dir + "/out.obj", dir + "/out.json"});
  const std::string tiles = dir + "/tiles";
  const std::string no_cloud = "not a PLY, LAS or LAZ cloud (its first bytes are neither 'ply' nor 'LASF')";
  EXPECT_EQ(
      r.out.rfind("skipped 1 entry of the cloud folders, no cloud files: " + tiles + "/notes.txt (" + no_cloud + ")\n",
                  0),
      0u)
      << r.out;
  const json files = json::parse(read_text(dir + "/out.json"))["cloud"]["files"];
  ASSERT_EQ(files.size(), 3u) << files.dump();
  EXPECT_EQ(files[0]["path"], tiles + "/a.ply");
  EXPECT_EQ(files[1]["path"], tiles + "/b.ply");
  EXPECT_EQ(files[2], json({{"path", tiles + "/notes.txt"}, {"skipped", no_cloud}}));
  add_row("refine --cloud tiles/ with a 0-byte, dangling, folder or truncated c.laz", "refused naming it", 2);
}

// A model refine wrote (its fins group after the solid) that is kept as read (kept-invalid:
// here a face of 1,001 vertices) lost its fins group: the fins came out among the solid's
// faces. Written as read, they keep their group.
TEST(BadInputFiles, AKeptInvalidModelKeepsItsFinsGroup) {
  const std::string dir = temp_dir("kept_invalid_fins");
  std::string extra = "g fins WallSurface\nv " + fmt(kOrigin.x()) + " " + fmt(kOrigin.y() - 0.4) + " 7\nv " +
                      fmt(kOrigin.x()) + " " + fmt(kOrigin.y() - 0.4) + " 8\nv " + fmt(kOrigin.x() + 1) + " " +
                      fmt(kOrigin.y() - 0.4) + " 8\nf 25 26 27\ng RoofSurface\n";
  std::string face = "f";
  for (int k = 0; k < 1001; ++k) {
    const double a = 2 * M_PI * k / 1001;
    extra += "v " + fmt(kOrigin.x() + 6 + 3 * std::cos(a)) + " " + fmt(kOrigin.y() + 4 + 3 * std::sin(a)) + " 3\n";
    face += " " + std::to_string(28 + k);
  }
  write_text(dir + "/m.obj", box_obj({0, 1, 2, 3, 4, 5}, extra + face + "\n"));
  write_text(dir + "/c.ply", valid_cloud());
  const CliRun r = run_cli("refine --model " + dir + "/m.obj --cloud " + dir + "/c.ply --out " + dir + "/r.obj", dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  EXPECT_NE(r.out.find("kept-invalid (face 7 has 1001 vertices"), std::string::npos) << r.out;
  const ObjModel written = read_obj_model(dir + "/r.obj");
  const ObjModel read = read_obj_model(dir + "/m.obj");
  ASSERT_EQ(written.fins.faces.size(), 1u) << "the fins group kept";
  EXPECT_EQ(written.fins.faces[0].sem, Semantic::Wall);
  EXPECT_EQ(written.solid.faces.size(), read.solid.faces.size());
  for (std::size_t i = 0; i < 3; ++i) EXPECT_LT((written.fins.vertices[i] - read.fins.vertices[i]).norm(), 1e-6);
  add_row("refine: a kept-invalid OBJ with a fins group", "written as read, fins in their group", r.exit);
}
