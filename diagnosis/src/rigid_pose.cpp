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

/// A specimen-frame point's signed distance to a surface (the top's plane, `lift` above the cloth's contact offset;
/// the side's cylinder).
double distance_to(Surface surface, const Eigen::Vector3d& q, const RigidSurfaces& s, double lift = 0.0) {
  return surface == Surface::kTop ? q.z() - s.top_height - lift : std::hypot(q.x(), q.y()) - s.cylinder_radius;
}

/// The surface a specimen-frame point lies on within `band`, and its signed distance to it.
Residual classify(const Eigen::Vector3d& q, const RigidSurfaces& s, double band, double lift) {
  const double r = std::hypot(q.x(), q.y());
  for (Surface surface : {Surface::kTop, Surface::kSide}) {
    const bool there = surface == Surface::kTop ? r < s.cylinder_radius - s.top_inset : q.z() < -s.side_below;
    const double d = distance_to(surface, q, s, lift);
    if (there && std::abs(d) < band) return {surface, d};
  }
  return {};
}

/// The capture's pixels and the surfaces, and the least-squares fit of the pose to them.
class RigidFit {
 public:
  RigidFit(const Capture& capture, const RigidSurfaces& surfaces, const RigidPoseSettings& settings)
      : capture_(capture), surfaces_(surfaces), settings_(settings) {
    for (std::size_t v = 0; v < capture.views.size(); ++v) {
      const CaptureView& view = capture.views[v];
      const auto& d = view.depth;
      for (int y = 0; y < d.height; ++y) {
        for (int x = 0; x < d.width; ++x) {
          const float z = d.depth[static_cast<std::size_t>(y) * d.width + x];
          if (z > 0.0f) points_.push_back({static_cast<double>(z) * view.camera.ray(x, y), static_cast<int>(v)});
        }
      }
    }
  }

  /// The residuals of every pixel on a surface within `band` at x (the top `lift` higher), with the surface each was
  /// classified on.
  void residuals(const Pose& x, double band, std::vector<Residual>& out, double lift = 0.0) const {
    const auto to_specimen = camera_to_specimen(sensor_of(x));
    out.resize(points_.size());
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const RigidPoint& p = points_[i];
      out[i] = classify(to_specimen[static_cast<std::size_t>(p.view)] * p.camera_point, surfaces_, band, lift);
    }
  }

  /// A start from a grid of camera rotations about its x and y axes (an image shift: what a pose error mostly is,
  /// translations of a few millimetres aside), the one that puts the most pixels within the last band of the
  /// surfaces. The band the iterations start with is narrow, so the start must already be near (a wide band takes in
  /// the skirt, which hangs a few millimetres outside the bare side).
  [[nodiscard]] Pose grid_start() const {
    std::vector<Residual> on;
    Pose best = Pose::Zero();
    int most = -1;
    const int n = settings_.grid_steps;
    for (int i = -n; i <= n; ++i) {
      for (int j = -n; j <= n; ++j) {
        Pose g = Pose::Zero();
        g[0] = settings_.grid_spacing_mrad * i, g[1] = settings_.grid_spacing_mrad * j;
        residuals(g, settings_.last_band, on);
        const int inliers = static_cast<int>(
            std::count_if(on.begin(), on.end(), [](const Residual& r) { return r.surface != Surface::kNone; }));
        if (inliers > most) most = inliers, best = g;
      }
    }
    return best;
  }

  /// Levenberg-Marquardt from x over the pixels within a band that narrows from the first to the last over the first
  /// half of the iterations, each step on the classification it starts from.
  [[nodiscard]] Pose solve(Pose x) const {
    std::vector<Residual> on;
    std::vector<double> r0, r1, rp, rm;
    std::vector<Pose> J(points_.size());
    const int narrowing = std::max(1, settings_.iterations / 2);
    double lambda = 1e-3;
    for (int it = 0; it < settings_.iterations; ++it) {
      const double t = std::min(1.0, static_cast<double>(it) / narrowing);
      const double band = settings_.first_band * std::pow(settings_.last_band / settings_.first_band, t);
      residuals(x, band, on);
      residuals_on(x, on, r0);
      // Central differences with steps of 0.01 mrad and 0.01 mm (the residuals are smooth in the parameters).
      for (int k = 0; k < 6; ++k) {
        constexpr double h = 1e-2;
        Pose xp = x, xm = x;
        xp[k] += h, xm[k] -= h;
        residuals_on(xp, on, rp);
        residuals_on(xm, on, rm);
        for (std::size_t i = 0; i < points_.size(); ++i) J[i][k] = (rp[i] - rm[i]) / (2.0 * h);
      }
      Eigen::Matrix<double, 6, 6> JtJ = Eigen::Matrix<double, 6, 6>::Zero();
      Pose Jtr = Pose::Zero();
      for (std::size_t i = 0; i < points_.size(); ++i) {
        if (on[i].surface == Surface::kNone) continue;
        JtJ.noalias() += J[i] * J[i].transpose();
        Jtr.noalias() += J[i] * r0[i];
      }
      // Damping relative to the largest curvature, so the direction the surfaces do not see (a turn about the
      // platform axis) stays put.
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
    return x;
  }

  /// The pixels within `band` of the surfaces at x (the top `lift` higher): how many on each, the top's mean signed
  /// distance, the RMS.
  struct Fit {
    int top_pixels = 0;
    int side_pixels = 0;
    double top_mean = 0.0;  // m
    double rms = 0.0;       // m
  };
  [[nodiscard]] Fit fit_at(const Pose& x, double band, double lift = 0.0) const {
    std::vector<Residual> on;
    residuals(x, band, on, lift);
    Fit f;
    double top_sum = 0.0, squares = 0.0;
    for (const Residual& r : on) {
      if (r.surface == Surface::kNone) continue;
      (r.surface == Surface::kTop ? f.top_pixels : f.side_pixels) += 1;
      if (r.surface == Surface::kTop) top_sum += r.value;
      squares += r.value * r.value;
    }
    const int n = f.top_pixels + f.side_pixels;
    f.top_mean = f.top_pixels > 0 ? top_sum / f.top_pixels : 0.0;
    f.rms = n > 0 ? std::sqrt(squares / n) : 0.0;
    return f;
  }

 private:
  /// Each view's camera-to-specimen transform if the camera really sat where `error` says.
  [[nodiscard]] std::vector<Eigen::Isometry3d> camera_to_specimen(const renderer::SensorError& error) const {
    std::vector<Eigen::Isometry3d> t;
    for (const auto& view : capture_.views) t.push_back(error.true_camera(view.camera).world_to_camera.inverse());
    return t;
  }
  /// The same pixels' residuals at another x (the classification held: for the Jacobian and the step's test).
  void residuals_on(const Pose& x, const std::vector<Residual>& on, std::vector<double>& out) const {
    const auto to_specimen = camera_to_specimen(sensor_of(x));
    out.assign(points_.size(), 0.0);
    for (std::size_t i = 0; i < points_.size(); ++i) {
      if (on[i].surface == Surface::kNone) continue;
      const Eigen::Vector3d q = to_specimen[static_cast<std::size_t>(points_[i].view)] * points_[i].camera_point;
      out[i] = distance_to(on[i].surface, q, surfaces_);
    }
  }
  static double sum_sq(const std::vector<double>& r) {
    double s = 0.0;
    for (double v : r) s += v * v;
    return s;
  }

  const Capture& capture_;
  RigidSurfaces surfaces_;
  RigidPoseSettings settings_;
  std::vector<RigidPoint> points_;
};

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
  const RigidFit fit(capture, surfaces, settings);
  Pose x = fit.solve(fit.grid_start());
  const RigidFit::Fit recorded = fit.fit_at(Pose::Zero(), settings.last_band);
  RigidFit::Fit estimated = fit.fit_at(x, settings.last_band);
  RigidPose result;
  if (estimated.top_pixels < settings.min_top_pixels || estimated.side_pixels < settings.min_side_pixels) {
    return sim::Error{fmt::format("rigid surfaces: {} pixels on the platform top and {} on its bare side within {:.0f} "
                                  "mm (needs {} and {})",
                                  estimated.top_pixels, estimated.side_pixels, settings.last_band * 1e3,
                                  settings.min_top_pixels, settings.min_side_pixels)};
  }
  // A camera that moved the top along the platform axis and the side not at all reads exactly as a specimen lying
  // off the top. A cloth lies on the top or above it, never below: a top seen above its contact offset (over the
  // first band) whose camera the side does not confirm is the cloth's lift, read at the recorded camera (its pixels
  // counted against the lifted top).
  const double top_offset = fit.fit_at(Pose::Zero(), settings.first_band).top_mean;
  const bool side_confirms =
      estimated.side_pixels > (1.0 + settings.side_confirms) * static_cast<double>(recorded.side_pixels);
  if (!side_confirms && top_offset >= settings.min_lift) {
    x = Pose::Zero();
    estimated = fit.fit_at(x, settings.last_band, top_offset);
    result.top_lift = top_offset;
  }
  result.top_pixels = estimated.top_pixels;
  result.side_pixels = estimated.side_pixels;
  result.pose = sensor_of(x);
  result.rms_estimated = estimated.rms;
  result.rms_recorded = recorded.rms;
  sim::logger()->debug("rigid surfaces: rotation ({:.2f}, {:.2f}, {:.2f}) mrad, translation ({:.2f}, {:.2f}, {:.2f}) "
                       "mm, top lifted {:.2f} mm, RMS {:.2f} -> {:.2f} mm on {} top and {} side pixels",
                       x[0], x[1], x[2], x[3], x[4], x[5], result.top_lift * 1e3, result.rms_recorded * 1e3,
                       result.rms_estimated * 1e3, result.top_pixels, result.side_pixels);
  return result;
}

}  // namespace drapegen::diagnosis
