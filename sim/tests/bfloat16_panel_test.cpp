// bfloat16 rounding and the two panel products of the preconditioner's triangular solves, against double-precision
// products of the rounded values.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "drapegen/sim/bfloat16_panel.hpp"

namespace drapegen::sim {
namespace {

TEST(Bfloat16, RoundsToNearestWithTiesToEven) {
  EXPECT_EQ(from_bfloat16(to_bfloat16(1.0f)), 1.0f);
  EXPECT_EQ(from_bfloat16(to_bfloat16(-3.5f)), -3.5f);
  EXPECT_EQ(from_bfloat16(to_bfloat16(0.0f)), 0.0f);
  // 1 + 2^-8 lies halfway between 1 and 1 + 2^-7 (8 significant bits): the tie goes to the even one, 1.
  EXPECT_EQ(from_bfloat16(to_bfloat16(1.0f + std::ldexp(1.0f, -8))), 1.0f);
  // 1 + 3 * 2^-8 lies halfway between 1 + 2^-7 and 1 + 2^-6: to the even one, 1 + 2^-6.
  EXPECT_EQ(from_bfloat16(to_bfloat16(1.0f + 3.0f * std::ldexp(1.0f, -8))), 1.0f + std::ldexp(1.0f, -6));
  EXPECT_EQ(from_bfloat16(to_bfloat16(1.0f + 1.5f * std::ldexp(1.0f, -8))), 1.0f + std::ldexp(1.0f, -7));
  // Relative error at most 2^-8 (half the spacing of 8 significant bits) over a wide range of magnitudes (the factor's
  // entries span many decades).
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> mantissa(-1.0f, 1.0f);
  std::uniform_int_distribution<int> exponent(-60, 60);
  for (int k = 0; k < 10000; ++k) {
    const float x = std::ldexp(mantissa(rng), exponent(rng));
    if (x == 0.0f) continue;
    EXPECT_LE(std::abs(from_bfloat16(to_bfloat16(x)) - x), std::ldexp(std::abs(x), -8)) << x;
  }
}

TEST(Bfloat16, PanelProductsMatchDoublePrecision) {
  std::mt19937 rng(7);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  // Row counts around the 8-row vector width, column counts around the 4- and 2-column blocking.
  for (int rows : {0, 1, 7, 8, 9, 23, 64, 131}) {
    for (int cols : {1, 2, 3, 4, 5, 7, 12}) {
      std::vector<std::uint16_t> a(static_cast<std::size_t>(rows) * cols);
      for (auto& v : a) v = to_bfloat16(normal(rng));
      std::vector<float> x(cols), y(rows), xt(rows), yt(cols);
      for (auto& v : x) v = normal(rng);
      for (auto& v : y) v = normal(rng);
      for (auto& v : xt) v = normal(rng);
      for (auto& v : yt) v = normal(rng);
      std::vector<double> expect_y(y.begin(), y.end()), expect_yt(yt.begin(), yt.end());
      double scale_y = 1.0, scale_yt = 1.0;  // sums of magnitudes: the bound of float round-off
      for (int j = 0; j < cols; ++j) {
        for (int i = 0; i < rows; ++i) {
          const double aij = from_bfloat16(a[static_cast<std::size_t>(j) * rows + i]);
          expect_y[i] += aij * x[j];
          expect_yt[j] -= aij * xt[i];
          scale_y += std::abs(aij * x[j]);
          scale_yt += std::abs(aij * xt[i]);
        }
      }
      bfloat16_multiply_add(a.data(), rows, cols, x.data(), y.data());
      bfloat16_transpose_multiply_subtract(a.data(), rows, cols, xt.data(), yt.data());
      const double tolerance = 1e-6;
      for (int i = 0; i < rows; ++i) EXPECT_NEAR(y[i], expect_y[i], tolerance * scale_y) << rows << "x" << cols;
      for (int j = 0; j < cols; ++j) EXPECT_NEAR(yt[j], expect_yt[j], tolerance * scale_yt) << rows << "x" << cols;
    }
  }
}

}  // namespace
}  // namespace drapegen::sim
