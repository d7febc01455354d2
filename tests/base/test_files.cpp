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
#include <set>

#include <sys/stat.h>
#include <unistd.h>

#include "lodrefine/base/files.h"
#include "lodrefine/formats/obj.h"
#include "lodrefine/formats/ply.h"
#include "support/io_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;
namespace fs = std::filesystem;

namespace {}  // namespace

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
  EXPECT_EQ(entries, 1u);  // no leftover .lodrefine-tmp-*
}

// An output that is a FIFO, a device or a socket (or a link to one: /dev/stdout) was renamed
// over: a reader waiting on the FIFO hung, and under root `--out /dev/full` or `--report
// /dev/stdout` replaced the device node with a regular file.
TEST(IoWrite, AtomicWriteRefusesToReplaceAFifoOrDevice) {
  const std::string dir = temp_path("special_outputs");
  fs::create_directories(dir);
  const std::string fifo = dir + "/pipe", link = dir + "/stdout";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  fs::create_symlink(fifo, link);
  for (const std::string& path : {fifo, link}) {
    try {
      write_file_atomic(path, "x");
      FAIL() << path << ": written";
    } catch (const std::runtime_error& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind("cannot write " + path + ": not a regular file", 0), 0u) << msg;
    }
  }
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_TRUE(fs::is_symlink(link));
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 2u);  // no temporary left
  // A link to a regular file is still replaced, never followed.
  const std::string target = dir + "/target", link2 = dir + "/link2";
  write_file_atomic(target, "kept");
  fs::create_symlink(target, link2);
  write_file_atomic(link2, "new");
  EXPECT_FALSE(fs::is_symlink(link2));
  std::ifstream in(target);
  std::string s;
  std::getline(in, s);
  EXPECT_EQ(s, "kept");
}

// ---------------------------------------------------------------------------------------------
// Untrusted names and paths (issue 15)

namespace {

bool only_safe_chars(const std::string& s) {
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
  });
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

TEST(SafeName, KeepsSafeIdsAndHashesTheRest) {
  EXPECT_EQ(safe_name("NL.IMBAG.Pand.0503100000031927-0"), "NL.IMBAG.Pand.0503100000031927-0");
  EXPECT_EQ(safe_name("bldg_0001"), "bldg_0001");
  for (const std::string& id : std::vector<std::string>{
           "$(touch PWNED)", "a';touch PWNED;'", "x;touch PWNED", "{10A31B7E-8FC2}", "..", ".", "", "-rf", ".hidden",
           "a/b c\\d:e\n", "caf\xc3\xa9", std::string(300, 'x'), std::string("nul\0byte", 8)}) {
    const std::string name = safe_name(id);
    EXPECT_NE(name, id);
    EXPECT_TRUE(is_safe_name(name)) << name;
    EXPECT_TRUE(only_safe_chars(name)) << name;
    EXPECT_LE(name.size(), kMaxSafeName) << name;
    EXPECT_TRUE(name[0] != '-' && name[0] != '.') << name;
    EXPECT_EQ(name.size() >= 14 ? name.substr(name.size() - 14, 2) : "", "--") << name << ": no hash suffix";
    EXPECT_EQ(safe_name(id), name) << "not deterministic";
    EXPECT_EQ(safe_name(name), name) << "not idempotent: convert's names would change in crop";
  }
  EXPECT_EQ(safe_name("a b").substr(0, 5), "a_b--");  // readable where it can be
  EXPECT_NE(safe_name("a b"), safe_name("a:b"));      // the hash tells them apart
  EXPECT_EQ(safe_name(std::string(100, 'y')), std::string(100, 'y'));
  EXPECT_NE(safe_name(std::string(101, 'y')), std::string(101, 'y'));
  EXPECT_FALSE(is_safe_name("a b"));
  EXPECT_FALSE(is_safe_name("-x"));
  EXPECT_FALSE(is_safe_name(".."));
  EXPECT_FALSE(is_safe_name(""));
}

TEST(SafeName, SafeNamesAreDistinctAlsoIgnoringCase) {
  // Ids that the old per-character mapping (or a case-folding file system) merged into one name.
  const std::vector<std::string> ids = {"a b",
                                        "a_b",
                                        "a:b",
                                        "a/b",
                                        "A_B",
                                        "A",
                                        "a",
                                        "a",
                                        "plots",
                                        "PLOTS",
                                        std::string(120, 'z') + "1",
                                        std::string(120, 'z') + "2",
                                        safe_name("a b"),
                                        "a_b--ffffffffffff"};
  SafeNames names({"plots"});
  std::set<std::string> seen;
  std::vector<std::string> given;
  for (const auto& id : ids) {
    given.push_back(names.add(id));
    EXPECT_TRUE(is_safe_name(given.back())) << given.back();
    EXPECT_TRUE(seen.insert(lower(given.back())).second) << id << " -> " << given.back();
  }
  EXPECT_EQ(given[1], "a_b");  // an id that is safe keeps its name when it is free
  EXPECT_EQ(given[5], "A");
  EXPECT_NE(lower(given[8]), "plots");  // reserved
  SafeNames again({"plots"});
  for (std::size_t i = 0; i < ids.size(); ++i) EXPECT_EQ(again.add(ids[i]), given[i]) << "not deterministic";
}

TEST(IoWrite, PlantedSymlinkAtATempNameIsNeverFollowed) {
  const fs::path dir = fs::path(temp_path("symlink_dir"));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path victim = dir / "victim.txt", target = dir / "out.txt";
  { std::ofstream(victim) << "precious\n"; }
  // The old temporary name (<path>.tmp.<pid>) and a link at the target itself.
  fs::create_symlink(victim, dir / ("out.txt.tmp." + std::to_string(::getpid())));
  write_file_atomic(target.string(), "new\n");
  fs::create_symlink(victim, dir / "link.txt");
  write_file_atomic((dir / "link.txt").string(), "replaced the link\n");
  std::ifstream in(victim);
  std::string s;
  std::getline(in, s);
  EXPECT_EQ(s, "precious");
  EXPECT_FALSE(fs::is_symlink(dir / "link.txt"));
  // Temporaries are ours by name and created exclusively.
  std::string path;
  const int fd = create_temp_file(dir.string(), target.string(), path);
  ASSERT_GE(fd, 0);
  ::close(fd);
  EXPECT_EQ(fs::path(path).filename().string().rfind(kTempPrefix, 0), 0u) << path;
  fs::remove_all(dir);
}

TEST(IoWrite, NonRegularFilesAreRefusedAndSameFilesRecognised) {
  EXPECT_THROW(require_regular_file("/dev/zero"), InputError);
  EXPECT_THROW(require_regular_file("/tmp"), InputError);
  EXPECT_EQ(sniff_file("/dev/zero"), FileKind::Other);
  const fs::path dir = fs::path(temp_path("same_dir"));
  fs::remove_all(dir);
  fs::create_directories(dir / "sub");
  const fs::path a = dir / "a.obj";
  { std::ofstream(a) << "x\n"; }
  require_regular_file(a.string());
  fs::create_symlink(a, dir / "link.obj");
  fs::create_hard_link(a, dir / "hard.obj");
  EXPECT_TRUE(same_file(a.string(), (dir / "link.obj").string()));
  EXPECT_TRUE(same_file(a.string(), (dir / "hard.obj").string()));
  EXPECT_TRUE(same_file(a.string(), (dir / "sub" / ".." / "a.obj").string()));
  EXPECT_FALSE(same_file(a.string(), (dir / "b.obj").string()));
  EXPECT_TRUE(same_file((dir / "new.obj").string(), (dir / "sub" / ".." / "new.obj").string()));  // neither exists yet
  EXPECT_FALSE(same_file((dir / "new.obj").string(), (dir / "sub" / "new.obj").string()));
  fs::remove_all(dir);
}

// A message line quoting untrusted text: control characters escaped (C0, DEL, C1 as its UTF-8
// bytes: U+009B is a CSI on some terminals), everything else, UTF-8 included, as it is.
TEST(EscapedLine, ControlCharactersEscapedTextKept) {
  EXPECT_EQ(escaped_line("a\nb\rc\td"), "a\\nb\\rc\\td");
  EXPECT_EQ(escaped_line("x\x1b[31my\x7f"), "x\\x1b[31my\\x7f");
  EXPECT_EQ(escaped_line("csi \xc2\x9b"
                         "2J"),
            "csi \\xc2\\x9b2J");
  EXPECT_EQ(escaped_line("Größe 東京 \xc2\xa0nbsp"), "Größe 東京 \xc2\xa0nbsp");
  EXPECT_EQ(escaped_line(std::string("nul\0end", 7)), "nul\\x00end");
}

// The outputs of one run (issue 47): a folder below the root that is a symbolic link is refused
// (a planted `truth -> /elsewhere` took synth's files there), and a run that does not finish
// removes the files and folders it created, never one that was there before.
TEST(OutputTree, RefusesLinkedFoldersAndRemovesOnlyWhatItCreated) {
  const std::string root = temp_path("output_tree");
  fs::remove_all(root);
  fs::create_directories(root + "/old");
  write_file_atomic(root + "/old/keep.txt", "keep");
  fs::create_directories(root + "/elsewhere");
  fs::create_directory_symlink(root + "/elsewhere", root + "/old/linked");
  {
    OutputTree tree(root + "/");
    tree.folder("new/deeper");
    write_file_atomic(tree.file("new/deeper/x.txt"), "x");
    write_file_atomic(tree.file("old/keep.txt"), "replaced");
    write_file_atomic(tree.file("old/y.txt"), "y");
    EXPECT_TRUE(fs::exists(root + "/new/deeper/x.txt"));
    for (const std::string rel : {"old/linked", "old/linked/sub"}) {
      EXPECT_THROW(tree.folder(rel), InputError) << rel;
      EXPECT_THROW(tree.file(rel + "/z.txt"), InputError) << rel;
    }
    try {
      tree.check_folder("old/linked");
      ADD_FAILURE() << "a linked folder was taken";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()),
                root + "/old/linked: is a symbolic link; outputs are written only inside " + root + "/");
    }
    EXPECT_THROW(tree.folder("old/keep.txt"), InputError);
    EXPECT_THROW(tree.file("../x.txt"), std::logic_error);
  }  // not kept
  EXPECT_FALSE(fs::exists(root + "/new"));
  EXPECT_FALSE(fs::exists(root + "/old/y.txt"));
  EXPECT_EQ(read_file(root + "/old/keep.txt"), "replaced") << "replaced, not removed: it was there before";
  EXPECT_TRUE(fs::is_empty(root + "/elsewhere"));
  {
    OutputTree tree(root + "/made/here");
    tree.folder("a");
    write_file_atomic(tree.file("a/x.txt"), "x");
  }
  EXPECT_FALSE(fs::exists(root + "/made")) << "the root's missing parents too";
  {
    OutputTree tree(root + "/made");
    tree.folder("a");
    write_file_atomic(tree.file("a/x.txt"), "x");
    tree.keep();
  }
  EXPECT_TRUE(fs::exists(root + "/made/a/x.txt"));
  fs::remove_all(root);
}

// A 100 kB id quoted whole gave a 100 kB message line: cut at kMaxShownId bytes, at a
// character's start (a cut UTF-8 character would show as U+FFFD), its size said.
TEST(ShownId, QuotesShortIdsWholeAndCutsLongOnes) {
  EXPECT_EQ(shown_id("B 1"), "\"B 1\"");
  EXPECT_EQ(shown_id("a\nb"), "\"a\\nb\"");
  EXPECT_EQ(shown_id(std::string(kMaxShownId, 'a')), "\"" + std::string(kMaxShownId, 'a') + "\"");
  const std::string huge(100000, 'x');
  EXPECT_EQ(shown_id(huge), "\"" + std::string(kMaxShownId, 'x') + "...\" (100000 bytes)");
  const std::string accents = std::string(kMaxShownId - 1, 'a') + "\xc3\xa9" + "tail";  // é across the cut
  EXPECT_EQ(shown_id(accents),
            "\"" + std::string(kMaxShownId - 1, 'a') + "...\" (" + std::to_string(accents.size()) + " bytes)");
  const std::string controls(100000, '\x01');  // each shown as \u0001: still bounded
  EXPECT_LT(shown_id(controls).size(), 6 * kMaxShownId + 40);
}
