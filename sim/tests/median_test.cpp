#include "drapegen/sim/median.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace drapegen::sim {
namespace {

TEST(Median, OddCountIsTheMiddleValueWhateverTheOrder) {
  EXPECT_DOUBLE_EQ(median({3.0, -1.0, 7.0}), 3.0);
  EXPECT_DOUBLE_EQ(median({7.0, 3.0, -1.0, 100.0, 2.0}), 3.0);
  EXPECT_DOUBLE_EQ(median({4.5}), 4.5);
}

TEST(Median, EvenCountIsTheMeanOfTheTwoMiddleValues) {
  EXPECT_DOUBLE_EQ(median({1.0, 2.0}), 1.5);
  EXPECT_DOUBLE_EQ(median({10.0, 1.0, 4.0, 2.0}), 3.0);       // sorted 1 2 4 10
  EXPECT_DOUBLE_EQ(median({5.0, 5.0, 0.0, 9.0, 5.0, 1.0}), 5.0);  // sorted 0 1 5 5 5 9: ties
  EXPECT_DOUBLE_EQ(median({6.0, 0.0, 2.0, 8.0, 4.0, 10.0}), 5.0);
}

TEST(Median, AgreesWithSortingOnSamplesOfEverySizeUpToTwelve) {
  // Against the definition (sort, then take the middle or the mean of the two middles), every size 1..12.
  std::vector<double> values;
  for (int n = 1; n <= 12; ++n) {
    values.push_back(std::fmod(37.0 * n, 11.0) - 5.0);
    std::vector<double> sorted = values;
    std::sort(sorted.begin(), sorted.end());
    const std::size_t m = sorted.size();
    const double expected = m % 2 ? sorted[m / 2] : 0.5 * (sorted[m / 2 - 1] + sorted[m / 2]);
    EXPECT_DOUBLE_EQ(median(values), expected) << "n = " << n;
  }
}

TEST(Median, EmptySampleIsNaN) { EXPECT_TRUE(std::isnan(median({}))); }

}  // namespace
}  // namespace drapegen::sim
