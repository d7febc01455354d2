// Point clouds as PLY (ascii, binary little/big endian). Readers throw InputError with a
// one-line message on malformed input; the writer is atomic.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "lodrefine/base/files.h"
#include "lodrefine/base/types.h"

namespace lodrefine {

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

// A binary little-endian PLY of one vertex element written in pieces (a tile's clouds one
// building at a time, so memory does not grow with the tile), through an AtomicFile: the vertex
// count, known only at the end, is a fixed-width field (zero-padded) that commit() sets; nothing
// is left at `path` unless commit() is reached.
class PlyStream {
 public:
  // `comment`: the header's comment (one line); `properties`: the vertex's property lines
  // ("property double x\n..."), little-endian, whose records write() takes as bytes.
  PlyStream(const std::string& path, const std::string& comment, const std::string& properties);
  // Appends `vertices` records, `bytes` bytes in all.
  void write(const char* records, std::size_t bytes, std::uint64_t vertices);
  void commit();
  std::uint64_t vertices() const { return vertices_; }

 private:
  std::string header() const;
  AtomicFile file_;
  std::string comment_, properties_;
  std::uint64_t vertices_ = 0;
};

}  // namespace lodrefine
