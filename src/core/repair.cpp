// Polygon soup -> closed, consistently outward-oriented polyhedron; coplanar face merging.
#include "lodrefine/core/repair.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <queue>
#include <set>

#include "lodrefine/base/files.h"
#include "lodrefine/base/geometry.h"
#include "lodrefine/base/submesh.h"
#include "lodrefine/base/topology.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/validate.h"

namespace lodrefine {
namespace {

constexpr double kHolePlanarity = 0.02;  // m: a boundary loop flatter than this becomes one face
constexpr double kHorizontalDeg = 10.0;  // filled holes this close to horizontal are ground/roof
// weld_tolerance may be 0 (RepairConfig allows it): welding, degenerate faces and T-junctions then
// work at this floor, well above the rounding of coordinates in a local frame (m).
constexpr double kMinWeldTolerance = 1e-9;
// The fewest faces of a closed polyhedron (a tetrahedron).
constexpr std::size_t kMinClosedFaces = 4;

[[noreturn]] void reject(const Mesh& m, const std::string& why) {
  throw InputError("building " + (m.id.empty() ? std::string("(no id)") : line_id(m.id)) + ": " + why);
}

void check_input(const Mesh& soup) {
  for (std::size_t i = 0; i < soup.vertices.size(); ++i)
    if (!soup.vertices[i].allFinite()) reject(soup, "vertex " + std::to_string(i) + " is not finite");
  for (std::size_t k = 0; k < soup.faces.size(); ++k)
    for (int i : soup.faces[k].v)
      if (i < 0 || std::size_t(i) >= soup.vertices.size())
        reject(soup, "face " + std::to_string(k) + " references missing vertex " + std::to_string(i));
}

// ---------------------------------------------------------------------------------------------
// Welding

// Clusters the soup's vertices: the closest pairs first (Kruskal), vertices of different faces
// within `gap`, two vertices of one face only within `tol` (a repeated corner, a sliver's tip).
// Jittered exports (a corner a few mm off in each face) weld whole, while a face's own short
// edges never collapse. Returns each vertex's cluster; `centres` gets each cluster's mean.
std::vector<int> weld(const Mesh& soup, double tol, double gap, std::vector<Vec3>& centres) {
  const auto& pts = soup.vertices;
  const int n = int(pts.size());
  std::vector<std::vector<int>> faces_of(n);
  for (int f = 0; f < int(soup.faces.size()); ++f)
    for (int v : soup.faces[f].v)
      if (faces_of[v].empty() || faces_of[v].back() != f) faces_of[v].push_back(f);
  for (auto& fs : faces_of) {
    std::sort(fs.begin(), fs.end());
    fs.erase(std::unique(fs.begin(), fs.end()), fs.end());
  }
  gap = std::max(gap, tol);
  PointGrid grid(gap);
  for (int i = 0; i < n; ++i) grid.insert(pts[i], i);
  struct Pair {
    double d;
    int i, j;
  };
  std::vector<Pair> pairs;
  for (int i = 0; i < n; ++i)
    grid.visit_near(pts[i], [&](int j) {
      if (j <= i) return false;
      const double d = (pts[j] - pts[i]).norm();
      if (d <= gap) pairs.push_back({d, i, j});
      return false;
    });
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
    return a.d != b.d ? a.d < b.d : std::make_pair(a.i, a.j) < std::make_pair(b.i, b.j);
  });
  DisjointSets sets(n);
  for (const auto& [d, i, j] : pairs) {
    int a = sets.find(i), b = sets.find(j);
    if (a == b) continue;
    if (faces_of[a].size() < faces_of[b].size()) std::swap(a, b);
    const auto& big = faces_of[a];
    bool shared = false;
    for (int f : faces_of[b]) shared = shared || std::binary_search(big.begin(), big.end(), f);
    if (shared && d > tol) continue;
    std::vector<int> merged;
    std::set_union(big.begin(), big.end(), faces_of[b].begin(), faces_of[b].end(), std::back_inserter(merged));
    faces_of[a] = std::move(merged);
    faces_of[b].clear();
    sets.link(b, a);
  }
  std::vector<int> cluster(n), id(n, -1), count;
  centres.clear();
  for (int i = 0; i < n; ++i) {
    const int r = sets.find(i);
    if (id[r] < 0) {
      id[r] = int(centres.size());
      centres.push_back(Vec3::Zero());
      count.push_back(0);
    }
    cluster[i] = id[r];
    centres[id[r]] += pts[i];
    ++count[id[r]];
  }
  for (std::size_t k = 0; k < centres.size(); ++k) centres[k] /= count[k];
  return cluster;
}

// ---------------------------------------------------------------------------------------------
// Face cleaning

std::vector<Vec3> positions(const std::vector<Vec3>& V, const std::vector<int>& idx) {
  std::vector<Vec3> pts;
  pts.reserve(idx.size());
  for (int i : idx) pts.push_back(V[i]);
  return pts;
}

// Fewer than 3 distinct vertices, or narrower than `tol` (twice the area over the longest edge).
bool is_degenerate(const std::vector<int>& v, const std::vector<Vec3>& V, double tol) {
  if (std::set<int>(v.begin(), v.end()).size() < 3) return true;
  double longest = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) longest = std::max(longest, (V[v[i]] - V[v[(i + 1) % v.size()]]).norm());
  return 2.0 * polygon_area(positions(V, v)) < tol * longest;
}

// Remaps faces to welded vertices and drops degenerate faces and duplicates (same vertex set,
// either orientation; the first one is kept).
std::vector<Face> clean_faces(const Mesh& soup, const std::vector<int>& cluster, const std::vector<Vec3>& V, double tol,
                              RepairReport& r) {
  std::vector<Face> faces;
  std::set<std::vector<int>> seen;
  for (const Face& in : soup.faces) {
    Face f = in;
    for (int& i : f.v) i = cluster[i];
    drop_repeats(f.v);
    if (is_degenerate(f.v, V, tol)) {
      ++r.removed_degenerate_faces;
      continue;
    }
    std::vector<int> key = f.v;
    std::sort(key.begin(), key.end());
    if (!seen.insert(key).second) {
      ++r.removed_duplicate_faces;
      continue;
    }
    faces.push_back(std::move(f));
  }
  return faces;
}

// Inserts every vertex lying on a face edge into that edge, so a long edge meeting several
// shorter ones (a T-junction) shares their vertices and each edge ends up with two faces.
int split_t_junctions(const std::vector<Vec3>& V, std::vector<Face>& faces, double tol) {
  std::set<int> used_set;
  for (const Face& f : faces) used_set.insert(f.v.begin(), f.v.end());
  // The used vertices sorted by x: an edge tests only those in its box grown by `tol` (testing
  // every vertex made a ring pinched thousands of times take seconds).
  std::vector<int> by_x(used_set.begin(), used_set.end());
  std::sort(by_x.begin(), by_x.end(), [&V](int a, int b) { return V[a].x() < V[b].x(); });
  std::vector<double> xs;
  for (int v : by_x) xs.push_back(V[v].x());
  // Strictly within `tol` of the edge, farther than `tol` from its ends, not in the face yet.
  const SegmentRule on_edge{tol, true, 0.0, tol};
  std::vector<int> near;
  int inserted = 0;
  for (Face& f : faces) {
    std::vector<int> out;
    for (std::size_t i = 0; i < f.v.size(); ++i) {
      const int a = f.v[i], b = f.v[(i + 1) % f.v.size()];
      const Vec3 lo = V[a].cwiseMin(V[b]).array() - tol, hi = V[a].cwiseMax(V[b]).array() + tol;
      near.clear();
      for (auto k = std::size_t(std::lower_bound(xs.begin(), xs.end(), lo.x()) - xs.begin());
           k < xs.size() && xs[k] <= hi.x(); ++k) {
        const Vec3& p = V[std::size_t(by_x[k])];
        if (p.y() >= lo.y() && p.y() <= hi.y() && p.z() >= lo.z() && p.z() <= hi.z()) near.push_back(by_x[k]);
      }
      out.push_back(a);
      for (int w : vertices_on_segment(V, a, b, on_edge, &near, &f.v)) {
        if (std::find(out.begin(), out.end(), w) != out.end()) continue;  // already on another edge
        out.push_back(w);
        ++inserted;
      }
    }
    f.v = std::move(out);
  }
  return inserted;
}

// ---------------------------------------------------------------------------------------------
// Orientation and hole filling

struct Adjacent {
  int face;
  bool same_direction;  // both faces traverse the shared edge the same way (inconsistent)
};

// Neighbours across manifold edges (exactly two faces).
std::vector<std::vector<Adjacent>> adjacency(const std::vector<Face>& faces, const EdgeUses& uses) {
  std::vector<std::vector<Adjacent>> adj(faces.size());
  for (const auto& entry : uses) {
    const auto& u = entry.second;
    if (u.size() != 2) continue;
    const bool same = u[0].forward == u[1].forward;
    adj[u[0].face].push_back({u[1].face, same});
    adj[u[1].face].push_back({u[0].face, same});
  }
  return adj;
}

// BFS over manifold edges reversing faces so that neighbours traverse their shared edge in
// opposite directions; toggles `flipped` for reversed faces. Returns each face's component.
std::vector<int> orient_consistently(std::vector<Face>& faces, std::vector<char>& flipped) {
  const AgreeingParts a = agreeing_parts(adjacency(faces, edge_uses(faces)));
  for (std::size_t f = 0; f < faces.size(); ++f)
    if (a.flip[f]) std::reverse(faces[f].v.begin(), faces[f].v.end()), flipped[f] ^= 1;
  return a.part;
}

// Reverses every component whose enclosed volume is negative.
void orient_outward(const std::vector<Vec3>& V, std::vector<Face>& faces, const std::vector<int>& comp,
                    std::vector<char>& flipped) {
  const int ncomp = comp.empty() ? 0 : *std::max_element(comp.begin(), comp.end()) + 1;
  std::vector<std::vector<Face>> parts(ncomp);
  for (std::size_t f = 0; f < faces.size(); ++f) parts[comp[f]].push_back(faces[f]);
  std::vector<char> negative(std::size_t(ncomp), 0);  // once per component, not per face (quadratic)
  for (int c = 0; c < ncomp; ++c) negative[std::size_t(c)] = signed_volume(V, parts[std::size_t(c)]) < 0;
  for (std::size_t f = 0; f < faces.size(); ++f)
    if (negative[std::size_t(comp[f])]) std::reverse(faces[f].v.begin(), faces[f].v.end()), flipped[f] ^= 1;
}

int pop(std::vector<int>& v) {
  const int x = v.back();
  v.pop_back();
  return x;
}

// Boundary loops, each traced against its faces' direction so that a polygon through it
// continues the neighbours' orientation. Where boundaries touch at a vertex, the walk is cut
// into simple loops; walks that do not close are left open.
std::vector<std::vector<int>> hole_loops(const std::vector<Face>& faces) {
  std::map<int, std::vector<int>> next;
  for (const auto& [e, u] : edge_uses(faces))
    if (u.size() == 1) {
      if (u[0].forward) next[e.second].push_back(e.first);
      else next[e.first].push_back(e.second);
    }
  std::vector<std::vector<int>> loops;
  const auto emit = [&loops](std::vector<int> loop) {
    if (loop.size() >= 3) loops.push_back(std::move(loop));
  };
  for (auto& [start, outs] : next)
    while (!outs.empty()) {
      std::vector<int> walk{start};
      for (int cur = pop(outs);;) {
        const auto seen = std::find(walk.begin(), walk.end(), cur);
        if (seen != walk.end()) {  // closed a loop at cur: cut it off, keep walking from cur
          emit(std::vector<int>(seen, walk.end()));
          walk.erase(seen + 1, walk.end());
          if (cur == start) break;
        } else {
          walk.push_back(cur);
        }
        const auto it = next.find(cur);
        if (it == next.end() || it->second.empty()) break;
        cur = pop(it->second);
      }
    }
  return loops;
}

// Closes each hole with one polygon when it is planar within kHolePlanarity, else with the
// triangles of its projection (noted). New faces are appended with source -1, added to close the
// shell (Provenance::Added: no model face lies there).
void fill_holes(const std::vector<Vec3>& V, std::vector<Face>& faces, RepairReport& r) {
  for (const auto& loop : hole_loops(faces)) {
    const std::vector<Vec3> pts = positions(V, loop);
    const Plane plane = polygon_plane(pts);
    double err = 0.0;
    for (const Vec3& p : pts) err = std::max(err, std::abs(plane.distance(p)));
    ++r.filled_holes;
    if (err <= kHolePlanarity) {
      faces.push_back({loop, Semantic::Other, -1, Provenance::Added});
      continue;
    }
    const auto tris = triangulate_polygon(pts);
    for (const auto& t : tris)
      faces.push_back({{loop[t[0]], loop[t[1]], loop[t[2]]}, Semantic::Other, -1, Provenance::Added});
    r.notes.push_back("hole of " + std::to_string(loop.size()) + " vertices is not planar (" +
                      std::to_string(int(std::round(err * 1000))) + " mm): filled with " + std::to_string(tris.size()) +
                      " triangles");
  }
}

// A filled face facing straight down is ground, straight up roof; otherwise it takes the
// semantic its original neighbours share the longest edges with.
Semantic fill_semantic(const std::vector<Vec3>& V, const std::vector<Face>& faces, int f, const EdgeUses& uses,
                       std::size_t first_new) {
  const Vec3 n = newell_normal(positions(V, faces[f].v)).normalized();
  const double c = std::cos(radians(kHorizontalDeg));
  if (n.z() < -c) return Semantic::Ground;
  if (n.z() > c) return Semantic::Roof;
  std::map<Semantic, double> weight;
  const auto& v = faces[f].v;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const int a = v[i], b = v[(i + 1) % v.size()];
    const auto it = uses.find({std::min(a, b), std::max(a, b)});
    if (it == uses.end()) continue;
    for (const EdgeUse& u : it->second)
      if (std::size_t(u.face) < first_new) weight[faces[u.face].sem] += (V[a] - V[b]).norm();
  }
  Semantic best = Semantic::Other;
  double best_w = 0.0;
  for (const auto& [s, w] : weight)
    if (w > best_w) best = s, best_w = w;
  return best;
}

// ---------------------------------------------------------------------------------------------
// Coplanar merging

// Region growing from the largest faces: a neighbour joins when it has the same semantic, its
// normal is within `angle_deg` of the region's, and all its vertices lie within `distance` of
// the region's plane (refitted as the region grows, so slow curvature cannot chain faces).
std::vector<int> coplanar_regions(const Mesh& m, const std::vector<std::vector<Adjacent>>& adj, double angle_deg,
                                  double distance) {
  const std::size_t n = m.faces.size();
  std::vector<Vec3> normal(n);
  std::vector<double> area(n);
  for (std::size_t f = 0; f < n; ++f) {
    const Vec3 nn = newell_normal(positions(m.vertices, m.faces[f].v));
    area[f] = nn.norm();
    normal[f] = area[f] > 0 ? Vec3(nn / area[f]) : Vec3::Zero();
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return area[a] > area[b]; });
  const double min_cos = std::cos(radians(angle_deg));
  std::vector<int> region(n, -1);
  int next_id = 0;
  for (int s : order) {
    if (region[s] >= 0) continue;
    const int id = next_id++;
    region[s] = id;
    std::vector<Vec3> pts = positions(m.vertices, m.faces[s].v);
    Vec3 sum_normal = normal[s] * area[s];
    Plane plane = polygon_plane(pts);
    std::queue<int> q;
    q.push(s);
    while (!q.empty()) {
      const int f = q.front();
      q.pop();
      for (const auto& [g, same] : adj[f]) {
        if (region[g] >= 0 || same || m.faces[g].sem != m.faces[s].sem || normal[g].dot(plane.n) < min_cos) continue;
        const auto gp = positions(m.vertices, m.faces[g].v);
        if (std::any_of(gp.begin(), gp.end(), [&](const Vec3& p) { return std::abs(plane.distance(p)) > distance; }))
          continue;
        region[g] = id;
        q.push(g);
        pts.insert(pts.end(), gp.begin(), gp.end());
        sum_normal += normal[g] * area[g];
        plane = fit_plane(pts);
        if (plane.n.dot(sum_normal) < 0) plane = plane.flipped();
      }
    }
  }
  return region;
}

// The merged outline of region `id`: its faces' half-edges whose other side lies outside the
// region, chained into a loop. nullopt when they form several loops (a hole) or touch at a
// vertex; such regions keep their faces.
std::optional<std::vector<int>> region_outline(const std::vector<Face>& faces, const std::vector<int>& members,
                                               const std::vector<int>& region, int id, const EdgeUses& uses) {
  std::map<int, int> next;
  for (int f : members) {
    const auto& v = faces[f].v;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const int a = v[i], b = v[(i + 1) % v.size()];
      const auto it = uses.find({std::min(a, b), std::max(a, b)});
      if (it == uses.end()) return std::nullopt;  // a repeated vertex: leave such faces alone
      const auto& u = it->second;
      const bool interior = u.size() == 2 && region[u[0].face] == id && region[u[1].face] == id;
      if (!interior && !next.emplace(a, b).second) return std::nullopt;
    }
  }
  if (next.empty()) return std::nullopt;
  std::vector<int> loop;
  const int start = next.begin()->first;
  int cur = start;
  do {
    loop.push_back(cur);
    const auto it = next.find(cur);
    if (it == next.end() || loop.size() > next.size()) return std::nullopt;
    cur = it->second;
  } while (cur != start);
  if (loop.size() != next.size()) return std::nullopt;
  return loop;
}

// Whether face `f` passes straight through its vertex `v` (collinear within `distance`).
bool passes_straight(const std::vector<Vec3>& V, const Face& f, int v, double distance) {
  const auto it = std::find(f.v.begin(), f.v.end(), v);
  const std::size_t i = std::size_t(it - f.v.begin()), n = f.v.size();
  return inside_segment(V[f.v[(i + n - 1) % n]], V[f.v[(i + 1) % n]], V[v], SegmentRule{distance}).has_value();
}

// Removes vertices used by exactly two faces that both pass straight through them. Both faces
// drop the vertex together, so no T-junction appears.
void drop_straight_vertices(const std::vector<Vec3>& V, std::vector<Face>& faces, double distance) {
  for (bool changed = true; changed;) {
    changed = false;
    std::vector<std::vector<int>> users(V.size());
    for (std::size_t f = 0; f < faces.size(); ++f)
      for (int v : std::set<int>(faces[f].v.begin(), faces[f].v.end())) users[v].push_back(int(f));
    std::vector<char> touched(faces.size(), 0);  // their vertex lists changed: recheck next round
    for (std::size_t v = 0; v < V.size(); ++v) {
      if (users[v].size() != 2) continue;
      Face &f = faces[users[v][0]], &g = faces[users[v][1]];
      if (touched[users[v][0]] || touched[users[v][1]] || f.v.size() < 4 || g.v.size() < 4) continue;
      if (!passes_straight(V, f, int(v), distance) || !passes_straight(V, g, int(v), distance)) continue;
      f.v.erase(std::find(f.v.begin(), f.v.end(), int(v)));
      g.v.erase(std::find(g.v.begin(), g.v.end(), int(v)));
      touched[users[v][0]] = touched[users[v][1]] = 1;
      changed = true;
    }
  }
}

// Welds the soup, drops its degenerate and duplicate faces and splits its T-junctions: the
// faces on shared vertices, as read otherwise.
std::vector<Face> welded_faces(const Mesh& soup, double weld_tolerance, double gap_tolerance, std::vector<Vec3>& V,
                               RepairReport& r) {
  r.input_vertices = int(soup.vertices.size());
  r.input_faces = int(soup.faces.size());
  check_input(soup);
  const double tol = std::max(weld_tolerance, kMinWeldTolerance);
  const std::vector<int> cluster = weld(soup, tol, gap_tolerance, V);
  r.welded_vertices = int(soup.vertices.size() - V.size());
  std::vector<Face> faces = clean_faces(soup, cluster, V, tol, r);
  r.split_t_junctions = split_t_junctions(V, faces, tol);
  return faces;
}

}  // namespace

int orient_outward(Mesh& mesh) {
  std::vector<char> flipped(mesh.faces.size(), 0);
  orient_outward(mesh.vertices, mesh.faces, orient_consistently(mesh.faces, flipped), flipped);
  return int(std::count(flipped.begin(), flipped.end(), 1));
}

Mesh welded_soup(const Mesh& soup, double weld_tolerance, RepairReport* report) {
  RepairReport r;
  std::vector<Vec3> V;
  std::vector<Face> faces = welded_faces(soup, weld_tolerance, weld_tolerance, V, r);
  if (report) *report = r;
  return compacted(V, std::move(faces), soup.id);
}

Mesh repair_model(const Mesh& soup, double weld_tolerance, RepairReport* report, double gap_tolerance) {
  RepairReport r;
  std::vector<Vec3> V;
  std::vector<Face> faces = welded_faces(soup, weld_tolerance, gap_tolerance, V, r);

  std::vector<char> flipped(faces.size(), 0);
  orient_consistently(faces, flipped);
  const std::size_t first_new = faces.size();
  fill_holes(V, faces, r);
  flipped.resize(faces.size(), 0);
  orient_outward(V, faces, orient_consistently(faces, flipped), flipped);
  const EdgeUses uses = edge_uses(faces);
  for (std::size_t f = first_new; f < faces.size(); ++f)
    faces[f].sem = fill_semantic(V, faces, int(f), uses, first_new);
  r.flipped_faces = int(std::count(flipped.begin(), flipped.begin() + long(first_new), 1));

  Mesh out = compacted(V, std::move(faces), soup.id);
  const Validation val = validate_mesh(out, std::numeric_limits<double>::infinity(), false);
  r.closed = out.faces.size() >= kMinClosedFaces && val.watertight() && val.inconsistent_edges == 0 && val.volume > 0;
  if (report) *report = r;
  if (out.faces.size() < kMinClosedFaces)
    reject(soup, "only " + std::to_string(out.faces.size()) + " usable faces after repair");
  if (!r.closed) reject(soup, "not closable: " + (val.problem.empty() ? "zero volume" : val.problem));
  return out;
}

int split_warped_faces(Mesh& mesh, double tolerance) {
  const EdgeUses edges = edge_uses(mesh.faces);
  std::vector<Face> faces;
  int split = 0;
  for (const auto& f : mesh.faces) {
    const auto pts = positions(mesh.vertices, f.v);
    const Plane pl = polygon_plane(pts);
    double err = 0.0;
    for (const auto& q : pts) err = std::max(err, std::abs(pl.distance(q)));
    if (err <= tolerance) {
      faces.push_back(f);
      continue;
    }
    ++split;
    const auto tris = triangulate_polygon(pts);
    const int n = int(f.v.size());
    bool clash = false;
    for (const auto& t : tris)
      for (int k = 0; k < 3; ++k) {
        const int ia = t[k], ib = t[(k + 1) % 3];
        const bool boundary = (ia + 1) % n == ib || (ib + 1) % n == ia;
        clash = clash || (!boundary && edges.count(edge_key(f.v[ia], f.v[ib])));
      }
    if (!clash) {
      for (const auto& t : tris) faces.push_back(with_corners(f, {f.v[t[0]], f.v[t[1]], f.v[t[2]]}));
      continue;
    }
    const int centre = int(mesh.vertices.size());
    mesh.vertices.push_back(polygon_centroid(pts));
    for (int k = 0; k < n; ++k) faces.push_back(with_corners(f, {f.v[k], f.v[(k + 1) % n], centre}));
  }
  mesh.faces = std::move(faces);
  return split;
}

Mesh merge_coplanar_faces(const Mesh& mesh, double angle_deg, double distance) {
  const EdgeUses uses = edge_uses(mesh.faces);
  const std::vector<int> region = coplanar_regions(mesh, adjacency(mesh.faces, uses), angle_deg, distance);
  std::map<int, std::vector<int>> members;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) members[region[f]].push_back(int(f));
  std::map<int, Face> merged;
  for (const auto& [id, fs] : members) {
    const auto outline = fs.size() > 1 ? region_outline(mesh.faces, fs, region, id, uses) : std::nullopt;
    if (!outline) continue;
    // The merged polygon descends mostly from its largest face.
    const int largest = *std::max_element(fs.begin(), fs.end(), [&](int a, int b) {
      return polygon_area(positions(mesh.vertices, mesh.faces[a].v)) <
             polygon_area(positions(mesh.vertices, mesh.faces[b].v));
    });
    merged[id] = with_corners(mesh.faces[largest], *outline);
  }
  // Input order is kept: a merged polygon takes the place of its region's first face.
  std::vector<Face> faces;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const auto it = merged.find(region[f]);
    if (it == merged.end()) faces.push_back(mesh.faces[f]);
    else if (members[region[f]].front() == int(f)) faces.push_back(it->second);
  }
  drop_straight_vertices(mesh.vertices, faces, distance);
  return compacted(mesh.vertices, std::move(faces), mesh.id);
}

Mesh repair_input(const Mesh& local_model, const RepairConfig& prm, RepairReport& rr) {
  // Before any weld: each step validates, and validation's time grows with the model's size.
  if (const std::string too_large = size_problem(local_model); !too_large.empty()) throw InputError(too_large);
  // Welds tried in turn, relative to weld_tolerance: the tolerance itself; gaps between faces
  // up to 1.5x and 2x it (corners jittered a little more than the tolerance); then 10x and 100x
  // finer for detailed models whose features are shorter than it.
  struct Step {
    double weld, gap;
  };
  constexpr Step kSteps[] = {{1.0, 1.0}, {1.0, 1.5}, {1.0, 2.0}, {0.1, 0.1}, {0.01, 0.01}};
  std::optional<std::pair<Mesh, RepairReport>> first;
  std::string error;
  for (const auto& [weld, gap] : kSteps) {
    RepairReport r;
    try {
      Mesh m = repair_model(local_model, prm.weld_tolerance * weld, &r, prm.weld_tolerance * gap);
      if (weld != 1.0 || gap != 1.0)
        r.notes.push_back("welded at " + std::to_string(prm.weld_tolerance * weld) + " m, gaps up to " +
                          std::to_string(prm.weld_tolerance * gap) + " m");
      r.split_warped_faces = split_warped_faces(m, prm.planarity_tolerance);
      if (validate_mesh(m, prm.planarity_tolerance).valid()) {
        rr = r;
        return m;
      }
      if (!first) first.emplace(std::move(m), r);
    } catch (const InputError& e) {
      if (error.empty()) error = e.what();
    }
  }
  if (!first) throw InputError(error);
  rr = first->second;
  return first->first;
}

}  // namespace lodrefine
