// Bending on per-triangle curvature tensors: derivatives, exactness for constant curvature on any mesh, and
// second-order convergence for a plane wave with the same energy on every triangulation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <set>

#include "derivative_checks.hpp"
#include "drapegen/sim/hessian_assembler.hpp"
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
  const auto energy_at = [&](double beta) {
    TriangleCurvatureBending bending(mesh, topology,
                                     DihedralModuli{{1e-5, 1.5e-5, 2e-5}, {beta, 0.5 * beta, 0.8 * beta}},
                                     AnisotropyRule::kCurvature);
    (void)bending.update_lagged(mesh.positions);  // directions from the current curvature
    return bending.energy(mesh.positions);
  };
  const double linear = energy_at(0.0);
  EXPECT_LT(energy_at(-3e-7), linear);  // softening: beta < 0 lowers the energy of the same shape
  EXPECT_GT(energy_at(3e-9), linear);   // stiffening
  for (double beta : {-3e-7, 3e-9}) {
    TriangleCurvatureBending bending(mesh, topology,
                                     DihedralModuli{{1e-5, 1.5e-5, 2e-5}, {beta, 0.5 * beta, 0.8 * beta}},
                                     AnisotropyRule::kCurvature);
    (void)bending.update_lagged(mesh.positions);
    check_derivatives(bending, mesh.positions, 1e-8, 1e-5);
    expect_projected_psd(bending, mesh.positions);
  }
}

TEST(TriangleCurvatureBending, EveryTriangleIsAnElementBorderWingsAbsent) {
  const ClothMesh mesh = make_specimen(SpecimenSpec{0.1, 0.1, 6, 6, 0.1, Triangulation::kRandom, 2, 0.0});
  const Topology topology = build_topology(mesh);
  const TriangleCurvatureBending bending(mesh, topology, DihedralModuli{{1e-5, 1e-5, 1e-5}, {0, 0, 0}},
                                         AnisotropyRule::kCurvature);
  ASSERT_EQ(bending.element_count(), mesh.triangle_count());
  std::set<std::pair<int, int>> hinge_edges;
  for (const Hinge& h : topology.hinges) hinge_edges.insert({std::min(h.v0, h.v1), std::max(h.v0, h.v1)});
  std::vector<int> vertices(6);
  int absent = 0;
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    bending.element_vertices(t, vertices.data());
    int hinges = 0;
    for (int i = 0; i < 3; ++i) {
      const int a = vertices[(i + 1) % 3], b = vertices[(i + 2) % 3];
      hinges += hinge_edges.count({std::min(a, b), std::max(a, b)}) > 0 ? 1 : 0;
    }
    const int wings =
        static_cast<int>(std::count_if(vertices.begin() + 3, vertices.end(), [](int v) { return v >= 0; }));
    EXPECT_EQ(wings, hinges) << t;
    absent += 3 - wings;
  }
  EXPECT_EQ(absent, static_cast<int>(topology.boundary_edges.size()));
}

/// The continuum energy density, over alpha/2, that a triangle should carry for the constant curvature K: |K|^2
/// inside; at the border the least |K - S|^2 over the tensors S spanned by n n^T of its free edges' normals n (the
/// components its hinges do not see, relaxed to zero moment: the free edge's natural boundary condition).
double expected_density(const Eigen::Matrix2d& k, const std::vector<Eigen::Vector2d>& free_normals) {
  if (free_normals.empty()) return k.squaredNorm();
  Eigen::MatrixXd basis(4, static_cast<Eigen::Index>(free_normals.size()));  // vec(n n^T) per free edge
  for (std::size_t i = 0; i < free_normals.size(); ++i) {
    const Eigen::Matrix2d nn = free_normals[i] * free_normals[i].transpose();
    basis.col(static_cast<Eigen::Index>(i)) = Eigen::Map<const Eigen::Vector4d>(nn.data());
  }
  const Eigen::Vector4d v = Eigen::Map<const Eigen::Vector4d>(k.data());
  const Eigen::VectorXd c = basis.colPivHouseholderQr().solve(v);
  return (v - basis * c).squaredNorm();
}

/// E over the continuum energy (alpha/2) sum_T density_T area_T for the surface z = p^T K p / 2 (tiny amplitude),
/// K a cylinder bent about an axis at `axis_degrees`.
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
  std::set<std::pair<int, int>> free_edges;
  for (const Eigen::Vector2i& e : topology.boundary_edges)
    free_edges.insert({std::min(e.x(), e.y()), std::max(e.x(), e.y())});
  double continuum = 0.0;
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    const Eigen::Vector2d p[3] = {mesh.rest.col(mesh.triangles(0, t)), mesh.rest.col(mesh.triangles(1, t)),
                                  mesh.rest.col(mesh.triangles(2, t))};
    std::vector<Eigen::Vector2d> normals;
    for (int i = 0; i < 3; ++i) {
      const int u = mesh.triangles((i + 1) % 3, t), w = mesh.triangles((i + 2) % 3, t);
      if (free_edges.count({std::min(u, w), std::max(u, w)}) == 0) continue;
      const Eigen::Vector2d edge = (p[(i + 2) % 3] - p[(i + 1) % 3]).normalized();
      normals.emplace_back(-edge.y(), edge.x());
    }
    const Eigen::Vector2d u = p[1] - p[0], w = p[2] - p[0];
    continuum += 0.5 * std::abs(u.x() * w.y() - u.y() * w.x()) * expected_density(k, normals);
  }
  return bending.energy(x) / (0.5 * alpha * amplitude * amplitude * continuum);
}

TEST(TriangleCurvatureBending, ExactForConstantCurvatureOnAnyTriangulation) {
  // Inside, the continuum energy; at the border, the continuum energy without the curvature normal to the free
  // edge: exact where the border triangles' hinges are symmetric about that normal (union jack), within 0.1% of the
  // whole where they are not (their hinges see a little of it). The hinge model gives 1.0 to 2.0 here depending on
  // mesh and axis (bench/drape_physics.cpp, check d).
  for (double axis : {0.0, 22.5, 45.0}) {
    EXPECT_NEAR(energy_ratio(Triangulation::kAlternating, 0.0, axis), 1.0, 1e-4) << axis;
    EXPECT_NEAR(energy_ratio(Triangulation::kRandom, 0.2, axis), 1.0, 1.5e-3) << axis;
    EXPECT_NEAR(energy_ratio(Triangulation::kEquilateral, 0.0, axis), 1.0, 1.5e-3) << axis;
  }
}

/// A plane wave under a smooth envelope, z = A cos^4(pi x / L) cos^4(pi y / L) sin(k . p) on the specimen
/// [-L/2, L/2]^2: height, slope and curvature vanish at the border, so the free edges (which carry no moment
/// across them) do not enter the comparison.
struct EnvelopedWave {
  double amplitude, size;
  Eigen::Vector2d k;
  double operator()(const Eigen::Vector2d& p) const {
    const double ex = std::pow(std::cos(std::numbers::pi * p.x() / size), 4);
    const double ey = std::pow(std::cos(std::numbers::pi * p.y() / size), 4);
    return amplitude * ex * ey * std::sin(k.dot(p));
  }
};

/// E over the continuum energy (alpha/2) integral |Hess z|^2 dA (midpoint rule, Hessian by central differences) of
/// the enveloped wave of `spacings` vertex spacings at `degrees` to the rest x axis, on a 0.1 m specimen of 41 x 41
/// vertices.
double wave_energy_ratio(Triangulation triangulation, double jitter, double spacings, double degrees) {
  const int n = 41;
  const double size = 0.1, alpha = 2e-5, a = degrees * std::numbers::pi / 180.0;
  const ClothMesh mesh = make_specimen(SpecimenSpec{size, size, n, n, jitter, triangulation, 3, 0.0});
  const Topology topology = build_topology(mesh);
  const double wavenumber = 2.0 * std::numbers::pi / (spacings * size / (n - 1));
  const EnvelopedWave z{1e-5, size, wavenumber * Eigen::Vector2d(std::cos(a), std::sin(a))};
  const TriangleCurvatureBending bending(mesh, topology, DihedralModuli{{alpha, alpha, alpha}, {0, 0, 0}},
                                         AnisotropyRule::kCurvature);
  Eigen::Matrix3Xd x(3, mesh.vertex_count());
  for (int v = 0; v < mesh.vertex_count(); ++v) x.col(v) << mesh.rest.col(v), z(mesh.rest.col(v));
  const int cells = 200;
  const double step = size / cells, h = 1e-5;
  const Eigen::Vector2d dx(h, 0.0), dy(0.0, h);
  double continuum = 0.0;
  for (int i = 0; i < cells; ++i) {
    for (int j = 0; j < cells; ++j) {
      const Eigen::Vector2d p((i + 0.5) * step - 0.5 * size, (j + 0.5) * step - 0.5 * size);
      const double zxx = (z(p + dx) - 2.0 * z(p) + z(p - dx)) / (h * h);
      const double zyy = (z(p + dy) - 2.0 * z(p) + z(p - dy)) / (h * h);
      const double zxy = (z(p + dx + dy) - z(p + dx - dy) - z(p - dx + dy) + z(p - dx - dy)) / (4.0 * h * h);
      continuum += 0.5 * alpha * (zxx * zxx + 2.0 * zxy * zxy + zyy * zyy) * step * step;
    }
  }
  return bending.energy(x) / continuum;
}

TEST(TriangleCurvatureBending, PlaneWaveConvergesAlikeOnEveryTriangulation) {
  // A resolved wave has (nearly) the same energy on every grid, and the error falls with the square of the spacing:
  // the discretisation does not prefer one triangulation (unlike the hinge model, docs/PHYSICS.md).
  struct Grid {
    Triangulation triangulation;
    double jitter;
  };
  const Grid grids[] = {{Triangulation::kAlternating, 0.0}, {Triangulation::kUniform, 0.0},
                        {Triangulation::kEquilateral, 0.0}, {Triangulation::kRandom, 0.0},
                        {Triangulation::kRandom, 0.2}};
  for (double degrees : {0.0, 22.5, 45.0}) {
    double lo = 1e9, hi = -1e9;
    for (const Grid& g : grids) {
      const double coarse = wave_energy_ratio(g.triangulation, g.jitter, 8.0, degrees);
      const double fine = wave_energy_ratio(g.triangulation, g.jitter, 16.0, degrees);
      std::printf("[ wave     ] triangulation %d, jitter %.1f, %4.1f deg: E / continuum %.4f (8 spacings), %.4f (16)\n",
                  static_cast<int>(g.triangulation), g.jitter, degrees, coarse, fine);
      lo = std::min(lo, fine);
      hi = std::max(hi, fine);
      EXPECT_LT(fine, 1.0) << degrees;
      EXPECT_LT(1.0 - fine, 0.5 * (1.0 - coarse)) << degrees;  // second order: 0.25 in the limit
    }
    EXPECT_LT(hi - lo, 0.02) << degrees;  // every grid alike
  }
}

// A vertex of valence 3 (here the centre of a triangle split in three, as a scanned or remeshed PLY file may have):
// two hinges of each triangle around it share their wing, so their angles are of the same four vertices and measure
// one bending mode; the element keeps the first (the system of both is singular: the energy was NaN) and holds every
// vertex once (the solver's assembler refused the element that repeated the wing).
TEST(TriangleCurvatureBending, AWingSharedByTwoHingesIsOneVertex) {
  ClothMesh mesh;
  mesh.rest.resize(2, 4);
  mesh.rest << 0.0, 0.02, 0.0, 0.006,  //
      0.0, 0.0, 0.02, 0.006;
  mesh.triangles.resize(3, 3);
  mesh.triangles << 3, 3, 3,  //
      0, 1, 2,                //
      1, 2, 0;
  mesh.positions.resize(3, 4);
  mesh.positions.topRows<2>() = mesh.rest;
  mesh.positions.row(2) << 0.0, 0.001, -0.0005, 0.0015;
  const Topology topology = build_topology(mesh);
  ASSERT_EQ(topology.hinges.size(), 3u);
  const TriangleCurvatureBending bending(mesh, topology, DihedralModuli{{1e-5, 2e-5, 3e-5}, {0, 0, 0}},
                                         AnisotropyRule::kCurvature);
  ASSERT_EQ(bending.element_count(), 3);
  for (int e = 0; e < bending.element_count(); ++e) {
    int vertices[6];
    bending.element_vertices(e, vertices);
    std::set<int> present;
    for (const int v : vertices) {
      if (v < 0) continue;
      EXPECT_TRUE(present.insert(v).second) << "element " << e << " repeats vertex " << v;
    }
    EXPECT_EQ(present.size(), 4u) << "element " << e;  // its triangle and the one wing
  }
  const Eigen::MatrixXd dense_hessian = check_derivatives(bending, mesh.positions, 1e-8, 1e-5);
  // The solver's assembler (vertex 0 held) takes the element and sums the same Hessian.
  const std::vector<bool> fixed{true, false, false, false};
  HessianAssembler assembler(4, fixed, {&bending});
  Eigen::Matrix3Xd gradient = Eigen::Matrix3Xd::Zero(3, 4);
  assembler.assemble(mesh.positions, HessianMode::kExact, gradient);
  Eigen::MatrixXd assembled = Eigen::MatrixXd::Zero(9, 9);
  for (int j = 0; j < assembler.dof_count(); ++j) {
    for (int p = assembler.column_pointers()[j]; p < assembler.column_pointers()[j + 1]; ++p) {
      assembled(assembler.row_indices()[p], j) = assembled(j, assembler.row_indices()[p]) = assembler.values()[p];
    }
  }
  EXPECT_LE((assembled - dense_hessian.bottomRightCorner(9, 9)).norm(), 1e-12 * dense_hessian.norm());
}

}  // namespace
}  // namespace drapegen::sim
