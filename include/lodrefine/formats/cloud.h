// Point cloud input of either format, chosen by the file's content (not its name): PLY
// ('ply' magic line) or LAS/LAZ ('LASF' signature). City models, JSON and other files given as
// a cloud are refused with a one-line message saying what the file is. A cloud may be several
// files (cloud_files), read as one.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "lodrefine/base/geometry.h"  // bounding_box, for overlap_problem
#include "lodrefine/base/types.h"

namespace lodrefine {

// The cloud formats read_cloud and stream_cloud take, as the commands' help names them: the
// readers' table's (src/formats/cloud_readers.cpp; tests/app/test_help.cpp checks every command
// that reads a cloud names each).
const std::vector<std::string>& cloud_format_names();
inline const std::vector<std::string> kCloudFormatNames = cloud_format_names();

inline constexpr std::uint64_t kDefaultMaxPoints = 20000000;

struct CloudOptions {
  // Classification codes to keep (LAS only; empty: every point). Formats 0–5 carry 5-bit
  // classes (0–31), 6–10 the full byte. A PLY has no classification: a filter is an error.
  std::vector<int> classes;
  // The most points read_cloud holds (a building's crop, not a tile; all its files together): a
  // LAZ file of a few hundred kilobytes can announce 1e9 points, which would fill the memory.
  // Beyond: InputError.
  std::uint64_t max_points = kDefaultMaxPoints;
};

// A survey delivered as many files (one per drive, or per tile) is read as one cloud: the files'
// points one file after another, in the list's order, as if they were one file holding them all
// (the same points, in the same order, so the same results). Every function below that takes
// such a list bounds memory as for one file: max_points and max_held apply to the total.

// An entry of a folder given as a cloud that is no cloud file, and what it is instead.
struct SkippedEntry {
  std::string path;    // the folder's path as given, then the entry's name
  std::string reason;  // "a folder (a folder's subfolders are not read)", "not a PLY, LAS or LAZ cloud (…)", …
};

// The cloud files of a command's --cloud (or --tile) values, in reading order. Each value is a
// file or a folder, expanded in the order given:
// - a file is taken as named; one that is no cloud is refused when read (its reader says what
//   it is, the PLY reader refuses anything else);
// - a folder gives its regular files (links to them too) whose content is a cloud (sniff_file:
//   PLY or LAS/LAZ), sorted by name (byte order). A folder is a survey: an entry named as a
//   cloud file (.ply, .las, .laz, any case) that is not one (empty, unreadable, a link to
//   nothing, a folder, a FIFO or device, or other content) is refused, never left out. Its
//   other entries (files neither named nor holding a cloud, subfolders, lodrefine's temporaries
//   .lodrefine-tmp-*) are skipped: each with what it is in `skipped` (when given), by path.
// Throws InputError (one line) for a value that is no file or folder, a folder holding no
// cloud, a folder's cloud-named entry that is no cloud file, and one file given twice (the same
// device and inode: links and other spellings count), naming `option`.
std::vector<std::string> cloud_files(const std::vector<std::string>& values, const std::string& option = "--cloud",
                                     std::vector<SkippedEntry>* skipped = nullptr);

// One line for stdout saying what the folders' skipped entries were ("skipped 2 entries of the
// cloud folders, no cloud files: t/notes.txt (…), t/old (…)"; at most five named, then "and N
// more"); empty when none. Paths and reasons escaped (escaped_line).
std::string skipped_entries_text(const std::vector<SkippedEntry>& skipped);

// "a.las", or "a.las and 2 other cloud files": a list of files in a message.
std::string cloud_files_text(const std::vector<std::string>& paths);

// What was read of one file of a list.
struct CloudFileRead {
  std::string path;
  std::uint64_t points = 0;    // read (after the class filter)
  Eigen::AlignedBox3d bounds;  // of those points; empty when none
};

// The number of points the headers declare (each validated against its file size), before any
// class filter, summed over the files: lets callers refuse clouds too large to hold without
// reading them, and gives a progress line its total.
std::uint64_t cloud_point_count(const std::vector<std::string>& paths);
inline std::uint64_t cloud_point_count(const std::string& path) {
  return cloud_point_count(std::vector<std::string>{path});
}

// Streams the points file by file, each in file order (chunked; memory does not grow with the
// files). Every file's format and header are checked before any point is read (a class filter
// refuses a PLY, a broken header its file, at once, not after the files before it are read).
// `read` (optional) gets one entry per file,
// appended as its reading starts (so while `on_point` runs, read->back() is the file being read).
// Each file is read under read_naming_memory: memory running out names it.
void stream_cloud(const std::vector<std::string>& paths, const CloudOptions& options,
                  const std::function<void(const Vec3&)>& on_point, std::vector<CloudFileRead>* read = nullptr);
inline void stream_cloud(const std::string& path, const CloudOptions& options,
                         const std::function<void(const Vec3&)>& on_point) {
  stream_cloud(std::vector<std::string>{path}, options, on_point);
}

// Reads the files whole, as one cloud. Throws InputError when their headers announce more than
// options.max_points points together, before reading them. `read` as for stream_cloud.
PointCloud read_cloud(const std::vector<std::string>& paths, const CloudOptions& options = {},
                      std::vector<CloudFileRead>* read = nullptr);
inline PointCloud read_cloud(const std::string& path, const CloudOptions& options = {}) {
  return read_cloud(std::vector<std::string>{path}, options);
}

// CRS / tile sanity: one line "cloud x a..b y c..d does not overlap <what> x e..f y g..h: wrong
// CRS or tile?" when the boxes are disjoint in XY (the model grown by `margin` metres); empty
// when they overlap. A cloud in another CRS or of another tile otherwise only shows up as
// "no planes found".
std::string overlap_problem(const Eigen::AlignedBox3d& cloud, const Eigen::AlignedBox3d& model,
                            const std::string& what = "the model", double margin = 3.0);

// overlap_problem of each file read against the model, as "<file>: <problem>", in reading order
// (a file that overlaps it, or holds no point, gives no line): the cloud files of another tile
// or CRS among those given, named.
std::vector<std::string> overlap_problems(const std::vector<CloudFileRead>& files, const Eigen::AlignedBox3d& model,
                                          const std::string& what = "the model", double margin = 3.0);

// "--classes 2,6" as text, for messages ("" without a filter).
std::string classes_text(const std::vector<int>& classes);

}  // namespace lodrefine
