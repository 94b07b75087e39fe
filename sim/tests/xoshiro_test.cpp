// The project's generator against reference outputs. The expected words were computed by a separate
// implementation of xoshiro256** seeded through SplitMix64 (Python integers, written from Blackman and Vigna's
// description); SplitMix64's first output for seed 0, 0xe220a8397b1dcdaf, is the published one.
#include "drapegen/sim/xoshiro.hpp"

#include <gtest/gtest.h>

#include <cstdint>

namespace drapegen::sim {
namespace {

TEST(Xoshiro256, SplitMixOfZeroIsThePublishedValue) { EXPECT_EQ(splitmix64_mix(0), 0xe220a8397b1dcdafULL); }

TEST(Xoshiro256, MatchesAnIndependentImplementation) {
  Xoshiro256 zero(0);
  EXPECT_EQ(zero.next(), 0x99ec5f36cb75f2b4ULL);
  EXPECT_EQ(zero.next(), 0xbf6e1f784956452aULL);
  EXPECT_EQ(zero.next(), 0x1a5f849d4933e6e0ULL);
  Xoshiro256 other(12345);
  EXPECT_EQ(other.next(), 0xbe6a36374160d49bULL);
  EXPECT_EQ(other.next(), 0x214aaa0637a688c6ULL);
  EXPECT_EQ(other.next(), 0xf69d16de9954d388ULL);
}

TEST(Xoshiro256, UniformIsTheTop53BitsScaled) {
  Xoshiro256 a(99), b(99);
  for (int i = 0; i < 100; ++i) {
    const double u = a.uniform();
    EXPECT_EQ(u, static_cast<double>(b.next() >> 11) / 9007199254740992.0);
    EXPECT_GE(u, 0.0);
    EXPECT_LT(u, 1.0);
  }
}

}  // namespace
}  // namespace drapegen::sim
