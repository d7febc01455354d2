// Repair by reconstruction: see shell_rebuild.h.
#include "lodrefine/refine/shell_rebuild.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include "hole_planes.h"
#include "lodrefine/base/geometry.h"
#include "lodrefine/core/distance.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/refine/candidates.h"
#include "lodrefine/refine/selection.h"
#include "lodrefine/refine/shell_trace.h"
#include "occupancy.h"
#include "shell_checks.h"
#include "shell_describe.h"
#include "shell_mend.h"
#include "shell_supports.h"

namespace lodrefine {
namespace {

using detail::face_flags;
using detail::FaceIndex;
using detail::FaceProps;
using detail::Frame2;
using detail::frame_of;
using detail::nearest_closed_selection;
using detail::shell_problem;
using detail::snapped_to_start;
using detail::Supports;

// A soup's planes are cut over the whole region (a local section can end a plane short of where
// a part closes), up to this many candidates: a larger program is refused (GLPK's root LP of
// 60,000 columns took seconds its work budget does not count: time, not work, ended it). Cutting
// such a soup's planes to 1 m of its faces instead changed no outcome of Delfshaven's 853
// buildings (the 18 it reached stayed kept-invalid), of the sweep or of the tests.
constexpr int kRebuildWholeRegion = 10000;
// A covered candidate dropped costs this times what an uncovered one added costs (per m²): a
// missing wall is added whatever its size, and only what crosses another face is dropped.
constexpr double kKeepCover = 10.0;
// Spacing (m) of the samples the rebuild's distances are measured on, both ways; wider for a
// soup so large that it would take more than kMaxRebuildSamples (each face's grid spans its box).
constexpr double kRebuildSampling = 0.25;
constexpr double kMaxRebuildSamples = 250000;
// The most triangle-sample terms the winding numbers may take per building (each sample farther
// than the tolerance from the shell costs the soup's triangles); past it, a sample counts as
// uncovered: the rebuild is refused rather than slow (untrusted input).
constexpr double kMaxWindingTerms = 2e8;

// The selection of the candidates at each point where the traced `shell` is no 2-manifold
// (pinched_vertices): one the edge constraints allow that no solid is. Each is then excluded and
// the program solved again (a candidate added there or one dropped), at most kPinchRounds times.
constexpr int kPinchRounds = 4;
std::vector<LocalSelection> pinches(const CandidateSet& cs, const std::vector<char>& chosen, const Mesh& shell) {
  std::vector<LocalSelection> out;
  for (int v : pinched_vertices(shell)) {
    const Vec3& p = shell.vertices[std::size_t(v)];
    LocalSelection at;
    for (int f = 0; f < cs.size(); ++f) {
      const std::vector<int> corners = cs.corners(f);
      if (std::any_of(corners.begin(), corners.end(),
                      [&](int c) { return (cs.vertices[std::size_t(c)] - p).norm() < 1e-9; }))
        (chosen[f] ? at.selected : at.unselected).push_back(f);
    }
    if (!at.selected.empty()) out.push_back(std::move(at));
  }
  return out;
}

void set_selected(CandidateSet& cs, const std::vector<char>& chosen) {
  auto map = candidate_props::selected.add(cs.mesh);
  for (int f = 0; f < cs.size(); ++f) map[FaceIndex(f)] = chosen[f] != 0;
}

// The spacing of `m`'s samples: kRebuildSampling, or wider where its faces' boxes (bounded by
// their diagonals) would hold more than kMaxRebuildSamples.
double sample_spacing(const Mesh& m) {
  double box_area = 0.0;
  for (const Face& f : m.faces) box_area += bounding_box(face_points(m, f)).sizes().squaredNorm();
  return std::max(kRebuildSampling, std::sqrt(box_area / kMaxRebuildSamples));
}

// The samples of a face: a grid every `spacing`, and its vertices moved a hundredth of the way to
// its centroid (inside the face, off its neighbours).
std::vector<Vec3> face_samples(const Mesh& m, int f, double spacing) {
  std::vector<Vec3> pts = sample_faces(m, {f}, spacing);
  const std::vector<Vec3> corners = face_points(m, m.faces[std::size_t(f)]);
  const Vec3 c = polygon_centroid(corners);
  for (const Vec3& p : corners) pts.push_back(p + 0.01 * (c - p));
  return pts;
}

// The shell's area on the soup (samples within `tolerance` of it) and beside it (added), and the
// farthest a sample and a vertex lie from it.
void added_area(const Mesh& shell, const Mesh& soup, double tolerance, ShellRebuild& out) {
  const MeshDistance dist(soup);
  for (const Vec3& p : shell.vertices) out.corner_to_input = std::max(out.corner_to_input, dist.distance(p, false));
  const double spacing = sample_spacing(shell);
  for (int f = 0; f < int(shell.faces.size()); ++f)
    for (const Vec3& p : sample_faces(shell, {f}, spacing)) {
      const double d = dist.distance(p, false);
      out.output_to_input = std::max(out.output_to_input, d);
      (d <= tolerance ? out.area_kept : out.area_added) += spacing * spacing;
    }
}

// The generalized winding number (Jacobson, Kavan and Sorkine-Hornung 2013) of a soup's faces, as
// read (outward): about 1 inside what they enclose, 0 outside, fractional near a hole.
class Winding {
 public:
  explicit Winding(const Mesh& soup) {
    for_each_triangle(soup, [&](const Vec3& a, const Vec3& b, const Vec3& c, int f) { tris_.push_back({a, b, c, f}); });
  }
  std::size_t triangles() const { return tris_.size(); }
  // At `p`, of the faces other than `skip`.
  double without(int skip, const Vec3& p) const {
    double sum = 0.0;
    for (const Tri& t : tris_) {
      if (t.face == skip) continue;
      const Vec3 a = t.a - p, b = t.b - p, c = t.c - p;
      const double la = a.norm(), lb = b.norm(), lc = c.norm();
      sum += 2.0 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
    }
    return sum / (4.0 * kPi);
  }

 private:
  struct Tri {
    Vec3 a, b, c;
    int face;
  };
  std::vector<Tri> tris_;
};

// A soup face's point where the rest of the soup winds more than this has the soup's volume on
// both sides: a partition between two parts. An outer wall has it on one side only (about 1/2),
// a fin on neither (less than kFinWinding).
constexpr double kPartitionWinding = 0.75;
constexpr double kFinWinding = 0.25;

// The soup's samples (face_samples, every `spacing`), per face, with their signed distances to
// the rebuilt shell: the fins and the coverage are measured on the same ones.
struct SoupSamples {
  double spacing = 0.0;
  std::vector<std::vector<Vec3>> at;
  std::vector<std::vector<double>> to_shell;
  // Whether a sample of face `f` lies farther than `tolerance` from the shell.
  bool off(int f, double tolerance) const {
    const auto& d = to_shell[std::size_t(f)];
    return std::any_of(d.begin(), d.end(), [&](double x) { return std::abs(x) > tolerance; });
  }
};
SoupSamples samples_of(const Mesh& soup, const MeshDistance& to_shell) {
  SoupSamples out;
  out.spacing = sample_spacing(soup);
  for (int f = 0; f < int(soup.faces.size()); ++f) {
    out.at.push_back(face_samples(soup, f, out.spacing));
    out.to_shell.emplace_back();
    for (const Vec3& p : out.at.back()) out.to_shell.back().push_back(to_shell.distance(p, true));
  }
  return out;
}

bool convex_2d(const std::vector<Vec2>& poly) {
  int sign = 0;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2 a = poly[(i + 1) % poly.size()] - poly[i];
    const Vec2 b = poly[(i + 2) % poly.size()] - poly[(i + 1) % poly.size()];
    const double z = a.x() * b.y() - a.y() * b.x();
    if (std::abs(z) < 1e-12) continue;
    if (sign != 0 && (z > 0) != (sign > 0)) return false;
    sign = z > 0 ? 1 : -1;
  }
  return true;
}

// The parts of a face (`points`, flat: `face`) inside the convex `candidate`, each convex: a
// convex face clipped whole, another triangle by triangle (clipped whole it could come out
// touching itself). Without those narrower than `tolerance` (twice the area over the perimeter):
// a sliver where two planes cross within it.
std::vector<std::vector<Vec2>> convex_pieces(const std::vector<Vec3>& points, const std::vector<Vec2>& face,
                                             const std::vector<Vec2>& candidate, double tolerance) {
  std::vector<std::vector<Vec2>> parts;
  if (convex_2d(face)) {
    parts.push_back(face);
  } else {
    for (const auto& t : triangulate_polygon(points))
      parts.push_back({face[std::size_t(t[0])], face[std::size_t(t[1])], face[std::size_t(t[2])]});
  }
  std::vector<std::vector<Vec2>> out;
  for (const auto& part : parts) {
    std::vector<Vec2> piece = polygon_clipped_to_convex(part, candidate);
    double perimeter = 0.0;
    for (std::size_t i = 0; i < piece.size(); ++i) perimeter += (piece[(i + 1) % piece.size()] - piece[i]).norm();
    if (piece.size() >= 3 && 2.0 * std::abs(signed_area_2d(piece)) > tolerance * perimeter)
      out.push_back(std::move(piece));
  }
  return out;
}

// The pieces of the soup's faces outside the shell with the soup's outside on both sides (its
// winding there, without their own face, below kFinWinding): a fin, such as a neighbour's wall
// standing above the roof. No solid holds one, so it goes beside the shell, as read: each soup
// face with samples off the shell clipped to the candidates of its plane the selection left out,
// in the face's orientation, semantic and source. Each piece's winding number counts against
// `terms` (kMaxWindingTerms): past it, no piece is carried (the rebuild is then refused).
Mesh fins_beside(const CandidateSet& cs, const Supports& s, const std::vector<char>& chosen, const Mesh& soup,
                 const SoupSamples& samples, const MeshDistance& to_shell, const Winding& winding, double tolerance,
                 double& terms) {
  std::vector<std::vector<int>> left_out(cs.planes.size());
  const auto support = cs.supports();
  for (int f = 0; f < cs.size(); ++f)
    if (!chosen[f]) left_out[std::size_t(support[FaceIndex(f)])].push_back(f);
  Mesh fins;
  fins.id = soup.id;
  for (int sf = 0; sf < int(soup.faces.size()); ++sf) {
    const int k = s.face_plane[std::size_t(sf)];
    if (k < 0 || !samples.off(sf, tolerance)) continue;
    // At the plane's point nearest the local origin: the clip rounds as it was measured (an origin
    // at the region's centre changed one Delfshaven building's figures).
    const Frame2 frame = frame_of(cs.planes[std::size_t(k)].plane, Vec3::Zero());
    auto flat = [&](const std::vector<Vec3>& poly) {
      std::vector<Vec2> out;
      for (const Vec3& p : poly) out.push_back(frame(p));
      return out;
    };
    const std::vector<Vec3> points = face_points(soup, soup.faces[std::size_t(sf)]);
    const std::vector<Vec2> face = flat(points);
    const Eigen::AlignedBox2d face_box = bounding_box(face);
    for (int f : left_out[std::size_t(k)]) {
      const std::vector<Vec2> candidate = flat(cs.polygon(f));
      if (!face_box.intersects(bounding_box(candidate))) continue;
      for (const std::vector<Vec2>& piece : convex_pieces(points, face, candidate, tolerance)) {
        std::vector<Vec3> corners;
        for (const Vec2& q : piece) corners.push_back(frame.lifted(q));
        const Vec3 c = polygon_centroid(corners);
        if (to_shell.distance(c, true) <= tolerance) continue;
        terms += double(winding.triangles());
        if (terms > kMaxWindingTerms || std::abs(winding.without(sf, c)) >= kFinWinding) continue;
        Face out = soup.faces[std::size_t(sf)];
        out.v.clear();
        for (const Vec3& p : corners) {
          out.v.push_back(int(fins.vertices.size()));
          fins.vertices.push_back(p);
        }
        fins.faces.push_back(std::move(out));
      }
    }
  }
  return snapped_to_start(fins, soup);
}

// The farthest a soup sample lies from the rebuilt shell (`samples`: their distances to it) and
// the `fins` beside it (m), over the samples they must cover: all but a partition between parts
// the shell joins (inside it, the soup's volume on both sides). An outer wall the shell swallows
// is no partition, and a fin not carried beside it leaves the soup uncovered too. `out` gets the
// areas (m²) of the samples farther than `tolerance` from the shell: on the fins (carried), the
// partitions' (dropped), the others (uncovered) and of those a fin's.
double uncovered(const SoupSamples& samples, const Mesh& fins, const Winding& winding, double tolerance, double terms,
                 ShellRebuild& out) {
  const std::optional<MeshDistance> to_fins =
      fins.faces.empty() ? std::nullopt : std::make_optional<MeshDistance>(fins);
  const double sample_area = samples.spacing * samples.spacing;
  out.sampling = samples.spacing;
  double worst = 0.0;
  for (int f = 0; f < int(samples.at.size()); ++f)
    for (std::size_t i = 0; i < samples.at[std::size_t(f)].size(); ++i) {
      const Vec3& p = samples.at[std::size_t(f)][i];
      const double d = samples.to_shell[std::size_t(f)][i];
      if (std::abs(d) <= tolerance) {
        worst = std::max(worst, std::abs(d));
        continue;
      }
      if (to_fins) {
        const double d_fin = to_fins->distance(p, false);
        if (d_fin <= tolerance) {
          worst = std::max(worst, d_fin);
          out.area_carried += sample_area;
          continue;
        }
      }
      terms += double(winding.triangles());
      const double w = terms <= kMaxWindingTerms ? winding.without(f, p) : 0.5;  // past the budget: a wall
      if (d < 0.0 && w > kPartitionWinding) {
        out.area_dropped += sample_area;
        continue;
      }
      worst = std::max(worst, std::abs(d));
      out.area_uncovered += sample_area;
      if (std::abs(w) < kFinWinding) out.area_fins += sample_area;
    }
  return worst;
}

}  // namespace

ShellRebuild rebuild_shell(const Mesh& soup, const RefineConfig& prm) {
  ShellRebuild out;
  Supports s;
  detail::add_start_planes(soup, prm.repair.planarity_tolerance, s);
  if (!detail::carries_ground(soup, s)) {
    out.reason = "it has no ground face: the foot of its walls would be invented";
    return out;
  }
  detail::add_hole_planes(soup, s);
  out.planes_added = s.hole_planes;
  const Region region = detail::building_region(soup, s, prm.plane.facade_max_tilt_deg);
  CandidateSet cs = build_candidates(s.planes, region, {}, kRebuildWholeRegion);
  if (cs.capped) {
    out.reason = "too many candidate faces (over " + std::to_string(kRebuildWholeRegion) + " from " +
                 std::to_string(s.planes.size()) + " planes)";
    return out;
  }
  const FaceProps props = describe_candidates(cs, soup, s, prm);
  const std::vector<char> cover = face_flags(cs, props.in_start);
  std::vector<char> chosen;
  std::vector<LocalSelection> excluded;
  for (int round = 0;; ++round) {
    chosen = nearest_closed_selection(cs, cover, prm.selection, {true, kKeepCover}, excluded);
    if (chosen.empty()) {
      out.reason = "its planes bound no closed shell";
      return out;
    }
    set_selected(cs, chosen);
    out.mesh = traced_shell(cs);
    out.mesh.id = soup.id;
    const std::string problem = shell_problem(out.mesh, prm.repair);
    if (problem.empty()) break;
    const std::vector<LocalSelection> more = pinches(cs, chosen, out.mesh);
    if (more.empty() || round == kPinchRounds) {
      out.reason = "the shell on its planes is invalid: " + problem;
      return out;
    }
    excluded.insert(excluded.end(), more.begin(), more.end());
  }
  for (int f = 0; f < cs.size(); ++f) out.candidates_changed += chosen[f] != cover[f];
  Mesh snapped = snapped_to_start(out.mesh, soup);
  if (shell_problem(snapped, prm.repair).empty()) out.mesh = std::move(snapped);
  const Winding winding(soup);
  const MeshDistance to_shell(out.mesh);
  const SoupSamples samples = samples_of(soup, to_shell);
  double terms = 0.0;  // the winding numbers' work, both passes (kMaxWindingTerms)
  const double tolerance = prm.repair.weld_tolerance;
  out.fins = fins_beside(cs, s, chosen, soup, samples, to_shell, winding, tolerance, terms);
  out.input_to_output = uncovered(samples, out.fins, winding, tolerance, terms, out);
  added_area(out.mesh, soup, prm.repair.weld_tolerance, out);
  out.ok = true;
  return out;
}

}  // namespace lodrefine
