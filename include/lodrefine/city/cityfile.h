// A city file in, a city file out: every building of a CityJSON / CityJSONSeq / CityGML model
// that the cloud covers is refined, and one CityJSON 2.0 file (or CityJSONSeq for a sequence)
// is written with everything else kept exactly.
//
// The cloud (one file or several, read as one: cloud.h) is read once: one streaming pass cuts a
// crop per building (lodrefine crop's box),
// then each building is refined on its crop, `jobs` buildings at once (memory: the crops, not
// the cloud); results are written in file order. A refined building's chosen LoD geometry is replaced by a Solid with
// semantics (WallSurface / RoofSurface / GroundSurface from the refined mesh's faces); its other LoDs, attributes and
// id stay. Every other building, attribute, LoD, the metadata and the transform are kept as read (new vertices are
// appended, so existing indices hold). Each building the cloud reaches gets the attributes lodrefine_outcome ("refined"
// / "repaired" / "kept" / "kept-invalid"), lodrefine_reason and lodrefine_facades_moved; buildings without cloud points
// are untouched (with repair_all, those too are repaired when they are no valid solid, and get the attributes). A
// repaired building (no valid solid as read, its shell rebuilt on its own planes: refine.h) is written as a Solid, as a
// refined one is. CityGML input is converted first (citygml_to_cityjson) and written as CityJSON 2.0.
#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lodrefine/core/judge.h"
#include "lodrefine/core/outcome.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/formats/cityjson_write.h"  // cityjson_solid, cityjson_multisurface
#include "lodrefine/formats/cloud.h"

namespace lodrefine {

struct CityBuildingOutcome;
struct RefineResult;

// Called once per building of the file when set (e.g. to collect a review page): in file order on
// the caller's thread for a CityJSON file; for a CityJSONSeq by the thread that refines the
// feature, so concurrently and in any order when jobs > 1 (the hook must then be thread-safe,
// and order what it collects by `index`, the building's place among the file's buildings).
// `outcome` and `crop` are null for a building the cloud does not reach, `result` is null unless
// refine_building returned. All in the input frame.
using CityBuildingHook = std::function<void(std::size_t index, const Mesh& model, const CityBuildingOutcome* outcome,
                                            const RefineResult* result, const PointCloud* crop)>;
struct CityRefineSummary;

inline constexpr std::uint64_t kDefaultMaxCropPoints = 50000000;

struct CityRefineOptions {
  std::string building;      // refine only this CityObject id ("" = every building the cloud covers)
  std::string lod;           // the LoD geometry to refine, e.g. "2.2" ("" = the highest 2.x)
  CloudOptions cloud;        // LAS class filter
  double crop_expand = 0.1;  // crop box growth, relative and absolute (as lodrefine crop)
  double crop_margin = 3.0;
  // The most points the crops may hold together: they are in memory during the run (24 bytes
  // each, up to twice that while a crop's vector grows: ~1.2-2.4 GB at the default), and a LAZ
  // file of a few hundred kilobytes can announce 1e9 identical points. Delfshaven's 16.6 M point
  // tile fills its 853 crops with 36.7 M. Beyond, the run is refused.
  std::uint64_t max_crop_points = kDefaultMaxCropPoints;
  CityBuildingHook on_building;  // optional
  // Buildings refined at once, each on its own thread (1: one after another on the caller's).
  // The output is the same bytes whatever the number.
  int jobs = 1;
  // Every building goes through refinement, with or without cloud points: each one that is no
  // valid solid is repaired (or kept-invalid) and says so; the others are kept as read. With it,
  // the cloud may be no file at all (refine_city's cloud_paths empty: lodrefine repair).
  bool repair_all = false;
  // With repair_all: only the buildings validate_soup finds invalid (val3dity's tolerances) go
  // through refinement; the valid ones are written exactly as read, and are in the summary's
  // outcomes as untouched (lodrefine repair).
  bool only_invalid = false;
  // Called after each building (CityJSONSeq: each feature) is written into the output, in
  // file order on the caller's thread, with the counts so far (may be empty).
  std::function<void(const CityRefineSummary&)> progress;
  std::function<void(std::uint64_t)> crop_progress;  // points read so far in the cloud pass (may be empty)
};

struct CityBuildingOutcome {
  std::string id;
  Outcome outcome = Outcome::KeptInvalid;  // refined, repaired, kept or kept-invalid (outcome_name: the text)
  std::string reason;                      // why repaired / kept / kept-invalid (empty when refined)
  int facades_moved = 0;
  JudgeCheck refused_by = JudgeCheck::None;  // the never-worse check that refused its refinement (judge.h)
  std::size_t points = 0;                    // cloud points in the building's crop box
  double seconds = 0.0;
  // The defects under val3dity's codes (validate.h: validate_soup, val3dity's tolerances) of the
  // geometry as read and of the geometry written (the same when it is kept as read).
  std::vector<ValidityError> errors_before{}, errors_after{};
};

struct CityRefineSummary {
  std::string input_format;  // "CityJSON 2.0", "CityJSONSeq 2.0", "CityGML 2.0"
  int buildings = 0;         // LoD 2 buildings / building parts in the file
  int refined = 0, repaired = 0, kept = 0, kept_invalid = 0;
  int untouched = 0;                   // no cloud point in their box: written exactly as read
  std::map<std::string, int> refused;  // kept because this never-worse check refused the refinement
  int objects_without_lod = 0;         // Building/BuildingPart objects without the LoD asked for
  std::uint64_t cloud_points = 0;      // points read (after the class filter)
  std::vector<CloudFileRead> clouds;   // each cloud file, in reading order: its points and bounds
  // One line per cloud file whose bounds miss the city model ("<file>: cloud x .. does not overlap
  // the city model ..: wrong CRS or tile?") when other files reach it (else the run is refused).
  std::vector<std::string> warnings;
  std::uint64_t cropped_points = 0;  // points held in the crops after the cloud pass (the memory that grows)
  // The buildings the cloud reached (only_invalid: every building), in file order.
  std::vector<CityBuildingOutcome> outcomes;
  double seconds_read = 0.0, seconds_crop = 0.0, seconds_refine = 0.0, seconds_write = 0.0;
};

// Throws InputError (one line, nothing written) when the model or a cloud file cannot be read,
// when no building has the LoD asked for, when --building names no such building, or when no
// cloud file reaches a building ("cloud x..y does not overlap the city model x..y: wrong CRS or
// tile?"). A building whose refinement throws is kept as read with outcome kept-invalid and the
// reason. `cloud_paths` are files (cloud_files expands folders), read in that order as one cloud:
// the output is that of one file holding their points in that order; none at all only with
// repair_all (every building is then repaired without a scan). Every building the refinement
// reaches gets the attributes lodrefine_outcome, lodrefine_reason, lodrefine_facades_moved and,
// when it had or has errors (errors_before or errors_after not empty), lodrefine_errors_before /
// lodrefine_errors_after (their codes); a valid building's other attributes stay as read.
CityRefineSummary refine_city(const std::string& model_path, const std::vector<std::string>& cloud_paths,
                              const std::string& out_path, const RefineConfig& params,
                              const CityRefineOptions& options);

}  // namespace lodrefine
