#include "drapegen/diagnosis/rigid_pose.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <fmt/format.h>

#include "drapegen/sim/logging.hpp"

namespace drapegen::diagnosis {
namespace {

/// The pose parameters in units of comparable effect on the pixels (a milliradian moves a point 0.7 mm at the
/// camera's 0.7 m; a millimetre moves it a millimetre): rotation (mrad), translation (mm).
using Pose = Eigen::Matrix<double, 6, 1>;

renderer::SensorError sensor_of(const Pose& x) {
  renderer::SensorError s;
  s.rotation = x.head<3>() * 1e-3;
  s.translation = x.tail<3>() * 1e-3;
  return s;
}

/// A pixel's point in its camera's frame, and its view.
struct RigidPoint {
  Eigen::Vector3d camera_point;
  int view = 0;
};

enum class Surface { kNone, kTop, kSide };

struct Residual {
  Surface surface = Surface::kNone;
  double value = 0.0;  // m
};

/// A specimen-frame point's signed distance to a surface (the top's plane, the side's cylinder).
double distance_to(Surface surface, const Eigen::Vector3d& q, const RigidSurfaces& s) {
  return surface == Surface::kTop ? q.z() - s.top_height : std::hypot(q.x(), q.y()) - s.cylinder_radius;
}

/// The surface a specimen-frame point lies on within `band`, and its signed distance to it.
Residual classify(const Eigen::Vector3d& q, const RigidSurfaces& s, double band) {
  const double r = std::hypot(q.x(), q.y());
  for (Surface surface : {Surface::kTop, Surface::kSide}) {
    const bool there = surface == Surface::kTop ? r < s.cylinder_radius - s.top_inset : q.z() < -s.side_below;
    const double d = distance_to(surface, q, s);
    if (there && std::abs(d) < band) return {surface, d};
  }
  return {};
}

}  // namespace

RigidSurfaces RigidSurfaces::for_specimen(const SpecimenFacts& specimen) {
  RigidSurfaces s;
  s.cylinder_radius = 0.5 * specimen.cylinder_diameter;
  s.side_below = 0.5 * std::hypot(specimen.size_x, specimen.size_y) - s.cylinder_radius + 0.01;
  return s;
}

double platform_displacement(const renderer::SensorError& pose, const Capture& capture) {
  double largest = 0.0;
  for (const auto& view : capture.views) {
    const Eigen::Vector3d recorded = view.camera.world_to_camera.translation();  // the centre, in the camera's frame
    largest = std::max(largest, (pose.true_camera(view.camera).world_to_camera.translation() - recorded).norm());
  }
  return largest;
}

sim::Expected<RigidPose> estimate_rigid_pose(const Capture& capture, const RigidSurfaces& surfaces,
                                             const RigidPoseSettings& settings) {
  std::vector<RigidPoint> points;
  for (std::size_t v = 0; v < capture.views.size(); ++v) {
    const CaptureView& view = capture.views[v];
    const auto& d = view.depth;
    for (int y = 0; y < d.height; ++y) {
      for (int x = 0; x < d.width; ++x) {
        const float z = d.depth[static_cast<std::size_t>(y) * d.width + x];
        if (z > 0.0f) points.push_back({static_cast<double>(z) * view.camera.ray(x, y), static_cast<int>(v)});
      }
    }
  }
  // Each view's camera-to-specimen transform if the camera really sat where pose x says.
  const auto camera_to_specimen = [&](const Pose& x) {
    const renderer::SensorError error = sensor_of(x);
    std::vector<Eigen::Isometry3d> t;
    for (const auto& view : capture.views) t.push_back(error.true_camera(view.camera).world_to_camera.inverse());
    return t;
  };
  // The residuals of every pixel on a surface within `band` at pose x, with the surface each was classified on.
  const auto residuals = [&](const Pose& x, double band, std::vector<Residual>& out) {
    const auto to_specimen = camera_to_specimen(x);
    out.resize(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      const RigidPoint& p = points[i];
      out[i] = classify(to_specimen[static_cast<std::size_t>(p.view)] * p.camera_point, surfaces, band);
    }
  };
  // The same pixels' residuals at another pose (the classification held: for the Jacobian and the step's test).
  const auto residuals_on = [&](const Pose& x, const std::vector<Residual>& on, std::vector<double>& out) {
    const auto to_specimen = camera_to_specimen(x);
    out.assign(points.size(), 0.0);
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (on[i].surface == Surface::kNone) continue;
      const Eigen::Vector3d q = to_specimen[static_cast<std::size_t>(points[i].view)] * points[i].camera_point;
      out[i] = distance_to(on[i].surface, q, surfaces);
    }
  };
  const auto sum_sq = [](const std::vector<double>& r) {
    double s = 0.0;
    for (double v : r) s += v * v;
    return s;
  };
  const auto count = [](const std::vector<Residual>& r, Surface surface) {
    int n = 0;
    for (const auto& v : r) n += v.surface == surface;
    return n;
  };
  const auto rms = [&](const std::vector<Residual>& r) {
    double s = 0.0;
    int n = 0;
    for (const auto& v : r)
      if (v.surface != Surface::kNone) s += v.value * v.value, ++n;
    return n > 0 ? std::sqrt(s / n) : 0.0;
  };

  // A start from a grid of camera rotations about its x and y axes (an image shift: what a pose error mostly is,
  // translations of a few millimetres aside), the one that puts the most pixels within the last band of the surfaces.
  // The band the iterations start with is narrow, so the start must already be near (a wide band takes in the skirt,
  // which hangs a few millimetres outside the bare side).
  std::vector<Residual> on;
  Pose x = Pose::Zero();
  {
    int most = -1;
    const int n = settings.grid_steps;
    for (int i = -n; i <= n; ++i) {
      for (int j = -n; j <= n; ++j) {
        Pose g = Pose::Zero();
        g[0] = settings.grid_spacing_mrad * i, g[1] = settings.grid_spacing_mrad * j;
        residuals(g, settings.last_band, on);
        const int inliers = count(on, Surface::kTop) + count(on, Surface::kSide);
        if (inliers > most) most = inliers, x = g;
      }
    }
  }
  std::vector<double> r0, r1;
  const int narrowing = std::max(1, settings.iterations / 2);
  double lambda = 1e-3;
  for (int it = 0; it < settings.iterations; ++it) {
    const double t = std::min(1.0, static_cast<double>(it) / narrowing);
    const double band = settings.first_band * std::pow(settings.last_band / settings.first_band, t);
    residuals(x, band, on);
    residuals_on(x, on, r0);
    // Central differences with steps of 0.01 mrad and 0.01 mm (the residuals are smooth in the pose).
    Eigen::Matrix<double, 6, 6> JtJ = Eigen::Matrix<double, 6, 6>::Zero();
    Pose Jtr = Pose::Zero();
    std::vector<Pose> J(points.size(), Pose::Zero());
    for (int k = 0; k < 6; ++k) {
      constexpr double h = 1e-2;
      Pose xp = x, xm = x;
      xp[k] += h, xm[k] -= h;
      std::vector<double> rp, rm;
      residuals_on(xp, on, rp);
      residuals_on(xm, on, rm);
      for (std::size_t i = 0; i < points.size(); ++i) J[i][k] = (rp[i] - rm[i]) / (2.0 * h);
    }
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (on[i].surface == Surface::kNone) continue;
      JtJ.noalias() += J[i] * J[i].transpose();
      Jtr.noalias() += J[i] * r0[i];
    }
    // Levenberg-Marquardt on the held classification: damping relative to the largest curvature, so the direction
    // the surfaces do not see (a turn about the platform axis) stays put.
    const double scale = JtJ.diagonal().maxCoeff();
    if (!(scale > 0.0)) break;
    const double before = sum_sq(r0);
    for (int attempt = 0; attempt < 8; ++attempt) {
      const Eigen::Matrix<double, 6, 6> A = JtJ + lambda * scale * Eigen::Matrix<double, 6, 6>::Identity();
      const Pose step = -A.ldlt().solve(Jtr);
      residuals_on(x + step, on, r1);
      if (sum_sq(r1) < before) {
        x += step;
        lambda = std::max(1e-9, lambda * 0.3);
        break;
      }
      lambda *= 10.0;
    }
  }
  RigidPose result;
  residuals(x, settings.last_band, on);
  result.top_pixels = count(on, Surface::kTop);
  result.side_pixels = count(on, Surface::kSide);
  if (result.top_pixels < settings.min_top_pixels || result.side_pixels < settings.min_side_pixels) {
    return sim::Error{fmt::format("rigid surfaces: {} pixels on the platform top and {} on its bare side within {:.0f} "
                                  "mm (needs {} and {})",
                                  result.top_pixels, result.side_pixels, settings.last_band * 1e3,
                                  settings.min_top_pixels, settings.min_side_pixels)};
  }
  result.pose = sensor_of(x);
  result.rms_estimated = rms(on);
  residuals(Pose::Zero(), settings.last_band, on);
  result.rms_recorded = rms(on);
  sim::logger()->debug("rigid surfaces: rotation ({:.2f}, {:.2f}, {:.2f}) mrad, translation ({:.2f}, {:.2f}, {:.2f}) "
                       "mm, RMS {:.2f} -> {:.2f} mm on {} top and {} side pixels",
                       x[0], x[1], x[2], x[3], x[4], x[5], result.rms_recorded * 1e3, result.rms_estimated * 1e3,
                       result.top_pixels, result.side_pixels);
  return result;
}

}  // namespace drapegen::diagnosis
