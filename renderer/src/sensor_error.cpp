#include "drapegen/renderer/sensor_error.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace drapegen::renderer {

bool SensorError::any() const { return !rotation.isZero(0.0) || !translation.isZero(0.0) || changes_depth(); }

bool SensorError::changes_depth() const { return bias_offset != 0.0 || bias_slope != 0.0 || multipath_gain != 0.0; }

Camera SensorError::true_camera(const Camera& recorded) const {
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
  const double angle = rotation.norm();
  if (angle > 0.0) delta.linear() = Eigen::AngleAxisd(angle, rotation / angle).toRotationMatrix();
  delta.translation() = translation;
  Camera c = recorded;
  c.world_to_camera = delta * recorded.world_to_camera;
  return c;
}

std::vector<float> SensorError::concavity(const DepthImage& depth, const Intrinsics& intrinsics, int radius_px) {
  const int w = depth.width, h = depth.height;
  std::vector<float> s(depth.depth.size(), 0.0f);
  const double f = 0.5 * (std::abs(intrinsics.K(0, 0)) + std::abs(intrinsics.K(1, 1)));
  if (radius_px < 1 || f <= 0.0) return s;
  // Half of the window's offsets: one of each symmetric pair.
  std::vector<Eigen::Vector2i> half;
  for (int dy = 0; dy <= radius_px; ++dy) {
    for (int dx = -radius_px; dx <= radius_px; ++dx) {
      if (dy == 0 && dx <= 0) continue;
      half.emplace_back(dx, dy);
    }
  }
  const double pairs = static_cast<double>(half.size());
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const float zp = depth.at(u, v);
      if (zp <= 0.0f) continue;
      double sum = 0.0;
      for (const auto& d : half) {
        const int u1 = u + d.x(), v1 = v + d.y(), u2 = u - d.x(), v2 = v - d.y();
        if (u1 < 0 || u1 >= w || v1 < 0 || v1 >= h || u2 < 0 || u2 >= w || v2 < 0 || v2 >= h) continue;
        const float z1 = depth.at(u1, v1), z2 = depth.at(u2, v2);
        if (z1 <= 0.0f || z2 <= 0.0f) continue;
        const double rho = std::hypot(d.x(), d.y()) * zp / f;
        sum += std::clamp((zp - 0.5 * (z1 + z2)) / rho, 0.0, 1.0);
      }
      s[static_cast<std::size_t>(v) * w + u] = static_cast<float>(sum / pairs);
    }
  }
  return s;
}

DepthImage SensorError::apply(const DepthImage& clean, const Intrinsics& intrinsics) const {
  DepthImage out = clean;
  std::vector<float> s;
  if (multipath_gain != 0.0) s = concavity(clean, intrinsics, multipath_radius_px);
  for (std::size_t i = 0; i < out.depth.size(); ++i) {
    const float z = clean.depth[i];
    if (z <= 0.0f) continue;
    double dz = bias_offset + bias_slope * (z - bias_reference);
    if (!s.empty()) dz += multipath_gain * s[i];
    out.depth[i] = std::max(1e-4f, static_cast<float>(z + dz));
  }
  return out;
}

}  // namespace drapegen::renderer
