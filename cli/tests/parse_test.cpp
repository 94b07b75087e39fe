#include <gtest/gtest.h>
#include <unistd.h>

#include <iostream>
#include <string>

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

TEST(DecimalInteger, DropsLeadingZerosOfIntegersOnly) {
  EXPECT_EQ(decimal_integer("010"), "10");
  EXPECT_EQ(decimal_integer("0018"), "18");
  EXPECT_EQ(decimal_integer("000"), "0");
  EXPECT_EQ(decimal_integer("-007"), "-7");
  EXPECT_EQ(decimal_integer("+08"), "+8");
  EXPECT_EQ(decimal_integer("42"), "42");
  for (const char* other : {"", "-", "0x10", "1e3", "07a", "abc", " 07"}) {
    EXPECT_EQ(decimal_integer(other), other);
    EXPECT_FALSE(is_decimal_integer(other)) << other;
  }
  for (const char* integer : {"0", "010", "-7", "+8", "18446744073709551615"}) EXPECT_TRUE(is_decimal_integer(integer));
}

TEST(CheckWritable, ReportsMissingDirectory) {
  EXPECT_TRUE(check_writable(::testing::TempDir() + "/ok.ply"));
  const auto s = check_writable("/nonexistent-dir/x.ply");
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("/nonexistent-dir/x.ply"), std::string::npos);
}

TEST(CheckWritable, TakesAnExistingDeviceOrPipeAsItIs) {
  // `--out /dev/stdout` into a pipe: written in place, so no probe file is made beside it (/proc/self/fd, like /dev
  // for a user, takes none).
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const std::string pipe_path = "/proc/self/fd/" + std::to_string(fds[1]);
  const auto s = check_writable(pipe_path);
  EXPECT_TRUE(s) << s.error().message;
  ::close(fds[0]);
  ::close(fds[1]);
  EXPECT_TRUE(check_writable("/dev/null"));
}

// An output that is the file standard output writes to (`--out /dev/stdout`, redirected or piped) takes the summary
// off standard output: on the same descriptor it wrote over the mesh (under `>`) or into it (down a pipe).
TEST(SummaryStream, StandardErrorWhenAnOutputIsStandardOutputsFile) {
  EXPECT_EQ(&summary_stream({}), &std::cout);
  EXPECT_EQ(&summary_stream({"", ::testing::TempDir() + "/other.ply"}), &std::cout);
  EXPECT_EQ(&summary_stream({"/proc/self/fd/1"}), &std::cerr);
  EXPECT_EQ(&summary_stream({"", "/dev/stdout"}), &std::cerr);
}

// Two outputs of one command, or an output and its input, under two spellings of one path.
TEST(SameFile, OnePathUnderTwoSpellings) {
  const std::string dir = ::testing::TempDir();
  EXPECT_TRUE(same_file(dir + "/a.csv", dir + "/./a.csv"));
  EXPECT_FALSE(same_file(dir + "/a.csv", dir + "/b.csv"));
}

TEST(ParseEffects, EveryEffectAndItsErrors) {
  const auto all = parse_effects({"curl=30,15", "yield=40", "shear=2.5", "friction=0.3"});
  ASSERT_TRUE(all.has_value()) << all.error().message;
  ASSERT_TRUE(all->edge_curl && all->bending_yield_curvature && all->shear_stiffness && all->friction);
  EXPECT_DOUBLE_EQ(all->edge_curl->curvature, 30.0);
  EXPECT_DOUBLE_EQ(all->edge_curl->width, 0.015);
  EXPECT_DOUBLE_EQ(*all->bending_yield_curvature, 40.0);
  EXPECT_DOUBLE_EQ(*all->shear_stiffness, 2.5);
  EXPECT_DOUBLE_EQ(all->friction->coefficient, 0.3);
  const auto none = parse_effects({});
  ASSERT_TRUE(none.has_value());
  EXPECT_FALSE(none->any());
  EXPECT_DOUBLE_EQ(parse_effects({"curl=-20"})->edge_curl->width, 0.01);  // default width, curling down
  for (const char* bad : {"curl", "curl=", "curl=x", "curl=1,0", "curl=1,", "yield=0", "yield=-1", "shear=-1",
                          "friction=nan", "friction=-0.1", "plasticity=1", "=3"}) {
    EXPECT_FALSE(parse_effects({bad}).has_value()) << bad;
  }
  EXPECT_FALSE(parse_effects({"shear=1", "shear=2"}).has_value());
}

}  // namespace
}  // namespace drapegen::cli
