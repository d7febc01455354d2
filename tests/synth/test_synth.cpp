// Synthetic building generator: truth is a valid closed shell, the coarse model differs only at
// the moved facades, the cloud lies on the scanned walls, and everything is deterministic.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "lodrefine/base/geometry.h"
#include "lodrefine/core/validate.h"
#include "lodrefine/synth/synth.h"

using namespace lodrefine;

namespace {

const std::uint64_t kSeeds[] = {1, 2, 3, 7, 12};

std::vector<Vec3> pts_of(const Mesh& m, const Face& f) {
  std::vector<Vec3> p;
  for (int i : f.v) p.push_back(m.vertices[i]);
  return p;
}

// Every directed edge once, its reverse once: closed, 2-manifold along edges, consistently oriented.
std::string closedness_problem(const Mesh& m) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& f : m.faces)
    for (std::size_t i = 0; i < f.v.size(); ++i) ++directed[{f.v[i], f.v[(i + 1) % f.v.size()]}];
  for (const auto& [e, c] : directed) {
    if (c != 1) return "edge " + std::to_string(e.first) + "-" + std::to_string(e.second) + " used twice the same way";
    const auto rev = directed.find({e.second, e.first});
    if (rev == directed.end()) return "boundary edge " + std::to_string(e.first) + "-" + std::to_string(e.second);
  }
  return "";
}

// A vertex inside another face's edge is a T-junction.
int t_junctions(const Mesh& m) {
  int n = 0;
  for (const auto& f : m.faces)
    for (std::size_t i = 0; i < f.v.size(); ++i) {
      const Vec3 a = m.vertices[f.v[i]], ab = m.vertices[f.v[(i + 1) % f.v.size()]] - a;
      for (const auto& p : m.vertices) {
        const double t = (p - a).dot(ab) / ab.squaredNorm();
        if (t > 1e-6 && t < 1 - 1e-6 && (a + t * ab - p).norm() < 1e-5) ++n;
      }
    }
  return n;
}

// Divergence theorem on the polygons, relative to one vertex (georeferenced magnitudes).
double signed_volume(const Mesh& m) {
  const Vec3 o = m.vertices.front();
  double v = 0;
  for (const auto& f : m.faces) {
    auto p = pts_of(m, f);
    v += (p[0] - o).dot(newell_normal(p)) / 6.0;
  }
  return v;
}

// Per-face planarity from the project's validator (no topology needed, so soups work too).
double max_planarity_error(const Mesh& m) { return validate_mesh(m, 1e-3, false).max_planarity_error; }

std::vector<Plane> planes_of(const Mesh& m, Semantic sem) {
  std::vector<Plane> out;
  for (const auto& f : m.faces)
    if (f.sem == sem) out.push_back(polygon_plane(pts_of(m, f)));
  return out;
}

bool same_plane(const Plane& a, const Plane& b, const Vec3& on_a, double tol) {
  return unoriented_angle_deg(a.n, b.n) < 0.01 && std::abs(b.distance(on_a)) < tol;
}

SynthOptions clean_options() {
  SynthOptions o;
  o.defects = false;
  return o;
}

class SynthAll : public ::testing::TestWithParam<BuildingType> {};

}  // namespace

TEST(SynthNames, RoundTrip) {
  for (auto t : all_building_types()) EXPECT_EQ(building_type_from_name(building_type_name(t)), t);
  EXPECT_EQ(building_type_from_name("L-Shape"), BuildingType::LShape);
  EXPECT_THROW(building_type_from_name("castle"), InputError);
  EXPECT_EQ(all_building_types().size(), 11u);
  EXPECT_EQ(building_type_from_name("setback"), BuildingType::Setback);
  int street = 0;
  for (auto t : all_building_types()) street += street_facade_type(t);
  EXPECT_EQ(street, 3);
  EXPECT_TRUE(street_facade_type(BuildingType::Bay));
  EXPECT_FALSE(street_facade_type(BuildingType::Stepped));
}

TEST(SynthOptionsCheck, RejectsInvertedShiftRange) {
  SynthOptions o;
  o.min_shift = 0.9;
  o.max_shift = 0.5;
  EXPECT_THROW(make_building(BuildingType::Flat, 1, o), InputError);
}

TEST_P(SynthAll, TruthIsClosedPlanarOutwardAndGeoreferenced) {
  for (auto seed : kSeeds) {
    SCOPED_TRACE(std::string(building_type_name(GetParam())) + " seed " + std::to_string(seed));
    const auto b = make_building(GetParam(), seed);
    const Mesh& t = b.truth;
    EXPECT_EQ(closedness_problem(t), "");
    EXPECT_EQ(t_junctions(t), 0);
    Mesh local = t;  // the validator's checks, in a local frame
    for (auto& v : local.vertices) v -= b.frame_origin;
    const Validation val = validate_mesh(local, 1e-3);
    EXPECT_TRUE(val.valid()) << val.problem;
    EXPECT_EQ(val.components, 1);
    EXPECT_GT(signed_volume(t), 50.0);
    EXPECT_LT(max_planarity_error(t), 1e-3);
    int walls = 0, roofs = 0, grounds = 0;
    for (const auto& f : t.faces) {
      const Vec3 n = newell_normal(pts_of(t, f)).normalized();
      walls += f.sem == Semantic::Wall;
      roofs += f.sem == Semantic::Roof;
      grounds += f.sem == Semantic::Ground;
      if (f.sem == Semantic::Wall) {
        EXPECT_LT(std::abs(n.z()), 1e-6);
      }
      if (f.sem == Semantic::Roof) {
        EXPECT_GT(n.z(), 0.3);
      }
      if (f.sem == Semantic::Ground) {
        EXPECT_LT(n.z(), -1 + 1e-9);
      }
    }
    EXPECT_GE(walls, 3);
    EXPECT_GE(roofs, 1);
    EXPECT_EQ(grounds, 1);  // part grounds merge into one polygon
    double zmin = 1e9, zmax = -1e9;
    for (const auto& v : t.vertices) {
      EXPECT_GT(v.x(), 80000.0);
      EXPECT_GT(v.y(), 440000.0);
      zmin = std::min(zmin, v.z()), zmax = std::max(zmax, v.z());
    }
    EXPECT_GT(zmin, -1.0);
    EXPECT_LT(zmax, 25.0);
    EXPECT_GE(zmax - zmin, 3.0);
  }
}

TEST_P(SynthAll, CoarseKeepsRoofPlanesAndMovesOnlyChosenWalls) {
  const SynthOptions o = clean_options();
  for (auto seed : kSeeds) {
    SCOPED_TRACE(std::string(building_type_name(GetParam())) + " seed " + std::to_string(seed));
    const auto b = make_building(GetParam(), seed, o);
    ASSERT_GE(b.moved_walls.size(), 1u);
    ASSERT_LE(b.moved_walls.size(), 3u);
    EXPECT_LE(b.coarse_shift.norm(), o.global_shift + 1e-12);
    Mesh c = b.coarse;
    for (auto& v : c.vertices) v -= b.coarse_shift;
    EXPECT_LT(max_planarity_error(c), 1e-3);
    // Soup: no vertex shared.
    std::size_t corners = 0;
    for (const auto& f : c.faces) corners += f.v.size();
    EXPECT_EQ(corners, c.vertices.size());
    const auto truth_roofs = planes_of(b.truth, Semantic::Roof);
    for (const auto& f : c.faces) {
      if (f.sem != Semantic::Roof) continue;
      const auto p = pts_of(c, f);
      const Plane pl = polygon_plane(p);
      bool found = false;
      for (const auto& tr : truth_roofs) found |= same_plane(pl, tr, polygon_centroid(p), 1e-3);
      EXPECT_TRUE(found) << "coarse roof plane not in the truth";
    }
    // Each coarse vertex is a truth vertex or lies near a moved wall.
    for (const auto& m : b.moved_walls) {
      EXPECT_LE(std::abs(m.offset), o.max_shift + 1e-12);
      EXPECT_LE(std::abs(m.rotation_deg), o.max_rotation_deg + 1e-12);
      // A street type's generalised front moves by 0.1-0.6 m (half the minimum shift and up).
      const double min_shift = street_facade_type(GetParam()) ? 0.5 * o.min_shift : o.min_shift;
      EXPECT_TRUE(std::abs(m.offset) >= min_shift - 1e-12 || m.offset == 0.0);
      EXPECT_GT(std::abs(m.offset) + std::abs(m.rotation_deg), 0.0);
    }
    for (const auto& q : c.vertices) {
      double best = 1e9;
      for (const auto& v : b.truth.vertices) best = std::min(best, (v - q).norm());
      if (best < 1e-4) continue;
      bool near = false;
      for (const auto& m : b.moved_walls) {
        const auto wp = pts_of(b.truth, b.truth.faces[m.truth_faces.front()]);
        const Plane pl = polygon_plane(wp);
        double len = 0;
        for (const auto& a : wp)
          for (const auto& bb : wp) len = std::max(len, (a - bb).head<2>().norm());
        const double bound = std::abs(m.offset) + (len / 2 + 2) * std::tan(radians(std::abs(m.rotation_deg))) + 0.01;
        near |= std::abs(pl.distance(q)) <= bound;
      }
      EXPECT_TRUE(near) << "coarse vertex " << q.transpose() << " moved away from the truth far from a moved wall";
    }
    // The coarse shape itself is a valid closed shell once welded: same face structure check
    // via volume (within what the facade moves can change).
    const double dv = 0.5 * (o.max_shift + 1.0) * 40 * 20 * b.moved_walls.size();
    EXPECT_GT(signed_volume(c), 0.0);
    EXPECT_NEAR(signed_volume(c), signed_volume(b.truth), dv);
  }
}

TEST_P(SynthAll, CloudLiesOnScannedWallsWithinNoise) {
  for (auto seed : kSeeds) {
    SCOPED_TRACE(std::string(building_type_name(GetParam())) + " seed " + std::to_string(seed));
    const SynthOptions o;
    const auto b = make_building(GetParam(), seed, o);
    ASSERT_EQ(b.cloud.points.size(), b.point_label.size());
    ASSERT_GE(b.scanned_truth_faces.size(), 1u);
    ASSERT_LE(b.scanned_truth_faces.size(), street_facade_type(GetParam()) ? 6u : 3u);
    for (int f : b.scanned_truth_faces) EXPECT_EQ(b.truth.faces[f].sem, Semantic::Wall);
    std::map<int, Plane> planes;
    for (int f : b.scanned_truth_faces) planes[f] = polygon_plane(pts_of(b.truth, b.truth.faces[f]));
    std::size_t facade = 0, recess = 0;
    for (std::size_t i = 0; i < b.cloud.points.size(); ++i) {
      const int l = b.point_label[i];
      const Vec3& p = b.cloud.points[i];
      EXPECT_GT(p.x(), 80000.0);
      ASSERT_GE(l, -4);
      if (l >= 0) {
        ASSERT_TRUE(planes.count(l)) << "label " << l << " is not a scanned wall";
        EXPECT_LE(std::abs(planes[l].distance(p)), 4 * o.noise);
        ++facade;
      } else if (l == -1) {
        double best = 1e9;  // 8-25 cm behind one of the scanned walls
        for (const auto& [f, pl] : planes) best = std::min(best, std::abs(pl.distance(p) + 0.165));
        EXPECT_LE(best, 0.085 + 4 * o.noise);
        ++recess;
      }
    }
    EXPECT_GE(facade + recess, std::size_t(0.35 * o.target_points));
    EXPECT_LE(facade + recess, std::size_t(1.1 * o.target_points));
    EXPECT_LE(b.cloud.points.size(), 45000u);
    EXPECT_GT(b.point_spacing, 0.0299);
  }
}

INSTANTIATE_TEST_SUITE_P(SynthTypes, SynthAll, ::testing::ValuesIn(all_building_types()),
                         [](const auto& info) { return std::string(building_type_name(info.param)); });

TEST(SynthFlat, VolumeIsFootprintTimesHeight) {
  for (auto seed : kSeeds) {
    const auto b = make_building(BuildingType::Flat, seed);
    double area = 0, zg = 0, zr = 0;
    for (const auto& f : b.truth.faces) {
      const auto p = pts_of(b.truth, f);
      if (f.sem == Semantic::Ground) area = polygon_area(p), zg = p[0].z();
      if (f.sem == Semantic::Roof) zr = p[0].z();
    }
    EXPECT_EQ(b.truth.faces.size(), 6u);
    EXPECT_NEAR(signed_volume(b.truth), area * (zr - zg), 1e-6 * area * (zr - zg));
  }
}

TEST(SynthStepped, SharedWallAboveLowRoofIsPartOfOneClosedShell) {
  for (auto seed : kSeeds) {
    const auto b = make_building(BuildingType::Stepped, seed);
    std::set<double> roof_heights;
    for (const auto& f : b.truth.faces)
      if (f.sem == Semantic::Roof) roof_heights.insert(std::round(b.truth.vertices[f.v[0]].z() * 1000) / 1000);
    EXPECT_GE(roof_heights.size(), 2u);  // parts of different heights
    EXPECT_EQ(closedness_problem(b.truth), "");
    // Some wall rises from a lower roof: it shares a roof edge and reaches well above it.
    std::map<std::pair<int, int>, int> face_of_edge;
    for (int fi = 0; fi < int(b.truth.faces.size()); ++fi) {
      const auto& v = b.truth.faces[fi].v;
      for (std::size_t i = 0; i < v.size(); ++i) face_of_edge[{v[i], v[(i + 1) % v.size()]}] = fi;
    }
    bool wall_on_roof = false;
    for (const auto& [e, fi] : face_of_edge) {
      const auto other = face_of_edge.find({e.second, e.first});
      if (b.truth.faces[fi].sem != Semantic::Roof || other == face_of_edge.end()) continue;
      const Face& w = b.truth.faces[other->second];
      double ztop = -1e9;
      for (int v : w.v) ztop = std::max(ztop, b.truth.vertices[v].z());
      wall_on_roof |= w.sem == Semantic::Wall && ztop > b.truth.vertices[e.first].z() + 1.0;
    }
    EXPECT_TRUE(wall_on_roof);
  }
}

// The street-facade types: the truth's street facade has a recess (back wall and two returns), a
// bay (front and two sides) or a second facade line; the coarse model is the plain block with
// its front 0.1-0.6 m off; the van scans every street wall, the oblique ones (returns, bay
// sides) more sparsely than the front.
TEST(SynthStreetFacade, TruthHasTheDetailTheGeneralisedModelLacks) {
  const SynthOptions o = clean_options();
  const std::map<BuildingType, std::size_t> street_walls{
      {BuildingType::Recess, 5}, {BuildingType::Bay, 5}, {BuildingType::Setback, 3}};
  for (const auto& [type, n_street] : street_walls)
    for (auto seed : kSeeds) {
      SCOPED_TRACE(std::string(building_type_name(type)) + " seed " + std::to_string(seed));
      const auto b = make_building(type, seed, o);
      int truth_walls = 0, coarse_walls = 0;
      for (const auto& f : b.truth.faces) truth_walls += f.sem == Semantic::Wall;
      for (const auto& f : b.coarse.faces) coarse_walls += f.sem == Semantic::Wall;
      EXPECT_EQ(truth_walls, int(n_street) + 3);  // the street walls, two sides and the back
      EXPECT_EQ(coarse_walls, 4);                 // the generalised block
      ASSERT_GE(b.moved_walls.size(), 1u);
      const MovedWall& front = b.moved_walls.front();
      EXPECT_TRUE(front.scanned);
      EXPECT_EQ(front.rotation_deg, 0.0);
      EXPECT_GE(std::abs(front.offset), 0.1 - 1e-12);
      EXPECT_LE(std::abs(front.offset), 0.6 + 1e-12);
      // Every street wall scanned (one side wall may be too), the street-facing ones densely.
      ASSERT_GE(b.scanned_truth_faces.size(), n_street);
      ASSERT_LE(b.scanned_truth_faces.size(), n_street + 1);
      const Vec3 street = newell_normal(pts_of(b.truth, b.truth.faces[front.truth_faces.front()])).normalized();
      std::map<int, int> points;
      for (int l : b.point_label)
        if (l >= 0) ++points[l];
      double front_density = 0.0, oblique_density = 1e9;
      for (int f : b.scanned_truth_faces) {
        const auto p = pts_of(b.truth, b.truth.faces[f]);
        const double density = points[f] / polygon_area(p);
        EXPECT_GT(points[f], 30) << "truth wall " << f << " has no scan";
        if (newell_normal(p).normalized().dot(street) > 0.9) front_density = std::max(front_density, density);
        else oblique_density = std::min(oblique_density, density);
      }
      EXPECT_LT(oblique_density, front_density);
    }
}

TEST(SynthDeterminism, SameSeedSameBuilding) {
  for (auto t : {BuildingType::Gable, BuildingType::Stepped, BuildingType::Polygon, BuildingType::Recess}) {
    const auto a = make_building(t, 5), b = make_building(t, 5), c = make_building(t, 6);
    ASSERT_EQ(a.cloud.points.size(), b.cloud.points.size());
    for (std::size_t i = 0; i < a.cloud.points.size(); ++i) ASSERT_EQ(a.cloud.points[i], b.cloud.points[i]);
    EXPECT_EQ(a.point_label, b.point_label);
    ASSERT_EQ(a.coarse.vertices.size(), b.coarse.vertices.size());
    for (std::size_t i = 0; i < a.coarse.vertices.size(); ++i) ASSERT_EQ(a.coarse.vertices[i], b.coarse.vertices[i]);
    EXPECT_EQ(a.defects, b.defects);
    EXPECT_EQ(a.id, "synth_" + std::string(building_type_name(t)) + "_0005");
    EXPECT_NE(a.truth.vertices.front(), c.truth.vertices.front());
  }
}

TEST(SynthOptionsEffect, NoNuisancesGivesOnlyFacadePointsNearTarget) {
  SynthOptions o;
  o.nuisances = false;
  o.target_points = 12000;
  o.scanned_facades = 2;
  for (auto seed : kSeeds) {
    const auto b = make_building(BuildingType::Hip, seed, o);
    EXPECT_EQ(b.scanned_truth_faces.size(), 2u);
    for (int l : b.point_label) ASSERT_GE(l, 0);
    EXPECT_GE(b.cloud.points.size(), std::size_t(0.85 * o.target_points));
    EXPECT_LE(b.cloud.points.size(), std::size_t(1.1 * o.target_points));
  }
}

TEST(SynthOptionsEffect, NuisancesAddEveryClutterClass) {
  std::map<int, int> seen;
  for (auto seed : kSeeds)
    for (int l : make_building(BuildingType::LShape, seed).point_label) seen[std::max(l, -5)]++;
  EXPECT_GT(seen[-1], 0);  // window recesses
  EXPECT_GT(seen[-2], 0);  // trees, cars, people
  EXPECT_GT(seen[-3], 0);  // street
  EXPECT_GT(seen[-4], 0);  // neighbour
}

// A neighbour stands past an open end of the street facade: never in the building's own
// footprint hull (in a recess, or before a setback's rear line, where it once stood against the
// facade and the selection took its side wall for a bay's side).
TEST(SynthNuisances, NoNeighbourStandsInTheBuildingsFootprintHull) {
  int neighbours = 0;
  for (BuildingType t : {BuildingType::Recess, BuildingType::Bay, BuildingType::Setback, BuildingType::LShape})
    for (std::uint64_t seed = 1; seed <= 10; ++seed) {
      const auto b = make_building(t, seed);
      SCOPED_TRACE(b.id);
      std::vector<Vec2> xy;
      for (const auto& v : b.truth.vertices) xy.emplace_back(v.x(), v.y());
      const std::vector<Vec2> hull = convex_hull_2d(xy);
      for (std::size_t i = 0; i < b.cloud.points.size(); ++i) {
        if (b.point_label[i] != -4) continue;
        ++neighbours;
        const Vec2 q(b.cloud.points[i].x(), b.cloud.points[i].y());
        double edge = 1e300;
        for (std::size_t k = 0; k < hull.size(); ++k)
          edge = std::min(edge, segment_distance_2d(q, hull[k], hull[(k + 1) % hull.size()]));
        ASSERT_FALSE(point_in_polygon_2d(q, hull) && edge > 0.05) << "a neighbour point " << edge << " m inside";
      }
    }
  EXPECT_GT(neighbours, 0);
}

TEST(SynthDefects, LoggedDefectsArePresentInTheSoup) {
  int missing_ground = 0, duplicates = 0, reversed = 0, gaps = 0;
  for (std::uint64_t seed = 1; seed <= 24; ++seed) {
    const auto b = make_building(BuildingType::Gable, seed);
    const auto clean = make_building(BuildingType::Gable, seed, clean_options());
    ASSERT_FALSE(b.defects.empty());
    int grounds = 0;
    for (const auto& f : b.coarse.faces) grounds += f.sem == Semantic::Ground;
    for (const auto& d : b.defects) {
      if (d == "missing_ground") {
        ++missing_ground;
        EXPECT_EQ(grounds, 0);
      }
      if (d.rfind("duplicate_face:", 0) == 0) {
        ++duplicates;
        const int f = std::stoi(d.substr(15));
        const auto a = pts_of(b.coarse, b.coarse.faces[f]), last = pts_of(b.coarse, b.coarse.faces.back());
        const bool jittered = std::count(b.defects.begin(), b.defects.end(), "roof_jitter") &&
                              b.coarse.faces[f].sem == Semantic::Roof;  // each copy jittered on its own
        if (!jittered) EXPECT_EQ(a, last);
        else EXPECT_EQ(a.size(), last.size());
      }
      if (d.rfind("reversed_face:", 0) == 0) {
        ++reversed;
        const int f = std::stoi(d.substr(14));
        const auto n = newell_normal(pts_of(b.coarse, b.coarse.faces[f]));
        // Outward faces of a convex gable point away from the centroid; reversed ones inward.
        Vec3 centre = Vec3::Zero();
        for (const auto& v : b.coarse.vertices) centre += v;
        centre /= double(b.coarse.vertices.size());
        EXPECT_LT(n.dot(polygon_centroid(pts_of(b.coarse, b.coarse.faces[f])) - centre), 0.0);
      }
      if (d.rfind("mm_gaps:", 0) == 0) ++gaps;
    }
    EXPECT_GE(b.coarse.faces.size() + 1, clean.coarse.faces.size());
  }
  EXPECT_GT(missing_ground, 0);
  EXPECT_GT(duplicates, 0);
  EXPECT_GT(reversed, 0);
  EXPECT_GT(gaps, 0);
}

TEST(SynthDeterminism, DefectsFlagLeavesGeometryAndCloudAlone) {
  const auto a = make_building(BuildingType::Hip, 9), b = make_building(BuildingType::Hip, 9, clean_options());
  EXPECT_EQ(a.point_label, b.point_label);
  ASSERT_EQ(a.cloud.points.size(), b.cloud.points.size());
  EXPECT_EQ(a.cloud.points.back(), b.cloud.points.back());
  EXPECT_EQ(a.truth.vertices, b.truth.vertices);
  EXPECT_FALSE(a.defects.empty());
  EXPECT_TRUE(b.defects.empty());
}

TEST(SynthCloud, ClutterStaysOutsideTheFootprint) {
  for (auto t : {BuildingType::LShape, BuildingType::TShape, BuildingType::Stepped})
    for (auto seed : kSeeds) {
      const auto b = make_building(t, seed);
      std::vector<Vec2> fp;
      for (const auto& f : b.truth.faces)
        if (f.sem == Semantic::Ground)
          for (int v : f.v) fp.push_back((b.truth.vertices[v] - b.frame_origin).head<2>());
      int inside = 0;
      for (std::size_t i = 0; i < b.cloud.points.size(); ++i)
        if (b.point_label[i] <= -2) inside += point_in_polygon_2d((b.cloud.points[i] - b.frame_origin).head<2>(), fp);
      EXPECT_EQ(inside, 0) << b.id;
    }
}
