// Cross-check of our C2M signed distances against CloudCompare's (`CloudCompare -C2M_DIST`, run
// headless). Skipped when CloudCompare is not on PATH (Debian package `cloudcompare`).
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "lodrefine/base/geometry.h"
#include "lodrefine/eval/eval.h"
#include "support/mesh_fixtures.h"

using namespace lodrefine;
using namespace lodrefine::fixtures;
namespace fs = std::filesystem;

namespace {

using Triangles = std::vector<std::array<Vec3, 3>>;

Triangles triangles(const Mesh& m) {
  Triangles out;
  for (const Face& f : m.faces) {
    std::vector<Vec3> poly;
    for (int v : f.v) poly.push_back(m.vertices[std::size_t(v)]);
    for (const auto& t : triangulate_polygon(poly)) out.push_back({poly[t[0]], poly[t[1]], poly[t[2]]});
  }
  return out;
}

// CloudCompare needs triangles; orientation is kept so its normals point outward too.
void write_triangle_obj(const std::string& path, const Triangles& tris) {
  std::ofstream out(path);
  out.precision(17);
  for (const auto& t : tris)
    for (const auto& v : t) out << "v " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
  for (std::size_t i = 0; i < tris.size(); ++i)
    out << "f " << 3 * i + 1 << ' ' << 3 * i + 2 << ' ' << 3 * i + 3 << '\n';
}

void write_ascii_ply(const std::string& path, const std::vector<Vec3>& pts) {
  std::ofstream out(path);
  out << "ply\nformat ascii 1.0\nelement vertex " << pts.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  out.precision(9);
  for (const auto& p : pts) out << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
}

// Points everywhere around the mesh plus points within ±0.4 m of its surface, rounded to float
// so that CloudCompare (which stores float coordinates) sees exactly the same points.
std::vector<Vec3> points_around(const Mesh& m, const Triangles& tris, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::AlignedBox3d box = bounding_box(m.vertices);
  const Vec3 lo = box.min() - Vec3::Constant(1.5), hi = box.max() + Vec3::Constant(1.5);
  std::vector<Vec3> pts;
  for (int i = 0; i < 2000; ++i)
    pts.emplace_back(lo.x() + unit(rng) * (hi.x() - lo.x()), lo.y() + unit(rng) * (hi.y() - lo.y()),
                     lo.z() + unit(rng) * (hi.z() - lo.z()));
  for (int i = 0; i < 2000; ++i) {
    const auto& t = tris[std::size_t(unit(rng) * double(tris.size())) % tris.size()];
    double a = unit(rng), b = unit(rng);
    if (a + b > 1) a = 1 - a, b = 1 - b;
    const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
    pts.push_back(t[0] + a * (t[1] - t[0]) + b * (t[2] - t[0]) + (unit(rng) - 0.5) * 0.8 * n);
  }
  for (auto& p : pts) p = p.cast<float>().cast<double>();
  return pts;
}

// Runs CloudCompare's C2M on the files in `dir`; returns its scalar field (one value per point).
std::vector<double> cloudcompare_c2m(const fs::path& dir) {
  const std::string cmd = "cd '" + dir.string() +
                          "' && QT_QPA_PLATFORM=offscreen CloudCompare -SILENT -AUTO_SAVE OFF -O cloud.ply -O mesh.obj"
                          " -C2M_DIST -C_EXPORT_FMT ASC -SAVE_CLOUDS FILE out.asc > cc.log 2>&1";
  if (std::system(cmd.c_str()) != 0) return {};
  std::ifstream in(dir / "out.asc");
  std::vector<double> d;
  for (std::string line; std::getline(in, line);) {
    std::istringstream s(line);
    double x, y, z, v;
    if (s >> x >> y >> z >> v) d.push_back(v);
  }
  return d;
}

bool cloudcompare_available() { return std::system("command -v CloudCompare > /dev/null 2>&1") == 0; }

struct Comparison {
  std::vector<Vec3> points;
  std::vector<double> ours, theirs;
};

// Our C2M and CloudCompare's for points around `mesh` (plus `extra`), in a fresh temp dir.
Comparison run_both(const Mesh& mesh, const std::string& name, const std::vector<Vec3>& extra) {
  const fs::path dir = fs::temp_directory_path() / ("lodrefine_c2m_" + name + "_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const Triangles tris = triangles(mesh);
  Comparison c;
  c.points = points_around(mesh, tris, 7);
  c.points.insert(c.points.end(), extra.begin(), extra.end());
  write_triangle_obj((dir / "mesh.obj").string(), tris);
  write_ascii_ply((dir / "cloud.ply").string(), c.points);
  c.theirs = cloudcompare_c2m(dir);
  c.ours = cloud_to_mesh(mesh, c.points);
  EXPECT_EQ(c.theirs.size(), c.points.size()) << "CloudCompare failed, see " << (dir / "cc.log");
  if (c.theirs.size() != c.points.size()) c.theirs.assign(c.points.size(), 0.0);
  else fs::remove_all(dir);
  return c;
}

// Max |ours − CloudCompare| over all points; `absolute` compares unsigned values.
double max_difference(const Comparison& c, const std::string& name, bool absolute) {
  double worst = 0.0;
  for (std::size_t i = 0; i < c.points.size(); ++i) {
    const double a = absolute ? std::abs(c.ours[i]) : c.ours[i], b = absolute ? std::abs(c.theirs[i]) : c.theirs[i];
    EXPECT_NEAR(a, b, 1e-3) << name << " point " << i << " at " << c.points[i].transpose();
    worst = std::max(worst, std::abs(a - b));
  }
  std::printf("[ C2M vs CloudCompare ] %s: %zu points, max |ours - CloudCompare| = %.3g m (%s)\n", name.c_str(),
              c.points.size(), worst, absolute ? "unsigned" : "signed");
  return worst;
}

double compare_with_cloudcompare(const Mesh& mesh, const std::string& name) {
  return max_difference(run_both(mesh, name, {}), name, false);
}

// Inside a convex mesh: behind every face plane.
bool inside_convex(const Mesh& m, const Vec3& p) {
  for (const Face& f : m.faces) {
    std::vector<Vec3> poly;
    for (int v : f.v) poly.push_back(m.vertices[std::size_t(v)]);
    if (polygon_plane(poly).distance(p) > 0) return false;
  }
  return true;
}

}  // namespace

class C2MCloudCompare : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!cloudcompare_available()) GTEST_SKIP() << "CloudCompare not on PATH (apt-get install cloudcompare)";
  }
};

TEST_F(C2MCloudCompare, Box) { EXPECT_LE(compare_with_cloudcompare(box({0, 0, 0}, {10, 8, 6}), "box"), 1e-3); }

TEST_F(C2MCloudCompare, GableHouse) { EXPECT_LE(compare_with_cloudcompare(gable_house(), "gable"), 1e-3); }

TEST_F(C2MCloudCompare, LShapeWithReflexCorner) {
  const Mesh l = extrusion({{0, 0}, {10, 0}, {10, 4}, {4, 4}, {4, 10}, {0, 10}}, 0, 5);
  EXPECT_LE(compare_with_cloudcompare(l, "lshape"), 1e-3);
}

// CloudCompare 2.11 signs a distance with the normal of one triangle it finds nearest, so just
// above a sharp apex it reports points outside as negative. Unsigned values must still agree;
// our signs must match the true inside/outside of the (convex) pyramid.
TEST_F(C2MCloudCompare, NeedleApexUnsignedAndTrueSign) {
  std::vector<Vec3> ring;  // just above and below the apex, all around it
  for (int k = 0; k < 36; ++k)
    for (double dz : {0.5, 0.05, -0.3}) {
      const double a = k * kPi / 18;
      ring.push_back(Vec3(0.5 * std::cos(a), 0.5 * std::sin(a), 10 + dz).cast<float>().cast<double>());
    }
  const Mesh m = needle();
  const Comparison c = run_both(m, "needle", ring);
  EXPECT_LE(max_difference(c, "needle", true), 1e-3);
  std::size_t cc_wrong = 0;
  for (std::size_t i = 0; i < c.points.size(); ++i) {
    if (std::abs(c.ours[i]) < 1e-6) continue;
    const bool inside = inside_convex(m, c.points[i]);
    EXPECT_EQ(c.ours[i] < 0, inside) << "point " << i << " at " << c.points[i].transpose();
    cc_wrong += (c.theirs[i] < 0) != inside;
  }
  std::printf("[ C2M vs CloudCompare ] needle: CloudCompare's sign is wrong for %zu points, ours for none\n", cc_wrong);
}
