// The coarse model's errors (see perturb.h).
#include "perturb.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <set>
#include <stdexcept>

#include "lodrefine/base/geometry.h"

namespace lodrefine::synth {

// Walls: scanning and moving.

std::vector<WallInfo> wall_infos(const Mesh& m) {
  std::vector<WallInfo> out;
  for (int fi = 0; fi < int(m.faces.size()); ++fi) {
    const auto& f = m.faces[fi];
    if (f.sem != Semantic::Wall) continue;
    const auto pts = face_points(m, f);
    const Vec2 n = xy(newell_normal(pts)).normalized(), u(-n.y(), n.x());
    double lo = 1e300, hi = -1e300;
    for (const auto& p : pts) lo = std::min(lo, u.dot(xy(p))), hi = std::max(hi, u.dot(xy(p)));
    const Vec2 base = xy(pts[0]) - u * u.dot(xy(pts[0]));
    out.push_back({fi, f.source, n, base + u * (0.5 * (lo + hi)), hi - lo});
  }
  return out;
}

namespace {

// The generalised front of the street-facade types moves by [kFrontShiftMin min_shift,
// kFrontShiftMax max_shift]: 0.1-0.6 m with the default options, as the topo dev tile's models.
constexpr double kFrontShiftMin = 0.5, kFrontShiftMax = 0.75;

void move_line(Line& l, const Vec2& pivot, const Vec2& n_out, double offset, double rot_deg) {
  const Eigen::Rotation2Dd R(radians(rot_deg));
  l.p = pivot + R * (l.p - pivot) + offset * (R * n_out);
  l.d = R * l.d;
}

MovedWall random_move(const SynthOptions& o, Rng& r) {
  MovedWall mv;
  const double mode = r.uniform();  // shift only / rotation only / both
  const bool shift = o.max_rotation_deg <= 0 || mode<0.85, rotate = o.max_rotation_deg> 0 && mode >= 0.45;
  if (shift) mv.offset = r.sign() * r.uniform(o.min_shift, o.max_shift);
  if (rotate) mv.rotation_deg = r.sign() * r.uniform(0.3 * o.max_rotation_deg, o.max_rotation_deg);
  return mv;
}

// Moves the footprint line of walls[w] by mv about the wall's middle; mv gets the truth walls on
// that line (walls[w] first) and whether walls[w] is scanned.
MovedWall move_wall_line(Spec& s, const std::vector<WallInfo>& walls, int w, const std::vector<int>& scanned,
                         MovedWall mv) {
  const WallInfo& wi = walls[w];
  for (const auto& x : walls)
    if (x.line == wi.line && x.face != wi.face) mv.truth_faces.push_back(x.face);
  mv.truth_faces.insert(mv.truth_faces.begin(), wi.face);
  mv.scanned = std::count(scanned.begin(), scanned.end(), w) > 0;
  move_line(s.lines[wi.line], wi.mid, wi.n, mv.offset, mv.rotation_deg);
  return mv;
}

int first_wall_on(const std::vector<WallInfo>& walls, int line) {
  for (int w = 0; w < int(walls.size()); ++w)
    if (walls[w].line == line) return w;
  return -1;
}

}  // namespace

std::vector<MovedWall> move_facades(Spec& s, const std::vector<WallInfo>& walls, const std::vector<int>& scanned,
                                    const SynthOptions& o, Rng& r) {
  std::vector<int> pick;  // indices into walls
  for (int w : scanned)
    if (r.chance(0.75)) pick.push_back(w);
  std::vector<int> others;
  for (int w = 0; w < int(walls.size()); ++w)
    if (!std::count(scanned.begin(), scanned.end(), w) && walls[w].length >= 2) others.push_back(w);
  if (!others.empty() && (pick.empty() || r.chance(0.25))) pick.push_back(others[r.integer(0, int(others.size()) - 1)]);
  if (pick.empty()) pick.push_back(scanned.front());
  std::vector<MovedWall> moves;
  std::set<int> moved_lines;
  for (int w : pick) {
    if (moves.size() >= 3 || !moved_lines.insert(walls[w].line).second) continue;
    moves.push_back(move_wall_line(s, walls, w, scanned, random_move(o, r)));
  }
  return moves;
}

std::vector<MovedWall> move_generalised(Spec& s, const std::vector<WallInfo>& walls, const std::vector<int>& scanned,
                                        const SynthOptions& o, Rng& r) {
  std::vector<MovedWall> moves;
  MovedWall front;
  front.offset = r.sign() * r.uniform(kFrontShiftMin * o.min_shift, kFrontShiftMax * o.max_shift);
  if (const int w = first_wall_on(walls, s.coarse_front); w >= 0)
    moves.push_back(move_wall_line(s, walls, w, scanned, front));
  if (r.chance(0.25)) {  // now and then a side or the back is off too
    std::vector<int> others;
    for (int l : s.generalised.front().lines)
      if (l != s.coarse_front) others.push_back(l);
    if (const int w = first_wall_on(walls, others[r.integer(0, int(others.size()) - 1)]); w >= 0)
      moves.push_back(move_wall_line(s, walls, w, scanned, random_move(o, r)));
  }
  if (moves.empty()) throw std::logic_error("synth: the generalised front has no truth wall");
  return moves;
}

Mesh to_soup(const Mesh& m) {
  Mesh s;
  s.id = m.id;
  for (const auto& f : m.faces) {
    Face g{{}, f.sem, -1};
    for (int v : f.v) {
      g.v.push_back(int(s.vertices.size()));
      s.vertices.push_back(m.vertices[v]);
    }
    s.faces.push_back(std::move(g));
  }
  return s;
}

namespace {

int random_face(const Mesh& m, Rng& r, bool roof_only) {
  std::vector<int> c;
  for (int i = 0; i < int(m.faces.size()); ++i)
    if (roof_only ? m.faces[i].sem == Semantic::Roof : m.faces[i].sem != Semantic::Ground) c.push_back(i);
  return c.empty() ? -1 : c[r.integer(0, int(c.size()) - 1)];
}

void copy_face(Mesh& s, int fi) {
  Face g = s.faces[fi];
  for (int& v : g.v) {
    s.vertices.push_back(s.vertices[v]);
    v = int(s.vertices.size()) - 1;
  }
  s.faces.push_back(std::move(g));
}

}  // namespace

std::vector<std::string> add_defects(Mesh& s, Rng& r) {
  bool use[4];
  for (bool& u : use) u = r.chance(0.4);
  if (!(use[0] || use[1] || use[2] || use[3])) use[r.integer(0, 3)] = true;
  std::vector<std::string> log;
  if (use[0]) {
    s.faces.erase(
        std::remove_if(s.faces.begin(), s.faces.end(), [](const Face& f) { return f.sem == Semantic::Ground; }),
        s.faces.end());
    log.push_back("missing_ground");
  }
  if (int f = random_face(s, r, true); use[1] && f >= 0) {  // in-plane jitter keeps the face planar
    const auto [u, v] = polygon_plane(face_points(s, s.faces[f])).basis();
    for (int i : s.faces[f].v) {
      const Vec2 d = r.unit2() * r.uniform(0.001, 0.003);
      s.vertices[i] += d.x() * u + d.y() * v;
    }
    log.push_back("mm_gaps:" + std::to_string(f));
  }
  if (int f = random_face(s, r, false); use[2] && f >= 0) {
    std::reverse(s.faces[f].v.begin(), s.faces[f].v.end());
    log.push_back("reversed_face:" + std::to_string(f));
  }
  if (int f = random_face(s, r, false); use[3] && f >= 0) {
    copy_face(s, f);
    log.push_back("duplicate_face:" + std::to_string(f));
  }
  // Drawn last, so the defects above stay those of earlier versions for every seed.
  if (r.chance(0.5)) {  // every roof polygon's own copy of its corners a few mm off, some > 1 cm
    constexpr double kJitterMin = 0.002, kJitterMax = 0.013;
    for (const auto& f : s.faces)
      if (f.sem == Semantic::Roof)
        for (int i : f.v) {
          const Vec2 d = r.unit2() * r.uniform(kJitterMin, kJitterMax);
          s.vertices[i] += Vec3(d.x(), d.y(), r.uniform(-0.5, 0.5) * kJitterMin);
        }
    log.push_back("roof_jitter");
  }
  return log;
}

}  // namespace lodrefine::synth
