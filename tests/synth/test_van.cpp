// The van scanner (`synth --scanner van`): first-hit ray casting from two drives. What a real
// survey delivers and the even sampling lacks: density falling with range, two drives
// misregistered, returns from rooms behind glass, only the street side.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "lodrefine/base/geometry.h"
#include "lodrefine/refine/refine.h"
#include "lodrefine/synth/synth.h"

using namespace lodrefine;

namespace {

SynthOptions van(bool relief) {
  SynthOptions o;
  o.scanner = Scanner::Van;
  o.nuisances = relief;
  o.defects = false;
  o.scanned_facades = 1;
  return o;
}

Plane wall_plane(const SynthBuilding& b, int face) { return polygon_plane(face_points(b.truth, b.truth.faces[face])); }

// The points labelled with truth face f.
std::vector<Vec3> on_face(const SynthBuilding& b, int f) {
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < b.cloud.points.size(); ++i)
    if (b.point_label[i] == f) out.push_back(b.cloud.points[i]);
  return out;
}

}  // namespace

TEST(VanScan, SameSeedSameCloudOtherSeedAnother) {
  const auto a = make_building(BuildingType::Flat, 4, van(true)), b = make_building(BuildingType::Flat, 4, van(true));
  const auto c = make_building(BuildingType::Flat, 5, van(true));
  ASSERT_GT(a.cloud.points.size(), 1000u);
  ASSERT_EQ(a.cloud.points.size(), b.cloud.points.size());
  for (std::size_t i = 0; i < a.cloud.points.size(); i += 97) EXPECT_EQ(a.cloud.points[i], b.cloud.points[i]);
  EXPECT_NE(a.cloud.points.size(), c.cloud.points.size());
}

// Only walls facing a drive return points: the wall opposite the scanned one is never seen.
TEST(VanScan, TheWallAcrossTheBuildingIsNeverSeen) {
  for (std::uint64_t seed : {1, 2, 3}) {
    const auto b = make_building(BuildingType::Flat, seed, van(false));
    const int scanned = b.scanned_truth_faces.front();
    const Vec3 n = wall_plane(b, scanned).n;
    EXPECT_GT(on_face(b, scanned).size(), 2000u) << seed;
    for (int f = 0; f < int(b.truth.faces.size()); ++f) {
      if (b.truth.faces[f].sem == Semantic::Wall && wall_plane(b, f).n.dot(n) < -0.9) {
        EXPECT_EQ(on_face(b, f).size(), 0u) << "seed " << seed << " face " << f;
      }
    }
  }
}

// Profiles fan out from the scanner: the top of a facade gets far fewer points per m² than its
// foot (the ~300 points/m² at 5 m, ~50 at 20 m of a real van).
TEST(VanScan, DensityFallsWithHeight) {
  SynthOptions o = van(false);
  const auto b = make_building(BuildingType::Flat, 11, o);
  const int f = b.scanned_truth_faces.front();
  const auto pts = on_face(b, f);
  double z0 = 1e300, z1 = -1e300;
  for (const auto& v : face_points(b.truth, b.truth.faces[f])) z0 = std::min(z0, v.z()), z1 = std::max(z1, v.z());
  ASSERT_GT(z1 - z0, 5.0);
  int low = 0, high = 0;
  for (const auto& p : pts) low += p.z()<z0 + 2.0, high += p.z()> z1 - 2.0;
  EXPECT_GT(low, 2 * high) << low << " low, " << high << " high";
  const double area = polygon_area(face_points(b.truth, b.truth.faces[f]));
  EXPECT_GT(double(low) / (area * 2.0 / (z1 - z0)), 150.0);  // points per m² at the foot
}

// The second drive is misregistered: the wall appears twice, offset by the drive's shift along
// its normal; each copy holds a share of the points.
TEST(VanScan, TwoDrivesSeeTheWallTwiceByTheirMisregistration) {
  SynthOptions o = van(false);
  o.noise = 0.002;
  o.van.offset = 0.08;
  int checked = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const auto b = make_building(BuildingType::Flat, seed, o);
    const int f = b.scanned_truth_faces.front();
    const Plane pl = wall_plane(b, f);
    const double gap = b.misregistration.dot(pl.n);
    if (std::abs(gap) < 0.02) continue;  // shifted along the wall: one copy
    ++checked;
    int first = 0, second = 0, other = 0;
    for (const auto& p : on_face(b, f)) {
      const double d = pl.distance(p);
      if (std::abs(d) < 0.008) ++first;
      else if (std::abs(d - gap) < 0.008 + 0.01)  // the heading error tilts the copy by up to ~1 cm
        ++second;
      else ++other;
    }
    EXPECT_GT(first, 1000) << seed;
    EXPECT_GT(second, 1000) << seed;
    EXPECT_LT(other, (first + second) / 20) << seed;
  }
  EXPECT_GE(checked, 2);
}

// Through glass the van sees the room: those points lie 1-4 m (and more, obliquely) behind the
// wall, inside the building; panes in their reveals lie 0.1-0.3 m behind it.
TEST(VanScan, GlassShowsTheRoomBehindAndPanesSitInTheirReveals) {
  int rooms = 0, panes = 0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    const auto b = make_building(BuildingType::Flat, seed, van(true));
    const Plane pl = wall_plane(b, b.scanned_truth_faces.front());
    for (std::size_t i = 0; i < b.cloud.points.size(); ++i) {
      const double d = pl.distance(b.cloud.points[i]);
      if (b.point_label[i] == -6 && std::abs(d) < 20) {
        ++rooms;
        EXPECT_LT(d, -0.9) << seed;
      }
      if (b.point_label[i] == -1 && std::abs(d) < 0.5) {
        ++panes;
        EXPECT_LT(d, 0.05) << seed;
        EXPECT_GT(d, -0.35) << seed;
      }
    }
  }
  EXPECT_GT(rooms, 100);
  EXPECT_GT(panes, 100);
}

TEST(VanScan, RejectsAVanThatCannotScan) {
  SynthOptions o = van(false);
  o.van.drives = 0;
  EXPECT_THROW(make_building(BuildingType::Flat, 1, o), InputError);
  o = van(false);
  o.van.profile_rate = 1e6;
  EXPECT_THROW(make_building(BuildingType::Flat, 1, o), InputError);
}

// Refinement on a van's scan: the report's scan object gives the misregistration of the two
// drives where they see a wall apart, and the refined wall stands between the copies, within the
// scan's noise of the truth's middle.
TEST(VanScan, RefinementEstimatesTheMisregistrationAndKeepsOneWall) {
  SynthOptions o = van(false);
  o.van.offset = 0.08;
  int checked = 0;
  for (std::uint64_t seed = 1; seed <= 6 && checked < 2; ++seed) {
    const auto b = make_building(BuildingType::Flat, seed, o);
    const int f = b.scanned_truth_faces.front();
    const double gap = std::abs(b.misregistration.dot(wall_plane(b, f).n));
    if (gap < 0.05) continue;
    ++checked;
    const RefineResult r = refine_building(b.coarse, b.cloud, RefineConfig{});
    ASSERT_TRUE(r.trace.scan.has_value());
    EXPECT_GE(r.trace.scan->doubled_walls, 1) << seed;
    EXPECT_NEAR(r.trace.scan->misregistration, gap, 0.01) << seed;
  }
  EXPECT_EQ(checked, 2);
}
