// Acceptance 3: noise statistics on flat targets match the model's formulas; seeds make it reproducible.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "drapegen/renderer/depth_renderer.hpp"
#include "shared_renderer.hpp"
#include "drapegen/renderer/noise.hpp"
#include "drapegen/renderer/random.hpp"
#include "drapegen/renderer/rig.hpp"

namespace drapegen::renderer {
namespace {

/// A large plane z = 0 seen from `distance` with its normal at `angle_deg` from the optical axis.
struct FlatTarget {
  DepthImage clean;
  Camera camera;
};
FlatTarget flat_target(double distance, double angle_deg) {
  DepthRenderer& renderer = shared_renderer();
  TriangleMesh plane;
  plane.vertices = {{-5, -5, 0}, {5, -5, 0}, {5, 5, 0}, {-5, 5, 0}};
  plane.triangles = {{0, 1, 2}, {0, 2, 3}};
  EXPECT_TRUE(renderer.set_scene(plane));
  const double a = angle_deg * M_PI / 180.0;
  const Eigen::Vector3d eye(distance * std::sin(a), 0.0, distance * std::cos(a));
  FlatTarget t;
  t.camera = Camera::look_at(RigSpec{}.intrinsics(), eye, {0, 0, 0}, {0, 1, 0});
  auto image = renderer.render(t.camera);
  EXPECT_TRUE(image);
  t.clean = std::move(*image);
  return t;
}

/// Mean over pixels of (measured per-pixel variance over `runs` realisations) / (expected variance), for pixels in
/// the central half of the image; `expected(u, v, z, theta)` gives the model's standard deviation.
template <class F>
double variance_ratio(const FlatTarget& t, const NoiseModel& model, int runs, F expected) {
  const int W = t.clean.width, H = t.clean.height;
  std::vector<double> sum(t.clean.depth.size(), 0.0), sum_sq(t.clean.depth.size(), 0.0);
  for (int r = 0; r < runs; ++r) {
    const DepthImage noisy = model.apply(t.clean, 1000 + r);
    for (std::size_t i = 0; i < sum.size(); ++i) {
      const double d = noisy.depth[i] - t.clean.depth[i];
      sum[i] += d;
      sum_sq[i] += d * d;
    }
  }
  const Eigen::Vector3d n = t.camera.world_to_camera.linear() * Eigen::Vector3d::UnitZ();
  double ratio = 0.0;
  int count = 0;
  for (int v = H / 4; v < 3 * H / 4; ++v) {
    for (int u = W / 4; u < 3 * W / 4; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * W + u;
      const double mean = sum[i] / runs;
      const double variance = (sum_sq[i] - runs * mean * mean) / (runs - 1);
      // The incidence angle from the plane's geometry (independent of the renderer's normal estimate).
      const double theta = std::acos(std::abs(t.camera.ray(u, v).normalized().dot(n)));
      const double sigma = expected(u, v, static_cast<double>(t.clean.depth[i]), theta);
      ratio += variance / (sigma * sigma);
      ++count;
    }
  }
  return ratio / count;
}

NoiseModel only_axial() {
  NoiseModel m = NoiseModel::none();
  m.axial = true;
  return m;
}

TEST(Noise, AxialStandardDeviationMatchesFormulaAtSeveralDepthsAndAngles) {
  const NoiseModel model = only_axial();
  for (double distance : {0.5, 0.8, 1.5, 3.0}) {
    for (double angle : {0.0, 30.0, 50.0, 65.0}) {
      const FlatTarget t = flat_target(distance, angle);
      // Nguyen, Izadi, Lovell 2012, written out here independently of NoiseModel::axial_sigma.
      const double ratio = variance_ratio(t, model, 60, [&](int, int, double z, double theta) {
        return 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4) +
               0.0001 / std::sqrt(z) * theta * theta / ((M_PI / 2 - theta) * (M_PI / 2 - theta));
      });
      std::printf("axial: distance %.1f m, angle %2.0f deg: measured/model sigma = %.4f\n", distance, angle,
                  std::sqrt(ratio));
      EXPECT_NEAR(std::sqrt(ratio), 1.0, 0.10) << "distance " << distance << " angle " << angle;
    }
  }
}

TEST(Noise, AxialFormulaIsNguyensModel) {
  const NoiseModel m = NoiseModel::kinect();
  // sigma_z(z, 0) = 1.2 mm + 1.9 mm/m^2 (z - 0.4)^2
  EXPECT_NEAR(m.axial_sigma(0.4, 0.0), 0.0012, 1e-12);
  EXPECT_NEAR(m.axial_sigma(1.4, 0.0), 0.0012 + 0.0019, 1e-12);
  // Angle term at 60 degrees: 0.1 mm / sqrt(z) * theta^2 / (pi/2 - theta)^2 = 0.1 mm * 4 at z = 1.
  EXPECT_NEAR(m.axial_sigma(1.0, M_PI / 3) - m.axial_sigma(1.0, 0.0), 0.0004, 1e-9);
}

TEST(Noise, AxialPlusQuantisationAddsTheStepVariance) {
  NoiseModel model = only_axial();
  model.quantisation = true;
  const FlatTarget t = flat_target(0.7, 20.0);
  // Rounding to a step q adds about q^2 / 12 (Sheppard) when sigma is comparable to q.
  const double ratio = variance_ratio(t, model, 60, [&](int, int, double z, double theta) {
    const double s = model.axial_sigma(z, theta), q = model.quantisation_step;
    return std::sqrt(s * s + q * q / 12.0);
  });
  std::printf("axial + quantisation at 0.7 m: measured/model sigma = %.4f\n", std::sqrt(ratio));
  EXPECT_NEAR(std::sqrt(ratio), 1.0, 0.10);
  // Every value is a whole number of steps.
  const DepthImage noisy = model.apply(t.clean, 7);
  for (float z : noisy.depth) {
    if (z > 0.0f) {
      ASSERT_NEAR(z / model.quantisation_step, std::round(z / model.quantisation_step), 1e-3);
    }
  }
}

/// Variance of round(sigma * N(0, 1)).
double rounded_gaussian_second_moment(double sigma) {
  double m = 0.0;
  for (int k = 1; k < 10; ++k) {
    const double p = std::erfc((k - 0.5) / (sigma * std::sqrt(2.0))) - std::erfc((k + 0.5) / (sigma * std::sqrt(2.0)));
    m += k * k * p;  // p counts both signs: erfc gives twice the upper tail
  }
  return m;
}

TEST(Noise, LateralJitterMatchesFormula) {
  NoiseModel model = NoiseModel::none();
  model.lateral = true;
  // A depth ramp of 1 cm per column: the lateral offset along u shows as depth, 1 cm per pixel moved.
  for (double theta_deg : {0.0, 45.0, 70.0}) {
    DepthImage ramp(240, 180);
    ramp.incidence.assign(ramp.depth.size(), static_cast<float>(std::cos(theta_deg * M_PI / 180.0)));
    for (int v = 0; v < 180; ++v)
      for (int u = 0; u < 240; ++u) ramp.at(u, v) = static_cast<float>(1.0 + 0.01 * u);
    double sum_sq = 0.0;
    int count = 0;
    for (int r = 0; r < 20; ++r) {
      const DepthImage noisy = model.apply(ramp, 50 + r);
      for (int v = 0; v < 180; ++v) {
        for (int u = 5; u < 235; ++u) {
          const double moved = (noisy.at(u, v) - ramp.at(u, v)) / 0.01;
          sum_sq += moved * moved;
          ++count;
        }
      }
    }
    const double sigma = model.lateral_sigma_px(theta_deg * M_PI / 180.0);
    const double expected = rounded_gaussian_second_moment(sigma);
    std::printf("lateral: theta %2.0f deg, sigma_L %.3f px: measured/model E[offset^2] = %.4f\n", theta_deg, sigma,
                sum_sq / count / expected);
    EXPECT_NEAR(sum_sq / count / expected, 1.0, 0.10) << "theta " << theta_deg;
  }
}

TEST(Noise, GrazingDropoutHolesAndFlyingPixels) {
  NoiseModel model = NoiseModel::none();
  // Grazing: nothing beyond the cut-off angle survives, everything below does.
  model.grazing = true;
  DepthImage img(100, 100);
  img.incidence.assign(img.depth.size(), 0.0f);
  for (int v = 0; v < 100; ++v) {
    for (int u = 0; u < 100; ++u) {
      img.at(u, v) = 1.0f;
      img.incidence[v * 100 + u] = static_cast<float>(std::cos((u < 50 ? 75.0 : 85.0) * M_PI / 180.0));
    }
  }
  DepthImage out = model.apply(img, 1);
  EXPECT_EQ(out.foreground_count(), 5000);
  for (int v = 0; v < 100; ++v) EXPECT_EQ(out.at(70, v), 0.0f);

  // Dropout: the fraction lost matches the probability (binomial, 10000 x 20 pixels).
  model = NoiseModel::none();
  model.dropout = true;
  model.dropout_probability = 0.01;
  for (auto& c : img.incidence) c = 1.0f;
  int lost = 0;
  for (int r = 0; r < 20; ++r) lost += 10000 - model.apply(img, r).foreground_count();
  EXPECT_NEAR(lost / 200000.0, 0.01, 0.0015);

  // Edges: a near square (0.6 m) on a far wall (1.0 m) next to a region of no return.
  model = NoiseModel::none();
  model.edges = true;
  DepthImage scene(100, 100);
  scene.incidence.assign(scene.depth.size(), 1.0f);
  for (int v = 0; v < 100; ++v)
    for (int u = 0; u < 80; ++u) scene.at(u, v) = (u >= 20 && u < 50 && v >= 20 && v < 50) ? 0.6f : 1.0f;
  int holes = 0, rim = 0, flying = 0, jumps = 0;
  for (int r = 0; r < 20; ++r) {
    out = model.apply(scene, 100 + r);
    for (int v = 0; v < 100; ++v) {
      // Column 79 borders the no-return region (u >= 80).
      ++rim;
      holes += out.at(79, v) == 0.0f;
      EXPECT_EQ(out.at(80, v), 0.0f);
    }
    for (int v = 25; v < 45; ++v) {
      for (int u : {19, 20, 49, 50}) {  // both sides of the square's vertical edges
        ++jumps;
        const float z = out.at(u, v);
        ASSERT_GE(z, 0.6f - 1e-6f);
        ASSERT_LE(z, 1.0f + 1e-6f);
        flying += z != scene.at(u, v);
      }
    }
    EXPECT_EQ(out.at(35, 35), 0.6f);  // away from edges nothing changes
    EXPECT_EQ(out.at(5, 5), 1.0f);
  }
  EXPECT_NEAR(static_cast<double>(holes) / rim, model.edge_hole_probability, 0.05);
  EXPECT_NEAR(static_cast<double>(flying) / jumps, model.flying_probability, 0.05);
}

TEST(Noise, NoneIsTheCleanDepth) {
  const FlatTarget t = flat_target(0.8, 30.0);
  const DepthImage out = NoiseModel::none().apply(t.clean, 3);
  EXPECT_EQ(out.depth, t.clean.depth);
  EXPECT_EQ(NoiseModel::none().describe(), "none");
}

TEST(Noise, SameSeedSameImageDifferentSeedDifferentImage) {
  const FlatTarget t = flat_target(0.8, 30.0);
  const NoiseModel model = NoiseModel::kinect();
  const DepthImage a = model.apply(t.clean, 42), b = model.apply(t.clean, 42), c = model.apply(t.clean, 43);
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_NE(a.depth, c.depth);
}

TEST(Random, GaussianTableHasUnitVarianceAndZeroMean) {
  Rng rng(9);
  double sum = 0.0, sum_sq = 0.0;
  const int n = 2000000;
  for (int i = 0; i < n; ++i) {
    const double g = rng.gaussian();
    sum += g;
    sum_sq += g * g;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.005);
  EXPECT_NEAR(sum_sq / n, 1.0, 0.005);
  EXPECT_NE(mix_seed(1, 0), mix_seed(1, 1));
  EXPECT_NE(mix_seed(1, 0), mix_seed(2, 0));
}

TEST(Random, BulkIndicesAndThresholdsDrawTheSameNumbers) {
  // gaussian_indices gives the draws of gaussian() in turn, whatever the pool holds before; uniform_below(t) is
  // uniform() < p for t = below_threshold(p), on the same random bits.
  for (const std::size_t before : {0, 1, 3, 4, 5}) {
    Rng one(11), bulk(11);
    for (std::size_t k = 0; k < before; ++k) EXPECT_EQ(one.gaussian(), bulk.gaussian());
    std::vector<std::uint16_t> indices(37);
    bulk.gaussian_indices(indices.data(), indices.size());
    for (const std::uint16_t index : indices) EXPECT_EQ(one.gaussian(), bulk.gaussian_of(index));
    EXPECT_EQ(one.gaussian(), bulk.gaussian());
  }
  for (const double p : {-0.5, 0.0, 0x1p-53, 0.002, 0.3, 0.5, 1.0 - 0x1p-53, 1.0, 2.0}) {
    Rng a(5), b(5);
    for (int k = 0; k < 10000; ++k) EXPECT_EQ(a.uniform() < p, b.uniform_below(Rng::below_threshold(p))) << p;
  }
  // Exactly at the threshold: k 2^-53 < p for the integer k just below p 2^53 and not for k at it.
  EXPECT_EQ(Rng::below_threshold(0.25), std::uint64_t{1} << 51);
  EXPECT_EQ(Rng::below_threshold(0.25 + 0x1p-54), (std::uint64_t{1} << 51) + 1);
  EXPECT_GT(Rng::below_threshold(0.002), 0u);
  EXPECT_GT(std::abs(Rng(1).gaussian_of(65535)), 4.0f);
}

}  // namespace
}  // namespace drapegen::renderer
