#pragma once
// The drape tester's camera rig and the seeded augmentation of paper Section 5.2.2: 12 stratified specimen
// orientations per drape, camera position / orientation / field-of-view perturbations (calibration error, one per
// data point) and affine image perturbations (one per view). Numbers and sources: docs/RENDERER.md.

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "drapegen/renderer/camera.hpp"
#include "drapegen/renderer/scene.hpp"

namespace drapegen::renderer {

/// The fixed tester: a rotary table turning the specimen on the cylinder by 2 pi / views between views, and an
/// Azure Kinect depth camera (NFOV 2x2 binned, 320x288, centre-cropped to 240x180) looking down at the drape.
struct RigSpec {
  int width = 240;
  int height = 180;
  double focal_px = 252.0;  // fx = fy: half the ~504 px of the NFOV unbinned calibration (2x2 binning)
  double cx = 119.5;        // principal point at the image centre (pixel centres at integers)
  double cy = 89.5;
  double distance = 0.72;        // m, camera centre to `target`
  double elevation_deg = 35.0;   // optical axis below the horizontal
  double azimuth_deg = -90.0;    // direction of the camera seen from the cylinder axis (-90: on the -y side)
  Eigen::Vector3d target = Eigen::Vector3d(0.0, 0.0, -0.08);  // m: about the middle of the drape and cylinder
  int views = 4;
  CylinderSpec cylinder;

  [[nodiscard]] Intrinsics intrinsics() const;
  /// The unperturbed camera.
  [[nodiscard]] Camera camera() const;
  /// The table's turn for `view` when the specimen starts at `orientation` (radians): a rotation about the z axis
  /// by orientation + view * 2 pi / views, applied to the cloth and the cylinder (the model pose).
  [[nodiscard]] Eigen::Isometry3d table_pose(double orientation, int view) const;
};

/// Magnitudes of the seeded perturbations (standard deviations of zero-mean Gaussians, per component).
struct AugmentationSpec {
  int orientations = 12;           // stratified over [0, 2 pi): one in each 2 pi / orientations sector
  double position_sigma = 0.005;   // m, camera centre, each axis
  double rotation_sigma_deg = 0.5; // camera orientation, each axis of a small rotation about the camera centre
  double focal_sigma = 0.01;       // relative focal length (field of view)
  double shift_sigma_px = 0.5;     // affine image perturbation: translation, pixels
  double image_rotation_sigma_deg = 0.5;  // affine: in-plane rotation about the image centre
  double scale_sigma = 0.005;      // affine: relative scale
  double shear_sigma = 0.002;      // affine: shear

  /// Orientations only (stratified), no camera or image perturbation.
  [[nodiscard]] static AugmentationSpec orientations_only(int orientations);
};

struct ViewSetup {
  Camera camera;                 // perturbed intrinsics (pinhole + affine image transform) and pose (world frame)
  Eigen::Isometry3d model;       // the table's turn applied to the scene
  double table_angle = 0.0;      // radians, orientation + view * 2 pi / views
  /// The camera in the drape's own frame (the PLY's coordinates): world_to_camera * model.
  [[nodiscard]] Eigen::Isometry3d mesh_to_camera() const { return camera.world_to_camera * model; }
};

struct DataPointSetup {
  int index = 0;                 // 0 .. orientations - 1
  double orientation = 0.0;      // radians
  std::uint64_t seed = 0;        // this data point's seed (noise seeds of its views derive from it)
  std::vector<ViewSetup> views;
  [[nodiscard]] std::uint64_t noise_seed(int view) const;
};

/// The data points of one drape, all drawn from `seed`: the same seed gives the same setups.
[[nodiscard]] std::vector<DataPointSetup> plan_data_points(const RigSpec& rig, const AugmentationSpec& augmentation,
                                                           std::uint64_t seed);

/// The scene of a drape on the tester: the cloth plus the cylinder.
[[nodiscard]] TriangleMesh tester_scene(const TriangleMesh& cloth, const RigSpec& rig);

}  // namespace drapegen::renderer
