// Bending on per-triangle curvature tensors: derivatives, and exactness for constant curvature on any mesh.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>

#include "derivative_checks.hpp"
#include "drapegen/sim/triangle_bending.hpp"

namespace drapegen::sim {
namespace {

TEST(TriangleCurvatureBending, DerivativesIsotropicLinear) {
  const ClothMesh mesh = crumpled_mesh(7, 4e-4);
  const Topology topology = build_topology(mesh);
  TriangleCurvatureBending bending(mesh, topology, DihedralModuli{{1e-5, 1e-5, 1e-5}, {0, 0, 0}},
                                   AnisotropyRule::kCurvature);
  ASSERT_GT(bending.element_count(), 0);
  check_derivatives(bending, mesh.positions, 1e-8, 1e-5);
  expect_projected_psd(bending, mesh.positions);
}

TEST(TriangleCurvatureBending, DerivativesAnisotropicSofteningAndStiffening) {
  const ClothMesh mesh = crumpled_mesh(8, 4e-4);
  const Topology topology = build_topology(mesh);
  // Soft enough that some directions sit on the torque plateau (kappa > alpha / 2|beta|).
  for (double beta : {-3e-7, 3e-9}) {
    TriangleCurvatureBending bending(mesh, topology, DihedralModuli{{1e-5, 1.5e-5, 2e-5}, {beta, 0.5 * beta, 0.8 * beta}},
                                     AnisotropyRule::kCurvature);
    EXPECT_GE(bending.update_lagged(mesh.positions), 0.0);
    check_derivatives(bending, mesh.positions, 1e-8, 1e-5);
    expect_projected_psd(bending, mesh.positions);
  }
}

TEST(TriangleCurvatureBending, BorderTrianglesLeaveTheirHingesToTheHingeModel) {
  const ClothMesh mesh = make_specimen(SpecimenSpec{0.1, 0.1, 6, 6, 0.1, Triangulation::kRandom, 2, 0.0});
  const Topology topology = build_topology(mesh);
  const TriangleCurvatureBending bending(mesh, topology, DihedralModuli{{1e-5, 1e-5, 1e-5}, {0, 0, 0}},
                                         AnisotropyRule::kCurvature);
  std::set<std::pair<int, int>> hinge_edges;
  for (const Hinge& h : topology.hinges) hinge_edges.insert({std::min(h.v0, h.v1), std::max(h.v0, h.v1)});
  int full = 0, border_incidences = 0;
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    int hinges = 0;
    for (int i = 0; i < 3; ++i) {
      const int a = mesh.triangles((i + 1) % 3, t), b = mesh.triangles((i + 2) % 3, t);
      hinges += hinge_edges.count({std::min(a, b), std::max(a, b)}) > 0 ? 1 : 0;
    }
    if (hinges == 3) ++full;
    else border_incidences += hinges;
  }
  EXPECT_EQ(bending.element_count(), full);
  int sides = 0;
  for (int s : bending.border_sides()) sides += s;
  EXPECT_EQ(sides, border_incidences);
  EXPECT_GT(sides, 0);
  const Eigen::VectorXd w = bending.border_hinge_weights();
  ASSERT_EQ(w.size(), static_cast<Eigen::Index>(topology.hinges.size()));
  EXPECT_NEAR(w.sum(), 0.5 * sides, 1e-12);
}

/// E over (alpha/2) |K|^2 A for the surface z = p^T K p / 2 (tiny amplitude), summed over the elements.
double energy_ratio(Triangulation triangulation, double jitter, double axis_degrees) {
  const ClothMesh mesh = make_specimen(SpecimenSpec{0.1, 0.1, 21, 21, jitter, triangulation, 5, 0.0});
  const Topology topology = build_topology(mesh);
  const double alpha = 2e-5, amplitude = 1e-3;
  TriangleCurvatureBending bending(mesh, topology, DihedralModuli{{alpha, alpha, alpha}, {0, 0, 0}},
                                   AnisotropyRule::kCurvature);
  const double a = axis_degrees * std::numbers::pi / 180.0;
  const Eigen::Vector2d across(-std::sin(a), std::cos(a));
  const Eigen::Matrix2d k = across * across.transpose();
  Eigen::Matrix3Xd x(3, mesh.vertex_count());
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    const Eigen::Vector2d p = mesh.rest.col(v);
    x.col(v) << p, amplitude * 0.5 * p.dot(k * p);
  }
  double area = 0.0;  // of the elements
  std::vector<int> vertices(6);
  for (int e = 0; e < bending.element_count(); ++e) {
    bending.element_vertices(e, vertices.data());
    const Eigen::Vector2d u = mesh.rest.col(vertices[1]) - mesh.rest.col(vertices[0]),
                          w = mesh.rest.col(vertices[2]) - mesh.rest.col(vertices[0]);
    area += 0.5 * std::abs(u.x() * w.y() - u.y() * w.x());
  }
  return bending.energy(x) / (0.5 * alpha * amplitude * amplitude * k.squaredNorm() * area);
}

TEST(TriangleCurvatureBending, ExactForConstantCurvatureOnAnyTriangulation) {
  // The hinge model gives 1.0 to 2.0 here depending on mesh and axis (bench/drape_physics.cpp, check d).
  for (double axis : {0.0, 22.5, 45.0}) {
    EXPECT_NEAR(energy_ratio(Triangulation::kAlternating, 0.0, axis), 1.0, 1e-4) << axis;
    EXPECT_NEAR(energy_ratio(Triangulation::kRandom, 0.2, axis), 1.0, 1e-4) << axis;
    EXPECT_NEAR(energy_ratio(Triangulation::kEquilateral, 0.0, axis), 1.0, 1e-4) << axis;
  }
}

}  // namespace
}  // namespace drapegen::sim
