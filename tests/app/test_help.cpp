// Issue 50, item 4: every command's help names every format its readers take. `crop --help` said
// "PLY or LAS" while it read LAZ too. The format lists are the readers' own (kCloudFormatNames,
// kCityFormatNames); this table says which command reads what.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "lodrefine/formats/cityjson.h"
#include "lodrefine/formats/cloud.h"
#include "support/cli_fixtures.h"

using namespace lodrefine;
using cli_fixtures::run_cli;

namespace {

struct Reads {
  std::string command;
  bool cloud = false, obj = false, city = false;
};

const std::vector<Reads> kCommands = {
    {"refine", true, true, true},    {"crop", true, true, false},      {"eval", true, true, false},
    {"convert", false, false, true}, {"validate", false, false, true}, {"repair", false, false, true},
};

}  // namespace

TEST(Help, EveryCommandNamesEveryFormatItReads) {
  const std::string dir = cli_fixtures::test_dir("help");
  for (const Reads& r : kCommands) {
    const cli_fixtures::Cli help = run_cli(r.command + " --help", dir);
    ASSERT_EQ(help.exit, 0) << r.command << ": " << help.err;
    std::vector<std::string> names;
    if (r.cloud) names.insert(names.end(), kCloudFormatNames.begin(), kCloudFormatNames.end());
    if (r.city) names.insert(names.end(), kCityFormatNames.begin(), kCityFormatNames.end());
    if (r.obj) names.push_back("OBJ");
    for (const std::string& name : names)
      EXPECT_NE(help.out.find(name), std::string::npos) << r.command << " --help does not name " << name;
  }
}

// The one-line summaries too: `lodrefine --help` lists crop as cutting from a LAZ tile.
TEST(Help, CropsSummaryNamesLaz) {
  const cli_fixtures::Cli help = run_cli("--help", cli_fixtures::test_dir("help"));
  const std::size_t crop = help.out.find("crop");
  ASSERT_NE(crop, std::string::npos);
  const std::string line = help.out.substr(crop, help.out.find('\n', crop) - crop);
  EXPECT_NE(line.find("LAZ"), std::string::npos) << line;
}
