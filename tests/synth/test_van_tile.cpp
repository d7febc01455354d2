// A dev tile scanned again by the van (`synth --rescan`, rescan_tile): the building's own city
// copy kept out of its street, meta.json checked whole before anything is written, walls listed
// again merged, buildings of kilometres refused, and nothing left behind on refusal (issue 47).
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "lodrefine/synth/synth.h"
#include "support/rescan_fixtures.h"

using namespace lodrefine;
using namespace rescan_fixtures;

namespace {

SynthOptions van() {
  SynthOptions o;
  o.scanner = Scanner::Van;
  return o;
}

fs::path test_root() {
  const char* tmp = std::getenv("TEST_TMPDIR");
  return fs::path(tmp ? tmp : "/tmp") /
         ("van_tile_" + std::string(testing::UnitTest::GetInstance()->current_test_info()->name()));
}

void set_building(const fs::path& tile, const json& building) {
  write_text(tile / "meta.json",
             json{{"origin", {kTileOrigin.x(), kTileOrigin.y(), 0.0}}, {"buildings", {building}}}.dump());
}

// The InputError rescan_tile throws ("" when it writes the tile).
std::string refusal(const fs::path& tile, const std::string& city, const fs::path& out, const SynthOptions& o = van()) {
  try {
    rescan_tile(tile.string(), city, out.string(), o, 1, {});
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Facade points (label 0 or 1) of building 0 in meta.json's first building.
long facade_points(const fs::path& out) {
  return json::parse(read_bytes(out / "meta.json"))["buildings"][0]["points"].get<long>();
}

}  // namespace

// Without cityjson_id, the building's copy in the city file stood in its street as a neighbour,
// coinciding with it: its facade's returns went to the copy (the real tile's facade labels fell
// from 99,485 to 10,806). The copy is found where the truth stands, also when it is the coarse
// model a metre off: the van's cloud is the one the id gives, byte for byte.
TEST(VanTile, TheBuildingsOwnCityCopyStaysOutOfItsStreetWithoutCityjsonId) {
  const fs::path root = test_root();
  const fs::path tile = write_tile(root);
  const std::string city = (root / "city.json").string();
  ASSERT_EQ(refusal(tile, city, root / "named"), "");
  set_building(tile, {{"id", "B"}, {"scanned_walls", {0}}});
  ASSERT_EQ(refusal(tile, city, root / "matched"), "");
  set_building(tile, {{"id", "B"}, {"cityjson_id", ""}, {"scanned_walls", {0}}});  // "" is no id (nor every parent)
  ASSERT_EQ(refusal(tile, city, root / "empty_id"), "");
  write_text(root / "coarse_city.json", terrace_city(-0.6));
  ASSERT_EQ(refusal(tile, (root / "coarse_city.json").string(), root / "coarse"), "");
  const std::string named = read_bytes(root / "named" / "tile.ply");
  EXPECT_GT(facade_points(root / "named"), 8000);
  EXPECT_EQ(facade_points(root / "matched"), facade_points(root / "named"));
  EXPECT_EQ(facade_points(root / "coarse"), facade_points(root / "named"));
  EXPECT_TRUE(read_bytes(root / "matched" / "tile.ply") == named) << "the same cloud as with cityjson_id";
  EXPECT_TRUE(read_bytes(root / "coarse" / "tile.ply") == named) << "the same cloud as with cityjson_id";
  EXPECT_TRUE(read_bytes(root / "empty_id" / "tile.ply") == named) << "the same cloud as with cityjson_id";
  // A cityjson_id the city file lacks is a wrong city file (or id): refused, not guessed.
  set_building(tile, {{"id", "B"}, {"cityjson_id", "Z"}, {"scanned_walls", {0}}});
  EXPECT_NE(refusal(tile, city, root / "unknown").find("building \"B\": cityjson_id \"Z\" is no building of"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(root / "unknown"));
  fs::remove_all(root);
}

// One wall listed 200,000 times drew its relief 200,000 times (90-140 s, 680 MB): a wall listed
// again adds nothing, and an entry that is no wall of the truth is refused naming the key.
TEST(VanTile, AWallListedAgainIsMergedAndNoWallIsRefused) {
  const fs::path root = test_root();
  const fs::path tile = write_tile(root, {{"id", "B"}, {"scanned_walls", {0}}});
  ASSERT_EQ(refusal(tile, "", root / "once"), "");
  set_building(tile, {{"id", "B"}, {"scanned_walls", std::vector<int>(200000, 0)}});
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(refusal(tile, "", root / "again"), "");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0);
  EXPECT_TRUE(read_bytes(root / "again" / "tile.ply") == read_bytes(root / "once" / "tile.ply"));
  for (const json& walls : {json{0, 4}, json{"0"}, json{-1}, json(0)}) {
    set_building(tile, {{"id", "B"}, {"scanned_walls", walls}});
    const std::string why = refusal(tile, "", root / "bad");
    EXPECT_NE(why.find("building \"B\": scanned_walls"), std::string::npos) << walls << ": " << why;
    EXPECT_FALSE(fs::exists(root / "bad")) << walls;
  }
  fs::remove_all(root);
}

// A stray vertex 50 km away in truth/<id>.obj had the van drive the 50 km (killed at 60 s): the
// 5 km building limit of refine and crop holds here too, for the truth and the model.
TEST(VanTile, AModelOfKilometresIsRefusedAtOnce) {
  const fs::path root = test_root();
  const fs::path tile = write_tile(root);
  const std::string stray = "v " + std::to_string(kTileOrigin.x() + 50000) + " 447000 0\nf 1 5 9\n";
  for (const char* which : {"truth", "models"}) {
    write_tile(root);
    write_text(tile / which / "B.obj", box_obj_text(0, 0, stray));
    const auto t0 = std::chrono::steady_clock::now();
    const std::string why = refusal(tile, "", root / "out");
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
    EXPECT_NE(why.find(std::string(which) + "/B.obj: spans 50 km, more than a building can (5 km)"), std::string::npos)
        << why;
    EXPECT_FALSE(fs::exists(root / "out")) << which;
  }
  fs::remove_all(root);
}

// Height counts too: one vertex 100 km below the building set its ground there (an empty scan,
// exit 0), and a truth 20 km tall had the van scan storey after storey until it was killed.
TEST(VanTile, AModelOfKilometresInHeightIsRefusedAtOnce) {
  const fs::path root = test_root();
  const fs::path tile = write_tile(root);
  for (const char* z : {"-100000", "20000"}) {
    write_tile(root);
    const std::string stray =
        "v " + std::to_string(kTileOrigin.x()) + " " + std::to_string(kTileOrigin.y()) + " " + z + "\nf 1 5 9\n";
    write_text(tile / "truth" / "B.obj", box_obj_text(0, 0, stray));
    const std::string why = refusal(tile, "", root / "out");
    EXPECT_NE(why.find("truth/B.obj: rises "), std::string::npos) << why;
    EXPECT_NE(why.find("km, more than a building can (1 km)"), std::string::npos) << why;
    EXPECT_FALSE(fs::exists(root / "out"));
  }
  fs::remove_all(root);
}

// meta.json is checked whole before anything is written: a key of the wrong type is named in one
// line (cityjson_id: 5 gave the JSON library's own message), and a refusal, for a missing file or
// an id no file can have, leaves no output folder behind; an output folder that was there before
// stays as it was.
TEST(VanTile, ARefusalLeavesNothingBehind) {
  const fs::path root = test_root();
  const fs::path tile = write_tile(root);
  set_building(tile, {{"id", "B"}, {"cityjson_id", 5}});
  EXPECT_NE(refusal(tile, (root / "city.json").string(), root / "out").find("building \"B\": cityjson_id is no string"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(root / "out"));
  set_building(tile, {{"id", "B"}});
  fs::remove(tile / "truth" / "B.obj");
  EXPECT_NE(refusal(tile, "", root / "out").find("B.obj"), std::string::npos);
  EXPECT_FALSE(fs::exists(root / "out"));
  fs::create_directories(root / "empty");
  EXPECT_NE(refusal(tile, "", root / "empty"), "");
  EXPECT_TRUE(fs::is_empty(root / "empty")) << "an output folder that was there keeps nothing of the run";
  write_text(tile / "truth" / "B.obj", box_obj_text(0, 0));
  for (const json& meta :
       {json{{"buildings", {{{"id", std::string(300, 'a')}}}}, {"origin", {0, 0, 0}}},
        json{{"buildings", {{{"id", "../../etc"}}}}, {"origin", {0, 0, 0}}},
        json{{"buildings", {{{"id", 5}}}}, {"origin", {0, 0, 0}}}, json{{"buildings", json::array()}, {"origin", "x"}},
        json{{"buildings", {{{"id", "B"}}, {{"id", "B"}}}}, {"origin", {0, 0, 0}}}}) {
    write_text(tile / "meta.json", meta.dump());
    EXPECT_NE(refusal(tile, "", root / "out").find("meta.json"), std::string::npos) << meta.dump().substr(0, 80);
    EXPECT_FALSE(fs::exists(root / "out")) << meta.dump().substr(0, 80);
  }
  fs::remove_all(root);
}

// A write failing half-way (here: a folder where a cloud goes) removes the folders the run
// created, and nothing that was there before.
TEST(VanTile, AFailureHalfWayRemovesWhatTheRunCreated) {
  const fs::path root = test_root();
  const fs::path tile = write_tile(root);
  fs::create_directories(root / "out" / "clouds" / "B.ply");
  write_text(root / "out" / "mine.txt", "mine\n");
  EXPECT_THROW(rescan_tile(tile.string(), "", (root / "out").string(), van(), 1, {}), std::exception);
  EXPECT_TRUE(fs::is_directory(root / "out" / "clouds" / "B.ply"));
  EXPECT_EQ(read_bytes(root / "out" / "mine.txt"), "mine\n");
  EXPECT_FALSE(fs::exists(root / "out" / "truth"));
  EXPECT_FALSE(fs::exists(root / "out" / "models"));
  EXPECT_FALSE(fs::exists(root / "out" / "meta.json"));
  fs::remove_all(root);
}

// The van's rays are bounded per building before any is cast: options that pass on the smallest
// building (30 m of drive) but not along this one's 42 m are refused naming the building.
TEST(VanTile, AScanOfTooManyRaysIsRefusedNamingTheBuilding) {
  const fs::path root = test_root();
  const fs::path tile = write_tile(root);
  SynthOptions o = van();
  o.van.angle_step_deg = 0.05, o.van.speed = 2.0, o.van.profile_rate = 50.0;  // 2 x 2,602 rays every 4 cm
  ASSERT_NO_THROW(check_synth_options(o));
  const std::string why = refusal(tile, "", root / "out", o);
  EXPECT_NE(why.find("building \"B\": the van would cast 10.9 M rays, more than the 10 M"), std::string::npos) << why;
  EXPECT_FALSE(fs::exists(root / "out"));
  fs::remove_all(root);
}
