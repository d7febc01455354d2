// A cloud in several files (issue 39): the --cloud / --tile values expanded into files in a fixed
// order (cloud_files), and the files read as one cloud: the same points in the same order as one
// file holding them, each file accounted for, the point bounds over all of them.
#include <gtest/gtest.h>

#include "support/io_fixtures.h"

#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <utility>

#include "lodrefine/formats/cloud.h"
#include "lodrefine/formats/las.h"
#include "lodrefine/formats/ply.h"

using namespace lodrefine;
namespace fs = std::filesystem;

namespace {

using fixtures::temp_path;

// `n` georeferenced points on a millimetre grid (the LAS scale: they read back exactly) from x0.
PointCloud points_from(double x0, int n) {
  PointCloud c;
  for (int i = 0; i < n; ++i) c.points.push_back(Vec3(x0 + 0.125 * i, 447987.654 - 0.25 * i, 1.234 + 0.001 * i));
  return c;
}

// The test's folder (temp_path's), created.
std::string folder(const std::string& name) {
  const std::string dir = temp_path(name);
  fs::create_directories(dir);
  return dir;
}

void write_text(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

// The InputError message of fn(), or "" when it throws none.
template <class F>
std::string refusal(F&& fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(CloudFiles, FolderGivesItsCloudsByNameAndSkipsTheRest) {
  const std::string dir = folder("tiles");
  // Created out of name order; names that sort differently as numbers and as bytes.
  for (const char* name : {"b.ply", "9.ply", "10.ply"}) write_ply(dir + "/" + name, points_from(85000.0, 3));
  write_las(dir + "/a.las", points_from(85010.0, 3), {}, {});
  write_text(dir + "/notes.txt", "tile index\n");
  write_text(dir + "/model.obj", "v 0 0 0\n");
  write_text(dir + "/city.json", "{\"type\": \"CityJSON\"}");
  write_text(dir + "/.lodrefine-tmp-x1", "ply\nformat ascii 1.0\n");  // a crop being written
  fs::create_directories(dir + "/sub");
  write_ply(dir + "/sub/deeper.ply", points_from(85000.0, 3));  // subfolders are not read
  const std::string lone = temp_path("lone.ply");
  write_ply(lone, points_from(85020.0, 3));
  const std::vector<std::string> expected = {lone, dir + "/10.ply", dir + "/9.ply", dir + "/a.las", dir + "/b.ply"};
  EXPECT_EQ(cloud_files({lone, dir}), expected);
  // A folder named with a trailing slash lists the same files.
  EXPECT_EQ(cloud_files({dir + "/"}), std::vector<std::string>(expected.begin() + 1, expected.end()));
  EXPECT_EQ(cloud_files({dir, lone}).back(), lone);  // values in the order given
  // A link to a cloud elsewhere is a cloud of the folder.
  fs::create_symlink(lone, dir + "/c.ply");
  EXPECT_EQ(cloud_files({dir}).back(), dir + "/c.ply");
  // What was skipped, and why, by path: a file neither named nor holding a cloud, a subfolder, a
  // link to nothing whose name says no cloud (an editor's lock), a temporary.
  fs::create_symlink(dir + "/gone", dir + "/.#lock");
  std::vector<SkippedEntry> skipped;
  cloud_files({dir}, "--cloud", &skipped);
  const std::string no_cloud = "not a PLY, LAS or LAZ cloud (its first bytes are neither 'ply' nor 'LASF')";
  const std::vector<std::pair<std::string, std::string>> expected_skips = {
      {dir + "/.#lock", "a link to nothing (its target does not exist)"},
      {dir + "/.lodrefine-tmp-x1", "a lodrefine temporary (a file being written)"},
      {dir + "/city.json", "not a PLY or LAS point cloud: the file is JSON (a CityJSON model?)"},
      {dir + "/model.obj", no_cloud},
      {dir + "/notes.txt", no_cloud},
      {dir + "/sub", "a folder (a folder's subfolders are not read)"}};
  ASSERT_EQ(skipped.size(), expected_skips.size());
  for (std::size_t i = 0; i < skipped.size(); ++i)
    EXPECT_EQ(std::make_pair(skipped[i].path, skipped[i].reason), expected_skips[i]);
  EXPECT_EQ(skipped_entries_text(skipped), "skipped 6 entries of the cloud folders, no cloud files: " + dir +
                                               "/.#lock (a link to nothing (its target does not exist)), " + dir +
                                               "/.lodrefine-tmp-x1 (a lodrefine temporary (a file being written)), " +
                                               dir + "/city.json (" + expected_skips[2].second + "), " + dir +
                                               "/model.obj (" + no_cloud + "), " + dir + "/notes.txt (" + no_cloud +
                                               ") and 1 more");
  EXPECT_EQ(skipped_entries_text({}), "");
}

// Issue 47: a folder is a survey. An entry named as a cloud file that is none (empty, a link to
// nothing, a folder, a truncated header, a FIFO) was left out without a word and the run went on
// with the other tiles: each refuses the list now, naming the entry and what it is.
TEST(CloudFiles, AFoldersCloudNamedEntryThatIsNoCloudIsRefused) {
  struct Fault {
    std::string name, is;
    std::function<void(const std::string&)> make;
  };
  const std::vector<Fault> faults = {
      {"c.laz", "empty (0 bytes)", [](const std::string& p) { write_text(p, ""); }},
      {".LAS", "empty (0 bytes)", [](const std::string& p) { write_text(p, ""); }},  // a name that is all suffix
      {"d.laz", "a link to nothing (its target does not exist)",
       [](const std::string& p) { fs::create_symlink(p + ".gone", p); }},
      {"x.LAZ", "a folder (a folder's subfolders are not read)", [](const std::string& p) { fs::create_directory(p); }},
      {"e.las", "not a PLY, LAS or LAZ cloud (its first bytes are neither 'ply' nor 'LASF')",
       [](const std::string& p) { write_text(p, "LAS"); }},
      {"f.Ply", "not a PLY or LAS point cloud: the file is JSON (a CityJSON model?)",
       [](const std::string& p) { write_text(p, "{\"type\": \"CityJSON\"}"); }},
      {"g.laz", "a link that cannot be followed (Too many levels of symbolic links)",
       [](const std::string& p) { fs::create_symlink(p, p); }},
      {"h.las", "not a regular file (a FIFO, device or socket)",
       [](const std::string& p) { ASSERT_EQ(::mkfifo(p.c_str(), 0644), 0); }},
      {"z.laz", "not a regular file (a FIFO, device or socket)",
       [](const std::string& p) { fs::create_symlink("/dev/zero", p); }}};
  for (const Fault& f : faults) {
    const std::string dir = folder("survey_" + f.name);
    write_ply(dir + "/a.ply", points_from(85000.0, 3));
    write_ply(dir + "/b.ply", points_from(85010.0, 3));
    f.make(dir + "/" + f.name);
    EXPECT_EQ(refusal([&] { cloud_files({dir}, "--tile"); }),
              dir + "/" + f.name + ": " + f.is +
                  "; a cloud file of the --tile folder is part of the survey: remove or replace it");
  }
}

TEST(CloudFiles, EmptyFoldersMissingPathsAndOneFileTwiceAreRefused) {
  const std::string empty = folder("empty"), other = folder("other"), dir = folder("tiles");
  write_text(other + "/readme.txt", "no clouds here\n");
  write_ply(dir + "/t1.ply", points_from(85000.0, 3));
  write_ply(dir + "/t2.ply", points_from(85001.0, 3));
  EXPECT_EQ(refusal([&] { cloud_files({empty}); }), empty + ": no PLY, LAS or LAZ cloud in the --cloud folder (empty)");
  EXPECT_EQ(refusal([&] {
              cloud_files({dir, other}, "--tile");
            }),
            other + ": no PLY, LAS or LAZ cloud in the --tile folder (1 other entry)");
  EXPECT_EQ(refusal([&] { cloud_files({dir + "/nope.ply"}); }), dir + "/nope.ply: no such file or folder (--cloud)");
  // One file twice: named twice, once by name and once through its folder, through a link, or
  // as another spelling of its path.
  const std::string twice = ": the same file as " + dir + "/t1.ply; --cloud may name each cloud file once";
  EXPECT_EQ(refusal([&] { cloud_files({dir + "/t1.ply", dir + "/t1.ply"}); }), dir + "/t1.ply" + twice);
  EXPECT_EQ(refusal([&] { cloud_files({dir + "/t1.ply", dir}); }), dir + "/t1.ply" + twice);
  EXPECT_EQ(refusal([&] {
              cloud_files({dir + "/t1.ply", empty + "/../tiles/t1.ply"});
            }),
            empty + "/../tiles/t1.ply" + twice);
  fs::create_symlink(dir + "/t1.ply", other + "/link.ply");
  EXPECT_EQ(refusal([&] { cloud_files({dir, other}); }), other + "/link.ply" + twice);
}

// A file named directly is taken as named and refused by the reader as one cloud is: the list
// is refused whole, before any point is read.
TEST(CloudFiles, ANamedFileThatIsNoCloudIsRefusedWhenRead) {
  const std::string dir = folder("named");
  write_ply(dir + "/t1.ply", points_from(85000.0, 3));
  write_text(dir + "/city.json", "{\"type\": \"CityJSON\"}");
  write_text(dir + "/notes.txt", "tile index\n");
  const std::vector<std::string> json = cloud_files({dir + "/t1.ply", dir + "/city.json"});
  EXPECT_EQ(json.size(), 2u);
  std::size_t seen = 0;
  EXPECT_EQ(refusal([&] { stream_cloud(json, {}, [&](const Vec3&) { ++seen; }); }),
            dir + "/city.json: not a PLY or LAS point cloud: the file is JSON (a CityJSON model?)");
  EXPECT_EQ(seen, 0u);
  const std::string text = refusal([&] {
    stream_cloud(cloud_files({dir + "/t1.ply", dir + "/notes.txt"}), {}, [&](const Vec3&) { ++seen; });
  });
  EXPECT_EQ(text.rfind(dir + "/notes.txt: ", 0), 0u) << text;
  EXPECT_NE(text.find("PLY"), std::string::npos) << text;
  EXPECT_EQ(seen, 0u);
}

// The files' points one file after another, as the file holding them in that order; each file
// with its points and bounds.
TEST(CloudFiles, SeveralFilesReadAsOneInTheirOrder) {
  const PointCloud a = points_from(85000.0, 40), b = points_from(85100.0, 25);
  const std::string pa = temp_path("a.ply"), pb = temp_path("b.las");
  write_ply(pa, a);
  write_las(pb, b, {}, {});
  std::vector<CloudFileRead> read;
  const PointCloud both = read_cloud({pb, pa}, {}, &read);
  std::vector<Vec3> expected = read_cloud(pb).points;
  ASSERT_EQ(expected.size(), b.points.size());
  expected.insert(expected.end(), a.points.begin(), a.points.end());
  EXPECT_EQ(both.points, expected);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[0].path, pb);
  EXPECT_EQ(read[0].points, 25u);
  EXPECT_EQ(read[1].path, pa);
  EXPECT_EQ(read[1].points, 40u);
  EXPECT_EQ(read[1].bounds.min(), Vec3(85000.0, 447987.654 - 0.25 * 39, 1.234));
  EXPECT_EQ(read[1].bounds.max(), Vec3(85000.0 + 0.125 * 39, 447987.654, 1.234 + 0.039));
  EXPECT_LT((read[0].bounds.min() - Vec3(85100.0, 447987.654 - 0.25 * 24, 1.234)).norm(), 1e-9);
  EXPECT_EQ(cloud_point_count({pa, pb}), 65u);
  std::vector<Vec3> streamed;
  stream_cloud({pb, pa}, {}, [&](const Vec3& p) { streamed.push_back(p); });
  EXPECT_EQ(streamed, expected);
  // A class filter refuses the PLY among them before the LAS before it is read.
  std::size_t seen = 0;
  EXPECT_EQ(refusal([&] {
              stream_cloud({pb, pa}, {{1}}, [&](const Vec3&) { ++seen; });
            }),
            pa + ": a PLY cloud has no classification; --classes needs a LAS cloud");
  EXPECT_EQ(seen, 0u);
}

// --max-points bounds the cloud, not each file: two files under it alone, over it together.
TEST(CloudFiles, MaxPointsBoundsTheFilesTogether) {
  const std::string pa = temp_path("a.ply"), pb = temp_path("b.ply"), pc = temp_path("c.ply");
  write_ply(pa, points_from(85000.0, 40));
  write_ply(pb, points_from(85010.0, 40));
  write_ply(pc, points_from(85020.0, 40));
  CloudOptions o;
  o.max_points = 60;
  EXPECT_EQ(read_cloud(pa, o).points.size(), 40u);
  EXPECT_EQ(read_cloud(pb, o).points.size(), 40u);
  EXPECT_EQ(refusal([&] {
              read_cloud({pa, pb}, o);
            }),
            pa + " and 1 other cloud file: 80 points together, more than --max-points 60; cut a crop per building "
                 "first (lodrefine crop)");
  EXPECT_EQ(refusal([&] { read_cloud({pa, pb, pc}, o); }).rfind(pa + " and 2 other cloud files: 120 points", 0), 0u);
  o.max_points = 80;
  EXPECT_EQ(read_cloud({pa, pb}, o).points.size(), 80u);
}

TEST(CloudFiles, OverlapProblemsNameEachFileThatMissesTheModel) {
  Eigen::AlignedBox3d model(Vec3(85000, 447000, 0), Vec3(85020, 447010, 10));
  std::vector<CloudFileRead> files(3);
  files[0] = {"near.ply", 10, Eigen::AlignedBox3d(Vec3(85010, 447005, 0), Vec3(85030, 447006, 5))};
  files[1] = {"far.ply", 10, Eigen::AlignedBox3d(Vec3(95010, 447005, 0), Vec3(95030, 447006, 5))};
  files[2] = {"none.las", 0, Eigen::AlignedBox3d()};  // no point after the class filter: nothing to say
  const std::vector<std::string> lines = overlap_problems(files, model, "the city model");
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0],
            "far.ply: cloud x 95010.0..95030.0 y 447005.0..447006.0 does not overlap the city model x "
            "85000.0..85020.0 y 447000.0..447010.0: wrong CRS or tile?");
}

// The formats the commands' help names are the readers' table's (src/formats/cloud_readers.cpp),
// each row's names in row order; a folder entry ending in any of them, in any case, is a cloud
// file of the survey (refused when it holds none).
TEST(CloudFiles, FormatNamesComeFromTheReadersTable) {
  EXPECT_EQ(cloud_format_names(), (std::vector<std::string>{"PLY", "LAS", "LAZ"}));
  EXPECT_EQ(kCloudFormatNames, cloud_format_names());
  for (const std::string name : {"a.PLY", "b.Las", "c.laz"}) {
    const std::string dir = temp_path("names_" + name);
    fs::create_directories(dir);
    write_text(dir + "/" + name, "not a cloud\n");
    const std::string why = refusal([&] { cloud_files({dir}); });
    EXPECT_NE(why.find(name + ": not a PLY, LAS or LAZ cloud (its first bytes are neither 'ply' nor 'LASF')"),
              std::string::npos)
        << name << ": " << why;
  }
}
