#include <gtest/gtest.h>

#include <cmath>

#include "drapegen/diagnosis/nelder_mead.hpp"

using namespace drapegen::diagnosis;

TEST(NelderMead, Rosenbrock) {
  auto f = [](const std::vector<double>& x) {
    return 100 * std::pow(x[1] - x[0] * x[0], 2) + std::pow(1 - x[0], 2);
  };
  NelderMeadOptions o;
  o.max_evaluations = 2000;
  o.f_tolerance = 1e-14;
  o.x_tolerance = 1e-8;
  const auto r = nelder_mead(f, {-1.2, 1.0}, {0.5, 0.5}, {-5, -5}, {5, 5}, o);
  EXPECT_NEAR(r.x[0], 1.0, 1e-3);
  EXPECT_NEAR(r.x[1], 1.0, 2e-3);
  EXPECT_TRUE(r.converged);
  EXPECT_LE(r.evaluations, 2000);
}

TEST(NelderMead, RespectsBoundsAndBudget) {
  int calls = 0;
  auto f = [&](const std::vector<double>& x) {
    ++calls;
    for (std::size_t i = 0; i < x.size(); ++i) {
      EXPECT_GE(x[i], -1.0);
      EXPECT_LE(x[i], 2.0);
    }
    double s = 0;
    for (double v : x) s += (v - 3.0) * (v - 3.0);  // minimum outside the box
    return s;
  };
  NelderMeadOptions o;
  o.max_evaluations = 300;
  const auto r = nelder_mead(f, {0, 0, 0, 0}, {0.5, 0.5, 0.5, 0.5}, {-1, -1, -1, -1}, {2, 2, 2, 2}, o);
  EXPECT_EQ(calls, r.evaluations);
  EXPECT_LE(r.evaluations, 300);
  for (double v : r.x) EXPECT_NEAR(v, 2.0, 1e-2);
  ASSERT_EQ(static_cast<int>(r.history.size()), r.evaluations);
  for (std::size_t i = 1; i < r.history.size(); ++i) EXPECT_LE(r.history[i], r.history[i - 1]);
}
