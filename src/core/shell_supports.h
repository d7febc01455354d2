// The supporting planes of a building's arrangement (stage 5, selection: shell_selection.h): the starting
// shell's planes, the scan's facades none of them carries, and the hypothesised walls across the
// steps of a facade line; and the region the arrangement covers. Internal to shell_selection.
#pragma once
#include <cstdint>
#include <string>
#include <unordered_set>
#include <vector>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/types.h"
#include "lodrefine/core/candidates.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/planes.h"
#include "lodrefine/core/selection.h"

namespace lodrefine::detail {

// Occupancy grid cell (m): several MLS points wide, a fraction of a window.
constexpr double kOccupancyCell = 0.25;

// The supporting planes: the starting shell's, then the scan's facades that none of them carries.
struct Supports {
  std::vector<SupportPlane> planes;
  int start_planes = 0;
  std::vector<int> face_plane;            // start face -> supporting plane
  std::vector<std::vector<Vec3>> points;  // per supporting plane: its scan points
  int added = 0;
  int slivers = 0;      // start surfaces on a plane by the planarity tolerance alone (add_start_planes)
  int hole_planes = 0;  // planes no face of the start lies on (add_hole_planes)
};

// A plane whose normal is within `max_tilt_deg` of horizontal (PlaneConfig::facade_max_tilt_deg)
// is a wall's: the contradiction and the represented-facade tests apply to walls only.
inline bool near_vertical(const Plane& pl, double max_tilt_deg) {
  return std::abs(pl.n.z()) < std::sin(radians(max_tilt_deg));
}

// The start's planes, one per set of its surfaces within kSurfaceAngleDeg / kSurfaceDistance
// (matching.h), largest first; a surface on none of them goes to the one nearest in angle of
// those its vertices all lie within `planarity_tolerance` (m) of (a sliver: counted in slivers).
// A plane's provenance: the scan's when a start face on it is (a moved wall), added when only
// added faces lie on it, else the model's.
void add_start_planes(const Mesh& start, double planarity_tolerance, Supports& s);
// The scan's facade planes near the footprint (within match_distance + bbox_margin, and along the
// facade no farther past the start's ends than the facade's own corner: a facade line running on
// into a neighbour's is the neighbour's there), each on the supporting plane it lies on, else a
// new one; ransac_min_points such points at least.
void add_scan_planes(const Mesh& start, const PointCloud& cloud, const std::vector<ScanPlane>& scan,
                     const RefineConfig& prm, Supports& s);
// The planes a soup's holes need to close (after add_start_planes): the vertical plane through each
// boundary edge (an edge of one face; through a vertical one, across the wall's end) unless a
// supporting plane carries it already. No scan points.
void add_hole_planes(const Mesh& soup, Supports& s);
// Whether a supporting plane lies on the soup's lowest level, horizontal, across its whole box:
// the ground its walls stand on.
bool carries_ground(const Mesh& soup, const Supports& s);
// Hypothesised walls across where a scanned facade's points end inside the footprint.
void add_step_walls(const Mesh& start, const RefineConfig& prm, Supports& s);
// Where the scan-only facades that step from another scanned facade ask for a change: each point
// swept along the normal of the nearest parallel start wall it stands before onto that wall (the
// step, bay or recess between them), sampled every `step` m.
std::vector<Vec3> step_volume_samples(const Mesh& start, const Supports& s, const RefineConfig& prm, double step);
// The region: the start and the scan evidence, in the axes of the start's largest wall (near_vertical
// within `max_tilt_deg`), grown by a margin.
Region building_region(const Mesh& start, const Supports& s, double max_tilt_deg);
// Per supporting plane, the box (region's axes) its candidates need: its start faces and its
// scan points, grown by `margin` (the farthest a wall may move); a plane with neither (a
// hypothesised wall) those of the start and the evidence within `margin` of it. A scanned wall
// spans the region's height (a street scan sees its lower storeys only).
// Points of `also` reach every plane they lie on (within kSurfaceDistance): a hole's edges, the
// plane that closes it.
std::vector<Region> plane_reach(const Mesh& start, const Supports& s, const Region& region, double margin,
                                const std::vector<Vec3>& also = {});

using FaceIndex = CandidateMesh::Face_index;

// The face map `in` of a candidate set on the candidates kept_candidates(that set, keep): the
// map `property` added to their mesh `to`, each kept face's value carried.
template <class T>
CandidateMap<T> carried(const CandidateMap<T>& in, const CandidateFaceProperty<T>& property, CandidateMesh& to,
                        const std::vector<char>& keep) {
  auto out = property.add(to);
  int g = 0;
  for (std::size_t f = 0; f < keep.size(); ++f)
    if (keep[f]) out[FaceIndex(g++)] = in[FaceIndex(f)];
  return out;
}

// What the program knows of each candidate, as face property maps of the candidate mesh (their
// names: candidate_props): in_start (the starting shell has a face there), source (that face's
// source, -1 without one; traced_shell gives it to the output's faces), confidence (the data
// term's c), in_zone (scan evidence reaches it), fit (the data-fitting term's scanned area it
// explains, m²). Added once (describe_candidates) and carried whole to the kept candidates. The
// selection adds its own maps (variable, selected).
struct FaceProps {
  CandidateMap<bool> in_start;
  CandidateMap<int> source;
  CandidateMap<double> confidence;
  CandidateMap<bool> in_zone;
  CandidateMap<double> fit;

  // The maps added to `mesh`, every face at each map's unset value.
  static FaceProps add(CandidateMesh& mesh) {
    return {candidate_props::in_start.add(mesh), candidate_props::source.add(mesh),
            candidate_props::confidence.add(mesh), candidate_props::in_zone.add(mesh), candidate_props::fit.add(mesh)};
  }
  // The same maps on `to`, the mesh of kept_candidates(this mesh's set, keep), with the kept
  // faces' values.
  FaceProps carried_to(CandidateMesh& to, const std::vector<char>& keep) const {
    return {carried(in_start, candidate_props::in_start, to, keep), carried(source, candidate_props::source, to, keep),
            carried(confidence, candidate_props::confidence, to, keep),
            carried(in_zone, candidate_props::in_zone, to, keep), carried(fit, candidate_props::fit, to, keep)};
  }
};

// Each candidate's FaceProps, from the starting shell `start` and the supports `s`.
FaceProps describe_candidates(CandidateSet& cs, const Mesh& start, const Supports& s, const RefineConfig& prm);

// The changed candidates (`changed`, per candidate) of the connected pieces that put solid where
// the scan saw through: at least PlaneEvidence::ransac_min_points of `evidence` (the supporting
// planes' points) more than 0.5 m inside `shell` though not inside `start`, nearest the piece.
std::vector<int> enclosing_changes(const CandidateSet& cs, const std::vector<char>& changed, const Mesh& start,
                                   const Mesh& shell, const std::vector<Vec3>& evidence, const PlaneEvidence& prm);

// A plane's 2D frame: its basis (Plane::basis) at an origin on it.
struct Frame2 {
  Vec3 o, u, v;
  Vec2 operator()(const Vec3& p) const { return {(p - o).dot(u), (p - o).dot(v)}; }
  Vec3 lifted(const Vec2& q) const { return o + q.x() * u + q.y() * v; }  // back onto the plane
};
// `pl`'s frame with its origin where `centre` projects onto it.
Frame2 frame_of(const Plane& pl, const Vec3& centre);

// A plane's kOccupancyCell grid cells (in its Frame2) that the scan covers, keyed by (i, j).
using CellSet = std::unordered_set<std::int64_t>;
// Marks the cells of `pts` (in `frame`) and those within 2 cells around each: a facade's windows
// and the gaps between scan lines (up to about a metre) count as scanned.
void mark_scanned(CellSet& cells, const std::vector<Vec3>& pts, const Frame2& frame);
// The share of a polygon's cells (by centre; `poly` in the frame's coordinates) in `cells`; a
// polygon holding no cell centre is judged by its centroid's cell.
double scanned_share(const std::vector<Vec2>& poly, const CellSet& cells);

// A boolean face map of `cs` as 0/1 per candidate (a selection).
std::vector<char> face_flags(const CandidateSet& cs, const CandidateMap<bool>& map);
// Output vertices within this (m) of a starting-shell vertex are put back on it: the plane meets
// of the arrangement only approximate a model that is planar within tolerance, and where the
// selection changed nothing a roof must not move by that. Used only when the shell still
// validates after it.
inline constexpr double kSnapBack = 0.03;
// `m` with its vertices within kSnapBack of a vertex of `start` put on it (those snapped to one start
// vertex become one; faces left with fewer than 3 vertices dropped).
Mesh snapped_to_start(const Mesh& m, const Mesh& start);
// What nearest_closed_selection may change and at which cost.
struct MendScope {
  bool whole_last = false;   // at last, every candidate free
  double keep_weight = 1.0;  // a start candidate dropped costs this times its area, one added its area
};
// The nearest selection to `in_start` that closes (every edge used 0 or 2 times) and makes none
// of `excluded`; empty when none is found (shell_supports.cpp says how it searches).
std::vector<char> nearest_closed_selection(CandidateSet& cs, const std::vector<char>& in_start,
                                           const SelectionConfig& prm, const MendScope& scope = {},
                                           const std::vector<LocalSelection>& excluded = {});
// Why an assembled shell cannot be written, or empty: validate_mesh's problem, or a face that
// passes through one vertex twice.
std::string shell_problem(const Mesh& m, const RepairConfig& prm);

}  // namespace lodrefine::detail
