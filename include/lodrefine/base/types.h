// Core value types shared by every pipeline stage.
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products on Vec3 everywhere
#include <chrono>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

namespace lodrefine {

using Vec3 = Eigen::Vector3d;
using Vec2 = Eigen::Vector2d;

// CityGML thematic surface of a face; Other for groups we do not recognise.
enum class Semantic { Wall, Roof, Ground, Other };
const char* semantic_name(Semantic s);                  // "WallSurface", "RoofSurface", ...
Semantic semantic_from_name(const std::string& group);  // case-insensitive substring match

// Where a face of a refined or repaired building comes from: its plane is the model's (kept,
// perhaps trimmed or extended), the scan's (a wall moved onto a scan plane, a facade the model
// lacked), or neither (added to close the shell: a step wall, a wall across a hole). None: a
// model as read, which says nothing (writers add nothing for it).
enum class Provenance : unsigned char { None, Model, Scan, Added };
const char* provenance_name(Provenance p);  // "model", "scan", "added"; "" for None
// The provenance an OBJ group names as one of its blank-separated words (`g WallSurface scan`);
// None when no word is a provenance_name.
Provenance provenance_from_group(const std::string& group);

// One planar polygon of a building, vertices indexing Mesh::vertices (counter-clockwise seen
// from outside once the mesh is oriented).
struct Face {
  std::vector<int> v;
  Semantic sem = Semantic::Other;
  int source = -1;  // index of the input face this one descends from (-1: new)
  Provenance provenance = Provenance::None;
  double coverage = 0.0;  // Provenance::Scan: the share of its area the scan covers (0..1)
};

// A face like `f` (semantic, source, provenance, coverage) on the corners `v`.
inline Face with_corners(const Face& f, std::vector<int> v) {
  Face g = f;
  g.v = std::move(v);
  return g;
}

// A polygonal building model. Coordinates are in whatever frame the caller uses: readers
// return the file's (georeferenced) frame, the pipeline works in a local frame.
struct Mesh {
  std::vector<Vec3> vertices;
  std::vector<Face> faces;
  std::string id;  // building id (OBJ `o` name or `# id:` comment)
};

struct PointCloud {
  std::vector<Vec3> points;
};

// Stage timings for reports.
using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Input that cannot be used; what() is a one-line message naming the file and the fault.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Memory ran out reading a named input: a bad_alloc (main's exit 3) whose what() is the one-line
// message naming the file. The message is copied into a fixed buffer (cut to fit): throwing it
// allocates nothing.
class OutOfMemory : public std::bad_alloc {
 public:
  explicit OutOfMemory(const std::string& message) noexcept;
  const char* what() const noexcept override { return what_; }

 private:
  char what_[512];
};

}  // namespace lodrefine
