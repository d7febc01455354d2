// Stage 3, matching: model-to-surface matching (paper Sec. 3.1).
#include "lodrefine/core/matching.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "lodrefine/base/topology.h"

namespace lodrefine {
namespace {

// Walls meeting at less than this angle make no corner (their meet runs away with any small
// move); kMinCornerSin is its sine, the length of the cross product of two unit normals.
constexpr double kMinCornerAngleDeg = 30.0;
constexpr double kMinCornerSin = 0.5;
// Areas in ratios are at least this (m^2): an empty or flat box divides by no zero.
constexpr double kMinArea = 1e-12;
// A wall needs this many of a plane's points in front of it to be matched (as many as RANSAC's
// default minimum of a plane: fewer is a stray patch, not the wall's scan).
constexpr int kMinOwnedPoints = 150;
// Wall surfaces smaller than this (m^2) are slivers (e.g. hole fills), no facades: a large scan
// box would "cover" them. The default minimum area of a scan plane.
constexpr double kMinWallArea = 1.0;

// In-plane extent [min u, max u] x [min v, max v] of points in a surface's frame.
struct Rect {
  double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300;
  void add(double u, double v) {
    u0 = std::min(u0, u);
    u1 = std::max(u1, u);
    v0 = std::min(v0, v);
    v1 = std::max(v1, v);
  }
  double area() const { return std::max(0.0, u1 - u0) * std::max(0.0, v1 - v0); }
};

// The surface's extent in its own plane frame (u, v) around its centroid.
Rect surface_rect(const Mesh& mesh, const ModelSurface& surf) {
  const auto [u, v] = surf.plane.basis();
  Rect box;
  for (int f : surf.faces)
    for (int vi : mesh.faces[f].v) {
      const Vec3 q = mesh.vertices[vi] - surf.centroid;
      box.add(q.dot(u), q.dot(v));
    }
  return box;
}

double overlap_area(const Rect& a, const Rect& b) {
  const double du = std::min(a.u1, b.u1) - std::max(a.u0, b.u0);
  const double dv = std::min(a.v1, b.v1) - std::max(a.v0, b.v0);
  return du > 0 && dv > 0 ? du * dv : 0.0;
}

// Two surfaces are adjacent when they share a vertex.
bool adjacent(const Mesh& mesh, const ModelSurface& a, const ModelSurface& b) {
  std::vector<int> va, vb;
  for (int f : a.faces) va.insert(va.end(), mesh.faces[f].v.begin(), mesh.faces[f].v.end());
  for (int f : b.faces) vb.insert(vb.end(), mesh.faces[f].v.begin(), mesh.faces[f].v.end());
  std::sort(va.begin(), va.end());
  std::sort(vb.begin(), vb.end());
  std::vector<int> common;
  std::set_intersection(va.begin(), va.end(), vb.begin(), vb.end(), std::back_inserter(common));
  return !common.empty();
}

// How far the corner where `plane` meets the adjacent facade's scan plane lies beyond both the
// end of that facade's points and the end of its wall in the model (`adjacent_wall`: 0 when
// either reaches it). A wall moved onto a neighbour's wall across a gap puts the new corner past
// where the adjacent facade ends, in the scan and in the model; a scan that stops short of the
// corner (a tree, a parked van, the range) leaves the model's corner where it was.
double corner_gap(const Plane& plane, const ScanPlane& adjacent_scan, const PointCloud& cloud,
                  const std::vector<Vec3>& adjacent_wall) {
  const auto [u, v] = adjacent_scan.plane.basis();
  const Vec3 dir = plane.n.cross(adjacent_scan.plane.n);
  if (dir.norm() < kMinCornerSin) return 0.0;  // not a corner (near-parallel walls)
  // A point on the corner line, at the height of the adjacent scan's centroid.
  const auto corner = meet(plane, adjacent_scan.plane, Plane::through(adjacent_scan.centroid, v));
  if (!corner) return 0.0;
  const double uc = (*corner - adjacent_scan.centroid).dot(u);
  double lo = 1e300, hi = -1e300;
  const Vec3 along = u;  // a lambda may not capture a structured binding (C++17)
  auto extend = [&](const Vec3& p) {
    const double q = (p - adjacent_scan.centroid).dot(along);
    lo = std::min(lo, q);
    hi = std::max(hi, q);
  };
  for (int i : adjacent_scan.inliers) extend(cloud.points[i]);
  for (const Vec3& p : adjacent_wall) extend(p);
  return std::max({0.0, uc - hi, lo - uc});
}

// The surface of faces `members`: PCA plane oriented outward, area, area-weighted centroid,
// and the semantic covering most of its area (one plane, one surface: a mislabelled piece, a
// repaired hole say, takes its surface's).
ModelSurface describe_surface(const Mesh& mesh, const std::vector<int>& members) {
  ModelSurface s;
  s.faces = members;
  std::map<Semantic, double> sem_area;
  std::vector<Vec3> pts;
  Vec3 nsum = Vec3::Zero(), csum = Vec3::Zero();
  for (int f : members) {
    const auto poly = face_points(mesh, mesh.faces[f]);
    pts.insert(pts.end(), poly.begin(), poly.end());
    const double a = polygon_area(poly);
    s.area += a;
    sem_area[mesh.faces[f].sem] += a;
    nsum += newell_normal(poly);
    csum += a * polygon_centroid(poly);
  }
  s.sem = std::max_element(sem_area.begin(), sem_area.end(), [](const auto& a, const auto& b) {
            return a.second < b.second;
          })->first;
  s.plane = fit_plane(pts);
  if (s.plane.n.dot(nsum) < 0) s.plane = s.plane.flipped();
  s.centroid = s.area > 0 ? Vec3(csum / s.area) : pts.front();
  return s;
}

}  // namespace

std::vector<ModelSurface> model_surfaces(const Mesh& mesh, double angle_deg, double distance) {
  const int nf = int(mesh.faces.size());
  const EdgeUses uses = edge_uses(mesh.faces);
  std::vector<Plane> face_plane(nf);
  for (int f = 0; f < nf; ++f) face_plane[f] = polygon_plane(face_points(mesh, mesh.faces[f]));

  std::vector<int> group(nf, -1);
  std::vector<ModelSurface> surfaces;
  for (int seed = 0; seed < nf; ++seed) {
    if (group[seed] >= 0) continue;
    const int gid = int(surfaces.size());
    std::vector<int> stack{seed}, members;
    group[seed] = gid;
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      members.push_back(f);
      const auto& v = mesh.faces[f].v;
      for (std::size_t i = 0; i < v.size(); ++i) {
        const auto across = uses.find(edge_key(v[i], v[(i + 1) % v.size()]));
        if (across == uses.end()) continue;  // a repeated vertex: no edge
        for (const EdgeUse& u : across->second) {
          const int g = u.face;
          if (group[g] >= 0) continue;
          if (face_plane[g].n.dot(face_plane[seed].n) < std::cos(radians(angle_deg))) continue;
          bool on_plane = true;
          for (int vi : mesh.faces[g].v)
            on_plane = on_plane && std::abs(face_plane[seed].distance(mesh.vertices[vi])) <= distance;
          if (!on_plane) continue;
          group[g] = gid;
          stack.push_back(g);
        }
      }
    }
    surfaces.push_back(describe_surface(mesh, members));
  }
  return surfaces;
}

namespace {

// A candidate wall, with its outline in its own plane frame (u, v) around its centroid.
struct Wall {
  int surface;
  Vec3 u, v;
  Rect box;
  std::vector<std::vector<Vec2>> outline;
};

// The model's wall surfaces that can be matched (no slivers).
std::vector<Wall> candidate_walls(const Mesh& mesh, const std::vector<ModelSurface>& surfaces) {
  std::vector<Wall> walls;
  for (int s = 0; s < int(surfaces.size()); ++s) {
    const ModelSurface& surf = surfaces[s];
    if (surf.sem != Semantic::Wall || surf.area < kMinWallArea) continue;
    Wall w{s, Vec3::Zero(), Vec3::Zero(), surface_rect(mesh, surf), {}};
    std::tie(w.u, w.v) = surf.plane.basis();
    for (int f : surf.faces) {
      std::vector<Vec2> poly;
      for (int vi : mesh.faces[f].v) {
        const Vec3 q = mesh.vertices[vi] - surf.centroid;
        poly.emplace_back(q.dot(w.u), q.dot(w.v));
      }
      w.outline.push_back(std::move(poly));
    }
    walls.push_back(std::move(w));
  }
  return walls;
}

// Whether in-plane point `q` lies in the wall's outline grown by `margin`.
bool in_outline(const Wall& w, const Vec2& q, double margin) {
  const double m = margin;
  if (q.x() < w.box.u0 - m || q.x() > w.box.u1 + m || q.y() < w.box.v0 - m || q.y() > w.box.v1 + m) return false;
  for (const auto& poly : w.outline) {
    if (point_in_polygon_2d(q, poly)) return true;
    for (std::size_t k = 0; k < poly.size(); ++k)
      if (segment_distance_2d(q, poly[k], poly[(k + 1) % poly.size()]) <= m) return true;
  }
  return false;
}

// The points of one scan plane that a wall owns: their in-plane box, sum and indices.
struct Owned {
  Rect box;
  Vec3 sum = Vec3::Zero();
  std::vector<int> idx;
};

// Each inlier of `sp` belongs to the nearest candidate wall (within match_distance) whose
// outline, grown by match_margin, it lies in front of: a plane spanning several walls, a
// setback or a flush neighbour then gives each wall only its own points, never those of a
// parallel wall. Indexed like `walls`.
std::vector<Owned> owned_points(const ScanPlane& sp, const std::vector<int>& cand, const std::vector<Wall>& walls,
                                const std::vector<ModelSurface>& surfaces, const PointCloud& cloud,
                                const MatchConfig& cfg) {
  std::vector<Owned> owned(walls.size());
  for (int i : sp.inliers) {
    const Vec3& x = cloud.points[i];
    int best = -1;
    double best_d = cfg.match_distance;
    for (int k : cand) {
      const ModelSurface& surf = surfaces[walls[k].surface];
      const double d = std::abs(surf.plane.distance(x));
      if (d > best_d) continue;
      const Vec3 q = x - surf.centroid;
      if (!in_outline(walls[k], Vec2(q.dot(walls[k].u), q.dot(walls[k].v)), cfg.match_margin)) continue;
      best = k;
      best_d = d;
    }
    if (best < 0) continue;
    const Vec3 q = x - surfaces[walls[best].surface].centroid;
    owned[best].box.add(q.dot(walls[best].u), q.dot(walls[best].v));
    owned[best].sum += x;
    owned[best].idx.push_back(i);
  }
  return owned;
}

// The matches of scan plane `p` with the candidate walls whose points cover enough of them
// (the largest of the boxes' IoU and the share of either box inside the other); the rest are
// turned down with a line in `rejected`.
void match_plane(int p, const ScanPlane& sp, const std::vector<Wall>& walls, const std::vector<ModelSurface>& surfaces,
                 const PointCloud& cloud, const MatchConfig& cfg, MatchResult& result) {
  const double cos_max = std::cos(radians(cfg.match_angle_deg));
  std::vector<int> cand;
  for (int k = 0; k < int(walls.size()); ++k)
    if (std::abs(sp.plane.n.dot(surfaces[walls[k].surface].plane.n)) >= cos_max) cand.push_back(k);
  if (cand.empty()) return;
  std::vector<Owned> owned = owned_points(sp, cand, walls, surfaces, cloud, cfg);
  for (int k : cand) {
    Owned& o = owned[k];
    const int count = int(o.idx.size());
    if (count < kMinOwnedPoints) continue;
    const ModelSurface& surf = surfaces[walls[k].surface];
    const Rect& model_box = walls[k].box;
    const double inter = overlap_area(model_box, o.box);
    const double uni = model_box.area() + o.box.area() - inter;
    const double iou = uni > 0 ? inter / uni : 0.0;
    const double coverage =
        std::max({iou, inter / std::max(kMinArea, o.box.area()), inter / std::max(kMinArea, model_box.area())});
    if (coverage < cfg.match_min_overlap) {
      result.rejected.push_back("scan plane " + std::to_string(p) + " / wall surface " +
                                std::to_string(walls[k].surface) + ": its points cover too little of the wall (" +
                                std::to_string(coverage) + ")");
      continue;
    }
    const double s_normal = sp.plane.n.dot(surf.plane.n);
    const double d_c = std::abs(surf.plane.distance(o.sum / count));
    const double score = cfg.w_normal * std::abs(s_normal) + cfg.w_coverage * iou;
    result.matches.push_back(Match{p, walls[k].surface, s_normal, d_c, iou, score, std::move(o.idx)});
  }
}

// One scan plane per wall: the best S_match (paper Sec. 3.1), then the most points in front of
// it. Not the most points first: where the scan shows two facade lines in front of one wall, a
// bay's front (nearer the scanner, never in the bay's shadow) has more points than the facade
// line it stands on, whose points span the wall.
std::vector<Match> best_plane_per_wall(const std::vector<Match>& matches) {
  std::map<int, Match> best;
  for (const auto& m : matches) {
    auto it = best.find(m.surface);
    if (it == best.end() || m.s_match > it->second.s_match ||
        (m.s_match == it->second.s_match && m.owned.size() > it->second.owned.size()))
      best[m.surface] = m;
  }
  std::vector<Match> out;
  for (const auto& [s, m] : best) out.push_back(m);
  return out;
}

// A scan plane sees one side of a wall: the surfaces it replaces must all face the way of the
// surface it fits best (else a notch's opposite wall would be pulled onto it).
std::vector<Match> facing_the_fitted_side(const std::vector<Match>& matches, const std::vector<ModelSurface>& surfaces,
                                          std::vector<std::string>& rejected) {
  std::vector<Match> same_side;
  for (const auto& m : matches) {
    const Match* ref = &m;
    for (const auto& o : matches)
      if (o.scan_plane == m.scan_plane && o.d_centroid < ref->d_centroid) ref = &o;
    if (surfaces[m.surface].plane.n.dot(surfaces[ref->surface].plane.n) > 0) same_side.push_back(m);
    else
      rejected.push_back("scan plane " + std::to_string(m.scan_plane) + " / wall surface " + std::to_string(m.surface) +
                         ": faces away from the wall the plane fits best");
  }
  return same_side;
}

// Pairs of matches of adjacent walls (meeting at a corner) whose corner lies more than
// corner_gap beyond the adjacent facade's points.
std::vector<std::vector<char>> corner_conflicts(const std::vector<Match>& matches, const Mesh& mesh,
                                                const std::vector<ModelSurface>& surfaces,
                                                const std::vector<ScanPlane>& planes, const PointCloud& cloud,
                                                double max_gap) {
  const int nm = int(matches.size());
  std::vector<std::vector<char>> conflict(nm, std::vector<char>(nm, 0));
  for (int i = 0; i < nm; ++i)
    for (int j = 0; j < nm; ++j) {
      const Match &m = matches[i], &a = matches[j];
      if (i == j || a.scan_plane == m.scan_plane) continue;
      if (unoriented_angle_deg(surfaces[a.surface].plane.n, surfaces[m.surface].plane.n) < kMinCornerAngleDeg) continue;
      if (!adjacent(mesh, surfaces[a.surface], surfaces[m.surface])) continue;
      std::vector<Vec3> wall;
      for (int f : surfaces[a.surface].faces)
        for (int v : mesh.faces[f].v) wall.push_back(mesh.vertices[v]);
      if (corner_gap(planes[m.scan_plane].plane, planes[a.scan_plane], cloud, wall) > max_gap)
        conflict[i][j] = conflict[j][i] = 1;
    }
  return conflict;
}

// Corner consistency (beyond the paper: rejects walls of neighbouring buildings seen across a
// gap). A wrong match also makes its correct neighbours look inconsistent, so the match with
// the most conflicts goes first (the lower S_match on a tie), until none is left; sums Q_model.
void drop_corner_conflicts(const std::vector<std::vector<char>>& conflict, MatchResult& result) {
  const int nm = int(result.matches.size());
  std::vector<char> alive(nm, 1);
  for (;;) {
    int worst = -1, worst_count = 0;
    for (int i = 0; i < nm; ++i) {
      if (!alive[i]) continue;
      int c = 0;
      for (int j = 0; j < nm; ++j) c += alive[j] && conflict[i][j];
      if (c > worst_count || (c == worst_count && c > 0 && result.matches[i].s_match < result.matches[worst].s_match)) {
        worst = i;
        worst_count = c;
      }
    }
    if (worst < 0) break;
    alive[worst] = 0;
    result.rejected.push_back("scan plane " + std::to_string(result.matches[worst].scan_plane) + " / wall surface " +
                              std::to_string(result.matches[worst].surface) +
                              ": its corner with an adjacent scanned facade lies beyond that facade's points");
  }
  std::vector<Match> kept;
  for (int i = 0; i < nm; ++i)
    if (alive[i]) {
      kept.push_back(result.matches[i]);
      result.q_model += result.matches[i].s_match;
    }
  result.matches = kept;
}

}  // namespace

MatchResult match_surfaces(const Mesh& mesh, const std::vector<ModelSurface>& surfaces, const PointCloud& cloud,
                           const std::vector<ScanPlane>& planes, const MatchConfig& cfg) {
  MatchResult result;
  const std::vector<Wall> walls = candidate_walls(mesh, surfaces);
  for (int p = 0; p < int(planes.size()); ++p)
    if (planes[p].facade) match_plane(p, planes[p], walls, surfaces, cloud, cfg, result);
  result.matches = best_plane_per_wall(result.matches);
  result.matches = facing_the_fitted_side(result.matches, surfaces, result.rejected);
  drop_corner_conflicts(corner_conflicts(result.matches, mesh, surfaces, planes, cloud, cfg.corner_gap), result);
  return result;
}

double surface_deviation(const Mesh& mesh, const ModelSurface& s, const Plane& pl) {
  double d = 0.0;
  for (int f : s.faces)
    for (int v : mesh.faces[f].v) d = std::max(d, std::abs(pl.distance(mesh.vertices[v])));
  return d;
}

double surface_mean_deviation(const Mesh& mesh, const ModelSurface& s, const Plane& pl) {
  double sum = 0.0;
  int n = 0;
  for (int f : s.faces)
    for (int v : mesh.faces[f].v) sum += std::abs(pl.distance(mesh.vertices[v])), ++n;
  return n > 0 ? sum / n : 0.0;
}

std::vector<int> points_in_front(const Mesh& mesh, const std::vector<ModelSurface>& surfaces,
                                 const std::vector<ScanPlane>& planes, const MatchResult& matched,
                                 const PointCloud& cloud, double margin) {
  std::vector<char> take(cloud.points.size(), 0);
  for (const auto& match : matched.matches) {
    const ModelSurface& surf = surfaces[match.surface];
    const auto [u, v] = surf.plane.basis();
    const Rect box = surface_rect(mesh, surf);
    for (int i : planes[match.scan_plane].inliers) {
      const Vec3 q = cloud.points[i] - surf.centroid;
      const double qu = q.dot(u), qv = q.dot(v);
      if (qu >= box.u0 - margin && qu <= box.u1 + margin && qv >= box.v0 - margin && qv <= box.v1 + margin) take[i] = 1;
    }
  }
  std::vector<int> idx;
  for (int i = 0; i < int(take.size()); ++i)
    if (take[i]) idx.push_back(i);
  return idx;
}

}  // namespace lodrefine
