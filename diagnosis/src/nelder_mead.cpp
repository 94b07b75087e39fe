#include "drapegen/diagnosis/nelder_mead.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace drapegen::diagnosis {

NelderMeadResult nelder_mead(const std::function<double(const std::vector<double>&)>& f,
                             const std::vector<double>& x0, const std::vector<double>& step,
                             const std::vector<double>& lower, const std::vector<double>& upper,
                             const NelderMeadOptions& options) {
  const std::size_t n = x0.size();
  if (step.size() != n || lower.size() != n || upper.size() != n || n == 0) {
    throw std::invalid_argument("nelder_mead: x0, step and bounds must have the same non-zero size");
  }
  // Coordinates boxed to a single value are held there: the simplex spans the others (a degenerate simplex would
  // spend evaluations on the held directions and never leave the plane they pin).
  std::vector<std::size_t> free;
  for (std::size_t i = 0; i < n; ++i) {
    if (!(lower[i] <= upper[i]))
      throw std::invalid_argument("nelder_mead: a lower bound above its upper bound (or NaN)");
    if (lower[i] < upper[i]) free.push_back(i);
  }
  if (free.size() < n) {
    auto expand = [&](const std::vector<double>& y) {
      std::vector<double> x(n);
      for (std::size_t i = 0; i < n; ++i) x[i] = std::clamp(x0[i], lower[i], upper[i]);
      for (std::size_t k = 0; k < free.size(); ++k) x[free[k]] = y[k];
      return x;
    };
    if (free.empty()) {  // nothing to search: the one point
      NelderMeadResult held;
      held.x = expand({});
      held.f = f(held.x);
      if (!std::isfinite(held.f)) held.f = std::numeric_limits<double>::max();
      held.evaluations = 1;
      held.converged = true;
      held.history = {held.f};
      return held;
    }
    std::vector<double> y0, y_step, y_lower, y_upper;
    for (std::size_t i : free) {
      y0.push_back(x0[i]), y_step.push_back(step[i]), y_lower.push_back(lower[i]), y_upper.push_back(upper[i]);
    }
    NelderMeadResult reduced = nelder_mead([&](const std::vector<double>& y) { return f(expand(y)); }, y0, y_step,
                                           y_lower, y_upper, options);
    reduced.x = expand(reduced.x);
    return reduced;
  }
  NelderMeadResult result;
  double best = std::numeric_limits<double>::infinity();
  auto clamp = [&](std::vector<double> x) {
    for (std::size_t i = 0; i < n; ++i) x[i] = std::clamp(x[i], lower[i], upper[i]);
    return x;
  };
  auto eval = [&](const std::vector<double>& x) {
    double v = f(x);
    if (!std::isfinite(v)) v = std::numeric_limits<double>::max();
    ++result.evaluations;
    if (v < best) {
      best = v;
      result.x = x;
      result.f = v;
    }
    result.history.push_back(best);
    return v;
  };
  std::vector<std::vector<double>> simplex(n + 1);
  std::vector<double> values(n + 1);
  simplex[0] = clamp(x0);
  values[0] = eval(simplex[0]);
  for (std::size_t i = 0; i < n && result.evaluations < options.max_evaluations; ++i) {
    std::vector<double> x = simplex[0];
    x[i] += step[i];
    if (x[i] > upper[i] || x[i] < lower[i]) x[i] = simplex[0][i] - step[i];  // reflect a step out of the box
    simplex[i + 1] = clamp(x);
    values[i + 1] = eval(simplex[i + 1]);
  }
  if (result.evaluations < static_cast<int>(n + 1)) return result;

  constexpr double kReflect = 1.0, kExpand = 2.0, kContract = 0.5, kShrink = 0.5;
  std::vector<std::size_t> order(n + 1);
  while (result.evaluations < options.max_evaluations) {
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return values[a] < values[b]; });
    const std::size_t lo = order[0], hi = order[n], second = order[n - 1];
    double size = 0.0;
    for (std::size_t k = 0; k <= n; ++k)
      for (std::size_t i = 0; i < n; ++i) {
        const double scale = std::max(std::abs(step[i]), 1e-12);
        size = std::max(size, std::abs(simplex[k][i] - simplex[lo][i]) / scale);
      }
    if (values[hi] - values[lo] < options.f_tolerance && size < options.x_tolerance) {
      result.converged = true;
      break;
    }
    std::vector<double> centroid(n, 0.0);
    for (std::size_t k = 0; k <= n; ++k) {
      if (k == hi) continue;
      for (std::size_t i = 0; i < n; ++i) centroid[i] += simplex[k][i] / static_cast<double>(n);
    }
    auto along = [&](double t) {
      std::vector<double> x(n);
      for (std::size_t i = 0; i < n; ++i) x[i] = centroid[i] + t * (simplex[hi][i] - centroid[i]);
      return clamp(x);
    };
    const std::vector<double> xr = along(-kReflect);
    const double fr = eval(xr);
    if (fr < values[lo]) {
      if (result.evaluations >= options.max_evaluations) break;
      const std::vector<double> xe = along(-kExpand);
      const double fe = eval(xe);
      if (fe < fr) {
        simplex[hi] = xe;
        values[hi] = fe;
      } else {
        simplex[hi] = xr;
        values[hi] = fr;
      }
    } else if (fr < values[second]) {
      simplex[hi] = xr;
      values[hi] = fr;
    } else {
      if (result.evaluations >= options.max_evaluations) break;
      const bool outside = fr < values[hi];
      const std::vector<double> xc = along(outside ? -kContract : kContract);
      const double fc = eval(xc);
      if (fc < std::min(fr, values[hi])) {
        simplex[hi] = xc;
        values[hi] = fc;
      } else {
        for (std::size_t k = 0; k <= n && result.evaluations < options.max_evaluations; ++k) {
          if (k == lo) continue;
          for (std::size_t i = 0; i < n; ++i)
            simplex[k][i] = simplex[lo][i] + kShrink * (simplex[k][i] - simplex[lo][i]);
          values[k] = eval(simplex[k]);
        }
      }
    }
  }
  return result;
}

}  // namespace drapegen::diagnosis
