#include <gtest/gtest.h>

#include "parse.hpp"

namespace drapegen::cli {
namespace {

TEST(ParseDirectional, ThreeValuesAreWarpBiasWeft) {
  const auto v = parse_directional("1000,2000.5,-3e3", "--alpha");
  ASSERT_TRUE(v);
  EXPECT_EQ(v->warp, 1000.0);
  EXPECT_EQ(v->bias, 2000.5);
  EXPECT_EQ(v->weft, -3000.0);
}

TEST(ParseDirectional, OneValueIsIsotropic) {
  const auto v = parse_directional("42", "--beta");
  ASSERT_TRUE(v);
  EXPECT_EQ(v->warp, 42.0);
  EXPECT_EQ(v->weft, 42.0);
}

TEST(ParseDirectional, RejectsGarbage) {
  for (const char* bad : {"", "1,2", "1,2,3,4", "a,b,c", "1,,3", "1,2,3,", "nan", "inf,1,1", "1x"}) {
    const auto v = parse_directional(bad, "--alpha");
    ASSERT_FALSE(v) << bad;
    EXPECT_NE(v.error().message.find("--alpha"), std::string::npos);
  }
}

TEST(CheckWritable, ReportsMissingDirectory) {
  EXPECT_TRUE(check_writable(::testing::TempDir() + "/ok.ply"));
  const auto s = check_writable("/nonexistent-dir/x.ply");
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("/nonexistent-dir/x.ply"), std::string::npos);
}

}  // namespace
}  // namespace drapegen::cli
