// Finite-difference checks of every energy's gradient and exact Hessian, and PSD-ness of the projected Hessian.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <memory>
#include <random>

#include "derivative_checks.hpp"
#include "drapegen/sim/bending.hpp"
#include "drapegen/sim/dihedral.hpp"
#include "drapegen/sim/gravity.hpp"
#include "drapegen/sim/membrane.hpp"
#include "drapegen/sim/platform.hpp"
#include "drapegen/sim/specimen.hpp"

namespace drapegen::sim {
namespace {

TEST(Derivatives, MembraneStretchBandIsC2) {
  CorotationalMembrane membrane(crumpled_mesh(1, 0.0), MembraneParameters{200.0, 0.99, 1.01, 0.01});
  for (double s : {0.95, 0.985, 0.99, 0.995, 1.0, 1.007, 1.01, 1.012, 1.015, 1.05}) {
    const double h = 1e-7;
    const auto g = membrane.stretch_energy(s);
    EXPECT_NEAR(g.first, (membrane.stretch_energy(s + h).value - membrane.stretch_energy(s - h).value) / (2 * h), 1e-7);
    // g is C2; its third derivative jumps at the band edges, which limits central differences to ~1e-5 there.
    EXPECT_NEAR(g.second, (membrane.stretch_energy(s + h).first - membrane.stretch_energy(s - h).first) / (2 * h),
                1e-4);
  }
  EXPECT_DOUBLE_EQ(membrane.stretch_energy(1.0).value, 0.0);
  EXPECT_DOUBLE_EQ(membrane.stretch_energy(1.005).second, 0.02);  // eps * 2 inside the band
  EXPECT_DOUBLE_EQ(membrane.stretch_energy(1.02).second, 2.0);
}

TEST(Derivatives, MembraneWithStretchBand) {
  // Stretches of 1.02 and 0.97 plus noise: principal stretches inside and outside the band.
  const ClothMesh mesh = crumpled_mesh(1, 3e-4);
  CorotationalMembrane membrane(mesh, MembraneParameters{200.0, 0.99, 1.01});
  EXPECT_GT(membrane.energy(mesh.positions), 0.0);
  check_derivatives(membrane, mesh.positions, 1e-7, 1e-5);
  expect_projected_psd(membrane, mesh.positions);
}

TEST(Derivatives, MembraneUnderCompressionHasIndefiniteExactHessian) {
  ClothMesh mesh = crumpled_mesh(3, 0.0);
  mesh.positions.topRows<2>() = 0.8 * mesh.rest;  // strong compression: twist and out-of-plane modes go negative
  mesh.positions.row(2).setZero();
  mesh.positions(2, 12) = 1e-4;
  CorotationalMembrane membrane(mesh, MembraneParameters{200.0, 1.0, 1.0});
  const Eigen::MatrixXd h = check_derivatives(membrane, mesh.positions, 1e-8, 1e-5);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(h);
  EXPECT_LT(eig.eigenvalues().minCoeff(), 0.0);
  expect_projected_psd(membrane, mesh.positions);
}

TEST(Derivatives, DihedralAngleMatchesGeometry) {
  // A hinge folded by a known angle: wing x2 rotated about the edge (x axis) by -phi (lifted), x3 flat.
  const double phi = 0.7;
  const Eigen::Vector3d x0(0, 0, 0), x1(1, 0, 0), x2(0.3, std::cos(phi), std::sin(phi)), x3(0.6, -1.0, 0.0);
  EXPECT_NEAR(dihedral_angle(x0, x1, x2, x3), -phi, 1e-12);
  EXPECT_NEAR(dihedral_angle(x0, x1, Eigen::Vector3d(0.3, 1, 0), x3), 0.0, 1e-15);
}

TEST(Derivatives, NonlinearDihedralBendingSofteningAndStiffening) {
  const ClothMesh mesh = crumpled_mesh(4, 4e-4);
  const Topology topo = build_topology(mesh);
  // Soft enough that some hinges sit on the torque plateau (kappa > alpha / 2|beta|) and some below.
  for (double beta : {-3e-7, 3e-9}) {
    DihedralModuli moduli{{1e-5, 1.5e-5, 2e-5}, {beta, 0.5 * beta, 0.8 * beta}};
    DihedralBending bending(mesh, topo, moduli, AnisotropyRule::kCurvature);
    bending.update_lagged(mesh.positions);
    if (beta < 0) {  // the configuration must exercise both branches of the torque law
      const std::vector<HingeRest> rest = hinge_rest_geometry(mesh, topo);
      int plateau = 0, rising = 0;
      for (std::size_t i = 0; i < topo.hinges.size(); ++i) {
        const Hinge& h = topo.hinges[i];
        const double kappa = 2.0 / rest[i].height_sum *
                             std::abs(dihedral_angle(mesh.positions.col(h.v0), mesh.positions.col(h.v1),
                                                     mesh.positions.col(h.v2), mesh.positions.col(h.v3)));
        (kappa > bending.laws()[i].peak_curvature() ? plateau : rising)++;
      }
      EXPECT_GT(plateau, 0);
      EXPECT_GT(rising, 0);
    }
    check_derivatives(bending, mesh.positions, 1e-8, 1e-5);
    expect_projected_psd(bending, mesh.positions);
  }
}

TEST(Derivatives, QuadraticBending) {
  const ClothMesh mesh = crumpled_mesh(5, 4e-4);
  const Topology topo = build_topology(mesh);
  QuadraticBending bending(mesh, topo, DirectionalValues{3e-6, 4e-6, 5e-6}, AnisotropyRule::kEdge);
  check_derivatives(bending, mesh.positions, 1e-7, 1e-5);
  expect_projected_psd(bending, mesh.positions);
}

TEST(Derivatives, PlatformContactOnTopRimAndWall) {
  ClothMesh mesh = make_specimen(SpecimenSpec{0.02, 0.02, 4, 4, 0.0, Triangulation::kAlternating, 0, 0.0});
  PlatformSpec spec;
  // Place vertices around the rim of the platform: on the top, over the rounded rim and against the wall, all
  // slightly inside the contact offset.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    const double azimuth = 2.0 * M_PI * u(rng);
    const double along = -0.004 + 0.008 * u(rng);  // from top (z>0 side) over the rim to the wall
    Eigen::Vector3d p;
    if (along < 0) {
      p = Eigen::Vector3d((spec.radius + along) * std::cos(azimuth), (spec.radius + along) * std::sin(azimuth),
                          0.0007);
    } else {
      const double a = along / 0.004 * M_PI / 2;  // over the fillet
      const double rr = spec.radius - spec.fillet + (spec.fillet + 0.0007) * std::sin(a);
      p = Eigen::Vector3d(rr * std::cos(azimuth), rr * std::sin(azimuth),
                          -spec.fillet + (spec.fillet + 0.0007) * std::cos(a) - 0.002 * u(rng));
    }
    mesh.positions.col(v) = p;
  }
  PlatformContact contact(mesh, spec);
  EXPECT_GT(contact.max_penetration(mesh.positions), 0.0);
  check_derivatives(contact, mesh.positions, 1e-9, 1e-5);
  expect_projected_psd(contact, mesh.positions);
}

TEST(Derivatives, GravityGradientIsWeight) {
  const ClothMesh mesh = crumpled_mesh(6, 1e-4);
  Gravity gravity(mesh, 0.3);
  Eigen::Matrix3Xd g = Eigen::Matrix3Xd::Zero(3, mesh.vertex_count());
  gravity.evaluate(mesh.positions, &g, nullptr);
  EXPECT_NEAR(g.row(2).sum(), 0.3 * kStandardGravity * 0.02 * 0.02, 1e-15);
  EXPECT_EQ(g.topRows<2>().norm(), 0.0);
  // The energy against its gradient (central differences; the energy is linear, so they agree to round-off): a sign
  // or scale error in the energy would pass the weight check above.
  for (int i = 0; i < static_cast<int>(mesh.positions.size()); ++i) {
    Eigen::Matrix3Xd xp = mesh.positions, xm = mesh.positions;
    xp.data()[i] += 1e-4;
    xm.data()[i] -= 1e-4;
    EXPECT_NEAR((gravity.energy(xp) - gravity.energy(xm)) / 2e-4, g.data()[i], 1e-12) << i;
  }
}

}  // namespace
}  // namespace drapegen::sim
