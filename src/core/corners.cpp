// Stage 3, matching: corners from the scan's extent, see corners.h.
#include "lodrefine/core/corners.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>

#include "lodrefine/base/topology.h"

namespace lodrefine {
namespace {

// Inliers of a facade plane are connected within the RANSAC cluster epsilon; a longer empty
// stretch along the facade ends it (a gap to a neighbour, or the corner).
constexpr double kInlierGap = 0.5;
// Corners closer than this to the scan's end already agree with it (scan spacing ~ cm).
constexpr double kCornerTolerance = 0.05;
// The end must be the same in every height band within this: a vertical building edge, not
// an occluder's outline.
constexpr double kEndSpread = 0.15;
constexpr int kBands = 4;
// At a facade's end the scanner must have seen the return onto the side wall within this depth
// off the facade (m), above the low part of the wall (ground and clutter below kLowBand of its
// height do not count), in all but kBands - 2 of the height bands.
constexpr double kLookPast = 1.0;
constexpr double kLowBand = 0.25;
// Stray inliers tolerated past a facade's end (noise, a drainpipe).
constexpr int kStrayPoints = 10;
// A return: at least this many points, the nearest within kReturnStart (m) of the facade's
// noise band, running at least kMinReturnDepth (m) back from it.
constexpr int kMinReturnPoints = 50;
constexpr double kReturnStart = 0.1;
constexpr double kMinReturnDepth = 0.3;
// Adjacent walls turned less than this from the scanned one are no corner (cos 45 deg).
constexpr double kMaxCornerCos = 0.707;
// The open end: the strip past (and before) a facade's end that is looked at (m along the
// facade), how far in front of the facade the street is looked at (m), and how much of it:
// street ground past the end at least kStreetGoesOn of that before it (a tile edge or the end
// of the drive cuts the ground too), things in front at the facade's height fewer than
// kClearInFront of the facade's own points before the end (an occluder's shadow), nothing on
// the facade's plane at its height past the end beyond stray points.
constexpr double kStrip = 2.0;
constexpr double kStreetNear = 0.3, kStreetFar = 10.0;
constexpr double kStreetGoesOn = 0.5;
constexpr double kClearInFront = 0.05;
// A flush neighbour: the facade's outline is read in bands of kHeightBand (m); at least kBands
// of them must show the corner, from kAboveTop (m) over the wall's top for a taller neighbour
// (a gutter or a roof's edge there does not count).
constexpr double kHeightBand = 0.5;
constexpr double kAboveTop = 0.3;
// A facade the scan moves by this much on average is misplaced beyond doubt: scan planes are good
// to a centimetre or two, airborne LoD2 facades are decimetres off.
constexpr double kMisplacedFacade = 0.1;
// Off the facade's plane means farther than this many RANSAC epsilons (its inliers lie within
// one; two keep the plane's own noisy points out).
constexpr double kOffPlaneEpsilons = 2.0;

// How far along +t the run of points starting at t = 0 reaches (-1 when it does not start).
double run_end(std::vector<double> t) {
  std::sort(t.begin(), t.end());
  double e = 0.0;
  bool started = false;
  for (double x : t) {
    if (x < 0) continue;
    if (x - e > kInlierGap) break;
    e = std::max(e, x);
    started = true;
  }
  return started ? e : -1.0;
}

// Which side of the scanned facade's plane the adjacent wall lies on: -1 behind it (a convex
// corner, the side wall runs back into the block), +1 in front (a concave corner).
double side_of(const Mesh& mesh, const ModelSurface& wall, const Plane& facade) {
  double sum = 0.0;
  for (int f : wall.faces)
    for (int v : mesh.faces[f].v) sum += facade.distance(mesh.vertices[v]);
  return sum >= 0 ? 1.0 : -1.0;
}

// Whether points lie on the side wall's new plane `moved`, off the facade plane on the wall's
// `side`, over the upper part of the facade's height [z0, z1] (ground and clutter below do not
// count): the return the scanner saw where the facade turns the corner.
bool shows_return(const PointCloud& cloud, const Plane& facade, const Plane& moved, double side, double z0, double z1,
                  const PlaneEvidence& prm) {
  const double on_plane = on_plane_band(prm);
  const double za = z0 + kLowBand * (z1 - z0);
  const double off = kOffPlaneEpsilons * prm.ransac_epsilon;
  int count = 0;
  double near = kLookPast, far = 0.0;
  std::set<int> bands;
  for (const auto& p : cloud.points) {
    if (p.z() < za || p.z() > z1) continue;
    const double depth = side * facade.distance(p);
    if (depth <= off || depth > kLookPast) continue;
    if (std::abs(moved.distance(p)) > on_plane) continue;
    ++count;
    near = std::min(near, depth);
    far = std::max(far, depth);
    bands.insert(std::min(kBands - 1, int(kBands * (p.z() - z0) / (z1 - z0))));
  }
  // A return starts at the facade and runs back from it (a strip of points at one depth is a
  // recess's or a neighbour's edge, not the building's side).
  return count >= kMinReturnPoints && int(bands.size()) >= kBands - 2 && near <= off + kReturnStart &&
         far - near >= kMinReturnDepth;
}

// Points in the strips just past and just before a facade's end (t: position along the facade
// towards the corner, measured from the wall's middle): the street's ground at the wall's foot
// `ground`, the facade at the corner's heights [z0, z1].
struct EndStrips {
  int street_past = 0, street_before = 0;  // ground in front of the facade
  int front_past = 0;                      // in front of the facade at its height
  int facade_past = 0, facade_before = 0;  // on the facade's plane at its height
};

EndStrips end_strips(const PointCloud& cloud, const Plane& facade, const Vec3& o, const Vec3& u, double s, double end,
                     double ground, double z0, double z1, const PlaneEvidence& prm) {
  const double za = z0 + kLowBand * (z1 - z0);
  const double on_plane = on_plane_band(prm);
  EndStrips e;
  for (const auto& p : cloud.points) {
    const double t = s * (p - o).dot(u) - end;
    const bool past = t > kCornerTolerance && t <= kStrip, before = t < -kCornerTolerance && t >= -kStrip;
    if (!past && !before) continue;
    const double d = facade.distance(p);  // outwards: the street side
    const bool in_front = d > kStreetNear && d < kStreetFar;
    const bool high = p.z() > za && p.z() < z1;
    if (in_front && p.z() < ground + kStreetGroundBand) ++(past ? e.street_past : e.street_before);
    if (in_front && high && past) ++e.front_past;
    if (std::abs(d) <= on_plane && high) ++(past ? e.facade_past : e.facade_before);
  }
  return e;
}

// Whether the facade's scan ends in the open: the scanner went on past the end (the street in
// front continues), nothing in front hid the facade there, and no facade is seen beyond. This
// is where a building ends -- or where a scan of a neighbour's facade was cut off, which looks
// the same; so it counts only for a facade the scan itself found displaced, a building the
// scan already shows mis-modelled (a correct building's facades all agree with the scan).
bool ends_in_the_open(const EndStrips& e) {
  return e.street_past >= kStreetGoesOn * e.street_before && e.front_past <= kClearInFront * e.facade_before &&
         e.facade_past <= kStrayPoints;
}

// Surfaces adjacent across an edge: (wall, neighbour) -> the edges they share.
using Adjacency = std::map<std::pair<int, int>, std::vector<std::pair<int, int>>>;
Adjacency adjacent_surfaces(const Mesh& mesh, const std::vector<ModelSurface>& surfaces) {
  std::vector<int> face_surface(mesh.faces.size(), -1);
  for (int s = 0; s < int(surfaces.size()); ++s)
    for (int f : surfaces[s].faces) face_surface[f] = s;
  Adjacency shared;
  for (const auto& [e, us] : edge_uses(mesh.faces)) {
    if (us.size() != 2) continue;
    const int s0 = face_surface[us[0].face], s1 = face_surface[us[1].face];
    if (s0 == s1) continue;
    shared[{s0, s1}].push_back(e);
    shared[{s1, s0}].push_back(e);
  }
  return shared;
}

// A scanned wall seen along its facade: a horizontal axis u from o, the wall's extent on it
// (centred at u_mid) and in height, and the scan plane's points over the wall's height as
// positions along u (from u_mid) and heights.
struct FacadeScan {
  Vec3 o, u;
  double u_mid = 0.0, z0 = 1e300, z1 = -1e300;
  std::vector<double> pu, pz;
  bool displaced = false;  // the scan moves the wall by kMisplacedFacade or more
};

FacadeScan facade_scan(const Mesh& mesh, const ModelSurface& ws, const ScannedWall& w, const PointCloud& cloud,
                       const std::vector<ScanPlane>& planes) {
  FacadeScan f;
  f.u = w.plane.basis().first;  // horizontal
  f.o = w.plane.project(ws.centroid);
  double u0 = 1e300, u1 = -1e300;
  for (int fi : ws.faces)
    for (int vi : mesh.faces[fi].v) {
      const Vec3& p = mesh.vertices[vi];
      u0 = std::min(u0, (p - f.o).dot(f.u));
      u1 = std::max(u1, (p - f.o).dot(f.u));
      f.z0 = std::min(f.z0, p.z());
      f.z1 = std::max(f.z1, p.z());
    }
  f.u_mid = 0.5 * (u0 + u1);
  f.displaced = surface_mean_deviation(mesh, ws, w.plane) >= kMisplacedFacade;
  for (int i : planes[w.scan_plane].inliers) {
    const Vec3& p = cloud.points[i];
    if (p.z() < f.z0 || p.z() > f.z1) continue;
    f.pu.push_back((p - f.o).dot(f.u) - f.u_mid);
    f.pz.push_back(p.z());
  }
  return f;
}

// Whether the facade's points (positions t towards the corner) end at the same place, within
// kEndSpread, in all but one of the height bands: a vertical building edge, not an occluder.
bool same_end_over_the_height(const FacadeScan& f, const std::vector<double>& t) {
  double lo = 1e300, hi = -1e300;
  int bands = 0;
  for (int b = 0; b < kBands; ++b) {
    const double za = f.z0 + (f.z1 - f.z0) * b / kBands, zb = f.z0 + (f.z1 - f.z0) * (b + 1) / kBands;
    std::vector<double> tb;
    for (std::size_t k = 0; k < f.pu.size(); ++k)
      if (f.pz[k] >= za && f.pz[k] < zb) tb.push_back(t[k]);
    const double eb = run_end(tb);
    if (eb < 0) continue;
    ++bands;
    lo = std::min(lo, eb);
    hi = std::max(hi, eb);
  }
  return bands >= kBands - 1 && hi - lo <= kEndSpread;
}

// The facade's scan over the heights [z0, z1] of one corner: where a facade steps (an upper
// storey set back, a lower wing running on), its end at the corner shows only at those heights.
FacadeScan at_heights(const FacadeScan& f, double z0, double z1) {
  FacadeScan g = f;
  g.pu.clear();
  g.pz.clear();
  g.z0 = z0;
  g.z1 = z1;
  for (std::size_t k = 0; k < f.pu.size(); ++k)
    if (f.pz[k] >= z0 && f.pz[k] <= z1) {
      g.pu.push_back(f.pu[k]);
      g.pz.push_back(f.pz[k]);
    }
  return g;
}

// Per band of kHeightBand from z0 up (n bands), the largest position t below `hi` of the points
// (positions t, heights z) at or past `lo`; -1e300 for a band without any.
std::vector<double> band_ends(const std::vector<double>& t, const std::vector<double>& z, double z0, int n, double lo,
                              double hi) {
  std::vector<double> ends(std::size_t(n), -1e300);
  for (std::size_t k = 0; k < t.size(); ++k) {
    const int b = int(std::floor((z[k] - z0) / kHeightBand));
    if (b >= 0 && b < n && t[k] >= lo && t[k] < hi) ends[std::size_t(b)] = std::max(ends[std::size_t(b)], t[k]);
  }
  return ends;
}

// The edge where consecutive bands (from the first that has points) end short of `stop` (a
// band whose points run on to it is the flush facade): the farthest end (a window near the edge
// ends its band short), when at least kBands of them end within kEndSpread of it.
std::optional<double> one_edge(const std::vector<double>& ends, double stop) {
  std::vector<double> run;
  for (double e : ends) {
    if (e < -1e299 && run.empty()) continue;  // bands the scan does not reach
    if (e < -1e299 || e > stop) break;
    run.push_back(e);
  }
  if (run.empty()) return std::nullopt;
  const double edge = *std::max_element(run.begin(), run.end());
  const auto at_edge = std::count_if(run.begin(), run.end(), [&](double e) { return e >= edge - kEndSpread; });
  if (at_edge < kBands) return std::nullopt;
  return edge;
}

// Where a facade that runs on past the corner at uc into a flush neighbour's (one plane below
// the lower roof) shows the party wall, within `reach` of the corner (t: position along the
// facade towards the corner): the wall's own points above a lower neighbour end there, top
// bands down; or the points of a taller neighbour above the wall's top (`top`) start there.
std::optional<double> flush_neighbour_edge(const PointCloud& cloud, const FacadeScan& f, const Plane& facade, double s,
                                           double uc, double reach, double top, const PlaneEvidence& prm) {
  std::vector<double> t(f.pu.size());
  for (std::size_t k = 0; k < t.size(); ++k) t[k] = s * f.pu[k];
  const int n = int(std::ceil((f.z1 - f.z0) / kHeightBand));
  std::vector<double> own = band_ends(t, f.pz, f.z0, n, uc - reach, uc + reach);
  std::reverse(own.begin(), own.end());
  if (auto e = one_edge(own, uc + reach - kInlierGap)) return e;
  // The taller neighbour's points, positions negated: their start is the largest.
  const double on_plane = on_plane_band(prm), z0 = top + kAboveTop;
  std::vector<double> back, z;
  for (const auto& p : cloud.points)
    if (p.z() >= z0 && std::abs(facade.distance(p)) <= on_plane) {
      back.push_back(-s * ((p - f.o).dot(f.u) - f.u_mid));
      z.push_back(p.z());
    }
  const auto e = one_edge(band_ends(back, z, z0, 2 * kBands, -uc - reach, -uc + reach), -uc + reach - kInlierGap);
  if (!e) return std::nullopt;
  return -*e;
}

// The move of the unscanned neighbour `a` (sharing `edges` with the scanned wall) to where the
// facade's points end, when the scan shows that corner.
std::optional<CornerMove> corner_at(const Mesh& mesh, const FacadeScan& wall_scan, const ScannedWall& w, int a,
                                    const ModelSurface& as, const std::vector<std::pair<int, int>>& edges,
                                    const PointCloud& cloud, const MatchConfig& prm, const PlaneEvidence& detection) {
  // The corner on the scanned plane, at mid height of the shared edge; the facade's points over
  // the edge's heights (the street's ground stays at the wall's foot).
  double zc = 0.0, ze0 = 1e300, ze1 = -1e300;
  for (const auto& [i, j] : edges) {
    zc += 0.5 * (mesh.vertices[i].z() + mesh.vertices[j].z());
    ze0 = std::min({ze0, mesh.vertices[i].z(), mesh.vertices[j].z()});
    ze1 = std::max({ze1, mesh.vertices[i].z(), mesh.vertices[j].z()});
  }
  zc /= double(edges.size());
  const double edge_u = (mesh.vertices[edges.front().first] - wall_scan.o).dot(wall_scan.u) - wall_scan.u_mid;
  const FacadeScan f = at_heights(wall_scan, ze0, ze1);
  if (f.pu.empty()) return std::nullopt;
  const auto c = meet(w.plane, as.plane, Plane(Vec3::UnitZ(), -zc));
  if (!c) return std::nullopt;
  const double uc = (*c - f.o).dot(f.u) - f.u_mid;
  const double s = uc >= 0 ? 1.0 : -1.0;
  std::vector<double> t(f.pu.size());
  for (std::size_t k = 0; k < f.pu.size(); ++k) t[k] = s * f.pu[k];
  double end = run_end(t);
  if (end < 0) return std::nullopt;
  // A facade running on past the corner into a flush neighbour's: on a facade the scan found
  // misplaced, the party wall where one of the two is taller is the corner (corners.h).
  std::optional<double> party_wall;
  if (end - s * uc > prm.match_distance && f.displaced)
    party_wall = flush_neighbour_edge(cloud, f, w.plane, s, s * uc, prm.match_distance, wall_scan.z1, detection);
  if (party_wall) end = *party_wall;
  const double gap = end - s * uc;  // > 0: the scan runs past the corner
  if (std::abs(gap) <= kCornerTolerance || std::abs(gap) > prm.match_distance) return std::nullopt;
  const Plane moved(as.plane.n, as.plane.d - as.plane.n.dot(s * gap * f.u));
  if (!party_wall) {
    // Points of this plane again past the end, short of the corner: the run ended at a gap in
    // the facade (a recessed entrance), not at the building's edge.
    int beyond = 0;
    for (double x : t) beyond += x > end + kInlierGap && x <= s * uc + prm.match_distance;
    if (beyond > kStrayPoints) return std::nullopt;
    // The scan must show the corner itself (corners.h): a return onto the side wall where the
    // facade's points end, or an open end on a facade the scan found misplaced.
    // An open end at the model's own corner edge (the facade's outline at those heights) agrees
    // with the model: a skewed side wall's corner slides along the facade as the facade moves,
    // and a scan that just ends where the model does shows nothing more (no points, no evidence).
    const bool off_the_edge = std::abs(end - s * edge_u) > kCornerTolerance;
    if (!shows_return(cloud, w.plane, moved, side_of(mesh, as, w.plane), f.z0, f.z1, detection) &&
        !(f.displaced && off_the_edge &&
          ends_in_the_open(
              end_strips(cloud, w.plane, f.o, f.u, s, end + s * f.u_mid, wall_scan.z0, f.z0, f.z1, detection))))
      return std::nullopt;
    if (!same_end_over_the_height(f, t)) return std::nullopt;
  }
  CornerMove cm;
  cm.move.surface = a;
  cm.move.plane = moved;
  cm.scanned_surface = w.surface;
  cm.shift = gap;
  if (party_wall) cm.flush_facade = w.plane;
  return cm;
}

// A wall between two scanned facades must get the same answer from both (within kEndSpread);
// it moves to their mean.
std::vector<CornerMove> agreed_moves(const std::map<int, std::vector<CornerMove>>& evidence) {
  std::vector<CornerMove> out;
  for (const auto& [a, list] : evidence) {
    double lo = 1e300, hi = -1e300, sum = 0.0;
    for (const auto& cm : list) {
      lo = std::min(lo, cm.move.plane.d);
      hi = std::max(hi, cm.move.plane.d);
      sum += cm.move.plane.d;
    }
    if (hi - lo > kEndSpread) continue;
    CornerMove cm = list.front();
    cm.move.plane.d = sum / double(list.size());
    out.push_back(cm);
  }
  return out;
}

}  // namespace

double on_plane_band(const PlaneEvidence& prm) {
  return std::max(kCornerTolerance, kOffPlaneEpsilons * prm.ransac_epsilon);
}

std::vector<CornerMove> corner_moves(const Mesh& mesh, const std::vector<ModelSurface>& surfaces,
                                     const std::vector<ScannedWall>& scanned, const PointCloud& cloud,
                                     const std::vector<ScanPlane>& planes, const MatchConfig& prm,
                                     const PlaneEvidence& detection) {
  const Adjacency shared = adjacent_surfaces(mesh, surfaces);
  std::set<int> is_scanned;
  for (const auto& w : scanned) is_scanned.insert(w.surface);
  std::map<int, std::vector<CornerMove>> evidence;  // per adjacent wall
  for (const auto& w : scanned) {
    const ModelSurface& ws = surfaces[w.surface];
    const FacadeScan f = facade_scan(mesh, ws, w, cloud, planes);
    if (f.pu.empty()) continue;
    for (const auto& [key, edges] : shared) {
      if (key.first != w.surface) continue;
      const int a = key.second;
      const ModelSurface& as = surfaces[a];
      if (as.sem != Semantic::Wall || is_scanned.count(a)) continue;
      if (std::abs(as.plane.n.dot(ws.plane.n)) > kMaxCornerCos) continue;
      if (auto cm = corner_at(mesh, f, w, a, as, edges, cloud, prm, detection)) evidence[a].push_back(*cm);
    }
  }
  return agreed_moves(evidence);
}

}  // namespace lodrefine
