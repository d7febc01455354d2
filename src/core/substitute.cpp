// Stage 4, substitution: wall substitution, see substitute.h.
#include "lodrefine/core/substitute.h"

#include "lodrefine/core/repair.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace lodrefine {
namespace {

// A wall plane is used in plan view (its trace at the vertex's height); roofs tilted less
// than this from vertical are walls here too (only walls are matched to facade scans).
constexpr double kWallMaxNz = 0.5;
// Regulariser of the plan-view solve: picks the nearest point on the trace when only one wall
// direction meets at a vertex; small against any real pair of walls (sin^2 of 0.1 deg ~ 3e-6).
constexpr double kNearestWeight = 1e-7;
// Planes flatter than this are flat roofs or ground: a vertex never slides along them.
constexpr double kFlatNz = 0.999;
// Two walls cross (and fix a vertex in plan view) when their traces differ by more than
// this (sin 15 deg): nearer to parallel, their meet runs away with any small move.
constexpr double kMinCrossing = 0.26;
// Moved walls at one vertex must meet there after the move; more than this apart means the move
// changes the topology (then the arrangement takes over).
constexpr double kMeetTolerance = 0.005;
// A moved face whose area (Newell normal length) shrinks below this share of its old one has
// collapsed: a wall passed its neighbour.
constexpr double kCollapsedShare = 1e-3;
// Faces bent by the move more than this share of the planarity tolerance are split; the rest is
// margin for the coplanar merge that follows (it accepts vertices 5 mm off a merged plane).
constexpr double kSplitShare = 0.5;

// A plane that fixes a moved vertex, in priority: 0 a moved wall, 1 a followed roof, 2 a kept wall.
struct Constraint {
  Vec3 n;
  double d;
  int rank;
};

// Which surfaces each vertex lies on (sorted, unique; -1 for a face of no surface).
std::vector<std::vector<int>> surfaces_at_vertices(const Mesh& mesh, const std::vector<ModelSurface>& surfaces) {
  std::vector<int> face_surface(mesh.faces.size(), -1);
  for (int s = 0; s < int(surfaces.size()); ++s)
    for (int f : surfaces[s].faces) face_surface[f] = s;
  std::vector<std::vector<int>> at(mesh.vertices.size());
  for (int f = 0; f < int(mesh.faces.size()); ++f)
    for (int v : mesh.faces[f].v) at[v].push_back(face_surface[f]);
  for (auto& ss : at) {
    std::sort(ss.begin(), ss.end());
    ss.erase(std::unique(ss.begin(), ss.end()), ss.end());
  }
  return at;
}

// The planes that fix vertex `p` on surfaces `ss`, in priority: the moved walls, then (where a
// moved wall follows its roof) the pitched roofs here, then the kept walls. Kept planes pass
// through the vertex itself, so a slightly warped input face never pulls it. Without a pitched
// roof to follow (`in_3d` false), a vertex keeps its height and only the walls' traces count.
std::vector<Constraint> vertex_constraints(const Vec3& p, const std::vector<int>& ss,
                                           const std::vector<ModelSurface>& surfaces,
                                           const std::vector<WallMove>& moves, const std::vector<int>& moved_plane,
                                           bool& in_3d) {
  std::vector<Constraint> cs;
  bool follow = false;
  for (int s : ss)
    if (s >= 0 && moved_plane[s] >= 0) follow = follow || moves[moved_plane[s]].follow_roof;
  for (int s : ss) {
    if (s < 0) continue;
    const bool moved = moved_plane[s] >= 0;
    const Plane pl = moved ? moves[moved_plane[s]].plane : Plane::through(p, surfaces[s].plane.n);
    const double nz = std::abs(pl.n.z());
    if (nz <= kWallMaxNz) {
      cs.push_back({pl.n, pl.d, moved ? 0 : 2});
    } else if (follow && nz < kFlatNz) {
      cs.push_back({pl.n, pl.d, 1});
    }
  }
  in_3d = std::any_of(cs.begin(), cs.end(), [](const Constraint& c) { return c.rank == 1; });
  if (!in_3d)  // plan view: each wall's trace at this height
    for (auto& c : cs) {
      c.d += c.n.z() * p.z();
      c.n.z() = 0.0;
      const double len = c.n.norm();
      c.n /= len;
      c.d /= len;
    }
  std::stable_sort(cs.begin(), cs.end(), [](const Constraint& a, const Constraint& b) { return a.rank < b.rank; });
  return cs;
}

// The vertex where the constraints meet, by priority: at most as many independent directions
// as fix a point. A kept plane (nearly) parallel to a moved one cannot follow it; its face bends
// to the new vertex and is split afterwards if no longer planar.
Vec3 meet_constraints(const Vec3& p, const std::vector<Constraint>& cs, bool in_3d) {
  std::vector<Constraint> used;
  for (const auto& c : cs) {
    bool independent = false;
    if (used.empty()) independent = true;
    else if (used.size() == 1) independent = used[0].n.cross(c.n).norm() > kMinCrossing;
    else if (used.size() == 2 && in_3d) {
      const Vec3 m = used[0].n.cross(used[1].n);
      independent = std::abs(m.normalized().dot(c.n)) > kMinCrossing;
    }
    if (independent) used.push_back(c);
  }
  Eigen::Matrix3d a = kNearestWeight * Eigen::Matrix3d::Identity();
  Vec3 b = kNearestWeight * p;
  if (!in_3d) a(2, 2) = 1.0, b.z() = p.z();  // plan view: the height stays
  for (const auto& c : used) {
    a += c.n * c.n.transpose();
    b -= c.d * c.n;
  }
  return a.ldlt().solve(b);
}

// Whether every face keeps its orientation and most of its area (else a wall passed a short
// neighbour and the face turned inside out).
bool faces_keep_orientation(const Mesh& before, const Mesh& after) {
  for (const auto& f : before.faces) {
    const Vec3 n0 = newell_normal(face_points(before, f)), n1 = newell_normal(face_points(after, f));
    if (n1.dot(n0) <= 0.0 || n1.norm() < kCollapsedShare * n0.norm()) return false;
  }
  return true;
}

}  // namespace

SubstitutionResult substitute_walls(const Mesh& mesh, const std::vector<ModelSurface>& surfaces,
                                    const std::vector<WallMove>& moves, double planarity_tolerance) {
  SubstitutionResult res;
  std::vector<int> moved_plane(surfaces.size(), -1);
  for (int m = 0; m < int(moves.size()); ++m) moved_plane[moves[m].surface] = m;
  const auto vertex_surfaces = surfaces_at_vertices(mesh, surfaces);
  res.mesh = mesh;
  for (const auto& m : moves)  // on the scan's plane now (a corner move's: where the scan shows the corner)
    for (int f : surfaces[m.surface].faces) res.mesh.faces[f].provenance = Provenance::Scan;
  for (int v = 0; v < int(mesh.vertices.size()); ++v) {
    const auto& ss = vertex_surfaces[v];
    if (std::none_of(ss.begin(), ss.end(), [&](int s) { return s >= 0 && moved_plane[s] >= 0; })) continue;
    const Vec3 p = mesh.vertices[v];
    bool in_3d = false;
    const auto cs = vertex_constraints(p, ss, surfaces, moves, moved_plane, in_3d);
    const Vec3 x = meet_constraints(p, cs, in_3d);
    double residual = 0.0;  // the moved walls must all pass through the new vertex
    for (const auto& c : cs)
      if (c.rank == 0) residual = std::max(residual, std::abs(c.n.dot(x) + c.d));
    if (!x.allFinite() || residual > kMeetTolerance) {
      res.reason = "the moved walls no longer meet at one vertex (residual " + std::to_string(residual) + " m)";
      return res;
    }
    res.mesh.vertices[v] = x;
    res.max_vertex_move = std::max(res.max_vertex_move, (x - p).norm());
    ++res.moved_vertices;
  }
  // A moved face must keep its orientation and stay planar; a roof under a turned wall may
  // not, and is split into triangles then.
  if (!faces_keep_orientation(mesh, res.mesh)) {
    res.reason = "a moved wall passes a neighbouring face (it would turn inside out)";
    return res;
  }
  res.split_faces = split_warped_faces(res.mesh, kSplitShare * planarity_tolerance);
  res.ok = true;
  return res;
}

// Whether the scan shows a moved wall's eave where its pitched roof's plane meets the new wall
// (the roof plane was right) rather than at the old eave height (the roof outline was right):
// the top of the wall's own points decides, and only where it clearly does.
bool eave_follows_roof(const Mesh& mesh, const std::vector<ModelSurface>& surfaces, const Match& m, const Plane& plane,
                       const PointCloud& cloud) {
  // m: the two eaves must differ by kDiffer; the scan's top must lie within kAgree of the
  // followed one and closer to it than to the kept one by kMargin (a scan may stop short of
  // the eave under an overhang).
  constexpr double kDiffer = 0.2, kAgree = 0.3, kMargin = 0.15;
  constexpr double kTopQuantile = 0.99;  // the wall's points' top, robust to a few strays
  if (m.owned.empty()) return false;
  constexpr double kNoSplit = 1e300;  // planarity tolerance: only the wall's top matters here
  auto top = [&](bool follow) {
    const auto sub = substitute_walls(mesh, surfaces, {{m.surface, plane, follow}}, kNoSplit);
    double z = -1e300;
    if (!sub.ok) return z;
    for (int f : surfaces[m.surface].faces)
      for (int v : mesh.faces[f].v) z = std::max(z, sub.mesh.vertices[v].z());
    return z;
  };
  const double keep = top(false), follow = top(true);
  if (std::abs(keep - follow) < kDiffer) return false;
  std::vector<double> z;
  for (int i : m.owned) z.push_back(cloud.points[i].z());
  const std::size_t k = std::size_t(kTopQuantile * double(z.size() - 1));
  std::nth_element(z.begin(), z.begin() + long(k), z.end());
  const double scan_top = z[k];
  return std::abs(scan_top - follow) <= kAgree && std::abs(scan_top - follow) + kMargin < std::abs(scan_top - keep);
}

}  // namespace lodrefine
