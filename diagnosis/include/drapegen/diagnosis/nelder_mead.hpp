#pragma once
// A derivative-free minimiser for a handful of parameters and a noisy objective (every evaluation is a simulation):
// Nelder-Mead with box bounds (points are projected into the box), the standard coefficients, and a budget.

#include <functional>
#include <vector>

namespace drapegen::diagnosis {

struct NelderMeadOptions {
  int max_evaluations = 60;
  /// Stop when the simplex's objective values differ by less than this (absolute) and its size is below x_tolerance.
  double f_tolerance = 1e-6;
  double x_tolerance = 1e-3;
};

struct NelderMeadResult {
  std::vector<double> x;
  double f = 0.0;
  int evaluations = 0;
  bool converged = false;
  std::vector<double> history;  // best value after each evaluation
};

/// Minimises f from x0 with an initial simplex x0 + step_i e_i (step_i < 0 allowed), inside [lower, upper]. A
/// coordinate with lower_i == upper_i is held at that value: the simplex spans only the others (none: f once).
[[nodiscard]] NelderMeadResult nelder_mead(const std::function<double(const std::vector<double>&)>& f,
                                           const std::vector<double>& x0, const std::vector<double>& step,
                                           const std::vector<double>& lower, const std::vector<double>& upper,
                                           const NelderMeadOptions& options = {});

}  // namespace drapegen::diagnosis
