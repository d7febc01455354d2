// Atomic writes: a missing directory is one error line and no file; a failed write leaves no temp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "lodrefine/io/files.h"
#include "lodrefine/io/obj.h"
#include "lodrefine/io/ply.h"
#include "support/io_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;
namespace fs = std::filesystem;

namespace {

}  // namespace

TEST(IoWrite, MissingDirectoryGivesOneLineErrorAndNoFile) {
  const std::string dir = temp_path("no_such_dir");
  const std::string path = dir + "/model.obj";
  Mesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.faces = {{{0, 1, 2}, Semantic::Roof, 0}};
  try {
    write_obj(path, m);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind("cannot write " + path + ": ", 0), 0u) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos);
  }
  EXPECT_FALSE(fs::exists(dir));
}

TEST(IoWrite, AtomicWriteReplacesAndLeavesNoTempOnFailure) {
  const std::string path = temp_path("t.txt");
  write_file_atomic(path, "old");
  write_file_atomic(path, "new content");
  std::ifstream in(path);
  std::string s;
  std::getline(in, s);
  EXPECT_EQ(s, "new content");
  Mesh bad;
  bad.vertices = {{0, 0, 0}};
  bad.faces = {{{0, 1, 2}, Semantic::Wall, 0}};
  EXPECT_THROW(write_obj(path, bad), std::runtime_error);  // the old file survives a failed write
  std::ifstream again(path);
  std::getline(again, s);
  EXPECT_EQ(s, "new content");
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(fs::path(path).parent_path())) ++entries;
  EXPECT_EQ(entries, 1u);  // no leftover .tmp.<pid>
}
