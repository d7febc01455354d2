// A building as a union of prism parts over shared footprint lines (internal to synth).
//
// Each part's footprint is a cyclic list of footprint lines, counter-clockwise seen from above
// (parts that touch share lines, so they stay glued when a line moves); its roof is the lower
// envelope of a few planes z = a x + b y + c. build_mesh turns a Spec into one closed shell; the
// make_*_spec functions draw the building types. Building frame: metres, z up.
#pragma once
#include <stdexcept>
#include <vector>

#include "lodrefine/synth/synth.h"
#include "rng.h"

namespace lodrefine::synth {

// The footprint lines or roof planes do not describe a valid building (e.g. after extreme moves).
struct ShapeError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Line {
  Vec2 p, d;  // a point and a unit direction
};

struct RoofPlane {
  double a = 0, b = 0, c = 0;  // z = a x + b y + c
  double z(const Vec2& q) const { return a * q.x() + b * q.y() + c; }
};

struct Part {
  std::vector<int> lines;       // footprint lines, counter-clockwise seen from above
  std::vector<RoofPlane> roof;  // roof = min over these planes; >1 plane needs a convex footprint
};

struct Spec {
  std::vector<Line> lines;
  std::vector<Part> parts;
  double z0 = 0.0;  // ground level
  // Street-facade types only (empty / -1 otherwise): the coarse model's parts, which generalise
  // the street facade away; the lines of the true street facade (all scanned); the generalised
  // front line the coarse model moves; the street's side (outward normal of the front).
  std::vector<Part> generalised;
  std::vector<int> street;
  int coarse_front = -1;
  Vec2 street_normal = Vec2::Zero();
};

int add_line(Spec& s, const Vec2& a, const Vec2& b);
// Lines of the axis-aligned rectangle [x0,x1]x[y0,y1], counter-clockwise from the bottom edge.
std::vector<int> rect_lines(Spec& s, double x0, double y0, double x1, double y1);
RoofPlane flat_roof(double z);
// Plane at height z_at through `at`, rising with slope k in direction `up`.
RoofPlane sloped_roof(const Vec2& at, const Vec2& up, double z_at, double k);

// Whether segments a-b and c-d cross (where one only touches the other, either answer).
bool segments_cross(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d);

// The closed shell of a spec: shared vertices, outward faces, coplanar pieces of one wall, roof or
// ground merged, no T-junction and no vertex that only continues a straight edge.
// Face::source holds the footprint line of each wall (-1 otherwise). Throws ShapeError when the
// spec folds (a footprint crosses itself, a roof comes within 0.5 m of the ground, roofs cross).
Mesh build_mesh(const Spec& s);

// The spec of a building of type t with its ground at z0, drawn from r.
Spec make_spec(BuildingType t, Rng& r, double z0);

}  // namespace lodrefine::synth
