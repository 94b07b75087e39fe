#pragma once
// The pinhole camera of a depth sensor: intrinsics (pixels) and pose (metres), in the OpenCV / Azure Kinect SDK
// convention. See docs/RENDERER.md, "Camera model".

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

namespace drapegen::renderer {

/// Pixel (u, v) = (column, row); the centre of the top-left pixel is (0, 0) and rows grow downwards. A camera-space
/// point X = (x, y, z) (x right, y down, z forward along the optical axis, metres) projects to
///
///   [u * z, v * z, z]^T = K X.
///
/// K is a pinhole matrix [[fx, s, cx], [0, fy, cy], [0, 0, 1]] optionally followed by an affine image transform, so
/// any first two rows are allowed; the third row must be (0, 0, 1).
struct Intrinsics {
  int width = 0;
  int height = 0;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();

  /// A plain pinhole with square pixels and no skew.
  [[nodiscard]] static Intrinsics pinhole(int width, int height, double fx, double fy, double cx, double cy);
};

/// A camera: intrinsics plus the rigid transform from world to camera coordinates (X_cam = world_to_camera * X).
struct Camera {
  Intrinsics intrinsics;
  Eigen::Isometry3d world_to_camera = Eigen::Isometry3d::Identity();

  /// The camera at `eye` looking at `target`, with `up` (world) pointing up in the image (towards -v).
  [[nodiscard]] static Camera look_at(const Intrinsics& intrinsics, const Eigen::Vector3d& eye,
                                      const Eigen::Vector3d& target,
                                      const Eigen::Vector3d& up = Eigen::Vector3d::UnitZ());

  /// The camera centre in world coordinates.
  [[nodiscard]] Eigen::Vector3d position() const;
  /// Image coordinates (u, v) and camera depth z of a world point; nullopt behind the camera (z <= 0).
  [[nodiscard]] std::optional<Eigen::Vector3d> project(const Eigen::Vector3d& world) const;
  /// The camera-space direction through pixel coordinates (u, v), scaled so that its z component is 1: the point at
  /// camera depth z on that ray is z * ray(u, v).
  [[nodiscard]] Eigen::Vector3d ray(double u, double v) const;
};

/// The OpenGL projection matrix that maps camera-space points (OpenCV axes, as above) to clip space such that
/// framebuffer row r holds image row v = r and column c holds u = c, with depth range [near, far].
[[nodiscard]] Eigen::Matrix4d gl_projection(const Intrinsics& intrinsics, double near, double far);

}  // namespace drapegen::renderer
