// A baseline to measure lodrefine against: CGAL 5.5's PolyFit (Nan & Wonka 2017,
// CGAL::Polygonal_surface_reconstruction with CGAL's GLPK traits, default weights) on one
// building's scan, with the planes lodrefine's own plane stage detects and, optionally, the
// coarse model's planes. Plain PolyFit: no substitution, no judge, no fallback to the model.
// Never throws: every way PolyFit can fail is a status with its one-line reason.
#pragma once
#include <string>

#include "lodrefine/base/types.h"
#include "lodrefine/core/params.h"

namespace lodrefine {

// Which planes PolyFit chooses its faces from.
enum class PolyfitPlanes {
  Scan,          // detect_planes on the scan near the model only
  ModelAndScan,  // those, plus one per surface of the repaired coarse model (sampled points)
};
const char* polyfit_planes_name(PolyfitPlanes planes);  // "scan", "model+scan"

struct PolyfitOptions {
  PolyfitPlanes planes = PolyfitPlanes::ModelAndScan;
  // m between the samples that stand for a model surface (its vertices are added too, so a
  // small surface still has a plane). Sparser than an MLS scan (~100 points/m²), so where the
  // scan sees a surface its points outweigh the model's in PolyFit's data term.
  double model_spacing = 0.25;
  // PolyFit's energy weights: CGAL's (and the paper's) defaults.
  double wt_fitting = 0.43, wt_coverage = 0.27, wt_complexity = 0.30;
  // Bounds of polyfit_baseline_isolated's child process. CGAL's arrangement and its GLPK traits
  // have none (the arrangement alone took 2 GB and minutes on a dev-tile building).
  double cpu_limit = 60.0;             // s of CPU time; beyond it: TimeLimit
  std::size_t memory_limit_mb = 2048;  // address space; beyond it an allocation fails: Error
};

enum class PolyfitStatus {
  Closed,     // the selected faces, corners welded, close (every edge joins two faces); oriented outward
  NotClosed,  // the program was solved but its faces do not close
  // No face selected: the empty selection scored best (the coverage term outweighs the fitting
  // of sparse evidence), or glp_intopt returned 0 without a solution (CGAL's traits do not ask
  // glp_mip_status): the two look alike from outside.
  Empty,
  Infeasible,    // glp_intopt failed (no feasible selection, or a solver error)
  TooFewPlanes,  // fewer than 4 planes or candidate faces: PolyFit cannot close a surface
  TimeLimit,     // the child process ran out of its CPU time (or of 10x that in wall time)
  Error,         // an exception (bad model, CGAL precondition, out of memory)
};
const char* polyfit_status_name(PolyfitStatus status);  // "closed", "not-closed", ...

struct PolyfitResult {
  PolyfitStatus status = PolyfitStatus::Error;
  std::string reason;  // one line; empty when closed
  Mesh mesh;           // input frame; the selected faces, corners welded (also when not closed), else empty
  int planes = 0;      // planes given to PolyFit (scan + model)
  int model_planes = 0;
  int candidates = 0;      // candidate faces of the arrangement (0 when it was not built)
  std::size_t points = 0;  // points given to PolyFit (scan points near the model + model samples)
  // Wall-clock seconds: the whole call; plane detection; CGAL (arrangement, confidences, solve).
  double seconds = 0, detection_seconds = 0, polyfit_seconds = 0;
  double cpu_seconds = 0;  // CPU time of the whole call (the child's, when isolated)
  bool closed() const { return status == PolyfitStatus::Closed; }
};

// PolyFit on `model` (a coarse LoD2 building, any frame, usually georeferenced) and `cloud` (its
// MLS crop, same frame). Computes in the model's local frame (refine.h's local_origin) on the
// scan points in the same region refine_building uses (the model's box grown by match_distance
// + bbox_margin and bbox_expand), with detect_planes(params) as lodrefine's plane stage; each
// point's normal is its plane's. With ModelAndScan the model is repaired (repair_input) and each
// of its surfaces (model_surfaces) adds a plane. Returns the mesh in the input frame.
PolyfitResult polyfit_baseline(const Mesh& model, const PointCloud& cloud, const RefineConfig& params,
                               const PolyfitOptions& options = {});

// The same in a forked child process with options.cpu_limit and memory_limit_mb, so that no
// building can hang, exhaust memory or crash the caller: a child killed at its limit is
// TimeLimit, one ended by another signal Error ("ended by signal N"). Call it from a
// single-threaded process (fork copies only the calling thread). POSIX only.
PolyfitResult polyfit_baseline_isolated(const Mesh& model, const PointCloud& cloud, const RefineConfig& params,
                                        const PolyfitOptions& options = {});

}  // namespace lodrefine
