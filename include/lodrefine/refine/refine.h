// The whole method for one building: repair the coarse model, detect scan planes, match them to
// walls, move the outdated walls (substitution), let the candidate selection decide the faces
// (shell_selection.h; when it ends with no shell, the substitution's stands in), validate, and
// keep the input unless the result fits the scan better.
#pragma once
#include <array>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "lodrefine/base/types.h"
#include "lodrefine/core/judge.h"
#include "lodrefine/core/matching.h"
#include "lodrefine/core/outcome.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/planes.h"
#include "lodrefine/core/repair.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/refine/shell_rebuild.h"
#include "lodrefine/refine/shell_selection.h"

namespace lodrefine {

// The stages a refinement times (RefineTrace::seconds), in the order refine_building runs them;
// "total" follows them. A building's run stops after any of them (a refusal, nothing to change).
// The README's Method numbers them 1-7, and each stage's header names its number and name
// (`// Stage 5, selection: ...`).
enum class RefineStage { Repair, Planes, Matching, Substitution, Selection, Judge, Validation };
inline constexpr std::array<const char*, 7> kRefineStageNames = {"repair",    "planes", "matching",  "substitution",
                                                                 "selection", "judge",  "validation"};
inline const char* stage_name(RefineStage stage) { return kRefineStageNames[std::size_t(stage)]; }

// What each stage found, kept for the report (built by city: city/refine_report.h).
// A record only: the stages hand their results to each other as values (the walls moved:
// move_plan.h) and never read them back from here. A stage the building did not reach leaves its
// member empty.
struct RefineTrace {
  struct MatchedWall {
    Match match;
    double deviation = 0.0;  // largest distance of the wall's vertices from its scan plane (m)
    std::vector<int> faces;  // the wall's faces in the repaired input
  };
  struct Matching {
    std::vector<MatchedWall> walls;
    std::vector<std::string> rejected;
    double q_model = 0.0;
  };
  struct Substitution {  // one substitution of several walls at once
    int walls = 0;
    bool ok = false;
    std::string reason;  // when !ok
    int moved_vertices = 0, split_faces = 0;
    double max_vertex_move = 0.0;
  };
  struct Step {  // one wall of the one-at-a-time fallback
    int scan_plane = -1;
    std::vector<int> wall_faces;
    double moved_by = 0.0;
    std::string method;  // "substitution"; empty when not tried
    bool ok = false;
    std::string reason;  // when !ok
  };
  struct FacadeMove {           // a moved wall, described on the mesh it was moved on
    std::set<int> input_faces;  // Face::source of its faces
    std::string evidence;       // "scan" or "corner"
    double max_move = 0.0, mean_move = 0.0;
  };

  std::string id;
  Vec3 origin = Vec3::Zero();                           // of the local frame
  std::vector<std::pair<std::string, double>> seconds;  // per stage, then "total"
  std::optional<RepairReport> repair;
  std::optional<Validation> input_validation;
  // When the repaired input was no valid solid: why, and its rebuild on its planes (no mesh).
  std::string invalid_input;
  std::optional<ShellRebuild> rebuild;
  Validation output_validation;
  std::size_t faces = 0;                                     // of the output
  std::optional<std::pair<std::size_t, std::size_t>> cloud;  // points, points near the model
  std::optional<std::vector<ScanPlane>> planes;              // the walls, roofs and ground (relief left out)
  // What the scan near the model is like: a survey's drives registered apart, relief, density.
  struct Scan {
    int doubled_walls = 0;                        // facades seen twice (ScanPlane::doubled)
    double misregistration = 0.0;                 // m: their distance, median over their points (0: none)
    std::vector<ScanPlane> relief;                // facade planes left out as relief (without_relief)
    std::size_t relief_points = 0;                // their points
    double relief_share = 0.0;                    // of the points near the model
    double min_density = 0.0, max_density = 0.0;  // points per m² on the facade planes kept
  };
  std::optional<Scan> scan;
  std::optional<Matching> matching;
  std::optional<Substitution> substitution;
  std::optional<std::vector<Step>> replacements;  // set together with `facades`
  std::vector<FacadeMove> facades;
  std::optional<Judgement> judgement;  // never worse (judge.h), when a refinement was made
  // The judge's refusal of the refinement with the corner moves, when it was tried again
  // without them (the judgement above is then the second attempt's).
  std::optional<std::string> corners_refused;
  // The judge's refusals of single scan moves (the wall check), each dropped in turn and the
  // building refined again on the other walls' moves.
  std::vector<std::string> walls_refused;
  std::optional<ShellSelectionStats> selection;  // the program that chose the output's faces
  std::string selection_reason;                  // why it gave no shell, when it did not

  // The seconds of `stage` (kRefineStageNames, or "total"); a retry's laps add up; none for a
  // stage the building did not reach.
  std::optional<double> stage_seconds(const std::string& stage) const {
    std::optional<double> sum;
    for (const auto& [name, s] : seconds)
      if (name == stage) sum = sum.value_or(0.0) + s;
    return sum;
  }
};

struct RefineResult {
  Mesh mesh;  // in the input (georeferenced) frame
  // Faces of the input no solid holds (ShellRebuild::fins: outside on both sides, beside a rebuilt
  // shell), same frame; written beside `mesh` (a city file's MultiSurface of the same LoD, an
  // OBJ's fins group). A model read back with them is a soup again: a second pass rebuilds the
  // shell, finds them again, and writes no refinement that would leave one floating.
  Mesh fins;
  Outcome outcome = Outcome::KeptInvalid;
  std::string reason;  // one line: why this outcome
  bool valid = false;  // `mesh` passed validate_mesh
  RefineTrace trace;
  bool refined() const { return outcome == Outcome::Refined; }
};

// Every model gets an output: the refined building, the repaired input, or the input as read,
// with the outcome and its reason. A refinement the judge refuses with corner moves is made again
// without them; one it refuses on a scan move's own wall, again without that move (in turn, while
// any is left). Never throws for a bad model (only for parameters out of
// range).
RefineResult refine_building(const Mesh& model, const PointCloud& cloud, const RefineConfig& config);

// The scan points refine_building works on, in the model's local frame (`origin` subtracted;
// crops may carry whole streets): those inside the model's bounding box grown by
// RefineConfig::scan_reach (m) and bbox_expand of its size on each side. `local_model` is in
// the local frame already.
PointCloud cloud_near(const Mesh& local_model, const PointCloud& cloud, const Vec3& origin, const RefineConfig& prm);

// The local origin used for a model: its bounding-box minimum rounded down to 100 m, so
// that all computation runs on small coordinates.
Vec3 local_origin(const Mesh& model);

}  // namespace lodrefine
