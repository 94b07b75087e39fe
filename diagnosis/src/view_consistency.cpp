#include "drapegen/diagnosis/view_consistency.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "drapegen/renderer/sensor_error.hpp"

namespace drapegen::diagnosis {
namespace {

/// A view prepared for the comparison: world points of the usable pixels, normals facing the camera, concavity.
struct PreparedView {
  const renderer::DepthImage* depth = nullptr;
  const renderer::Camera* camera = nullptr;
  std::vector<Eigen::Vector3d> point;   // NaN where the pixel is not usable
  std::vector<Eigen::Vector3d> normal;  // zero where not estimated
  std::vector<float> concavity;
};

/// A return whose 3x3 neighbourhood is whole and bends by less than `kink` along the rows, columns and diagonals.
bool usable(const renderer::DepthImage& d, int u, int v, double kink) {
  if (u < 1 || v < 1 || u + 1 >= d.width || v + 1 >= d.height) return false;
  for (int dv = -1; dv <= 1; ++dv)
    for (int du = -1; du <= 1; ++du)
      if (d.at(u + du, v + dv) <= 0.0f) return false;
  const double z = d.at(u, v);
  constexpr std::array<std::pair<int, int>, 4> kDirections{{{1, 0}, {0, 1}, {1, 1}, {1, -1}}};
  for (const auto& [du, dv] : kDirections)
    if (std::abs(double(d.at(u + du, v + dv)) + d.at(u - du, v - dv) - 2.0 * z) > kink) return false;
  return true;
}

/// The depth averaged over (2k+1)^2 pixels where all are returns (elsewhere as it was).
renderer::DepthImage box_filtered(const renderer::DepthImage& d, int k) {
  renderer::DepthImage out = d;
  const double count = (2.0 * k + 1.0) * (2.0 * k + 1.0);
  for (int v = k; v + k < d.height; ++v) {
    for (int u = k; u + k < d.width; ++u) {
      double sum = 0.0;
      bool whole = true;
      for (int dv = -k; dv <= k && whole; ++dv) {
        for (int du = -k; du <= k; ++du) {
          const float z = d.at(u + du, v + dv);
          whole = whole && z > 0.0f;
          sum += z;
        }
      }
      if (whole) out.at(u, v) = static_cast<float>(sum / count);
    }
  }
  return out;
}

PreparedView prepare(const renderer::DepthImage& d, const renderer::Camera& camera,
                     const ViewConsistencySettings& s) {
  PreparedView p;
  p.depth = &d;
  p.camera = &camera;
  const std::size_t n = d.depth.size();
  const Eigen::Isometry3d to_world = camera.world_to_camera.inverse();
  p.point.assign(n, Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  p.normal.assign(n, Eigen::Vector3d::Zero());
  auto at = [&](int u, int v) -> Eigen::Vector3d& { return p.point[static_cast<std::size_t>(v) * d.width + u]; };
  for (int v = 0; v < d.height; ++v)
    for (int u = 0; u < d.width; ++u)
      if (usable(d, u, v, s.kink)) at(u, v) = to_world * (double(d.at(u, v)) * camera.ray(u, v));
  const int k = s.normal_px;
  const Eigen::Vector3d eye = camera.position();
  for (int v = k; v + k < d.height; ++v) {
    for (int u = k; u + k < d.width; ++u) {
      if (!at(u, v).allFinite()) continue;
      Eigen::Vector3d normal = (at(u + k, v) - at(u - k, v)).cross(at(u, v + k) - at(u, v - k));
      if (!normal.allFinite() || normal.norm() == 0.0) continue;
      normal.normalize();
      if (normal.dot(eye - at(u, v)) < 0.0) normal = -normal;
      p.normal[static_cast<std::size_t>(v) * d.width + u] = normal;
    }
  }
  p.concavity = renderer::SensorError::concavity(box_filtered(d, s.smooth_px), camera.intrinsics,
                                                 s.concavity_radius_px);
  return p;
}

/// Sums for the least-squares line y = c + g x.
struct LineFit {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
  void add(double x, double y) { n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y, syy += y * y; }
  [[nodiscard]] ViewConsistency solve() const {
    ViewConsistency c;
    c.pixels = static_cast<long>(n);
    if (n < 3) return c;
    const double mx = sx / n, my = sy / n;
    const double vxx = sxx / n - mx * mx, vxy = sxy / n - mx * my, vyy = syy / n - my * my;
    c.rms = std::sqrt(std::max(0.0, syy / n));
    if (vxx <= 0.0) return c;
    c.gain = vxy / vxx;
    c.offset = my - c.gain * mx;
    c.standard_error = std::sqrt(std::max(0.0, vyy - c.gain * vxy) / (n - 2) / vxx);
    return c;
  }
};

/// Carries every usable pixel of `a` into `b`; adds (bracket, residual) of each pair seen alike by both.
void compare(const PreparedView& a, const PreparedView& b, const ViewConsistencySettings& s, LineFit& fit) {
  const renderer::DepthImage &da = *a.depth, &db = *b.depth;
  const Eigen::Matrix3d a_to_world = a.camera->world_to_camera.linear().transpose();
  const Eigen::Matrix3d b_to_world = b.camera->world_to_camera.linear().transpose();
  for (int v = 0; v < da.height; ++v) {
    for (int u = 0; u < da.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * da.width + u;
      const Eigen::Vector3d &x = a.point[i], &n = a.normal[i];
      if (!x.allFinite() || n.isZero()) continue;
      const auto q = b.camera->project(x);
      if (!q) continue;
      const int u0 = static_cast<int>(std::floor(q->x())), v0 = static_cast<int>(std::floor(q->y()));
      if (u0 < 1 || v0 < 1 || u0 + 2 >= db.width || v0 + 2 >= db.height) continue;
      const int qu = static_cast<int>(std::lround(q->x())), qv = static_cast<int>(std::lround(q->y()));
      const std::size_t j = static_cast<std::size_t>(qv) * db.width + qu;
      if (!b.point[j].allFinite()) continue;  // usable there: the four pixels around the projection are returns
      const double fu = q->x() - u0, fv = q->y() - v0;
      const double zb = (1 - fu) * (1 - fv) * db.at(u0, v0) + fu * (1 - fv) * db.at(u0 + 1, v0) +
                        (1 - fu) * fv * db.at(u0, v0 + 1) + fu * fv * db.at(u0 + 1, v0 + 1);
      const double r = zb - q->z();
      if (std::abs(r) > s.gate) continue;
      const Eigen::Vector3d ra = a_to_world * a.camera->ray(u, v), rb = b_to_world * b.camera->ray(q->x(), q->y());
      const double an = ra.dot(n), bn = rb.dot(n);
      if (-an < s.min_cos * ra.norm() || -bn < s.min_cos * rb.norm()) continue;
      fit.add(b.concavity[j] - a.concavity[i] * an / bn, r);
    }
  }
}

}  // namespace

double MultipathTest::smallest_gain() const {
  double smallest = placements.empty() ? 0.0 : placements.front().gain;
  for (const ViewConsistency& p : placements) smallest = std::min(smallest, p.gain);
  return smallest;
}

ViewConsistency view_consistency(const std::vector<renderer::DepthImage>& depth,
                                 const std::vector<renderer::Camera>& cameras,
                                 const ViewConsistencySettings& settings) {
  std::vector<PreparedView> views;
  for (std::size_t v = 0; v < depth.size() && v < cameras.size(); ++v)
    views.push_back(prepare(depth[v], cameras[v], settings));
  LineFit fit;
  for (std::size_t a = 0; a < views.size(); ++a)
    for (std::size_t b = 0; b < views.size(); ++b)
      if (a != b) compare(views[a], views[b], settings, fit);
  return fit.solve();
}

ViewConsistency view_consistency(const Capture& capture, const ViewConsistencySettings& settings) {
  std::vector<renderer::DepthImage> depth;
  std::vector<renderer::Camera> cameras;
  for (const CaptureView& v : capture.views) depth.push_back(v.depth), cameras.push_back(v.camera);
  return view_consistency(depth, cameras, settings);
}

}  // namespace drapegen::diagnosis
