// Stage 5, selection: the output shell, see shell_trace.h.
#include "lodrefine/refine/shell_trace.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <utility>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/topology.h"
#include "lodrefine/core/repair.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/refine/candidates.h"

namespace lodrefine {
namespace {

using FaceIndex = CandidateMesh::Face_index;

// The shell under construction: one face per chosen candidate that keeps 3 corners.
struct Trace {
  std::vector<int> candidate;  // per face
  std::vector<int> face_of;    // per candidate: its face, -1 when not chosen or gone
  std::vector<int> vertex_of;  // per point: its output vertex (-1: unused)
  std::vector<Vec3> vertices;
  std::vector<Face> faces;
  std::vector<char> reversed;  // per face: runs against its plane's normal
};

// The chosen candidates' faces on output vertices: the points of a chosen edge shorter than
// kCollapsedEdge are one vertex, numbered by first appearance (its first point gives the
// position), the faces in candidate order.
void trace_faces(const CandidateSet& cs, Trace& t) {
  const auto chosen = candidate_props::selected.get(cs.mesh);
  const auto source = candidate_props::source.find(cs.mesh);
  const auto support = cs.supports();
  std::vector<std::vector<int>> pieces(cs.size());
  DisjointSets same(cs.vertices.size());
  for (int f = 0; f < cs.size(); ++f) {
    if (!chosen[FaceIndex(f)]) continue;
    pieces[f] = cs.corners(f);
    const auto& c = pieces[f];
    for (std::size_t i = 0; i < c.size(); ++i) {
      const int a = c[i], b = c[(i + 1) % c.size()];
      if ((cs.vertices[a] - cs.vertices[b]).norm() < kCollapsedEdge) same.unite(a, b);
    }
  }
  t.face_of.assign(cs.size(), -1);
  t.vertex_of.assign(cs.vertices.size(), -1);
  std::vector<int> of_root(cs.vertices.size(), -1);
  for (int f = 0; f < cs.size(); ++f) {
    if (pieces[f].empty()) continue;
    Face face;
    for (int p : pieces[f]) {
      int& v = of_root[same.find(p)];
      if (v < 0) v = int(t.vertices.size()), t.vertices.push_back(cs.vertices[p]);
      t.vertex_of[p] = v;
      face.v.push_back(v);
    }
    drop_repeats(face.v);
    if (face.v.size() < 3) continue;
    face.sem = cs.planes[support[FaceIndex(f)]].sem;
    face.provenance = cs.planes[support[FaceIndex(f)]].provenance;
    face.source = source.second ? source.first[FaceIndex(f)] : -1;
    t.face_of[f] = int(t.faces.size());
    t.candidate.push_back(f);
    t.faces.push_back(std::move(face));
  }
}

// Two faces of the shell along one segment (its fans, CandidateSet::edges, joined where short
// edges collapsed), and whether they run along it in the same direction as their candidates'
// halfedges do (CCW about their planes).
struct Meeting {
  int f = -1, g = -1;
  bool same = false;
  int a = -1, b = -1;  // the segment's ends, as output vertices (a < b)
};
std::vector<Meeting> meetings(const CandidateSet& cs, const Trace& t) {
  // Per output segment: its faces, each with whether it runs from a to b.
  std::map<std::pair<int, int>, std::vector<std::pair<int, bool>>> along;
  const auto point = candidate_props::point.get(cs.mesh);
  for (const auto& e : cs.edges) {
    const auto [ea, eb] = cs.ends(e);
    const int a = t.vertex_of[ea], b = t.vertex_of[eb];
    if (a < 0 || b < 0 || a == b) continue;  // unused or collapsed
    auto& faces = along[edge_key(a, b)];
    for (auto h : e) {
      const int f = t.face_of[cs.face(h)];
      if (f < 0 || std::any_of(faces.begin(), faces.end(), [&](const auto& x) { return x.first == f; })) continue;
      faces.emplace_back(f, (point[cs.mesh.source(h)] == ea) == (a < b));
    }
  }
  std::vector<Meeting> out;
  for (const auto& [ab, faces] : along)
    if (faces.size() == 2)
      out.push_back({faces[0].first, faces[1].first, faces[0].second == faces[1].second, ab.first, ab.second});
  return out;
}

// Reverses faces so that neighbours run along their fans in opposite directions (breadth first
// from each part's first face) and every part encloses a positive volume.
void orient(const std::vector<Meeting>& meet, Trace& t) {
  const std::size_t n = t.faces.size();
  std::vector<std::vector<std::pair<int, bool>>> adj(n);
  for (const auto& m : meet) {
    adj[m.f].emplace_back(m.g, m.same);
    adj[m.g].emplace_back(m.f, m.same);
  }
  const AgreeingParts a = agreeing_parts(adj);
  const auto& part = a.part;
  const auto& flip = a.flip;
  const int parts = a.parts;
  std::vector<std::vector<Face>> oriented(static_cast<std::size_t>(parts));
  for (std::size_t f = 0; f < n; ++f) {
    Face face = t.faces[f];
    if (flip[f]) std::reverse(face.v.begin(), face.v.end());
    oriented[std::size_t(part[f])].push_back(std::move(face));
  }
  std::vector<char> inward(std::size_t(parts), 0);
  for (int p = 0; p < parts; ++p) inward[std::size_t(p)] = signed_volume(t.vertices, oriented[std::size_t(p)]) < 0;
  t.reversed.assign(n, 0);
  for (std::size_t f = 0; f < n; ++f) {
    t.reversed[f] = char(flip[f] ^ inward[std::size_t(part[f])]);
    if (t.reversed[f]) std::reverse(t.faces[f].v.begin(), t.faces[f].v.end());
  }
}

// The outline of the faces `members`, without the edges in `interior`: one simple loop from its
// lowest vertex, else empty (a hole, or boundaries touching at a vertex).
std::vector<int> outline(const std::vector<Face>& faces, const std::vector<int>& members,
                         const std::set<std::pair<int, int>>& interior) {
  std::map<int, int> next;
  for (int f : members) {
    const auto& v = faces[f].v;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const int a = v[i], b = v[(i + 1) % v.size()];
      if (!interior.count(edge_key(a, b)) && !next.emplace(a, b).second) return {};
    }
  }
  std::vector<int> loop;
  if (next.empty()) return loop;
  const int start = next.begin()->first;
  int cur = start;
  do {
    loop.push_back(cur);
    const auto it = next.find(cur);
    if (it == next.end() || loop.size() > next.size()) return {};
    cur = it->second;
  } while (cur != start);
  if (loop.size() != next.size()) return {};
  return loop;
}

// Whether faces f and g of the shell lie in one plane: the same supporting plane, or two that
// coincide where they are (normals within kCoplanarMergeAngleDeg as oriented, each face's corners
// within kCoplanarMergeDistance of the other's plane) with the same semantic. Supporting planes
// a few millimetres apart (a scan plane beside a model wall) otherwise leave slivers that high.
bool coplanar(const CandidateSet& cs, const Trace& t, int f, int g) {
  const auto support = cs.supports();
  const int k = support[FaceIndex(t.candidate[f])], l = support[FaceIndex(t.candidate[g])];
  if (k == l) return true;
  if (t.faces[f].sem != t.faces[g].sem) return false;
  const Plane& pk = cs.planes[k].plane;
  const Plane& pl = cs.planes[l].plane;
  const double side = t.reversed[f] == t.reversed[g] ? 1.0 : -1.0;
  if (side * pk.n.dot(pl.n) < std::cos(radians(kCoplanarMergeAngleDeg))) return false;
  auto within = [&](int face, const Plane& plane) {
    return std::all_of(t.faces[face].v.begin(), t.faces[face].v.end(),
                       [&](int v) { return std::abs(plane.distance(t.vertices[v])) <= kCoplanarMergeDistance; });
  };
  return within(g, pk) && within(f, pl);
}

// Chosen neighbours in one plane as one polygon (in place of the first of them, with the
// semantic, source and provenance of the largest); returns each output face's group of neighbours in one
// plane (faces left apart, their outline not one loop, share it).
std::vector<int> merge_coplanar(const CandidateSet& cs, const std::vector<Meeting>& meet, Trace& t) {
  const int n = int(t.faces.size());
  DisjointSets group{std::size_t(n)};
  std::set<std::pair<int, int>> interior;
  for (const auto& m : meet) {
    const bool opposite = (m.same ^ t.reversed[m.f] ^ t.reversed[m.g]) == 0;
    if (!opposite || !coplanar(cs, t, m.f, m.g)) continue;
    group.unite(m.f, m.g);
    interior.insert(edge_key(m.a, m.b));
  }
  std::map<int, std::vector<int>> members;
  for (int f = 0; f < n; ++f) members[group.find(f)].push_back(f);
  std::vector<Face> faces;
  std::vector<int> groups;
  for (int f = 0; f < n; ++f) {
    const auto& fs = members[group.find(f)];
    const std::vector<int> loop = fs.size() > 1 ? outline(t.faces, fs, interior) : std::vector<int>{};
    if (loop.empty()) {
      faces.push_back(t.faces[f]);
    } else if (fs.front() == f) {
      auto area = [&](int g) {
        std::vector<Vec3> pts;
        for (int v : t.faces[g].v) pts.push_back(t.vertices[v]);
        return polygon_area(pts);
      };
      const int largest = *std::max_element(fs.begin(), fs.end(), [&](int a, int b) { return area(a) < area(b); });
      faces.push_back(with_corners(t.faces[largest], loop));
    } else {
      continue;
    }
    groups.push_back(group.find(f));
  }
  t.faces = std::move(faces);
  return groups;
}

// Drops the corners used by exactly two faces of different planes (`groups`), both with 4 corners
// or more: such a corner lies on the line where the two planes meet.
void drop_straight_corners(const std::vector<int>& groups, Trace& t) {
  for (bool changed = true; changed;) {
    changed = false;
    std::vector<std::vector<int>> users(t.vertices.size());
    for (std::size_t f = 0; f < t.faces.size(); ++f)
      for (int v : std::set<int>(t.faces[f].v.begin(), t.faces[f].v.end())) users[v].push_back(int(f));
    std::vector<char> touched(t.faces.size(), 0);  // their corner lists changed: recheck next round
    for (std::size_t v = 0; v < users.size(); ++v) {
      if (users[v].size() != 2) continue;
      const int a = users[v][0], b = users[v][1];
      Face &f = t.faces[a], &g = t.faces[b];
      if (touched[a] || touched[b] || f.v.size() < 4 || g.v.size() < 4 || groups[a] == groups[b]) continue;
      f.v.erase(std::find(f.v.begin(), f.v.end(), int(v)));
      g.v.erase(std::find(g.v.begin(), g.v.end(), int(v)));
      touched[a] = touched[b] = 1;
      changed = true;
    }
  }
}

}  // namespace

Mesh traced_shell(const CandidateSet& cs) {
  Trace t;
  trace_faces(cs, t);
  const std::vector<Meeting> meet = meetings(cs, t);
  orient(meet, t);
  drop_straight_corners(merge_coplanar(cs, meet, t), t);
  // The vertices the faces use, in order of first use.
  Mesh m;
  std::vector<int> index(t.vertices.size(), -1);
  for (Face& f : t.faces) {
    for (int& v : f.v) {
      if (index[v] < 0) index[v] = int(m.vertices.size()), m.vertices.push_back(t.vertices[v]);
      v = index[v];
    }
    m.faces.push_back(std::move(f));
  }
  return m;
}

}  // namespace lodrefine
