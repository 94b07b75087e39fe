// The Newton solver's step control on small synthetic energies with known minimisers.
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "drapegen/sim/newton_solver.hpp"

namespace drapegen::sim {
namespace {

/// E = (k/2) |x_v - target_v|^2 per vertex, with a Hessian `overestimate` times too stiff: the situation of a
/// Gauss-Newton or stale model along a soft direction. Newton's full step then covers 1/overestimate of the way.
class StiffModelSpring final : public EnergyTerm {
 public:
  StiffModelSpring(Eigen::Matrix3Xd target, double k, double overestimate)
      : target_(std::move(target)), k_(k), overestimate_(overestimate) {}
  [[nodiscard]] std::string_view name() const override { return "spring"; }
  [[nodiscard]] int arity() const override { return 1; }
  [[nodiscard]] int element_count() const override { return static_cast<int>(target_.cols()); }
  void element_vertices(int element, int* out) const override { out[0] = element; }
  [[nodiscard]] double energy(const Eigen::Matrix3Xd& x) const override { return evaluate(x, nullptr, nullptr); }
  double evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient, HessianSink* hessian) const override {
    double e = 0.0;
    for (int v = 0; v < element_count(); ++v) {
      const Eigen::Vector3d d = x.col(v) - target_.col(v);
      e += 0.5 * k_ * d.squaredNorm();
      if (gradient != nullptr) gradient->col(v) += k_ * d;
      if (hessian != nullptr) {
        const Eigen::Matrix3d h = overestimate_ * k_ * Eigen::Matrix3d::Identity();
        hessian->add(v, h.data());
      }
    }
    return e;
  }

 private:
  Eigen::Matrix3Xd target_;
  double k_, overestimate_;
};

SolveReport solve_spring(double extrapolate_above, Eigen::Matrix3Xd& x) {
  const Eigen::Matrix3Xd target = Eigen::Matrix3Xd::Constant(3, 4, 1e-3);
  StiffModelSpring spring(target, 10.0, 4.0);
  SolverOptions options;
  options.extrapolate_above = extrapolate_above;
  options.exact_hessian_below = 0.0;  // the model Hessian throughout
  x = Eigen::Matrix3Xd::Zero(3, 4);
  const SolveReport report = NewtonSolver(options).solve({&spring}, std::vector<bool>(4, false), 1e-6, x);
  EXPECT_EQ(report.outcome, SolveOutcome::kConverged) << report.message;
  EXPECT_LT((x - target).cwiseAbs().maxCoeff(), 1e-6);  // m; residual 1e-3 of 1e-6 N at k = 10 N/m
  return report;
}

TEST(NewtonSolver, ExtrapolatesAlongStepsFlatterThanTheModel) {
  Eigen::Matrix3Xd x;
  // The model is 4x too stiff: a full step covers a quarter of the way, the energy drops by 7/8 of the first-order
  // prediction, and the parabola through E(0), E'(0), E(1) puts the minimum at t = 4: exact for a quadratic.
  const SolveReport with = solve_spring(0.75, x);
  const SolveReport without = solve_spring(0.0, x);
  EXPECT_LE(with.iterations, 2);
  // Without extrapolation the error shrinks by 3/4 per step: from 1.7 (relative residual) to 1e-3 takes ~26 steps.
  EXPECT_GE(without.iterations, 20);
}

// Every solve ends in an outcome that says why (docs/PHYSICS.md). A Hessian with NaN in it (energy and gradient
// finite) gives non-finite steps at every shift: diverged, not stalled.
TEST(NewtonSolver, ANonFiniteStepEndsDiverged) {
  const Eigen::Matrix3Xd target = Eigen::Matrix3Xd::Constant(3, 4, 1e-3);
  StiffModelSpring spring(target, 10.0, std::numeric_limits<double>::quiet_NaN());
  SolverOptions options;
  options.exact_hessian_below = 0.0;
  Eigen::Matrix3Xd x = Eigen::Matrix3Xd::Zero(3, 4);
  const SolveReport report = NewtonSolver(options).solve({&spring}, std::vector<bool>(4, false), 1e-6, x);
  EXPECT_EQ(report.outcome, SolveOutcome::kDiverged) << report.message;
  EXPECT_NE(report.message.find("non-finite"), std::string::npos) << report.message;
  EXPECT_EQ(x, Eigen::Matrix3Xd::Zero(3, 4));  // no step was taken
}

TEST(NewtonSolver, TheIterationLimitIsAnOutcome) {
  const Eigen::Matrix3Xd target = Eigen::Matrix3Xd::Constant(3, 4, 1e-3);
  StiffModelSpring spring(target, 10.0, 4.0);  // a quarter of the way per step
  SolverOptions options;
  options.exact_hessian_below = 0.0;
  options.extrapolate_above = 0.0;
  options.max_iterations = 3;
  Eigen::Matrix3Xd x = Eigen::Matrix3Xd::Zero(3, 4);
  const SolveReport report = NewtonSolver(options).solve({&spring}, std::vector<bool>(4, false), 1e-6, x);
  EXPECT_EQ(report.outcome, SolveOutcome::kIterationLimit) << report.message;
  EXPECT_GT(report.residual, options.tolerance);
  EXPECT_LT((x - target).norm(), (Eigen::Matrix3Xd::Zero(3, 4) - target).norm());  // it moved towards the minimum
}

// A start that is already the minimum (zero gradient): converged, not "no descent step" after raising the shift.
TEST(NewtonSolver, AStartAtTheMinimumConverges) {
  const Eigen::Matrix3Xd target = Eigen::Matrix3Xd::Constant(3, 4, 1e-3);
  StiffModelSpring spring(target, 10.0, 1.0);
  Eigen::Matrix3Xd x = target;
  const SolveReport report = NewtonSolver(SolverOptions{}).solve({&spring}, std::vector<bool>(4, false), 1e-6, x);
  EXPECT_EQ(report.outcome, SolveOutcome::kConverged) << report.message;
  EXPECT_EQ(report.residual, 0.0);
  EXPECT_EQ(x, target);
  EXPECT_LE(report.iterations, 3);
  EXPECT_EQ(report.regularized_iterations, 0);
}

}  // namespace
}  // namespace drapegen::sim
