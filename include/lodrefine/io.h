// Reading and writing building models (OBJ) and point clouds (PLY).
// Every reader throws InputError with a one-line message on malformed input; every writer
// writes to a temporary file beside the target and renames it, so no partial file is left.
#pragma once
#include <cstdint>
#include <functional>
#include <string>

#include "lodrefine/types.h"

namespace lodrefine {

// Georeferenced coordinates are at most a few 1e7 m (UTM northing); anything beyond 1e9 m is a
// broken file, and would overflow the integer grids of welding and hashing downstream. Every
// reader refuses such coordinates.
constexpr double kMaxCoordinate = 1e9;

// Reads an OBJ polygon soup as exported per building from CityGML: `g WallSurface` /
// `g RoofSurface` / `g GroundSurface` groups (also `usemtl`), polygons of 3+ vertices,
// georeferenced doubles. Building id from `o NAME`, else a `# id: X` comment, else the file
// stem. Faces are kept as given (no welding); Face::source is the face's index in the file.
Mesh read_obj(const std::string& path);
// Same, also reporting how many `f` statements with fewer than 3 vertices were skipped (they
// are no polygons and get no Face::source number; the file is rejected only when no face
// remains). Positive indices may refer to vertices defined later in the file; negative ones
// are relative to the vertices so far.
Mesh read_obj(const std::string& path, int* skipped_faces);

// Writes polygons grouped by semantic (`g WallSurface` ...), `o <id>`, vertices offset by
// `origin` (the local frame's origin) and printed with enough digits for < 0.1 mm at 7-digit
// magnitudes. Atomic (temp + rename). Throws std::runtime_error if the target is not writable.
void write_obj(const std::string& path, const Mesh& mesh, const Vec3& origin = Vec3::Zero());

// Reads x/y/z of a PLY (ascii, binary little- or big-endian; float or double or any integer
// type; extra properties and elements skipped). Rejects NaN/Inf and header/data mismatches.
PointCloud read_ply(const std::string& path);

// Streams the vertices of a PLY in chunks without holding the whole file; the callback gets
// each point in file order. Same validation as read_ply.
void stream_ply(const std::string& path, const std::function<void(const Vec3&)>& on_point);

// The vertex count a PLY header declares (validated against the file size), without reading
// the data: lets callers refuse clouds too large to hold.
std::uint64_t ply_vertex_count(const std::string& path);

// Writes x/y/z as binary little-endian doubles (plus an optional per-point float property).
void write_ply(const std::string& path, const PointCloud& cloud, const Vec3& origin = Vec3::Zero(),
               const std::vector<float>* scalar = nullptr, const std::string& scalar_name = "scalar");

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

// Writes `content` to `path` atomically (temp file in the same directory + rename).
void write_file_atomic(const std::string& path, const std::string& content);

}  // namespace lodrefine
