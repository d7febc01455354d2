// Stage 6, judge: never worse, for the whole building. The refined model is written only when the scan
// shows it better than the input, judged on every scan point near the building (facade points
// matched to a wall or not, roof points; street ground excepted), and on each moved wall's own
// points: a wall with points in front of it must fit them better; a wall without points
// may move only on the scan's corner evidence (corners.h).
//
// Inputs are in one (local) frame; distances in metres. A point is judged when it lies within
// MatchConfig::match_distance of either model (the cap: farther points are another object's) and
// above the lowest model vertex + kStreetGroundBand (corners.h: street ground in front of a wall moved inwards
// would count against a right move), and not a flush neighbour's (JudgedWall::flush_facade). Its
// distance to each model is capped at match_distance. A scanned facade line farther off is the
// building's, not another object's, where it stands before none of the face's own points: an
// inlier of a facade scan plane whose nearest point on either model lies inside a face facing
// like the plane (within match_angle_deg), in a column along that face (0.5 m wide, with its
// neighbours) holding no point within the cap whose nearest face it is, is judged up to
// `facade_reach` and capped there. So a move away from a setback's front line 2 m out counts,
// and a neighbour's side wall across an alley, standing before the wall's own points, does not.
// A return in space both models leave empty is no evidence either: a point outside both models by
// more than on_plane_band (corners.h) is judged only as an inlier of a scan plane that faces its
// nearest face in one of them (as above). A parked car, a tree or the neighbour's facade running on
// past the corner says only that its space is empty; it would count against every wall moved away
// from it. Points inside either model (the scanner saw through it) or on either's surface count.
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/types.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/planes.h"

namespace lodrefine {

// A wall the refinement moved, described before the move.
struct JudgedWall {
  std::vector<std::vector<Vec3>> polygons;  // its faces before the move
  Plane from, to;                           // its plane before and after (oriented outwards)
  bool corner = false;                      // moved on corner evidence (the scan shows its corner, not its face)
  // Moved to a flush neighbour's party wall (corners.h): the facade's plane; points on or behind
  // it past the wall's new plane are the neighbour's and are not judged.
  std::optional<Plane> flush_facade;
};

// The never-worse check that refused a refinement (None: none did).
enum class JudgeCheck { None, Building, Wall, Gain };
// Its name in reports and reasons: "building", "wall", "gain"; "" for None.
inline const char* check_name(JudgeCheck check) {
  switch (check) {
    case JudgeCheck::None: return "";
    case JudgeCheck::Building: return "building";
    case JudgeCheck::Wall: return "wall";
    case JudgeCheck::Gain: return "gain";
  }
  return "?";
}

struct Judgement {
  struct Fit {
    std::size_t points = 0;                    // judged points
    std::size_t better = 0, worse = 0;         // closer / farther by more than PlaneConfig::ransac_epsilon
    double rms_before = 0.0, rms_after = 0.0;  // of the capped distances
  };
  bool ok = true;
  JudgeCheck check = JudgeCheck::None;  // the check that refused; None when ok
  std::string detail;                   // one line with the figures of the refusal; empty when ok
  int wall = -1;                        // the refused wall (index into the JudgedWalls) when check is Wall
  Fit building;                         // every judged point
  std::vector<Fit> walls;               // per JudgedWall, its own points
  // "<check> check: <detail>", the refusal in a reason.
  std::string refusal() const { return check_name(check) + std::string(" check: ") + detail; }
};

// Whether `after` may replace `before` (both closed meshes, same frame as `cloud`). `planes`:
// the scan planes detected in `cloud` (indices into it), for the facade lines beyond
// match_distance, judged up to `facade_reach` (m; refine: RefineConfig::scan_reach, the
// reach of the selection's scan supports); without them every point is capped at match_distance.
// - building: refused when the capped RMS of every judged point grows by more than kRmsSlack,
//   or when more than kWorseShare of the points that changed (by more than
//   PlaneConfig::ransac_epsilon) got farther;
// - wall: each moved wall's own points (the judged points whose nearest face is the wall, before
//   the move or after it, and that lie on its old or its new plane within on_plane_band,
//   corners.h) must not grow in RMS by more than kWallRmsSlack (window recesses and clutter on
//   the wall are among them, so it is judged on the RMS only); a wall with fewer than
//   PlaneConfig::ransac_min_points points is unscanned and passes only when the wall moved on
//   corner evidence. Points nearest the wall but on neither plane stand on other surfaces (a
//   neighbour, a return): they count for the building, not for whether the wall is scanned.
// - gain: fewer than kMinGain points got closer and no moved wall's own points' RMS dropped by
//   kMinRmsGain (a move within the scan's noise, e.g. a correct wall refitted a few cm off by
//   its windows, is no refinement).
// The building is judged first, then each wall, then the gain. Refuses (never throws) when a
// mesh has no face.
constexpr double kRmsSlack = 0.001;     // m
constexpr double kWallRmsSlack = 0.01;  // m
constexpr double kWorseShare = 0.25;
constexpr int kMinGain = 50;
constexpr double kMinRmsGain = 0.001;  // m
Judgement judge_refinement(const Mesh& before, const Mesh& after, const std::vector<JudgedWall>& walls,
                           const PointCloud& cloud, const MatchConfig& match, const PlaneEvidence& detection,
                           const std::vector<ScanPlane>& planes = {}, double facade_reach = 0.0);

}  // namespace lodrefine
