// A real LAZ tile end to end: 3dfier's AHN3 crop (LAZ 1.2, point format 1, 640,510 points)
// goes through `crop`, `eval` and city refine with the city model of the same area and CRS
// (3dfier's testarea.json: CityJSON 1.0, 160 LoD1 buildings) and gets exactly the points of
// its LAS equivalent: the same header and records, uncompressed. Skips without ../shared.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "lodrefine/formats/las.h"
#include "support/cli_fixtures.h"
#include "support/realdata.h"

using namespace lodrefine;
namespace fs = std::filesystem;

namespace {

// The LAZ's LAS twin: its public header with the compression bits cleared and no VLRs, then
// every record as the decoder gives it.
void write_las_twin(const std::string& laz, const std::string& las) {
  const LasHeader h = read_las_header(laz);
  std::string bytes = cli_fixtures::slurp(laz).substr(0, h.header_size);
  bytes[104] = char(h.point_format);
  const std::uint32_t offset = h.header_size, vlrs = 0;
  std::memcpy(&bytes[96], &offset, 4);
  std::memcpy(&bytes[100], &vlrs, 4);
  stream_las_records(laz, [&](const LasHeader& hh, const unsigned char* r) {
    bytes.append(reinterpret_cast<const char*>(r), hh.record_length);
  });
  std::ofstream(las, std::ios::binary) << bytes;
}

}  // namespace

TEST(LazCity, Ahn3LazCropsAndRefinesLikeItsLas) {
  REQUIRE_REALDATA("3dfier/example_data/ahn3/ahn3_cropped_1.laz");
  const fs::path city = fixtures::realdata_dir() / "3dfier/example_data/output/testarea.json";
  ASSERT_TRUE(fs::exists(city)) << city;
  const std::string dir = cli_fixtures::test_dir("lodrefine_laz_city");
  const std::string laz = data_path.string(), las = dir + "/ahn3_cropped_1.las";
  write_las_twin(laz, las);
  ASSERT_EQ(read_las_header(las).point_count, 640510u);
  ASSERT_FALSE(read_las_header(las).compressed);

  // crop: one cloud per LoD1 building, the same bytes from either tile.
  auto r =
      cli_fixtures::run_cli("convert --cityjson '" + city.string() + "' --lod 1 --out-dir '" + dir + "/models'", dir);
  ASSERT_EQ(r.exit, 0) << r.err;
  for (const char* kind : {"laz", "las"}) {
    r = cli_fixtures::run_cli("crop --tile '" + std::string(std::strcmp(kind, "laz") == 0 ? laz : las) +
                                  "' --models '" + dir + "/models' --out '" + dir + "/run_" + kind + "'",
                              dir);
    ASSERT_EQ(r.exit, 0) << r.err;
    EXPECT_NE(r.out.find("640510 tile points, 160 buildings cropped"), std::string::npos) << r.out;
  }
  std::size_t clouds = 0, nonempty = 0;
  for (const auto& e : fs::directory_iterator(dir + "/run_laz")) {
    const fs::path from_laz = e.path() / "cloud.ply",
                   from_las = fs::path(dir) / "run_las" / e.path().filename() / "cloud.ply";
    ASSERT_TRUE(fs::exists(from_las)) << from_las;
    const std::string a = cli_fixtures::slurp(from_laz.string());
    EXPECT_EQ(a, cli_fixtures::slurp(from_las.string())) << e.path().filename();
    ++clouds;
    nonempty += a.size() > 300;
  }
  EXPECT_EQ(clouds, 160u);
  EXPECT_GT(nonempty, 130u);

  // eval reads the tile too (class 9, 267 points, keeps it short): the same figures.
  const std::string model = fs::directory_iterator(dir + "/models")->path().string();
  for (const char* kind : {"laz", "las"}) {
    r = cli_fixtures::run_cli("eval --original '" + model + "' --refined '" + model + "' --cloud '" +
                                  std::string(std::strcmp(kind, "laz") == 0 ? laz : las) + "' --classes 9 --json '" +
                                  dir + "/eval_" + kind + ".json'",
                              dir);
    ASSERT_EQ(r.exit, 0) << r.err;
  }
  const std::string eval = cli_fixtures::slurp(dir + "/eval_laz.json");
  EXPECT_NE(eval.find("\"mls\""), std::string::npos) << eval.substr(0, 400);
  EXPECT_EQ(eval, cli_fixtures::slurp(dir + "/eval_las.json"));

  // City refine (CityJSON 1.0 read, LoD1 refined): the same city file from either tile.
  for (const char* kind : {"laz", "las"}) {
    r = cli_fixtures::run_cli("refine --model '" + city.string() + "' --cloud '" +
                                  std::string(std::strcmp(kind, "laz") == 0 ? laz : las) + "' --lod 1 --out '" + dir +
                                  "/city_" + kind + ".json'",
                              dir);
    ASSERT_EQ(r.exit, 0) << r.err;
    EXPECT_NE((r.out + r.err).find("160 building(s), 640510 cloud points"), std::string::npos) << r.out << r.err;
  }
  const std::string from_laz = cli_fixtures::slurp(dir + "/city_laz.json");
  EXPECT_GT(from_laz.size(), 100000u);
  EXPECT_EQ(from_laz, cli_fixtures::slurp(dir + "/city_las.json"));
}
