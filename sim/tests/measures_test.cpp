#include "drapegen/sim/measures.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <vector>

#include "drapegen/sim/initial_state.hpp"
#include "drapegen/sim/specimen.hpp"

namespace drapegen::sim {
namespace {

constexpr double kPi = std::numbers::pi;

ClothMesh square_specimen(int vertices, double jitter = 0.0, bool random_diagonals = false) {
  return make_specimen(
      SpecimenSpec{.size_x = 0.3,
                   .size_y = 0.3,
                   .vertices_x = vertices,
                   .vertices_y = vertices,
                   .jitter = jitter,
                   .triangulation = random_diagonals ? Triangulation::kRandom : Triangulation::kAlternating,
                   .seed = 3});
}

/// The specimen draped analytically: flat on the platform for r <= R, then straight down a cone whose generators
/// make `half_angle` with the vertical, so rest radius r > R lands at shadow radius R + (r - R) sin(half_angle).
ClothMesh hang_as_cone(ClothMesh mesh, double platform_radius, double half_angle) {
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    const Eigen::Vector2d p = mesh.rest.col(i);
    const double r = p.norm();
    if (r <= platform_radius) {
      mesh.positions.col(i) << p, 0.0;
    } else {
      const double slant = r - platform_radius;
      mesh.positions.col(i) << p / r * (platform_radius + slant * std::sin(half_angle)), -slant * std::cos(half_angle);
    }
  }
  return mesh;
}

/// Two loose triangles (vertices 0-2 and 3-5).
ClothMesh triangle_pair(const std::array<Eigen::Vector3d, 6>& corners) {
  ClothMesh mesh;
  mesh.positions.resize(3, 6);
  for (int i = 0; i < 6; ++i) mesh.positions.col(i) = corners[i];
  mesh.rest = mesh.positions.topRows<2>();
  mesh.triangles.resize(3, 2);
  mesh.triangles << 0, 3, 1, 4, 2, 5;
  return mesh;
}

std::vector<double> cosine_profile(int bins, int k, double r0, double amplitude, double phase) {
  std::vector<double> profile(bins);
  for (int b = 0; b < bins; ++b) profile[b] = r0 + amplitude * std::cos(k * (2.0 * kPi * (b + 0.5) / bins) + phase);
  return profile;
}

template <class F>
double milliseconds(F&& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// ---------------------------------------------------------------------------------------------------------------------
// Projected area and drape coefficient.

TEST(ProjectedArea, FlatSpecimen) {
  EXPECT_NEAR(projected_area(square_specimen(31)), 0.09, 0.005 * 0.09);
  EXPECT_NEAR(projected_area(square_specimen(100, 0.3, true)), 0.09, 0.005 * 0.09);
  EXPECT_NEAR(projected_area(square_specimen(31), 2e-3), 0.09, 0.005 * 0.09);
}

TEST(ProjectedArea, TiltedSquareIsPixelAccurate) {
  // A 45-degree rotated square: no edge is aligned with the pixel grid.
  ClothMesh mesh = square_specimen(21);
  const Eigen::Matrix2d rotation = Eigen::Rotation2Dd(kPi / 4).toRotationMatrix();
  mesh.positions.topRows<2>() = rotation * mesh.rest;
  EXPECT_NEAR(projected_area(mesh), 0.09, 0.002 * 0.09);
}

TEST(ProjectedArea, FoldedInHalfCountsOverlapOnce) {
  ClothMesh mesh = square_specimen(61);
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    if (mesh.rest(0, i) > 0.0) mesh.positions.col(i) << -mesh.rest(0, i), mesh.rest(1, i), 2e-3;
  }
  EXPECT_NEAR(projected_area(mesh), 0.045, 0.005 * 0.045);
}

TEST(ProjectedArea, VerticalTrianglesHaveNoShadow) {
  ClothMesh mesh = square_specimen(11);
  mesh.positions.row(2) = mesh.positions.row(1);
  mesh.positions.row(1).setZero();
  EXPECT_EQ(projected_area(mesh), 0.0);
}

TEST(LiesFaceDown, ALaidOutSpecimenLiesOnTheFaceItWasLaidOn) {
  for (const InitialShape shape : {InitialShape::kFlat, InitialShape::kSine}) {
    for (const bool face_down : {false, true}) {
      ClothMesh mesh = square_specimen(12, 0.2, true);
      ASSERT_TRUE(apply_initial_state({.shape = shape, .seed = 4, .rotation = 2.0, .face_down = face_down}, mesh));
      EXPECT_EQ(lies_face_down(mesh), face_down) << static_cast<int>(shape);
    }
  }
}

TEST(LiesFaceDown, AFoldTurnsTheSpecimenOnlyWhereItLaysMostOfItBack) {
  // The square (x in +-0.15 m) folded back along x = f: the part beyond lies mirrored at 2f - x, its back face up.
  // The signed shadow is the unfolded part's area less the folded part's.
  const auto folded_at = [](double f) {
    ClothMesh mesh = square_specimen(41);
    for (int i = 0; i < mesh.vertex_count(); ++i) {
      const double x = mesh.rest(0, i);
      if (x > f) mesh.positions.col(i) << 2.0 * f - x, mesh.rest(1, i), 2e-3;
    }
    return mesh;
  };
  ClothMesh quarter = folded_at(0.075);
  EXPECT_FALSE(lies_face_down(quarter));  // 0.225 up, 0.075 down
  quarter.positions.row(1) *= -1.0;       // the same fold seen from below
  EXPECT_TRUE(lies_face_down(quarter));
  EXPECT_TRUE(lies_face_down(folded_at(-0.075)));  // 0.075 up, 0.225 down: mostly turned over
}

TEST(Measures, RejectBadInput) {
  ClothMesh mesh = square_specimen(5);
  EXPECT_THROW((void)projected_area(mesh, 0.0), std::invalid_argument);
  EXPECT_THROW((void)projected_area(mesh, 1e-9), std::invalid_argument);  // 3e8 pixels a side
  EXPECT_THROW((void)hem_profile(mesh, 0), std::invalid_argument);
  EXPECT_THROW((void)count_folds({0.1, 0.2, NAN, 0.1}), std::invalid_argument);
  mesh.triangles(2, 5) = 25;
  EXPECT_THROW((void)count_self_intersections(mesh), std::invalid_argument);
  mesh = square_specimen(5);
  mesh.positions(0, 3) = NAN;
  EXPECT_THROW((void)projected_area(mesh), std::invalid_argument);
  EXPECT_THROW((void)hem_profile(mesh), std::invalid_argument);
  EXPECT_THROW((void)count_self_intersections(mesh), std::invalid_argument);
  EXPECT_THROW((void)drape_coefficient(mesh, 0.05), std::invalid_argument);
  EXPECT_THROW((void)lies_face_down(mesh), std::invalid_argument);
}

TEST(DrapeCoefficient, FlatSpecimenIsOne) {
  EXPECT_NEAR(drape_coefficient(square_specimen(31), 0.09), 1.0, 0.005);
  EXPECT_THROW((void)drape_coefficient(square_specimen(5), 0.2), std::invalid_argument);  // platform too large
}

TEST(DrapeCoefficient, ConeMatchesCusickFormula) {
  const double platform = 0.09, half_side = 0.15, side = 0.3;
  for (const double half_angle : {0.0, 0.3, 0.7, 1.2}) {
    const ClothMesh mesh = hang_as_cone(square_specimen(61), platform, half_angle);
    // Shadow: the square's boundary r_max(psi) moved radially to R + (r_max - R) s; integrate r^2 / 2 over psi with
    // the integral of r_max over a square's boundary, 8 h ln(1 + sqrt 2), and of r_max^2 / 2, the square's area.
    const double s = std::sin(half_angle);
    const double shadow = kPi * platform * platform * (1 - s) * (1 - s) +
                          8.0 * half_side * platform * (1 - s) * s * std::log(1.0 + std::sqrt(2.0)) +
                          s * s * side * side;
    const double platform_area = kPi * platform * platform;
    const double expected = (shadow - platform_area) / (side * side - platform_area);
    EXPECT_NEAR(projected_area(mesh), shadow, 0.005 * shadow) << half_angle;
    EXPECT_NEAR(drape_coefficient(mesh, platform), expected, 0.005) << half_angle;
  }
}

// ---------------------------------------------------------------------------------------------------------------------
// Hem profile and folds.

TEST(HemProfile, FlatSquareIsExact) {
  const ClothMesh mesh = square_specimen(31, 0.3, true);
  const int bins = 360;
  const std::vector<double> profile = hem_profile(mesh, bins);
  ASSERT_EQ(profile.size(), 360u);
  // The square's boundary radius; no bin contains a corner in its interior, so each maximum is at a bin edge.
  auto boundary = [](double psi) { return 0.15 / std::max(std::abs(std::cos(psi)), std::abs(std::sin(psi))); };
  for (int b = 0; b < bins; ++b) {
    const double expected = std::max(boundary(2 * kPi * b / bins), boundary(2 * kPi * (b + 1) / bins));
    EXPECT_NEAR(profile[b], expected, 1e-12) << b;
  }
  EXPECT_NEAR(profile[44], 0.15 * std::sqrt(2.0), 1e-12);  // bins 44 and 45 share the corner at 45 degrees
  EXPECT_NEAR(profile[45], 0.15 * std::sqrt(2.0), 1e-12);
  EXPECT_EQ(count_folds(profile), 4);
}

TEST(HemProfile, ConeShadowRadius) {
  const double platform = 0.09, half_angle = 0.5;
  const std::vector<double> profile = hem_profile(hang_as_cone(square_specimen(61), platform, half_angle), 72);
  auto shadow = [&](double psi) {
    const double r = 0.15 / std::max(std::abs(std::cos(psi)), std::abs(std::sin(psi)));
    return platform + (r - platform) * std::sin(half_angle);
  };
  for (int b = 0; b < 72; ++b) {
    const double expected = std::max(shadow(2 * kPi * b / 72), shadow(2 * kPi * (b + 1) / 72));
    EXPECT_NEAR(profile[b], expected, 1e-4) << b;  // chords of the curved hem between vertices
  }
  EXPECT_EQ(count_folds(profile), 4);
}

TEST(HemProfile, OffAxisShadowLeavesEmptyBins) {
  ClothMesh mesh = square_specimen(5);
  mesh.positions.row(0).array() += 2.0;  // the shadow lies around (2, 0), within +-4.7 degrees
  const std::vector<double> profile = hem_profile(mesh, 36);
  EXPECT_NEAR(profile[0], std::hypot(2.15, 0.15), 1e-12);
  EXPECT_NEAR(profile[35], std::hypot(2.15, 0.15), 1e-12);
  for (int b = 1; b < 35; ++b) EXPECT_EQ(profile[b], 0.0) << b;
}

TEST(CountFolds, CosineProfiles) {
  for (int k = 3; k <= 12; ++k) {
    for (const int bins : {180, 360, 720}) {
      EXPECT_EQ(count_folds(cosine_profile(bins, k, 0.16, 0.01, 0.3 * k)), k) << "k " << k << " bins " << bins;
    }
  }
}

TEST(CountFolds, IgnoresNoiseAndSmallRipples) {
  for (int k = 3; k <= 12; ++k) {
    std::vector<double> profile = cosine_profile(360, k, 0.16, 0.008, 0.0);
    // Deterministic sub-millimetre noise, fast (removed by the smoothing) and slow (too little prominence).
    for (int b = 0; b < 360; ++b) {
      profile[b] += 4e-4 * std::sin(b * 2.4) + 3e-4 * std::cos(b * 7.1) + 4e-4 * std::sin(b * 0.37);
    }
    EXPECT_EQ(count_folds(profile), k) << k;
  }
  EXPECT_EQ(count_folds(cosine_profile(360, 6, 0.16, 5e-4, 0.0)), 0);  // 1 mm peak-to-valley < 2 mm
  EXPECT_EQ(count_folds(cosine_profile(360, 6, 0.16, 5e-4, 0.0), 5e-4), 6);
  EXPECT_EQ(count_folds(std::vector<double>(360, 0.2)), 0);
  EXPECT_EQ(count_folds({}), 0);
}

TEST(CountFolds, UnequalFoldsAndPlateaus) {
  // Two tall folds, one small fold and a flat-topped fold (a plateau counts once).
  std::vector<double> profile(360, 0.15);
  auto bump = [&](int centre, int half_width, double height) {
    for (int d = -half_width; d <= half_width; ++d) {
      double& r = profile[(centre + d + 360) % 360];
      r = std::max(r, 0.15 + height * (1.0 - std::abs(d) / static_cast<double>(half_width + 1)));
    }
  };
  bump(0, 20, 0.03);
  bump(90, 20, 0.03);
  bump(180, 15, 0.004);
  for (int b = 250; b <= 290; ++b)
    profile[b] = b < 260 || b > 280 ? 0.15 + 0.002 * (b < 260 ? b - 249 : 291 - b) : 0.17;
  EXPECT_EQ(count_folds(profile), 4);
  EXPECT_EQ(count_folds(profile, 0.01), 3);
}

// ---------------------------------------------------------------------------------------------------------------------
// Self-intersections.

TEST(SelfIntersections, FlatSheetHasNone) {
  EXPECT_EQ(count_self_intersections(square_specimen(31)), 0);
  EXPECT_EQ(count_self_intersections(square_specimen(40, 0.3, true)), 0);
  // The same sheet in a tilted plane, where coplanarity is only up to rounding.
  ClothMesh tilted = square_specimen(40, 0.3, true);
  const Eigen::Matrix3d rotation =
      (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  tilted.positions = (rotation * tilted.positions).colwise() + Eigen::Vector3d(0.3, -1.1, 2.0);
  EXPECT_EQ(count_self_intersections(tilted), 0);
}

TEST(SelfIntersections, SmoothlyBentSheetHasNone) {
  // Rolled 270 degrees round a cylinder: nearby layers approach but never meet.
  ClothMesh mesh = square_specimen(41, 0.3, true);
  const double radius = 0.3 / (1.5 * kPi);
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    const double angle = (mesh.rest(0, i) + 0.15) / radius;
    mesh.positions.col(i) << radius * std::sin(angle), mesh.rest(1, i), radius * (1.0 - std::cos(angle));
  }
  EXPECT_EQ(count_self_intersections(mesh), 0);
}

TEST(SelfIntersections, SheetFoldedThroughItself) {
  // The right half folds back over the left half (10 degrees above it at the fold), then bends down through it
  // along the line x = -0.074.
  ClothMesh mesh = square_specimen(31);
  const double tilt = 10.0 * kPi / 180.0, bend = std::sin(tilt) / 0.075;
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    const double x = mesh.rest(0, i);
    if (x > 0.0) mesh.positions.col(i) << -x * std::cos(tilt), mesh.rest(1, i), x * std::sin(tilt) - bend * x * x;
  }
  const int crossings = count_self_intersections(mesh);
  EXPECT_GT(crossings, 30);  // the crossing line runs across all 30 rows of cells
  // Folded just short of passing through: no crossing.
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    const double x = mesh.rest(0, i);
    if (x > 0.0) mesh.positions.col(i) << -x * std::cos(tilt), mesh.rest(1, i), x * std::sin(tilt) - 0.4 * bend * x * x;
  }
  EXPECT_EQ(count_self_intersections(mesh), 0);
}

TEST(SelfIntersections, FlatFoldCountsCoplanarOverlap) {
  // The right half laid exactly onto the left half overlaps it in the plane; lifted by 1 mm it does not.
  ClothMesh mesh = square_specimen(21);
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    if (mesh.rest(0, i) > 0.0) mesh.positions.col(i) << -mesh.rest(0, i), mesh.rest(1, i), 0.0;
  }
  EXPECT_GT(count_self_intersections(mesh), 100);
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    if (mesh.rest(0, i) > 0.0) mesh.positions(2, i) = 1e-3;
  }
  EXPECT_EQ(count_self_intersections(mesh), 0);
}

TEST(SelfIntersections, TwoLooseTriangles) {
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  // Piercing.
  EXPECT_EQ(count_self_intersections(triangle_pair({a, b, c, {0.2, 0.2, -0.5}, {0.3, 0.2, 0.5}, {0.2, 0.3, 0.5}})), 1);
  // Same, moved clear.
  EXPECT_EQ(count_self_intersections(triangle_pair({a, b, c, {1.2, 0.2, -0.5}, {1.3, 0.2, 0.5}, {1.2, 0.3, 0.5}})), 0);
  // Above the plane, over the triangle.
  EXPECT_EQ(count_self_intersections(triangle_pair({a, b, c, {0.2, 0.2, 0.1}, {0.3, 0.2, 0.5}, {0.2, 0.3, 0.5}})), 0);
  // Touching with a vertex inside the other (closed sets meet).
  EXPECT_EQ(count_self_intersections(triangle_pair({a, b, c, {0.2, 0.2, 0.0}, {0.3, 0.2, 0.5}, {0.2, 0.3, 0.5}})), 1);
  // An edge lying in the other's plane, crossing it.
  EXPECT_EQ(count_self_intersections(triangle_pair({a, b, c, {-0.5, 0.25, 0}, {1.5, 0.25, 0}, {0.5, 0.25, 1}})), 1);
  // Coplanar: overlapping, then containing, then apart.
  EXPECT_EQ(count_self_intersections(triangle_pair({a, b, c, {0.5, 0.5, 0}, {-0.5, 0.5, 0}, {0.5, -0.5, 0}})), 1);
  EXPECT_EQ(count_self_intersections(triangle_pair({a, b, c, {0.1, 0.1, 0}, {0.3, 0.1, 0}, {0.1, 0.3, 0}})), 1);
  EXPECT_EQ(count_self_intersections(triangle_pair({a, b, c, {0.6, 0.6, 0}, {1.6, 0.6, 0}, {0.6, 1.6, 0}})), 0);
  // A degenerate (collinear) triangle piercing a proper one.
  EXPECT_EQ(count_self_intersections(triangle_pair({a, b, c, {0.2, 0.2, -1}, {0.2, 0.2, 0}, {0.2, 0.2, 1}})), 1);
}

TEST(SelfIntersections, TrianglesSharingAVertexAreNotCounted) {
  ClothMesh mesh =
      triangle_pair({Eigen::Vector3d(0, 0, 0), {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {0.5, 0.5, 1}, {0.5, 0.5, -1}});
  EXPECT_EQ(count_self_intersections(mesh), 1);  // vertex 3 coincides with vertex 0 but is a different vertex
  mesh.triangles(0, 1) = 0;
  EXPECT_EQ(count_self_intersections(mesh), 0);
}

TEST(Measures, LargeMeshIsFast) {
  // 100 x 100 vertices, 19602 triangles, gently waved so that it is not planar.
  ClothMesh mesh = square_specimen(100, 0.3, true);
  for (int i = 0; i < mesh.vertex_count(); ++i) {
    mesh.positions(2, i) = 0.02 * std::sin(20.0 * mesh.rest(0, i)) * std::cos(15.0 * mesh.rest(1, i));
  }
  int crossings = -1;
  const double intersect_ms = milliseconds([&] { crossings = count_self_intersections(mesh); });
  double area = 0.0;
  const double area_ms = milliseconds([&] { area = projected_area(mesh); });
  EXPECT_EQ(crossings, 0);
  EXPECT_NEAR(area, 0.09, 0.005 * 0.09);
  RecordProperty("count_self_intersections_ms", std::to_string(intersect_ms));
  RecordProperty("projected_area_ms", std::to_string(area_ms));
#if defined(__OPTIMIZE__)
  // About 10 ms each when optimised; generous for loaded machines and sanitizers. A quadratic pair search (1.9e8
  // pairs) would take seconds. Unoptimised Eigen is 50-100 times slower, so no bound there.
  EXPECT_LT(intersect_ms, 400.0);
  EXPECT_LT(area_ms, 400.0);
#endif
}

}  // namespace
}  // namespace drapegen::sim
