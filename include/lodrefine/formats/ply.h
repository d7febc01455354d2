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

}  // namespace lodrefine
