// The readers' text helpers (src/base/text.cpp, text.h): quoting file content on one line,
// tokens, whole-token numbers, little-endian fields, input files opened with their reason.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "lodrefine/base/text.h"

using namespace lodrefine;
using namespace lodrefine::io_text;

TEST(Text, QuoteIsPrintableAndShort) {
  EXPECT_EQ(quote("abc"), "'abc'");
  EXPECT_EQ(quote(std::string("a\nb\0c\x7f", 6)), "'a?b?c?'");
  const std::string long_text(100, 'y');
  EXPECT_EQ(quote(long_text), "'" + std::string(40, 'y') + "...'");
  EXPECT_EQ(quote(std::string(40, 'z')), "'" + std::string(40, 'z') + "'");
}

TEST(Text, TrimAndSplitOnWhitespace) {
  EXPECT_EQ(trim(" \t a b \r\n"), "a b");
  EXPECT_EQ(trim(" \t\r\n"), "");
  const auto t = split_ws("  v 1.5\t-2  3e1 \n");
  ASSERT_EQ(t.size(), 4u);
  EXPECT_EQ(t[0], "v");
  EXPECT_EQ(t[1], "1.5");
  EXPECT_EQ(t[2], "-2");
  EXPECT_EQ(t[3], "3e1");
  EXPECT_TRUE(split_ws(" \t ").empty());
}

TEST(Text, NumbersAreWholeTokens) {
  EXPECT_EQ(parse_number<double>("1.25"), 1.25);
  EXPECT_EQ(parse_number<double>("+2"), 2.0);
  EXPECT_EQ(parse_number<double>("-3e2"), -300.0);
  EXPECT_EQ(parse_number<int>("42"), 42);
  EXPECT_FALSE(parse_number<double>("+-5"));
  EXPECT_FALSE(parse_number<double>("1.5x"));
  EXPECT_FALSE(parse_number<double>(""));
  EXPECT_FALSE(parse_number<double>("1e999"));  // overflow
  EXPECT_FALSE(parse_number<int>("99999999999"));
  EXPECT_FALSE(parse_number<int>("1.0"));
}

TEST(Text, LittleEndianFieldsRoundTripByteForByte) {
  std::string out;
  put_le<std::uint16_t>(out, 0x1234);
  put_le<std::int32_t>(out, -2);
  put_le<double>(out, 1.5);
  put_le<float>(out, -0.25f);
  ASSERT_EQ(out.size(), 2u + 4u + 8u + 4u);
  EXPECT_EQ(out.substr(0, 6), std::string("\x34\x12\xfe\xff\xff\xff", 6));
  EXPECT_EQ(out.substr(6, 8), std::string("\0\0\0\0\0\0\xf8\x3f", 8));  // 1.5 = 0x3ff8000000000000
  const auto* p = reinterpret_cast<const unsigned char*>(out.data());
  EXPECT_EQ(get_le<std::uint16_t>(p), 0x1234);
  EXPECT_EQ(get_le<std::int32_t>(p + 2), -2);
  EXPECT_EQ(get_le<double>(p + 6), 1.5);
  EXPECT_EQ(std::uint32_t(get_le<std::uint32_t>(p + 14)), 0xbe800000u);  // -0.25f's bits
}

TEST(Text, OneTokenReplacesBlanksAndControls) {
  EXPECT_EQ(one_token("a b\tc\x01"
                      "d"),
            "a_b_c_d");
  EXPECT_EQ(one_token("plain"), "plain");
}

TEST(Text, InputFilesAreReadWholeOrRefusedWithTheirReason) {
  const std::string dir = testing::TempDir() + "lodrefine_text";
  std::filesystem::create_directories(dir);
  const std::string file = dir + "/f.txt";
  std::ofstream(file, std::ios::binary) << std::string("ab\0c", 4);
  EXPECT_EQ(read_whole_file(file), std::string("ab\0c", 4));
  std::uint64_t size = 0;
  open_input(file, &size);
  EXPECT_EQ(size, 4u);
  const auto message = [](const std::string& path) {
    try {
      read_whole_file(path);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(dir), dir + ": is a directory, not a file");
  EXPECT_NE(message("/dev/null").find("/dev/null: not a regular file"), std::string::npos) << message("/dev/null");
  EXPECT_EQ(message(dir + "/missing").rfind(dir + "/missing: ", 0), 0u) << message(dir + "/missing");
}
