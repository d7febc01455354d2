// The CityGML reader's module (src/formats/citygml_module.h): libcitygml and what it brings are no
// NEEDED entry of the executable; the module is found beside the executable or in the installed
// layout only (never through LD_LIBRARY_PATH or the current folder); without it, CityGML input
// is one line and a non-zero exit, with nothing written, while the other formats still work.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "support/cli_fixtures.h"
#include "support/test_paths.h"

namespace fs = std::filesystem;
using cli_fixtures::Cli;
using cli_fixtures::slurp;

namespace {

const std::string kSource = test_paths::source_dir();
const std::string kCityGml = kSource + "/tests/fuzz/corpus/fuzz_citygml/thematic.gml";      // building "t"
const std::string kCityJson = kSource + "/tests/fuzz/corpus/fuzz_cityjson/cube.city.json";  // one building
const fs::path kBuildDir = fs::path(test_paths::lodrefine_binary()).parent_path();

// The shared libraries `readelf -d` lists as NEEDED by `file` (nullopt without readelf).
std::optional<std::vector<std::string>> needed_libraries(const std::string& file) {
  if (std::system("command -v readelf >/dev/null 2>&1") != 0) return std::nullopt;
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(::popen(("readelf -d '" + file + "'").c_str(), "r"), ::pclose);
  if (!pipe) return std::nullopt;
  std::vector<std::string> libs;
  char line[1024];
  while (std::fgets(line, sizeof line, pipe.get())) {
    const std::string s = line;
    const auto open = s.find("(NEEDED)"), lib = s.find('[');
    if (open != std::string::npos && lib != std::string::npos) libs.push_back(s.substr(lib + 1, s.find(']') - lib - 1));
  }
  return libs;
}

// Runs `exe args` with stdout/stderr captured under `dir` (`env` is put before the command).
Cli run(const std::string& exe, const std::string& args, const std::string& dir, const std::string& env = "") {
  const std::string out = dir + "/.out", err = dir + "/.err";
  const int st = std::system((env + " '" + exe + "' " + args + " >" + out + " 2>" + err).c_str());
  Cli r;
  r.exit = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

// A copy of the lodrefine executable alone in <dir>/bin.
std::string lone_executable(const std::string& dir) {
  fs::create_directories(dir + "/bin");
  const std::string exe = dir + "/bin/lodrefine";
  fs::copy_file(test_paths::lodrefine_binary(), exe, fs::copy_options::overwrite_existing);
  return exe;
}

bool is_one_error_line(const std::string& err) {
  return err.rfind("lodrefine: error: ", 0) == 0 && err.find('\n') == err.size() - 1;
}

}  // namespace

TEST(CityGmlModule, ExecutablesNeedNoCityGmlXercesOrGdal) {
  for (const std::string& file : {test_paths::lodrefine_binary(), fs::read_symlink("/proc/self/exe").string()}) {
    const auto libs = needed_libraries(file);
    if (!libs) GTEST_SKIP() << "readelf is not installed";
    ASSERT_FALSE(libs->empty()) << file;  // readelf read it: libc at least
    for (const std::string& lib : *libs)
      for (const char* heavy : {"libcitygml", "libgdal", "libxerces", "libGLU", "libGL."})
        EXPECT_EQ(lib.find(heavy), std::string::npos) << file << " needs " << lib;
  }
  // The module is what needs libcitygml.
  const auto module_libs = needed_libraries((kBuildDir / "lodrefine_citygml.so").string());
  ASSERT_TRUE(module_libs);
  EXPECT_NE(std::find_if(module_libs->begin(), module_libs->end(),
                         [](const std::string& l) { return l.rfind("libcitygml", 0) == 0; }),
            module_libs->end());
}

TEST(CityGmlModule, MissingModuleIsOneLineAndWritesNothing) {
  const std::string dir = cli_fixtures::test_dir("lodrefine_citygml_module");
  const std::string exe = lone_executable(dir);
  // Neither LD_LIBRARY_PATH nor the current folder brings the build tree's module in.
  const std::string env = "cd '" + kBuildDir.string() + "' && LD_LIBRARY_PATH='" + kBuildDir.string() + "'";
  const Cli c = run(exe, "convert --citygml '" + kCityGml + "' --out-dir '" + dir + "/out'", dir, env);
  EXPECT_EQ(c.exit, 2);  // unreadable input (README)
  EXPECT_TRUE(is_one_error_line(c.err)) << c.err;
  EXPECT_NE(c.err.find("CityGML input is unavailable"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find(dir + "/bin/lodrefine_citygml.so"), std::string::npos) << c.err;  // the module's path
  EXPECT_FALSE(fs::exists(dir + "/out"));

  const Cli r = run(exe,
                    "refine --model '" + kCityGml + "' --cloud '" + kSource +
                        "/data/samples/synth_gable_0001/cloud.ply' --out '" + dir + "/refined.json'",
                    dir, env);
  EXPECT_EQ(r.exit, 2);
  EXPECT_TRUE(is_one_error_line(r.err)) << r.err;
  EXPECT_NE(r.err.find("CityGML input is unavailable"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/refined.json"));

  // The other formats do not need the module.
  const Cli j = run(exe, "convert --cityjson '" + kCityJson + "' --out-dir '" + dir + "/json'", dir);
  EXPECT_EQ(j.exit, 0) << j.err;
  EXPECT_EQ(std::distance(fs::directory_iterator(dir + "/json"), fs::directory_iterator()), 1);
  const std::string sample = kSource + "/data/samples/synth_gable_0001/";
  const Cli o =
      run(exe, "refine --model '" + sample + "coarse.obj' --cloud '" + sample + "cloud.ply' --out '" + dir + "/r.obj'",
          dir);
  EXPECT_EQ(o.exit, 0) << o.err;
  EXPECT_TRUE(fs::exists(dir + "/r.obj"));
}

TEST(CityGmlModule, ABrokenModuleIsOneLineNamingIt) {
  const std::string dir = cli_fixtures::test_dir("lodrefine_citygml_module");
  const std::string exe = lone_executable(dir);
  std::ofstream(dir + "/bin/lodrefine_citygml.so") << "not an ELF file\n";
  const Cli c = run(exe, "convert --citygml '" + kCityGml + "' --out-dir '" + dir + "/out'", dir);
  EXPECT_EQ(c.exit, 2);  // unreadable input (README)
  EXPECT_TRUE(is_one_error_line(c.err)) << c.err;
  EXPECT_NE(c.err.find("CityGML input is unavailable: cannot load " + dir + "/bin/lodrefine_citygml.so"),
            std::string::npos)
      << c.err;
  EXPECT_FALSE(fs::exists(dir + "/out"));
}

TEST(CityGmlModule, InstalledLayoutIsFound) {
  const std::string dir = cli_fixtures::test_dir("lodrefine_citygml_module");
  const std::string exe = lone_executable(dir);
  const fs::path module_dir = (fs::path(dir) / "bin" / LODREFINE_CITYGML_MODULE_RELDIR).lexically_normal();
  fs::create_directories(module_dir);
  fs::copy_file(kBuildDir / "lodrefine_citygml.so", module_dir / "lodrefine_citygml.so",
                fs::copy_options::overwrite_existing);
  const Cli c = run(exe, "convert --citygml '" + kCityGml + "' --out-dir '" + dir + "/out'", dir);
  EXPECT_EQ(c.exit, 0) << c.err;
  EXPECT_NE(c.out.find("t.obj <- \"t\""), std::string::npos) << c.out;
  EXPECT_TRUE(fs::exists(dir + "/out/t.obj"));
}
