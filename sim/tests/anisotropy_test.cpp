// Directional interpolation of bending parameters (Eq. 8) and curvature-based bending directions (Section 4.4).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "drapegen/sim/anisotropy.hpp"
#include "drapegen/sim/specimen.hpp"

namespace drapegen::sim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDegree = kPi / 180.0;

/// The literal Eq. 8 with the explicit 2x2 inverse, for phi in [0, pi/2].
double literal_eq8(const DirectionalValues& k, double phi) {
  const bool first = phi <= kPi / 4.0;
  const double phi0 = first ? 0.0 : kPi / 4.0, phi1 = first ? kPi / 4.0 : kPi / 2.0;
  const double k0 = first ? k.warp : k.bias, k1 = first ? k.bias : k.weft;
  Eigen::Matrix2d m;
  m << std::pow(std::cos(phi0), 2), std::pow(std::sin(phi0), 2), std::pow(std::cos(phi1), 2),
      std::pow(std::sin(phi1), 2);
  const Eigen::RowVector2d w(std::pow(std::cos(phi), 2), std::pow(std::sin(phi), 2));
  return w * m.inverse() * Eigen::Vector2d(k0, k1);
}

/// Angle between two axes (directions modulo pi), in [0, pi/2].
double axis_difference(double a, double b) {
  const double d = std::fmod(std::abs(a - b), kPi);
  return std::min(d, kPi - d);
}

/// Angle between two direction axes given as vectors, in [0, pi/2].
double axis_angle(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized()))));
}

/// The q-quantile of values (q in [0, 1]).
double quantile(std::vector<double> values, double q) {
  const auto k = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

/// 100x100 specimen of 0.3 m: a "union jack" grid, or jittered (0.3) with random diagonals.
ClothMesh specimen(bool irregular, double material_angle = 0.0) {
  SpecimenSpec spec;
  spec.jitter = irregular ? 0.3 : 0.0;
  spec.triangulation = irregular ? Triangulation::kRandom : Triangulation::kAlternating;
  spec.seed = 11;
  spec.material_angle = material_angle;
  return make_specimen(spec);
}

/// Wraps the specimen isometrically on a cylinder of radius r whose curving direction is the rest direction at
/// angle alpha (the cylinder axis is perpendicular to it). The centre of curvature lies below the sheet.
void wrap_on_cylinder(ClothMesh& mesh, double r, double alpha) {
  const Eigen::Vector2d curving(std::cos(alpha), std::sin(alpha)), axis(-std::sin(alpha), std::cos(alpha));
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    const double u = curving.dot(mesh.rest.col(i)), v = axis.dot(mesh.rest.col(i));
    mesh.positions.col(i) = Eigen::Vector3d(r * std::sin(u / r), v, r * std::cos(u / r) - r);
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Eq. 8

const DirectionalValues kSamples[] = {{1.0, 2.0, 4.0}, {3.0, 0.5, 1.5}, {0.7, 0.1, 0.2}, {2.0, 5.0, 1.0}};

TEST(InterpolateDirectional, ReproducesTheThreeSamples) {
  for (const auto& k : kSamples) {
    EXPECT_DOUBLE_EQ(interpolate_directional(k, 0.0), k.warp);
    EXPECT_DOUBLE_EQ(interpolate_directional(k, kPi / 4.0), k.bias);
    EXPECT_DOUBLE_EQ(interpolate_directional(k, kPi / 2.0), k.weft);
  }
}

TEST(InterpolateDirectional, MatchesLiteralEquation8) {
  for (const auto& k : kSamples) {
    for (int i = 0; i <= 90; ++i) {
      const double phi = i * kPi / 180.0;
      EXPECT_NEAR(interpolate_directional(k, phi), literal_eq8(k, phi), 1e-12) << "phi = " << phi;
    }
  }
}

TEST(InterpolateDirectional, ContinuousAtBias) {
  for (const auto& k : kSamples) {
    for (const double eps : {1e-3, 1e-6, 1e-9}) {
      const double below = interpolate_directional(k, kPi / 4.0 - eps);
      const double above = interpolate_directional(k, kPi / 4.0 + eps);
      // Both one-sided slopes are bounded by 2 |k| (derivative of cos^2 is at most 1), so the jump is O(eps).
      EXPECT_NEAR(below, k.bias, 4.0 * eps * (std::abs(k.warp) + std::abs(k.bias) + std::abs(k.weft)));
      EXPECT_NEAR(above, k.bias, 4.0 * eps * (std::abs(k.warp) + std::abs(k.bias) + std::abs(k.weft)));
    }
  }
}

TEST(InterpolateDirectional, SymmetricAboutWarpAndWeft) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> angle(-10.0, 10.0);
  for (const auto& k : kSamples) {
    for (int i = 0; i < 200; ++i) {
      const double phi = angle(rng);
      const double value = interpolate_directional(k, phi);
      EXPECT_NEAR(interpolate_directional(k, -phi), value, 1e-12);
      EXPECT_NEAR(interpolate_directional(k, kPi - phi), value, 1e-12);
      EXPECT_NEAR(interpolate_directional(k, kPi + phi), value, 1e-12);
    }
  }
}

TEST(InterpolateDirectional, LinearBiasGivesEquation7) {
  for (const auto& sample : kSamples) {
    const DirectionalValues k{sample.warp, 0.5 * (sample.warp + sample.weft), sample.weft};
    for (int i = -180; i <= 180; i += 7) {
      const double phi = i * kDegree;
      const double c2 = std::pow(std::cos(phi), 2), s2 = std::pow(std::sin(phi), 2);
      EXPECT_NEAR(interpolate_directional(k, phi), c2 * k.warp + s2 * k.weft, 1e-12);
    }
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Principal curvatures

struct CylinderCase {
  bool irregular;
  double radius;
  double alpha;  // curving direction in the rest frame
};

class CylinderCurvature : public ::testing::TestWithParam<CylinderCase> {};

TEST_P(CylinderCurvature, MaxCurvatureIsInverseRadiusAlongTheCurvingDirection) {
  const auto [irregular, r, alpha] = GetParam();
  ClothMesh mesh = specimen(irregular);
  wrap_on_cylinder(mesh, r, alpha);
  const Topology topo = build_topology(mesh);
  const CurvatureField field = principal_curvatures(mesh, topo);
  const Eigen::Vector2d curving(std::cos(alpha), std::sin(alpha));

  std::vector<double> curvature_error, angle_error, boundary_error;
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    const double relative = std::abs(-field.max_curvature[i] * r - 1.0);  // centre below: negative curvature
    if (topo.on_boundary[i]) {
      boundary_error.push_back(relative);
      continue;
    }
    curvature_error.push_back(relative);
    angle_error.push_back(axis_angle(field.direction.col(i), curving));
    EXPECT_LT(std::abs(field.min_curvature[i]) * r, 0.05) << "vertex " << i;
  }
  const double max_error = *std::max_element(curvature_error.begin(), curvature_error.end());
  const double angle95 = quantile(angle_error, 0.95);
  const double max_angle = *std::max_element(angle_error.begin(), angle_error.end());
  const double max_boundary = *std::max_element(boundary_error.begin(), boundary_error.end());
  EXPECT_LT(max_error, 0.05);
  EXPECT_LT(angle95, 5.0 * kDegree);
  EXPECT_LT(max_angle, 5.0 * kDegree);
  EXPECT_LT(max_boundary, 0.05);
  std::printf("[ cylinder ] irregular=%d r=%.3f alpha=%.2f: max |kappa r - 1| interior %.2e boundary %.2e, "
              "direction error 95%% %.3f deg max %.3f deg\n",
              irregular, r, alpha, max_error, max_boundary, angle95 / kDegree, max_angle / kDegree);
}

INSTANTIATE_TEST_SUITE_P(Meshes, CylinderCurvature,
                         ::testing::Values(CylinderCase{false, 0.08, 0.0}, CylinderCase{true, 0.08, 0.0},
                                           CylinderCase{false, 0.08, 0.5}, CylinderCase{true, 0.08, 0.5},
                                           CylinderCase{true, 0.03, 1.2}, CylinderCase{true, 0.5, 2.0}));

TEST(PrincipalCurvatures, SphereHasEqualPrincipalCurvatures) {
  const double radius = 0.25;
  ClothMesh mesh = specimen(true);
  for (int i = 0; i < mesh.vertex_count(); ++i) {  // azimuthal equidistant map (not isometric)
    const Eigen::Vector2d x = mesh.rest.col(i);
    const double rho = x.norm(), s = rho > 0.0 ? std::sin(rho / radius) / rho : 1.0 / radius;
    mesh.positions.col(i) =
        Eigen::Vector3d(radius * s * x.x(), radius * s * x.y(), radius * std::cos(rho / radius) - radius);
  }
  const Topology topo = build_topology(mesh);
  const CurvatureField field = principal_curvatures(mesh, topo);
  double max_error = 0.0;
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    if (topo.on_boundary[i]) continue;
    max_error = std::max({max_error, std::abs(-field.max_curvature[i] * radius - 1.0),
                          std::abs(-field.min_curvature[i] * radius - 1.0)});
  }
  EXPECT_LT(max_error, 0.05);
  std::printf("[ sphere   ] max |kappa R - 1| over interior vertices %.2e\n", max_error);
}

TEST(PrincipalCurvatures, SaddleHasOppositePrincipalCurvatures) {
  // z = (x^2 / r1 - y^2 / r2) / 2: at the centre kappa = +1/r1 along x and -1/r2 along y (normal +z).
  const double r1 = 0.1, r2 = 0.25;
  ClothMesh mesh = specimen(true);
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    const double x = mesh.rest(0, i), y = mesh.rest(1, i);
    mesh.positions.col(i) = Eigen::Vector3d(x, y, 0.5 * (x * x / r1 - y * y / r2));
  }
  const Topology topo = build_topology(mesh);
  const CurvatureField field = principal_curvatures(mesh, topo);
  int checked = 0;
  double max_error = 0.0, max_angle = 0.0;
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    if (mesh.rest.col(i).norm() > 0.01) continue;  // the metric departs from the rest metric away from the centre
    ++checked;
    EXPECT_GT(field.max_curvature[i], 0.0);
    EXPECT_LT(field.min_curvature[i], 0.0);
    max_error = std::max({max_error, std::abs(field.max_curvature[i] * r1 - 1.0),
                          std::abs(-field.min_curvature[i] * r2 - 1.0)});
    max_angle = std::max(max_angle, axis_angle(field.direction.col(i), Eigen::Vector2d::UnitX()));
  }
  EXPECT_GT(checked, 20);
  EXPECT_LT(max_error, 0.05);
  EXPECT_LT(max_angle, 5.0 * kDegree);
  std::printf("[ saddle   ] %d central vertices: max relative error %.2e, direction error %.3f deg\n", checked,
              max_error, max_angle / kDegree);
}

// ---------------------------------------------------------------------------------------------------------------
// Hinge bending directions

/// The bending stiffness the hinges of a bent mesh act with: k(phi_h) averaged with the weights of the discrete
/// shell energy, theta_h^2 |e_h|^2 / (A_1 + A_2) (dihedral angle theta, rest edge e, rest areas A), so that hinges
/// which do not bend do not count.
double effective_stiffness(const ClothMesh& mesh, const Topology& topo, const DirectionalValues& k,
                           const Eigen::VectorXd& phi) {
  double weighted = 0.0, total = 0.0;
  for (std::size_t h = 0; h < topo.hinges.size(); ++h) {
    const Hinge& g = topo.hinges[h];
    const auto x = [&](int v) -> Eigen::Vector3d { return mesh.positions.col(v); };
    const auto area = [&](int a, int b, int c) {
      const Eigen::Vector2d e1 = mesh.rest.col(b) - mesh.rest.col(a), e2 = mesh.rest.col(c) - mesh.rest.col(a);
      return 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
    };
    const Eigen::Vector3d n1 = (x(g.v1) - x(g.v0)).cross(x(g.v2) - x(g.v0));
    const Eigen::Vector3d n2 = (x(g.v0) - x(g.v1)).cross(x(g.v3) - x(g.v1));
    const double theta = std::atan2(n1.cross(n2).norm(), n1.dot(n2));
    const double w = theta * theta * (mesh.rest.col(g.v1) - mesh.rest.col(g.v0)).squaredNorm() /
                     (area(g.v0, g.v1, g.v2) + area(g.v1, g.v0, g.v3));
    weighted += w * interpolate_directional(k, phi[static_cast<Eigen::Index>(h)]);
    total += w;
  }
  return weighted / total;
}

TEST(HingeBendingAngles, CurvatureRuleIsMeshIndependentEdgeRuleIsNot) {
  // Paper Fig. 12: the same cylinder on a structured and an irregular mesh, with a strongly anisotropic fabric.
  const DirectionalValues k{1.0, 2.0, 4.0};
  for (const double alpha : {0.0, 0.3, kPi / 4.0}) {
    const double expected = interpolate_directional(k, alpha);
    double curvature_rule[2], edge_rule[2];
    for (const bool irregular : {false, true}) {
      ClothMesh mesh = specimen(irregular);
      wrap_on_cylinder(mesh, 0.08, alpha);
      const Topology topo = build_topology(mesh);
      Eigen::VectorXd curvature_phi, edge_phi;
      hinge_bending_angles(mesh, topo, AnisotropyRule::kCurvature, curvature_phi);
      hinge_bending_angles(mesh, topo, AnisotropyRule::kEdge, edge_phi);
      ASSERT_EQ(curvature_phi.size(), static_cast<Eigen::Index>(topo.hinges.size()));

      double max_error = 0.0;
      for (Eigen::Index h = 0; h < curvature_phi.size(); ++h) {
        EXPECT_GE(curvature_phi[h], 0.0);
        EXPECT_LT(curvature_phi[h], kPi);
        max_error = std::max(max_error, axis_difference(curvature_phi[h], alpha));
      }
      EXPECT_LT(max_error, 1.0 * kDegree);
      curvature_rule[irregular] = effective_stiffness(mesh, topo, k, curvature_phi);
      edge_rule[irregular] = effective_stiffness(mesh, topo, k, edge_phi);
      std::printf("[ fig 12   ] alpha=%.3f irregular=%d: k(alpha) %.4f, effective k: curvature rule %.4f "
                  "(max direction error %.4f deg), edge rule %.4f\n",
                  alpha, irregular, expected, curvature_rule[irregular], max_error / kDegree, edge_rule[irregular]);
    }
    // The curvature rule bends every hinge with the stiffness of the true bending direction on both meshes ...
    EXPECT_NEAR(curvature_rule[0], expected, 1e-3 * expected);
    EXPECT_NEAR(curvature_rule[1], expected, 1e-3 * expected);
    // ... the edge rule's stiffness depends on how the mesh is triangulated, and off the warp it is wrong on the
    // structured mesh (which has no random draws: +10% at 0.3 rad, +8% at pi/4). The irregular mesh's error depends
    // on its draw (at pi/4: +11% on one, +5% on another, its random diagonals averaging out), so it is not asserted.
    EXPECT_GT(std::abs(edge_rule[1] - edge_rule[0]), 0.02 * expected);
    if (alpha > 0.0) {
      EXPECT_GT(std::abs(edge_rule[0] - expected), 0.05 * expected);
    }
  }
}

TEST(HingeBendingAngles, EdgeRuleOnGridUsesFourDirections) {
  ClothMesh mesh = specimen(false);
  const Topology topo = build_topology(mesh);
  Eigen::VectorXd phi;
  hinge_bending_angles(mesh, topo, AnisotropyRule::kEdge, phi);
  for (Eigen::Index h = 0; h < phi.size(); ++h) {
    const double q = phi[h] / (kPi / 4.0);
    EXPECT_NEAR(q, std::round(q), 1e-9);
  }
}

TEST(HingeBendingAngles, MaterialAngleShiftsPhi) {
  const double material_angle = 0.3;
  for (const bool irregular : {false, true}) {
    ClothMesh rotated = specimen(irregular, material_angle);
    ClothMesh aligned = specimen(irregular, 0.0);
    wrap_on_cylinder(rotated, 0.08, 0.0);  // curving along rest x, i.e. at -material_angle from the warp
    wrap_on_cylinder(aligned, 0.08, 0.0);
    const Topology topo = build_topology(aligned);
    for (const auto rule : {AnisotropyRule::kCurvature, AnisotropyRule::kEdge}) {
      Eigen::VectorXd phi_rotated, phi_aligned;
      hinge_bending_angles(rotated, topo, rule, phi_rotated);
      hinge_bending_angles(aligned, topo, rule, phi_aligned);
      for (Eigen::Index h = 0; h < phi_rotated.size(); ++h) {
        EXPECT_NEAR(axis_difference(phi_rotated[h] + material_angle, phi_aligned[h]), 0.0, 1e-9);
        if (rule == AnisotropyRule::kCurvature) {
          EXPECT_LT(axis_difference(phi_rotated[h], -material_angle), 1.0 * kDegree);
        }
      }
    }
  }
}

TEST(HingeBendingAngles, FlatRegionsFallBackToTheEdgeRule) {
  ClothMesh mesh = specimen(true);
  const Topology topo = build_topology(mesh);
  Eigen::VectorXd curvature_phi, edge_phi;
  hinge_bending_angles(mesh, topo, AnisotropyRule::kCurvature, curvature_phi);
  hinge_bending_angles(mesh, topo, AnisotropyRule::kEdge, edge_phi);
  EXPECT_EQ(curvature_phi, edge_phi);

  // A gentle cylinder (kappa = 0.2/m, below the default flat_curvature) stays close to the edge rule by default
  // but is resolved when the threshold is removed.
  wrap_on_cylinder(mesh, 5.0, 0.7);
  AnisotropyWorkspace workspace;
  AnisotropyOptions options;
  hinge_bending_angles(mesh, topo, AnisotropyRule::kCurvature, options, workspace, curvature_phi);
  double max_from_edge = 0.0;
  for (Eigen::Index h = 0; h < edge_phi.size(); ++h) {
    max_from_edge = std::max(max_from_edge, axis_difference(curvature_phi[h], edge_phi[h]));
  }
  EXPECT_LT(max_from_edge, 10.0 * kDegree);
  options.flat_curvature = 0.0;
  hinge_bending_angles(mesh, topo, AnisotropyRule::kCurvature, options, workspace, curvature_phi);
  for (Eigen::Index h = 0; h < curvature_phi.size(); ++h) {
    EXPECT_LT(axis_difference(curvature_phi[h], 0.7), 1.0 * kDegree);
  }
}

TEST(HingeBendingAngles, DirectionIsContinuousInTheCurvature) {
  // Sweeping the cylinder curvature through the flat_curvature blend (steps of ~10% in curvature) must not make any
  // hinge direction jump: the blend turns a hinge by at most ~90 degrees over the whole sweep.
  ClothMesh mesh = specimen(true);
  const Topology topo = build_topology(mesh);
  AnisotropyWorkspace workspace;
  const AnisotropyOptions options;
  Eigen::VectorXd previous, current;
  double max_step = 0.0;
  for (int s = 0; s <= 40; ++s) {
    const double kappa = 0.1 * std::pow(40.0, s / 40.0);  // 0.1 .. 4 (1/m)
    wrap_on_cylinder(mesh, 1.0 / kappa, 0.7);
    hinge_bending_angles(mesh, topo, AnisotropyRule::kCurvature, options, workspace, current);
    if (s > 0) {
      for (Eigen::Index h = 0; h < current.size(); ++h) {
        max_step = std::max(max_step, axis_difference(current[h], previous[h]));
      }
    }
    previous = current;
  }
  EXPECT_LT(max_step, 15.0 * kDegree);
  std::printf("[ blend    ] largest change of a hinge direction between sweep steps: %.2f deg\n", max_step / kDegree);
}

TEST(PrincipalCurvatures, DegenerateAndNoisyMeshesGiveFiniteResults) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> noise(-1e-6, 1e-6);
  for (const auto& [nx, ny] : {std::pair{2, 2}, std::pair{2, 7}, std::pair{3, 3}, std::pair{40, 40}}) {
    ClothMesh mesh = make_specimen(SpecimenSpec{.vertices_x = nx, .vertices_y = ny, .jitter = 0.3});
    for (int i = 0; i < mesh.vertex_count(); ++i) mesh.positions(2, i) = noise(rng);
    const Topology topo = build_topology(mesh);
    const CurvatureField field = principal_curvatures(mesh, topo);
    EXPECT_TRUE(field.direction.allFinite() && field.max_curvature.allFinite() && field.min_curvature.allFinite());
    for (int i = 0; i < mesh.vertex_count(); ++i) {
      EXPECT_NEAR(field.direction.col(i).norm(), 1.0, 1e-12);
      EXPECT_GE(std::abs(field.max_curvature[i]), std::abs(field.min_curvature[i]));
    }
    Eigen::VectorXd phi;
    hinge_bending_angles(mesh, topo, AnisotropyRule::kCurvature, phi);
    EXPECT_TRUE(phi.allFinite());
  }
}

TEST(HingeBendingAngles, WorkspaceIsReusedWithoutReallocation) {
  ClothMesh mesh = specimen(true);
  wrap_on_cylinder(mesh, 0.08, 0.4);
  const Topology topo = build_topology(mesh);
  AnisotropyWorkspace workspace;
  Eigen::VectorXd phi;
  const auto buffers = [&] {
    return std::vector<const double*>{workspace.curvature.vertex_normals.data(), workspace.curvature.systems.data(),
                                      workspace.curvature.reduced.data(),         workspace.field.direction.data(),
                                      workspace.field.max_curvature.data(),       phi.data()};
  };
  hinge_bending_angles(mesh, topo, AnisotropyRule::kCurvature, AnisotropyOptions{}, workspace, phi);
  const std::vector<const double*> before = buffers();
  wrap_on_cylinder(mesh, 0.05, 0.9);
  hinge_bending_angles(mesh, topo, AnisotropyRule::kCurvature, AnisotropyOptions{}, workspace, phi);
  EXPECT_EQ(buffers(), before);
}

TEST(HingeBendingAngles, RejectsMismatchedTopology) {
  const ClothMesh small = make_specimen(SpecimenSpec{.vertices_x = 4, .vertices_y = 4});
  const ClothMesh large = make_specimen(SpecimenSpec{.vertices_x = 5, .vertices_y = 5});
  Eigen::VectorXd phi;
  EXPECT_THROW(hinge_bending_angles(large, build_topology(small), AnisotropyRule::kCurvature, phi),
               std::invalid_argument);
}

}  // namespace
}  // namespace drapegen::sim
