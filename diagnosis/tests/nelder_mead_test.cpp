#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

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

TEST(NelderMead, HoldsCoordinatesBoxedToOneValue) {
  // The minimum of the free coordinates given the held ones: (x0 - 1)^2 + (x1 - x2)^2 + (x3 + 2)^2 with x2 held at 0.5
  // and x3 at 4 has its minimum at x0 = 1, x1 = 0.5; every call sees the held values exactly.
  int calls = 0;
  auto f = [&](const std::vector<double>& x) {
    ++calls;
    EXPECT_EQ(x[2], 0.5);
    EXPECT_EQ(x[3], 4.0);
    return std::pow(x[0] - 1.0, 2) + std::pow(x[1] - x[2], 2) + std::pow(x[3] + 2.0, 2);
  };
  NelderMeadOptions o;
  o.max_evaluations = 400;
  o.f_tolerance = 1e-12;
  o.x_tolerance = 1e-6;
  const auto r = nelder_mead(f, {0, 0, 0.5, 4.0}, {0.5, 0.5, 0.5, 0.5}, {-5, -5, 0.5, 4.0}, {5, 5, 0.5, 4.0}, o);
  ASSERT_EQ(r.x.size(), 4u);
  EXPECT_NEAR(r.x[0], 1.0, 1e-3);
  EXPECT_NEAR(r.x[1], 0.5, 1e-3);
  EXPECT_EQ(r.x[2], 0.5);
  EXPECT_EQ(r.x[3], 4.0);
  EXPECT_NEAR(r.f, 36.0, 1e-5);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(calls, r.evaluations);
  // The held coordinates are out of the simplex: the search is the one over the two free coordinates alone, point
  // for point (a simplex over four would spend more evaluations, and differently).
  const auto free_two = nelder_mead(
      [](const std::vector<double>& y) { return std::pow(y[0] - 1.0, 2) + std::pow(y[1] - 0.5, 2) + 36.0; },
      {0, 0}, {0.5, 0.5}, {-5, -5}, {5, 5}, o);
  EXPECT_EQ(r.evaluations, free_two.evaluations);
  EXPECT_EQ(r.x[0], free_two.x[0]);
  EXPECT_EQ(r.x[1], free_two.x[1]);

  // Every coordinate held: the one point, evaluated once.
  calls = 0;
  const auto one = nelder_mead(f, {7, 0.5, 0.5, 4.0}, {1, 1, 1, 1}, {7, 0.5, 0.5, 4.0}, {7, 0.5, 0.5, 4.0}, o);
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(one.evaluations, 1);
  EXPECT_EQ(one.x, (std::vector<double>{7, 0.5, 0.5, 4.0}));
  EXPECT_NEAR(one.f, 36.0 + 36.0, 1e-12);

  // A box upside down is an error, not a held coordinate.
  EXPECT_THROW((void)nelder_mead(f, {0, 0, 0.5, 4.0}, {1, 1, 1, 1}, {-5, 1, 0.5, 4.0}, {5, -1, 0.5, 4.0}, o),
               std::invalid_argument);
}
