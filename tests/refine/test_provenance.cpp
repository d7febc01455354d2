// Where a refined building's faces come from (src/refine/provenance.cpp): the share of each scan
// face the scan covers (0.25 m cells, each point covering those within 0.5 m) and the faces no
// stage marked made the model's.
#include <gtest/gtest.h>

#include "lodrefine/base/geometry.h"
#include "lodrefine/core/params.h"
#include "lodrefine/core/planes.h"
#include "lodrefine/refine/provenance.h"

using namespace lodrefine;

namespace {

// A 10 m x 4 m wall in the plane y = 0 (face 0) and the same wall 1 m behind (face 1), both
// Provenance::Scan, and a roof face (face 2) of the model.
Mesh two_walls_and_a_roof() {
  Mesh m;
  m.vertices = {{0, 0, 0}, {10, 0, 0}, {10, 0, 4}, {0, 0, 4}, {0, 1, 0}, {10, 1, 0}, {10, 1, 4}, {0, 1, 4}};
  Face front;
  front.v = {0, 1, 2, 3};
  front.sem = Semantic::Wall;
  front.provenance = Provenance::Scan;
  Face back = front;
  back.v = {5, 4, 7, 6};
  Face roof;
  roof.v = {3, 2, 6, 7};
  roof.sem = Semantic::Roof;
  roof.provenance = Provenance::Model;
  roof.coverage = 0.3;  // a model face's coverage is not the measure's to set
  m.faces = {front, back, roof};
  return m;
}

// Points every 0.25 m over x in [x0, x1], z in [0, 4] at y, and their scan plane (normal -y).
ScanPlane grid(PointCloud& cloud, double x0, double x1, double y, const Vec3& normal = -Vec3::UnitY()) {
  ScanPlane sp;
  sp.plane = Plane::through(Vec3(0, y, 0), normal.normalized());
  for (double x = x0; x <= x1 + 1e-9; x += 0.25)
    for (double z = 0.0; z <= 4.0 + 1e-9; z += 0.25) {
      sp.inliers.push_back(int(cloud.points.size()));
      cloud.points.emplace_back(x, y, z);
    }
  return sp;
}

}  // namespace

TEST(Provenance, CoverageIsTheShareOfTheFaceTheScanReaches) {
  Mesh m = two_walls_and_a_roof();
  PointCloud cloud;
  const std::vector<ScanPlane> planes = {grid(cloud, 0.0, 5.0, 0.0)};
  measure_coverage(m, cloud, planes, RefineConfig{});
  // The left half scanned, each point reaching 0.5 m around it: 5.5 m of the 10 m.
  EXPECT_NEAR(m.faces[0].coverage, 0.55, 0.03);
  EXPECT_DOUBLE_EQ(m.faces[1].coverage, 0.0);  // 1 m off the plane: no point of it
  EXPECT_DOUBLE_EQ(m.faces[2].coverage, 0.3);  // the model's face is left alone
}

TEST(Provenance, WholeScanIsFullCoverage) {
  Mesh m = two_walls_and_a_roof();
  PointCloud cloud;
  const std::vector<ScanPlane> planes = {grid(cloud, 0.0, 10.0, 0.0), grid(cloud, 0.0, 10.0, 1.0, Vec3::UnitY())};
  measure_coverage(m, cloud, planes, RefineConfig{});
  EXPECT_NEAR(m.faces[0].coverage, 1.0, 1e-9);
  EXPECT_NEAR(m.faces[1].coverage, 1.0, 1e-9);
}

TEST(Provenance, PointsOffThePlaneOrOnATurnedPlaneCountForNothing) {
  const RefineConfig prm;
  const double tolerance = prm.plane.ransac_epsilon + prm.selection.merge_distance;  // 0.08 m
  {
    Mesh m = two_walls_and_a_roof();
    PointCloud cloud;
    const std::vector<ScanPlane> planes = {grid(cloud, 0.0, 10.0, tolerance + 0.02)};
    measure_coverage(m, cloud, planes, prm);
    EXPECT_DOUBLE_EQ(m.faces[0].coverage, 0.0);
  }
  {
    Mesh m = two_walls_and_a_roof();
    PointCloud cloud;
    const std::vector<ScanPlane> planes = {grid(cloud, 0.0, 10.0, tolerance - 0.02)};
    measure_coverage(m, cloud, planes, prm);
    EXPECT_NEAR(m.faces[0].coverage, 1.0, 1e-9);
  }
  {
    Mesh m = two_walls_and_a_roof();
    PointCloud cloud;
    const double turned = radians(prm.selection.merge_angle_deg + 1.0);  // its points on y = 0 still
    const std::vector<ScanPlane> planes = {grid(cloud, 0.0, 10.0, 0.0, Vec3(std::sin(turned), -std::cos(turned), 0))};
    measure_coverage(m, cloud, planes, prm);
    EXPECT_DOUBLE_EQ(m.faces[0].coverage, 0.0);
  }
}

TEST(Provenance, FacesNoStageMarkedAreTheModels) {
  Mesh m = two_walls_and_a_roof();
  m.faces[1].provenance = Provenance::None;
  m.faces[2].provenance = Provenance::Added;
  m.faces.push_back(m.faces[1]);
  complete_provenance(m);
  EXPECT_EQ(m.faces[0].provenance, Provenance::Scan);
  EXPECT_EQ(m.faces[1].provenance, Provenance::Model);
  EXPECT_EQ(m.faces[2].provenance, Provenance::Added);
  EXPECT_EQ(m.faces[3].provenance, Provenance::Model);
}
