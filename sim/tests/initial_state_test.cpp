// Initial states place the specimen's centre point where the drift says, whatever the shape: a mesh initial state
// (another sample's drape) is brought back onto the axis first, so drifts do not add up along chains of drapes.
#include "drapegen/sim/initial_state.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "drapegen/sim/mesh_transfer.hpp"
#include "drapegen/sim/ply.hpp"
#include "drapegen/sim/specimen.hpp"
#include "drapegen/sim/xoshiro.hpp"

namespace drapegen::sim {
namespace {

ClothMesh small_specimen() {
  SpecimenSpec spec;
  spec.vertices_x = spec.vertices_y = 21;
  return make_specimen(spec);
}

// Where the specimen's centre point (rest (0, 0)) is, in mm.
Eigen::Vector2d centre_mm(const ClothMesh& mesh) {
  return 1e3 * transfer_positions(mesh, Eigen::Vector2d::Zero().eval()).col(0).head<2>();
}

TEST(InitialState, EveryShapePutsTheCentreAtTheDrift) {
  const Eigen::Vector2d drift(0.003, -0.001);
  for (const InitialShape shape : {InitialShape::kFlat, InitialShape::kSine, InitialShape::kFold}) {
    ClothMesh mesh = small_specimen();
    InitialStateSpec spec;
    spec.shape = shape;
    spec.seed = 5;
    spec.rotation = 0.7;
    spec.drift = drift;
    ASSERT_TRUE(apply_initial_state(spec, mesh));
    const Eigen::Vector2d c = centre_mm(mesh);
    EXPECT_NEAR(c.x(), 3.0, 1e-9) << static_cast<int>(shape);
    EXPECT_NEAR(c.y(), -1.0, 1e-9) << static_cast<int>(shape);
  }
}

TEST(InitialState, AMeshIsBroughtOntoTheAxisBeforeItsDrift) {
  // A source state 4 mm off the axis, as a drape with a drift leaves it.
  ClothMesh source = small_specimen();
  InitialStateSpec sine;
  sine.shape = InitialShape::kSine;
  sine.seed = 9;
  sine.drift = Eigen::Vector2d(0.004, 0.0);
  ASSERT_TRUE(apply_initial_state(sine, source));
  ASSERT_NEAR(centre_mm(source).x(), 4.0, 1e-9);
  const std::string path = testing::TempDir() + "/initial_state_source.ply";
  ASSERT_TRUE(write_ply(path, source));
  const Expected<ClothMesh> stored = read_ply(path);  // as the file holds it (its precision)
  ASSERT_TRUE(stored);

  InitialStateSpec from_mesh;
  from_mesh.shape = InitialShape::kMesh;
  from_mesh.mesh_path = path;
  from_mesh.rotation = std::numbers::pi / 2.0;
  from_mesh.drift = Eigen::Vector2d(0.0, 0.002);
  ClothMesh mesh = small_specimen();
  ASSERT_TRUE(apply_initial_state(from_mesh, mesh));
  const Eigen::Vector2d c = centre_mm(mesh);
  EXPECT_NEAR(c.x(), 0.0, 1e-6);  // not 4 mm turned to (0, 4) and drifted to (0, 6)
  EXPECT_NEAR(c.y(), 2.0, 1e-6);
  EXPECT_NEAR(centre_mm(*stored).x(), 4.0, 1e-3);
  // Moved and turned rigidly: every edge keeps its length, and the heights are the source's.
  for (int t = 0; t < mesh.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.triangles(k, t), b = mesh.triangles((k + 1) % 3, t);
      EXPECT_NEAR((mesh.positions.col(a) - mesh.positions.col(b)).norm(),
                  (stored->positions.col(a) - stored->positions.col(b)).norm(), 1e-12);
    }
  }
  EXPECT_TRUE(mesh.positions.row(2).isApprox(stored->positions.row(2)));
  // A specimen cut at another angle is not this drape's.
  ClothMesh turned = small_specimen();
  turned.material_angle = 0.5;
  const Status other = apply_initial_state(from_mesh, turned);
  ASSERT_FALSE(other);
  EXPECT_NE(other.error().message.find("material angle"), std::string::npos) << other.error().message;
  std::filesystem::remove(path);
}

// A seed means the same start with every standard library: the three waves (direction, wavelength 40-150 mm,
// phase, amplitude 4-12 mm) are the project generator's draws in that order. At a corner the ramp from the rim is 1.
TEST(InitialState, SineWavesAreTheProjectGeneratorsDraws) {
  ClothMesh mesh = small_specimen();
  InitialStateSpec spec;
  spec.shape = InitialShape::kSine;
  spec.seed = 77;
  ASSERT_TRUE(apply_initial_state(spec, mesh));
  Xoshiro256 rng(77);
  double waves[3][4];
  for (auto& w : waves) {
    for (double& x : w) x = rng.uniform();
  }
  const int corner = mesh.vertex_count() - 1;
  const Eigen::Vector2d p = mesh.rest.col(corner);
  ASSERT_GT(p.norm(), spec.platform_radius + 0.03);
  double z = spec.lift;
  for (const auto& w : waves) {
    const double angle = 2.0 * std::numbers::pi * w[0], wavelength = 0.04 + 0.11 * w[1];
    const Eigen::Vector2d k = (2.0 * std::numbers::pi / wavelength) * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    z += (0.004 + 0.008 * w[3]) * std::sin(k.dot(p) + 2.0 * std::numbers::pi * w[2]);
  }
  EXPECT_NEAR(mesh.positions(2, corner), z, 1e-12);
  EXPECT_GT(std::abs(z - spec.lift), 1e-4);  // the waves reach the corner
}

}  // namespace
}  // namespace drapegen::sim
