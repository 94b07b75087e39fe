#include "drapegen/renderer/rig.hpp"

#include <cmath>

#include "drapegen/renderer/random.hpp"

namespace drapegen::renderer {
namespace {

constexpr double kDeg = M_PI / 180.0;

Eigen::Matrix3d small_rotation(Rng& rng, double sigma_rad) {
  const Eigen::Vector3d w(sigma_rad * rng.gaussian(), sigma_rad * rng.gaussian(), sigma_rad * rng.gaussian());
  const double angle = w.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

}  // namespace

Intrinsics RigSpec::intrinsics() const { return Intrinsics::pinhole(width, height, focal_px, focal_px, cx, cy); }

Camera RigSpec::camera() const {
  const double e = elevation_deg * kDeg, a = azimuth_deg * kDeg;
  const Eigen::Vector3d eye =
      target + distance * Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
  return Camera::look_at(intrinsics(), eye, target, Eigen::Vector3d::UnitZ());
}

Eigen::Isometry3d RigSpec::table_pose(double orientation, int view) const {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(orientation + view * 2.0 * M_PI / views, Eigen::Vector3d::UnitZ())
                      .toRotationMatrix();
  return pose;
}

AugmentationSpec AugmentationSpec::orientations_only(int orientations) {
  AugmentationSpec a;
  a.orientations = orientations;
  a.position_sigma = a.rotation_sigma_deg = a.focal_sigma = 0.0;
  a.shift_sigma_px = a.image_rotation_sigma_deg = a.scale_sigma = a.shear_sigma = 0.0;
  return a;
}

std::uint64_t DataPointSetup::noise_seed(int view) const { return mix_seed(seed, 1000 + view); }

std::vector<DataPointSetup> plan_data_points(const RigSpec& rig, const AugmentationSpec& aug, std::uint64_t seed) {
  std::vector<DataPointSetup> points;
  const Camera nominal = rig.camera();
  for (int k = 0; k < aug.orientations; ++k) {
    DataPointSetup p;
    p.index = k;
    p.seed = mix_seed(seed, k);
    Rng rng(p.seed);
    p.orientation = (k + rng.uniform()) * 2.0 * M_PI / aug.orientations;

    // Calibration error: one camera per data point (the camera stays put while the table turns).
    Camera camera = nominal;
    const Eigen::Vector3d centre = nominal.position();
    const Eigen::Vector3d moved = centre + aug.position_sigma * Eigen::Vector3d(rng.gaussian(), rng.gaussian(),
                                                                                rng.gaussian());
    const Eigen::Matrix3d R = small_rotation(rng, aug.rotation_sigma_deg * kDeg) *
                              nominal.world_to_camera.linear();  // turn about the camera's own centre
    camera.world_to_camera.linear() = R;
    camera.world_to_camera.translation() = -R * moved;
    const double focal_scale = 1.0 + aug.focal_sigma * rng.gaussian();
    camera.intrinsics.K(0, 0) *= focal_scale;
    camera.intrinsics.K(1, 1) *= focal_scale;

    for (int view = 0; view < rig.views; ++view) {
      ViewSetup s;
      s.table_angle = p.orientation + view * 2.0 * M_PI / rig.views;
      s.model = rig.table_pose(p.orientation, view);
      s.camera = camera;
      // Affine image perturbation about the image centre: u' = A (u - c) + c + shift. Applied to K, it is the exact
      // warp of the ideal image (no resampling).
      const double angle = aug.image_rotation_sigma_deg * kDeg * rng.gaussian();
      const double scale = 1.0 + aug.scale_sigma * rng.gaussian();
      const double shear = aug.shear_sigma * rng.gaussian();
      const Eigen::Vector2d shift(aug.shift_sigma_px * rng.gaussian(), aug.shift_sigma_px * rng.gaussian());
      Eigen::Matrix2d A;
      A << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
      Eigen::Matrix2d S;
      S << 1.0, shear, 0.0, 1.0;
      A = scale * A * S;
      const Eigen::Vector2d c(0.5 * (rig.width - 1), 0.5 * (rig.height - 1));
      Eigen::Matrix3d affine = Eigen::Matrix3d::Identity();
      affine.topLeftCorner<2, 2>() = A;
      affine.topRightCorner<2, 1>() = c + shift - A * c;
      s.camera.intrinsics.K = affine * camera.intrinsics.K;
      p.views.push_back(s);
    }
    points.push_back(std::move(p));
  }
  return points;
}

TriangleMesh tester_scene(const TriangleMesh& cloth, const RigSpec& rig) {
  TriangleMesh scene = cloth;
  scene.append(make_cylinder(rig.cylinder));
  return scene;
}

}  // namespace drapegen::renderer
