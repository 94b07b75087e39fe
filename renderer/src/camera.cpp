#include "drapegen/renderer/camera.hpp"

namespace drapegen::renderer {

Intrinsics Intrinsics::pinhole(int width, int height, double fx, double fy, double cx, double cy) {
  Intrinsics i;
  i.width = width;
  i.height = height;
  i.K << fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0;
  return i;
}

Camera Camera::look_at(const Intrinsics& intrinsics, const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                       const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = (target - eye).normalized();      // forward
  const Eigen::Vector3d x = z.cross(up).normalized();         // right
  const Eigen::Vector3d y = z.cross(x);                       // down
  Eigen::Matrix3d R;  // rows: camera axes in world coordinates
  R.row(0) = x.transpose();
  R.row(1) = y.transpose();
  R.row(2) = z.transpose();
  Camera c;
  c.intrinsics = intrinsics;
  c.world_to_camera.linear() = R;
  c.world_to_camera.translation() = -R * eye;
  return c;
}

Eigen::Vector3d Camera::position() const { return world_to_camera.inverse().translation(); }

std::optional<Eigen::Vector3d> Camera::project(const Eigen::Vector3d& world) const {
  const Eigen::Vector3d X = world_to_camera * world;
  if (!(X.z() > 0.0)) return std::nullopt;
  const Eigen::Vector3d p = intrinsics.K * X;
  return Eigen::Vector3d(p.x() / X.z(), p.y() / X.z(), X.z());
}

Eigen::Vector3d Camera::ray(double u, double v) const { return intrinsics.K.inverse() * Eigen::Vector3d(u, v, 1.0); }

Eigen::Matrix4d gl_projection(const Intrinsics& in, double near, double far) {
  // NDC x = 2 (u + 0.5) / W - 1 puts pixel centre u = c at the centre of framebuffer column c; likewise for rows
  // (no flip: framebuffer row 0, read first by glReadPixels, is image row 0).
  const double W = in.width, H = in.height;
  const Eigen::Matrix3d& K = in.K;
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  for (int c = 0; c < 3; ++c) {
    P(0, c) = 2.0 / W * K(0, c);
    P(1, c) = 2.0 / H * K(1, c);
  }
  P(0, 2) += 1.0 / W - 1.0;
  P(1, 2) += 1.0 / H - 1.0;
  P(2, 2) = (far + near) / (far - near);
  P(2, 3) = -2.0 * far * near / (far - near);
  P(3, 2) = 1.0;
  return P;
}

}  // namespace drapegen::renderer
