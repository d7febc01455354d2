// Format dispatch for point clouds by content, through the readers' table (cloud_readers.h); a
// cloud of several files.
#include "lodrefine/formats/cloud.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <utility>

#include "cloud_readers.h"
#include "lodrefine/base/files.h"

namespace lodrefine {

namespace {

using detail::cloud_readers;
using detail::CloudReader;

// "PLY, LAS or LAZ": names in a message.
std::string or_list(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return out;
}

// Each reader's first name ("PLY or LAS"); only the classified ones' with `classified`.
std::string reader_names(bool classified_only = false) {
  std::vector<std::string> names;
  for (const CloudReader& r : cloud_readers())
    if (r.classified || !classified_only) names.push_back(r.names.front());
  return or_list(names);
}

// "neither 'ply' nor 'LASF'": the signatures a file's first bytes are not.
std::string not_any_magic() {
  const auto& rows = cloud_readers();
  std::string out = rows.size() == 2 ? "neither " : rows.size() > 2 ? "none of " : "not ";
  for (std::size_t i = 0; i < rows.size(); ++i)
    out += (i == 0                 ? ""
            : rows.size() == 2     ? " nor "
            : i + 1 == rows.size() ? " or "
                                   : ", ") +
           ("'" + rows[i].magic + "'");
  return out;
}

// The reader of a cloud file by its first bytes; refuses a city model or JSON with what it is.
const CloudReader& reader_of(const std::string& path) {
  const FileKind kind = sniff_file(path);
  if (const CloudReader* r = detail::cloud_reader(kind)) return *r;
  if (kind == FileKind::Xml || kind == FileKind::Json)
    throw InputError(path + ": not a " + reader_names() + " point cloud: the file is " + file_kind_text(kind));
  return cloud_readers().front();  // it reports any other content ("not a PLY file")
}

namespace fs = std::filesystem;

std::uint64_t saturated_sum(std::uint64_t a, std::uint64_t b) { return a > UINT64_MAX - b ? UINT64_MAX : a + b; }

detail::DeclaredPoints declared(const std::string& path) { return reader_of(path).declared(path); }

// What a folder entry is, as far as its cloud goes (see cloud_files): a cloud file, one of
// lodrefine's temporaries (skipped whatever its name), or anything else (said in the fault).
enum class EntryKind { Cloud, Temporary, NoCloud };

struct Entry {
  EntryKind kind;
  std::string fault;  // what it is when not a cloud, for a refusal or a skip
};

// Whether an entry's name says it is a cloud file: it ends in a reader's name (.ply, .las or
// .laz), in any case (".laz" alone too).
bool cloud_name(const fs::path& path) {
  std::string name = path.filename().string();
  for (char& c : name) c = char(std::tolower(static_cast<unsigned char>(c)));
  for (const CloudReader& r : cloud_readers())
    for (std::string ending : r.names) {
      for (char& c : ending) c = char(std::tolower(static_cast<unsigned char>(c)));
      ending.insert(0, ".");
      if (name.size() >= ending.size() && name.compare(name.size() - ending.size(), ending.size(), ending) == 0)
        return true;
    }
  return false;
}

// Looks at one entry without reading more than its first bytes; a FIFO or device is never opened.
Entry inspect(const fs::path& path) {
  if (path.filename().string().rfind(kTempPrefix, 0) == 0)
    return {EntryKind::Temporary, "a lodrefine temporary (a file being written)"};
  std::error_code ec, link_ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) {
    if (!fs::is_symlink(fs::symlink_status(path, link_ec)))
      return {EntryKind::NoCloud, "cannot be read (" + ec.message() + ")"};
    return {EntryKind::NoCloud, status.type() == fs::file_type::not_found
                                    ? std::string("a link to nothing (its target does not exist)")
                                    : "a link that cannot be followed (" + ec.message() + ")"};
  }
  if (fs::is_directory(status)) return {EntryKind::NoCloud, "a folder (a folder's subfolders are not read)"};
  if (!fs::is_regular_file(status)) return {EntryKind::NoCloud, "not a regular file (a FIFO, device or socket)"};
  if (fs::file_size(path, ec) == 0 && !ec) return {EntryKind::NoCloud, "empty (0 bytes)"};
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return {EntryKind::NoCloud, std::string("cannot be read (") + std::strerror(errno) + ")"};
  char head[64];  // its kind from the bytes this open reads (no second open)
  const ssize_t n = ::read(fd, head, sizeof head);
  ::close(fd);
  const FileKind kind = sniff_head(std::string(head, n > 0 ? std::size_t(n) : 0));
  if (detail::cloud_reader(kind)) return {EntryKind::Cloud, ""};
  return {EntryKind::NoCloud,
          kind == FileKind::Other
              ? "not a " + or_list(cloud_format_names()) + " cloud (its first bytes are " + not_any_magic() + ")"
              : "not a " + reader_names() + " point cloud: the file is " + file_kind_text(kind)};
}

bool by_path(const SkippedEntry& a, const SkippedEntry& b) { return a.path < b.path; }

// A folder's cloud files (see cloud_files), sorted by name; its other entries go to `skipped`.
std::vector<std::string> folder_clouds(const std::string& folder, const std::string& option,
                                       std::vector<SkippedEntry>& skipped) {
  std::vector<std::string> found;
  std::vector<SkippedEntry> others, refused;  // refused: cloud-named entries that are no cloud
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const Entry entry = inspect(it->path());
    const std::string path = it->path().string();
    if (entry.kind == EntryKind::Cloud) found.push_back(path);
    else if (entry.kind == EntryKind::NoCloud && cloud_name(it->path())) refused.push_back({path, entry.fault});
    else others.push_back({path, entry.fault});
  }
  if (!refused.empty()) {  // the first by name, whatever order the folder lists them in
    const SkippedEntry& first = *std::min_element(refused.begin(), refused.end(), by_path);
    throw InputError(first.path + ": " + first.reason + "; a cloud file of the " + option +
                     " folder is part of the survey: remove or replace it");
  }
  if (ec) throw InputError(folder + ": cannot list the folder (" + ec.message() + ")");
  if (found.empty())
    throw InputError(folder + ": no " + or_list(cloud_format_names()) + " cloud in the " + option + " folder" +
                     (others.empty()       ? std::string(" (empty)")
                      : others.size() == 1 ? std::string(" (1 other entry)")
                                           : " (" + std::to_string(others.size()) + " other entries)"));
  std::sort(found.begin(), found.end());
  std::sort(others.begin(), others.end(), by_path);
  skipped.insert(skipped.end(), others.begin(), others.end());
  return found;
}

}  // namespace

std::vector<std::string> cloud_files(const std::vector<std::string>& values, const std::string& option,
                                     std::vector<SkippedEntry>* skipped) {
  std::vector<std::string> files;
  std::vector<SkippedEntry> others;
  for (const std::string& value : values) {
    std::error_code ec;
    const fs::file_status status = fs::status(value, ec);
    if (fs::is_directory(status)) {
      const std::vector<std::string> found = folder_clouds(value, option, others);
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::exists(status)) {
      files.push_back(value);
    } else {
      const bool missing = status.type() == fs::file_type::not_found || !ec;
      throw InputError(value + ": " + (missing ? std::string("no such file or folder") : ec.message()) + " (" + option +
                       ")");
    }
  }
  if (files.empty()) throw InputError(option + ": no cloud given");
  if (skipped) *skipped = std::move(others);
  std::map<std::pair<dev_t, ino_t>, std::size_t> seen;  // each file's first place in the list
  for (std::size_t i = 0; i < files.size(); ++i) {
    struct stat st {};
    if (::stat(files[i].c_str(), &st) != 0) continue;  // gone: its reader says so
    const auto [it, added] = seen.emplace(std::make_pair(st.st_dev, st.st_ino), i);
    if (!added)
      throw InputError(files[i] + ": the same file as " + files[it->second] + "; " + option +
                       " may name each cloud file once");
  }
  return files;
}

std::string skipped_entries_text(const std::vector<SkippedEntry>& skipped) {
  constexpr std::size_t kNamed = 5;
  if (skipped.empty()) return {};
  std::string line = "skipped " + std::to_string(skipped.size()) + (skipped.size() == 1 ? " entry" : " entries") +
                     " of the cloud folders, no cloud files: ";
  for (std::size_t i = 0; i < skipped.size() && i < kNamed; ++i)
    line += (i ? ", " : "") + escaped_line(skipped[i].path) + " (" + escaped_line(skipped[i].reason) + ")";
  if (skipped.size() > kNamed) line += " and " + std::to_string(skipped.size() - kNamed) + " more";
  return line;
}

std::string cloud_files_text(const std::vector<std::string>& paths) {
  if (paths.size() <= 1) return paths.empty() ? std::string() : paths.front();
  const std::size_t others = paths.size() - 1;
  return paths.front() + " and " + std::to_string(others) + " other cloud file" + (others > 1 ? "s" : "");
}

std::uint64_t cloud_point_count(const std::vector<std::string>& paths) {
  std::uint64_t n = 0;
  for (const std::string& path : paths) n = saturated_sum(n, declared(path).points);
  return n;
}

void stream_cloud(const std::vector<std::string>& paths, const CloudOptions& options,
                  const std::function<void(const Vec3&)>& on_point, std::vector<CloudFileRead>* read) {
  std::vector<const CloudReader*> readers;
  for (const std::string& path : paths) {
    readers.push_back(&reader_of(path));
    if (!readers.back()->classified && !options.classes.empty())
      throw InputError(path + ": a " + readers.back()->names.front() +
                       " cloud has no classification; --classes needs a " + reader_names(true) + " cloud");
    declared(path);  // its header checked: a broken last tile is refused before the first is read
  }
  for (std::size_t i = 0; i < paths.size(); ++i) {
    CloudFileRead* file = nullptr;
    if (read) file = &read->emplace_back(CloudFileRead{paths[i], 0, {}});
    const std::function<void(const Vec3&)> counted = [&](const Vec3& p) {
      ++file->points;
      file->bounds.extend(p);
      on_point(p);
    };
    const auto& visit = file ? counted : on_point;
    read_naming_memory(paths[i], [&] { readers[i]->stream(paths[i], options.classes, visit); });
  }
}

PointCloud read_cloud(const std::vector<std::string>& paths, const CloudOptions& options,
                      std::vector<CloudFileRead>* read) {
  detail::DeclaredPoints total;
  for (const std::string& path : paths) {
    const detail::DeclaredPoints d = declared(path);
    total.points = saturated_sum(total.points, d.points);
    total.reserve = saturated_sum(total.reserve, d.reserve);
  }
  if (total.points > options.max_points)
    throw InputError(cloud_files_text(paths) + ": " + std::to_string(total.points) + " points" +
                     (paths.size() > 1 ? " together" : "") + ", more than --max-points " +
                     std::to_string(options.max_points) + "; cut a crop per building first (lodrefine crop)");
  PointCloud cloud;
  // The reservation is most of the memory a cloud takes. With a class filter most points may be
  // dropped, so the vector grows as they come.
  if (options.classes.empty())
    read_naming_memory(cloud_files_text(paths), [&] { cloud.points.reserve(total.reserve); });
  stream_cloud(
      paths, options, [&](const Vec3& p) { cloud.points.push_back(p); }, read);
  return cloud;
}

std::string overlap_problem(const Eigen::AlignedBox3d& cloud, const Eigen::AlignedBox3d& model, const std::string& what,
                            double margin) {
  if (cloud.isEmpty() || model.isEmpty()) return {};
  const Eigen::AlignedBox2d c(cloud.min().head<2>(), cloud.max().head<2>());
  const Eigen::AlignedBox2d m(model.min().head<2>() - Vec2::Constant(margin),
                              model.max().head<2>() + Vec2::Constant(margin));
  if (c.intersects(m)) return {};
  const auto range = [](const Eigen::AlignedBox3d& b) {
    char s[160];
    std::snprintf(s, sizeof s, "x %.1f..%.1f y %.1f..%.1f", b.min().x(), b.max().x(), b.min().y(), b.max().y());
    return std::string(s);
  };
  return "cloud " + range(cloud) + " does not overlap " + what + " " + range(model) + ": wrong CRS or tile?";
}

std::vector<std::string> overlap_problems(const std::vector<CloudFileRead>& files, const Eigen::AlignedBox3d& model,
                                          const std::string& what, double margin) {
  std::vector<std::string> lines;
  for (const CloudFileRead& f : files)
    if (const std::string why = overlap_problem(f.bounds, model, what, margin); !why.empty())
      lines.push_back(f.path + ": " + why);
  return lines;
}

std::string classes_text(const std::vector<int>& classes) {
  std::string s;
  for (int c : classes) s += (s.empty() ? "" : ",") + std::to_string(c);
  return s;
}

const std::vector<std::string>& cloud_format_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const CloudReader& r : cloud_readers()) out.insert(out.end(), r.names.begin(), r.names.end());
    return out;
  }();
  return names;
}

}  // namespace lodrefine
