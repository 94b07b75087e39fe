#pragma once
// Sensor and calibration errors the tester's calibration does not know about (issue 6, the reality generator and
// the gap diagnosis): a wrong camera pose, a depth bias, and time-of-flight multipath near concave regions. Each is a
// sensor model with named parameters (docs/RENDERER.md, "Sensor and calibration errors"), applied to the clean
// depth before the noise model.

#include <Eigen/Core>

#include "drapegen/renderer/camera.hpp"
#include "drapegen/renderer/depth_image.hpp"

namespace drapegen::renderer {

struct SensorError {
  /// 1. Extrinsic error: the camera really sits at delta * recorded (delta in the camera frame), with
  ///    delta = [R(rotation) | translation], R the rotation by the vector `rotation` (radians, axis * angle).
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // m
  /// 2. Depth bias: z' = z + bias_offset + bias_slope * (z - bias_reference) where there is a return.
  double bias_offset = 0.0;     // m
  double bias_slope = 0.0;      // m per m
  double bias_reference = 0.7;  // m
  /// 3. Multipath: z' = z + multipath_gain * S(p). S is the concavity seen from the camera: over the symmetric pixel
  ///    pairs (q, q') = (p + d, p - d), 0 < |d|_inf <= multipath_radius_px, with returns at p, q and q',
  ///      S(p) = (1 / N_pairs) sum clamp((z_p - (z_q + z_q') / 2) / rho_d, 0, 1),   rho_d = |d| z_p / f,
  ///    N_pairs counting every pair in the window (pairs without returns add 0). A plane gives S = 0; the bottom of a
  ///    valley (the gap between skirt and cylinder, a fold's trough) S > 0: light reaching it by a second bounce off
  ///    the nearby walls travels farther, so ToF depth reads long there.
  double multipath_gain = 0.0;  // m
  int multipath_radius_px = 4;

  [[nodiscard]] bool any() const;
  /// A depth bias or multipath: apply() changes the depths (a pose error moves only the camera).
  [[nodiscard]] bool changes_depth() const;
  /// The camera that really took the picture when `recorded` is what the calibration says.
  [[nodiscard]] Camera true_camera(const Camera& recorded) const;
  /// Bias and multipath applied to a clean depth image (keeps the incidence channel for the noise model).
  [[nodiscard]] DepthImage apply(const DepthImage& clean, const Intrinsics& intrinsics) const;
  /// The multipath concavity S(p) of every pixel (0 without a return).
  [[nodiscard]] static std::vector<float> concavity(const DepthImage& depth, const Intrinsics& intrinsics,
                                                    int radius_px);
};

}  // namespace drapegen::renderer
