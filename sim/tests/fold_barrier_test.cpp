// The fold barrier (a hinge's wings may not fold onto each other): its derivatives, its continuity where it starts
// acting, the bending term's derivatives with it, and the steps the line search may not take.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numbers>

#include "derivative_checks.hpp"
#include "drapegen/sim/bending.hpp"
#include "drapegen/sim/dihedral.hpp"
#include "drapegen/sim/fold_barrier.hpp"
#include "drapegen/sim/specimen.hpp"

namespace drapegen::sim {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(FoldBarrier, ZeroUntilTheGapFallsBelowItsWidth) {
  for (double theta : {0.0, 1.0, -2.0, kPi - FoldBarrier::kWidth, -(kPi - FoldBarrier::kWidth)}) {
    double first = 1.0, second = 1.0;
    EXPECT_EQ(FoldBarrier::energy(theta, 2.0, &first, &second), 0.0) << theta;
    EXPECT_EQ(first, 0.0);
    EXPECT_EQ(second, 0.0);
  }
  // Twice continuously differentiable where it starts: value, slope and curvature all vanish as the gap -> width.
  double first = 0.0, second = 0.0;
  const double energy = FoldBarrier::energy(kPi - FoldBarrier::kWidth + 1e-6, 2.0, &first, &second);
  EXPECT_GT(energy, 0.0);
  EXPECT_LT(energy, 1e-15);
  EXPECT_LT(std::abs(first), 1e-9);
  EXPECT_LT(std::abs(second), 1e-4);
  EXPECT_EQ(FoldBarrier::energy(kPi, 2.0), std::numeric_limits<double>::infinity());
}

TEST(FoldBarrier, DerivativesMatchFiniteDifferencesAndPushAwayFromTheWrap) {
  const double k = 3.0, h = 1e-7;
  for (double theta : {2.7, 2.9, 3.0, 3.13, -2.75, -3.05, -3.135}) {
    double first = 0.0, second = 0.0, f_plus = 0.0, f_minus = 0.0;
    const double e = FoldBarrier::energy(theta, k, &first, &second);
    const double e_plus = FoldBarrier::energy(theta + h, k, &f_plus);
    const double e_minus = FoldBarrier::energy(theta - h, k, &f_minus);
    EXPECT_GT(e, 0.0);
    EXPECT_NEAR(first, (e_plus - e_minus) / (2 * h), 1e-6 * std::abs(first)) << theta;
    EXPECT_NEAR(second, (f_plus - f_minus) / (2 * h), 1e-5 * std::abs(second)) << theta;
    EXPECT_GT(second, 0.0) << theta;               // convex
    EXPECT_GT(first * theta, 0.0) << theta;        // the force -dE/dtheta opens the fold
  }
}

/// A 2 x 2 vertex specimen (one hinge), its second wing turned about the hinge's edge until the dihedral angle is
/// `angle`.
Eigen::Matrix3Xd folded(const ClothMesh& mesh, const Hinge& h, double angle) {
  Eigen::Matrix3Xd x = mesh.positions;
  const Eigen::Vector3d origin = x.col(h.v0), axis = (x.col(h.v1) - x.col(h.v0)).normalized();
  auto turned = [&](double psi) {
    Eigen::Matrix3Xd y = x;
    y.col(h.v3) = origin + Eigen::AngleAxisd(psi, axis) * (x.col(h.v3) - origin);
    return y;
  };
  // The angle is +-psi depending on the orientation: pick the sign that gives `angle`.
  Eigen::Matrix3Xd y = turned(angle);
  if (std::abs(dihedral_angle(y.col(h.v0), y.col(h.v1), y.col(h.v2), y.col(h.v3)) - angle) > 1e-9) y = turned(-angle);
  EXPECT_NEAR(dihedral_angle(y.col(h.v0), y.col(h.v1), y.col(h.v2), y.col(h.v3)), angle, 1e-9);
  return y;
}

struct OneHinge {
  ClothMesh mesh = make_specimen(SpecimenSpec{0.02, 0.02, 2, 2, 0.0, Triangulation::kAlternating, 0, 0.0});
  Topology topology = build_topology(mesh);
  DihedralBending bending{mesh, topology, DihedralModuli{{1e-5, 1e-5, 1e-5}, {-1e-8, -1e-8, -1e-8}},
                          AnisotropyRule::kCurvature};
};

TEST(FoldBarrier, BendingDerivativesInsideTheBarrier) {
  OneHinge s;
  ASSERT_EQ(s.topology.hinges.size(), 1u);
  for (double angle : {2.95, 3.05, -3.1}) {
    const Eigen::Matrix3Xd x = folded(s.mesh, s.topology.hinges[0], angle);
    // The energy is the torque law's work plus the barrier, which is a real share of it (the checks below see it).
    const HingeRest rest = hinge_rest_geometry(s.mesh, s.topology)[0];
    const double c = 2.0 / rest.height_sum, e = rest.edge_length;
    const TorqueLaw& law = s.bending.laws()[0];
    const double barrier = FoldBarrier::energy(angle, e * c * law.alpha);
    EXPECT_NEAR(s.bending.energy(x), e / c * law.work(c * std::abs(angle)) + barrier, 1e-12 * s.bending.energy(x));
    EXPECT_GT(barrier, 0.02 * s.bending.energy(x)) << angle;
    check_derivatives(s.bending, x, 1e-9, 1e-5);
    expect_projected_psd(s.bending, x);
  }
}

TEST(FoldBarrier, StepEnergyIsTheEnergyAtTheEndOfAnAdmissibleStep) {
  const ClothMesh mesh = make_specimen(SpecimenSpec{0.03, 0.03, 4, 4, 0.0, Triangulation::kAlternating, 0, 0.0});
  const Topology topology = build_topology(mesh);
  const DihedralBending bending{mesh, topology, DihedralModuli{{1e-5, 2e-5, 3e-5}, {-1e-8, -2e-8, -1e-8}},
                                AnisotropyRule::kCurvature};
  ASSERT_GT(topology.hinges.size(), 10u);
  Eigen::Matrix3Xd wavy = mesh.positions;
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    wavy(2, v) += 0.003 * std::sin(150.0 * wavy(0, v)) * std::cos(110.0 * wavy(1, v));
  }
  // Both ways between a flat and a wavy state: exactly the energy at the end (same hinges, same order of the sum).
  EXPECT_EQ(bending.step_energy(mesh.positions, wavy), bending.energy(wavy));
  EXPECT_EQ(bending.step_energy(wavy, mesh.positions), bending.energy(mesh.positions));
  // A wrap in the last hinge, not the first, rules the step out as well.
  const Hinge& h = topology.hinges.back();
  const Eigen::Matrix3Xd near_pi = folded(mesh, h, 3.1), past_pi = folded(mesh, h, -3.0);
  EXPECT_FALSE(bending.admissible_step(near_pi, past_pi));
  EXPECT_EQ(bending.step_energy(near_pi, past_pi), std::numeric_limits<double>::infinity());
  EXPECT_EQ(bending.step_energy(folded(mesh, h, 2.0), near_pi), bending.energy(near_pi));
}

TEST(FoldBarrier, LineSearchMayNotFoldThroughTheWrap) {
  OneHinge s;
  const Hinge& h = s.topology.hinges[0];
  const Eigen::Matrix3Xd a = folded(s.mesh, h, 2.0), b = folded(s.mesh, h, 2.9), c = folded(s.mesh, h, 3.1),
                         d = folded(s.mesh, h, -3.0), e = folded(s.mesh, h, -1.0);
  EXPECT_TRUE(s.bending.admissible_step(a, b));  // into the barrier
  EXPECT_TRUE(s.bending.admissible_step(a, c));
  EXPECT_TRUE(s.bending.admissible_step(c, a));  // out of it
  EXPECT_FALSE(s.bending.admissible_step(c, d));  // 3.1 -> -3.0: through the wrap
  EXPECT_FALSE(s.bending.admissible_step(d, b));
  EXPECT_TRUE(s.bending.admissible_step(a, e));   // 2.0 -> -1.0: unfolded through flat, not through the wrap
  // Through the wrap and out of the barrier on the other side: the energy at the end has no barrier term at all.
  EXPECT_FALSE(s.bending.admissible_step(b, folded(s.mesh, h, -2.5)));
  // A swing of more than pi through flat is taken for a wrap (conservative: the line search only shortens it).
  EXPECT_FALSE(s.bending.admissible_step(folded(s.mesh, h, -1.7), folded(s.mesh, h, 1.7)));
  // Through the wrap the short way (2.38 rad) yet landing within pi/2 of flat: still ruled out.
  EXPECT_FALSE(s.bending.admissible_step(folded(s.mesh, h, 2.5), folded(s.mesh, h, -1.4)));
  // What the line search sees: the energy is finite at both ends, but the step between them is ruled out.
  EXPECT_TRUE(std::isfinite(s.bending.energy(c)) && std::isfinite(s.bending.energy(d)));
  EXPECT_EQ(s.bending.step_energy(c, d), std::numeric_limits<double>::infinity());
  EXPECT_EQ(s.bending.step_energy(a, c), s.bending.energy(c));  // an admissible step: the energy at its end
  EXPECT_EQ(s.bending.step_energy(c, a), s.bending.energy(a));
}

}  // namespace
}  // namespace drapegen::sim
