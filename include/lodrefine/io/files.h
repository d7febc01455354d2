// What every reader and writer shares: the coordinate bound, telling formats apart by content,
// and atomic writes (a temporary beside the target, renamed over it), so no partial file is left.
#pragma once
#include <cstddef>
#include <string>

#include "lodrefine/core/types.h"

namespace lodrefine {

// Georeferenced coordinates are at most a few 1e7 m (UTM northing); anything beyond 1e9 m is a
// broken file, and would overflow the integer grids of welding and hashing downstream. Every
// reader refuses such coordinates.
constexpr double kMaxCoordinate = 1e9;

// What a file holds, judged by its first bytes (not its name): lets each reader say what a
// file given in the wrong place is, and lets commands that take several formats pick one.
enum class FileKind { Ply, Las, Xml, Json, Other };
FileKind sniff_file(const std::string& path);  // Other also for unreadable files (the reader reports)
// "a PLY point cloud", "a LAS/LAZ point cloud", "XML (a CityGML model?)", "JSON (a CityJSON
// model?)"; empty for Other.
std::string file_kind_text(FileKind kind);

// A file written through a temporary beside the target and renamed over it on commit();
// the temporary is removed if commit() is never reached (an exception, a kill leaves only a
// "<path>.tmp.<pid>"). For outputs written in pieces (streams); write_file_atomic for one piece.
class AtomicFile {
 public:
  explicit AtomicFile(const std::string& path);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();
  void write(const char* data, std::size_t n);
  void write(const std::string& s) { write(s.data(), s.size()); }
  void commit();
  [[noreturn]] void fail(const std::string& reason);  // discards, throws std::runtime_error

 private:
  void discard();
  std::string path_, tmp_;
  int fd_ = -1;
  bool committed_ = false;
};

// The whole file as bytes (small inputs: a baseline, a gates file); throws InputError, one line
// naming `path`, for a directory or a file that cannot be read.
std::string read_file(const std::string& path);

// Writes `content` to `path` atomically (temp file in the same directory + rename).
void write_file_atomic(const std::string& path, const std::string& content);

}  // namespace lodrefine
