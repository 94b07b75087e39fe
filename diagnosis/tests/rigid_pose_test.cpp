// The camera's pose error read off the tester's rigid surfaces (rigid_pose.hpp), on captures of the reality generator
// whose truth says what the camera's error was.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "drapegen/diagnosis/rigid_pose.hpp"
#include "small_reality.hpp"

namespace drapegen::diagnosis {
namespace {

struct Generated {
  Capture capture;
  renderer::SensorError truth;
};

Generated generate(const std::string& name, const std::vector<std::string>& effects, std::uint64_t seed) {
  Generated g;
  const auto made = fixture::generate_small_reality(name, fixture::small_reality_spec(effects, seed));
  if (!made) return g;
  g.capture = made->capture;
  std::ifstream in(made->truth_path);
  const auto truth = nlohmann::json::parse(in)["sensor"];
  for (int k = 0; k < 3; ++k) {
    g.truth.rotation[k] = truth["rotation_rad"][k].get<double>();
    g.truth.translation[k] = truth["translation_m"][k].get<double>();
  }
  return g;
}

/// m: how far apart two pose errors put the platform's centre (the largest over the views).
double displacement_between(const renderer::SensorError& a, const renderer::SensorError& b, const Capture& c) {
  double worst = 0.0;
  for (const auto& view : c.views) {
    worst = std::max(worst, (a.true_camera(view.camera).world_to_camera.translation() -
                             b.true_camera(view.camera).world_to_camera.translation()).norm());
  }
  return worst;
}

TEST(RigidPose, PlatformDisplacementIsHowFarTheErrorMovesThePlatformCentreInTheCamerasFrame) {
  const Generated g = generate("displacement", {}, 19020);
  ASSERT_EQ(g.capture.views.size(), 4u);
  renderer::SensorError shift;
  shift.translation = Eigen::Vector3d(0.003, 0.004, 0.0);
  EXPECT_NEAR(platform_displacement(shift, g.capture), 0.005, 1e-12);
  // A turn by theta about the camera's x axis moves the centre (at p in the camera's frame) by 2 sin(theta / 2) times
  // its distance from that axis.
  renderer::SensorError turn;
  turn.rotation = Eigen::Vector3d(0.01, 0.0, 0.0);
  const Eigen::Vector3d p = g.capture.views[0].camera.world_to_camera.translation();
  EXPECT_NEAR(platform_displacement(turn, g.capture), 2.0 * std::sin(0.005) * std::hypot(p.y(), p.z()), 1e-9);
}

TEST(RigidPose, RecoversTheCameraPoseErrorOfACapture) {
  const Generated g = generate("pose", {"pose=1.5"}, 19015);
  ASSERT_EQ(g.capture.views.size(), 4u);
  ASSERT_GT(g.truth.rotation.norm(), 0.015);  // a pose error of 1.5 degrees: ~26 mrad
  auto estimate = estimate_rigid_pose(g.capture, RigidSurfaces::for_specimen(g.capture.specimen));
  ASSERT_TRUE(estimate.has_value()) << estimate.error().message;
  // The platform's centre seen through the estimated camera error lands within 3 mm of where the true error puts it;
  // the recorded camera puts it 15 mm or more away.
  EXPECT_GT(platform_displacement(g.truth, g.capture), 0.015);
  EXPECT_LT(displacement_between(g.truth, estimate->pose, g.capture), 0.003);
  // The rigid pixels lie on the surfaces, to the depth noise, once the camera is where the estimate says.
  EXPECT_LT(estimate->rms_estimated, 0.0016);
  EXPECT_GT(estimate->rms_recorded, estimate->rms_estimated + 3e-4);
  EXPECT_GT(estimate->top_pixels, 500);
  EXPECT_GT(estimate->side_pixels, 500);
}

TEST(RigidPose, FindsNoErrorInACalibratedCamera) {
  // The skirt lies against the platform's side near the top (1 mm out): side pixels are read only below where the
  // specimen can reach, else the estimate tilts the camera by ~15 mrad to put the skirt on the side.
  const Generated g = generate("control", {}, 19020);
  ASSERT_EQ(g.capture.views.size(), 4u);
  EXPECT_EQ(g.truth.rotation.norm(), 0.0);
  auto estimate = estimate_rigid_pose(g.capture, RigidSurfaces::for_specimen(g.capture.specimen));
  ASSERT_TRUE(estimate.has_value()) << estimate.error().message;
  std::printf("[ rigid    ] calibrated: rotation %.2f mrad, platform centre moved %.2f mm\n",
              estimate->pose.rotation.norm() * 1e3, displacement_between(g.truth, estimate->pose, g.capture) * 1e3);
  // What the diagnosis acts on is where the estimate moves the platform's centre (it holds the camera below 3 mm,
  // kCameraMovedAtPlatform): here under 2 mm. The rotation left by the depth noise and the drape's rim pixels is a few
  // mrad (below 4 on the machines before session 62, 4.17 on its; it follows the simulated drape, whose last digits
  // differ between CPUs), well apart from the ~15-17 mrad of a side read near the top (below).
  EXPECT_LT(estimate->pose.rotation.norm(), 0.006);
  EXPECT_LT(displacement_between(g.truth, estimate->pose, g.capture), 0.002);
  EXPECT_NEAR(estimate->rms_recorded, estimate->rms_estimated, 1e-4);
  RigidSurfaces near_the_top = RigidSurfaces::for_specimen(g.capture.specimen);
  near_the_top.side_below = 0.03;
  auto tilted = estimate_rigid_pose(g.capture, near_the_top);
  ASSERT_TRUE(tilted.has_value()) << tilted.error().message;
  std::printf("[ rigid    ] side read near the top: rotation %.2f mrad\n", tilted->pose.rotation.norm() * 1e3);
  EXPECT_GT(tilted->pose.rotation.norm(), 0.008);
}

TEST(RigidPose, SaysWhyWithoutTheRigidSurfaces) {
  const Generated g = generate("narrow", {}, 19020);
  ASSERT_EQ(g.capture.views.size(), 4u);
  RigidSurfaces surfaces = RigidSurfaces::for_specimen(g.capture.specimen);
  surfaces.cylinder_radius = 0.2;  // a platform the views do not see
  auto estimate = estimate_rigid_pose(g.capture, surfaces);
  ASSERT_FALSE(estimate.has_value());
  EXPECT_NE(estimate.error().message.find("pixels on the platform top"), std::string::npos) << estimate.error().message;
}

TEST(RigidPose, SidePixelsStartBelowWhereTheSpecimenReaches) {
  SpecimenFacts facts;
  facts.size_x = facts.size_y = 0.3;
  facts.cylinder_diameter = 0.1;
  const RigidSurfaces s = RigidSurfaces::for_specimen(facts);
  EXPECT_DOUBLE_EQ(s.cylinder_radius, 0.05);
  EXPECT_NEAR(s.side_below, 0.15 * std::sqrt(2.0) - 0.05 + 0.01, 1e-12);
}

/// Calls f(z, q, dz_dheight) for every pixel of the cloth on the platform top: within the estimator's first band of
/// the top's height (its depth z, writable; its point q in the specimen frame; how z changes per metre of height).
template <typename F>
void for_each_top_pixel(Capture& capture, const RigidSurfaces& s, F&& f) {
  for (auto& view : capture.views) {
    const Eigen::Isometry3d to_specimen = view.camera.world_to_camera.inverse();
    for (int y = 0; y < view.depth.height; ++y) {
      for (int x = 0; x < view.depth.width; ++x) {
        float& z = view.depth.depth[static_cast<std::size_t>(y) * view.depth.width + x];
        if (z <= 0.0f) continue;
        const Eigen::Vector3d ray = view.camera.ray(x, y);
        const Eigen::Vector3d q = to_specimen * (static_cast<double>(z) * ray);
        if (std::hypot(q.x(), q.y()) >= s.cylinder_radius - s.top_inset ||
            std::abs(q.z() - s.top_height) > RigidPoseSettings{}.first_band)
          continue;
        f(z, q, 1.0 / (to_specimen.linear() * ray).z());
      }
    }
  }
}

/// The capture with the cloth on the platform top moved `dz` along the platform axis (each top pixel's depth moved
/// along its ray), the rest as it was: a specimen lifted off the top (dz > 0), or a top seen lower than its contact.
Capture with_top_moved(Capture capture, const RigidSurfaces& s, double dz) {
  for_each_top_pixel(capture, s, [dz](float& z, const Eigen::Vector3d&, double dz_dheight) {
    z += static_cast<float>(dz * dz_dheight);
  });
  return capture;
}

/// m: the mean height above the top's contact offset of the pixels `with_top_moved` moves (what the recorded capture
/// reads as its top: the cloth's own offset, sensor noise and sag near the rim included).
double top_offset(Capture capture, const RigidSurfaces& s) {
  double sum = 0.0;
  int count = 0;
  for_each_top_pixel(capture, s, [&](float&, const Eigen::Vector3d& q, double) {
    sum += q.z() - s.top_height;
    ++count;
  });
  return count > 0 ? sum / count : 0.0;
}

TEST(RigidPose, ReadsATopAboveItsContactOffsetThatTheSideDoesNotConfirmAsTheClothLifted) {
  // A camera that moved the platform's centre along its axis moves the top and not the side, as a cloth lying above
  // the top does; a cloth cannot lie below it. Lifted 2 mm, the top is the cloth's: the camera stays as recorded.
  const Generated g = generate("lifted", {}, 19020);
  ASSERT_EQ(g.capture.views.size(), 4u);
  const RigidSurfaces surfaces = RigidSurfaces::for_specimen(g.capture.specimen);
  const Capture lifted = with_top_moved(g.capture, surfaces, 0.002);
  auto estimate = estimate_rigid_pose(lifted, surfaces);
  ASSERT_TRUE(estimate.has_value()) << estimate.error().message;
  // The lift read is the 2 mm plus what the recorded top reads already (-0.3 mm for one draw of the specimen, where
  // the cloth sags at the rim within the band), less what the lift takes out of the band.
  const double recorded_offset = top_offset(g.capture, surfaces);
  std::printf("[ lift     ] read %.3f mm; the recorded top's offset %.3f mm\n", estimate->top_lift * 1e3,
              recorded_offset * 1e3);
  EXPECT_NEAR(estimate->top_lift, 0.002 + recorded_offset, 1e-4);
  EXPECT_EQ(platform_displacement(estimate->pose, lifted), 0.0);
  // Without the rule the camera takes the lift: it moves the platform's centre by about the lift.
  RigidPoseSettings camera_only;
  camera_only.min_lift = 1.0;
  auto as_camera = estimate_rigid_pose(lifted, surfaces, camera_only);
  ASSERT_TRUE(as_camera.has_value()) << as_camera.error().message;
  EXPECT_EQ(as_camera->top_lift, 0.0);
  EXPECT_GT(platform_displacement(as_camera->pose, lifted), 0.0015);
  // Seen 2 mm lower, the top is the camera's.
  const Capture lowered = with_top_moved(g.capture, surfaces, -0.002);
  auto below = estimate_rigid_pose(lowered, surfaces);
  ASSERT_TRUE(below.has_value()) << below.error().message;
  EXPECT_EQ(below->top_lift, 0.0);
  EXPECT_GT(platform_displacement(below->pose, lowered), 0.0015);
  // Every depth 6 mm short (a camera nearer along its axis): the top is seen higher, but the side moved as well and
  // confirms the camera.
  Capture nearer = g.capture;
  for (auto& view : nearer.views)
    for (float& z : view.depth.depth)
      if (z > 0.0f) z -= 0.006f;
  auto confirmed = estimate_rigid_pose(nearer, surfaces);
  ASSERT_TRUE(confirmed.has_value()) << confirmed.error().message;
  EXPECT_EQ(confirmed->top_lift, 0.0);
  EXPECT_GT(platform_displacement(confirmed->pose, nearer), 0.003);
  // The calibrated capture itself: neither lifted nor moved.
  auto calibrated = estimate_rigid_pose(g.capture, surfaces);
  ASSERT_TRUE(calibrated.has_value()) << calibrated.error().message;
  EXPECT_EQ(calibrated->top_lift, 0.0);
}

}  // namespace
}  // namespace drapegen::diagnosis
