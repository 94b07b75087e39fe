#include "drapegen/diagnosis/depth_metric.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drapegen::diagnosis {
namespace {

constexpr float kJump = 0.01f;  // m: neighbours farther apart in depth belong to another surface

/// Box-filtered depth over the valid neighbours on the same surface.
std::vector<float> smooth(const renderer::DepthImage& d, int radius) {
  std::vector<float> out(d.depth.size(), 0.0f);
  for (int v = 0; v < d.height; ++v) {
    for (int u = 0; u < d.width; ++u) {
      const float zc = d.at(u, v);
      if (zc <= 0.0f) continue;
      double sum = 0.0;
      int n = 0;
      for (int dv = -radius; dv <= radius; ++dv) {
        const int y = v + dv;
        if (y < 0 || y >= d.height) continue;
        for (int du = -radius; du <= radius; ++du) {
          const int x = u + du;
          if (x < 0 || x >= d.width) continue;
          const float z = d.at(x, y);
          if (z <= 0.0f || std::abs(z - zc) > kJump) continue;
          sum += z;
          ++n;
        }
      }
      out[static_cast<std::size_t>(v) * d.width + u] = static_cast<float>(sum / n);
    }
  }
  return out;
}

}  // namespace

ViewFeatures view_features(const renderer::DepthImage& depth, const renderer::Intrinsics& intrinsics,
                           const MetricWeights& weights) {
  ViewFeatures f;
  f.depth = depth;
  f.depth.incidence.clear();
  f.intrinsics = intrinsics;
  const int W = depth.width, H = depth.height;
  const std::size_t N = static_cast<std::size_t>(W) * H;
  const std::vector<float> z = smooth(depth, weights.smoothing_radius);
  renderer::Camera cam;
  cam.intrinsics = intrinsics;
  std::vector<Eigen::Vector3f> p(N, Eigen::Vector3f::Zero());
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * W + u;
      if (z[i] > 0.0f) p[i] = (static_cast<double>(z[i]) * cam.ray(u, v)).cast<float>();
    }
  f.normals.assign(N, Eigen::Vector3f::Zero());
  constexpr int s = 2;
  auto idx = [W](int u, int v) { return static_cast<std::size_t>(v) * W + u; };
  for (int v = s; v < H - s; ++v) {
    for (int u = s; u < W - s; ++u) {
      const std::size_t c = idx(u, v), l = idx(u - s, v), r = idx(u + s, v), t = idx(u, v - s), b = idx(u, v + s);
      if (z[c] <= 0.0f || z[l] <= 0.0f || z[r] <= 0.0f || z[t] <= 0.0f || z[b] <= 0.0f) continue;
      if (std::abs(z[l] - z[c]) > 2 * kJump || std::abs(z[r] - z[c]) > 2 * kJump || std::abs(z[t] - z[c]) > 2 * kJump ||
          std::abs(z[b] - z[c]) > 2 * kJump) {
        continue;
      }
      Eigen::Vector3f n = (p[r] - p[l]).cross(p[b] - p[t]);
      const float len = n.norm();
      if (len <= 0.0f) continue;
      n /= len;
      if (n.dot(p[c]) > 0.0f) n = -n;
      f.normals[c] = n;
    }
  }
  f.fold_mask.assign(N, 0);
  const float cos_limit = static_cast<float>(std::cos(weights.fold_mask_deg * M_PI / 180.0));
  for (int v = s; v < H - s; ++v) {
    for (int u = s; u < W - s; ++u) {
      const auto& nl = f.normals[idx(u - s, v)];
      const auto& nr = f.normals[idx(u + s, v)];
      const auto& nt = f.normals[idx(u, v - s)];
      const auto& nb = f.normals[idx(u, v + s)];
      if (f.normals[idx(u, v)].isZero() || nl.isZero() || nr.isZero() || nt.isZero() || nb.isZero()) continue;
      if (nl.dot(nr) < cos_limit || nt.dot(nb) < cos_limit) f.fold_mask[idx(u, v)] = 1;
    }
  }
  return f;
}

ViewFeatures view_features(const renderer::DepthImage& depth, const renderer::Camera& camera,
                           const MetricWeights& weights) {
  ViewFeatures f = view_features(depth, camera.intrinsics, weights);
  f.world_to_camera = camera.world_to_camera;
  f.weighted = true;
  return f;
}

bool stable_pixel(const ViewFeatures& f, int u, int v, float z, const MetricWeights& weights) {
  if (!f.weighted || z <= 0.0f) return false;
  renderer::Camera cam;
  cam.intrinsics = f.intrinsics;
  const Eigen::Vector3d p = f.world_to_camera.inverse() * (static_cast<double>(z) * cam.ray(u, v));
  const double r = std::hypot(p.x(), p.y());
  return (r < weights.cylinder_radius - 0.005 && p.z() > -0.006) ||
         (r < weights.cylinder_radius + 0.004 && p.z() < -0.03);
}

double pixel_weight(const ViewFeatures& f, int u, int v, float z, const MetricWeights& weights) {
  if (!f.weighted || z <= 0.0f) return 1.0;
  return stable_pixel(f, u, v, z, weights) ? 1.0 : weights.variable_weight;
}

ViewComparison compare_view(const ViewFeatures& captured, const renderer::DepthImage& model,
                            const MetricWeights& weights) {
  ViewComparison c;
  const auto& cd = captured.depth;
  const std::size_t N = cd.depth.size();
  c.residual.assign(N, std::numeric_limits<float>::quiet_NaN());
  c.depth.assign(N, 0.0f);
  if (model.width != cd.width || model.height != cd.height) {
    c.score = std::numeric_limits<double>::infinity();
    return c;
  }
  const ViewFeatures m = view_features(model, captured.intrinsics, weights);
  const float T = static_cast<float>(weights.truncation);
  double sum_sq = 0.0, fold_sq = 0.0, both_w = 0.0, either_w = 0.0, mismatch_w = 0.0, fold_w = 0.0, stable_sq = 0.0;
  int both = 0, stable_n = 0, captured_stable = 0;
  const int W = cd.width;
  for (std::size_t i = 0; i < N; ++i) {
    const float a = cd.depth[i], b = model.depth[i];
    const bool ha = a > 0.0f, hb = b > 0.0f;
    if (!ha && !hb) continue;
    const int u = static_cast<int>(i % W), v = static_cast<int>(i / W);
    const bool rigid = ha && stable_pixel(captured, u, v, a, weights);  // the capture sees a rigid surface here
    captured_stable += rigid;
    const double w = rigid ? 1.0 : pixel_weight(captured, u, v, ha ? a : b, weights);
    either_w += w;
    if (ha && hb) {
      const float d = std::clamp(a - b, -T, T);
      sum_sq += w * d * d;
      both_w += w;
      ++both;
      if (rigid && stable_pixel(captured, u, v, b, weights)) {
        stable_sq += static_cast<double>(d) * d;
        ++stable_n;
      }
      c.residual[i] = d;
      c.depth[i] = a;
      if (captured.fold_mask[i] && !captured.normals[i].isZero() && !m.normals[i].isZero()) {
        const double cosang = std::clamp(static_cast<double>(captured.normals[i].dot(m.normals[i])), -1.0, 1.0);
        const double ang = std::acos(cosang) * 180.0 / M_PI;
        fold_sq += w * ang * ang;
        fold_w += w;
      }
    } else {
      mismatch_w += w;
      c.residual[i] = ha ? T : -T;
      c.depth[i] = ha ? a : b;
    }
  }
  c.overlap = both;
  c.depth_rms = both_w > 0.0 ? std::sqrt(sum_sq / both_w) : weights.truncation;
  c.silhouette = either_w > 0.0 ? mismatch_w / either_w : 1.0;
  c.fold_rms_deg = fold_w > 0.0 ? std::sqrt(fold_sq / fold_w) : 0.0;
  c.stable_pixels = stable_n;
  c.captured_stable_pixels = captured_stable;
  // The capture sees rigid surfaces but no pixel of them is one the model sees as rigid too (a camera whose stated
  // pose misses the platform, a model that does not cover it): the disagreement is as large as a pixel's can be, not
  // none. A view whose capture sees none has no stable term (ForwardModel leaves it out of the mean).
  c.stable_rms = stable_n > 0 ? std::sqrt(stable_sq / stable_n) : captured_stable > 0 ? weights.truncation : 0.0;
  const double pixel = c.depth_rms + weights.silhouette * c.silhouette + weights.fold * c.fold_rms_deg;
  c.score = captured.weighted ? weights.stable * c.stable_rms + weights.pixel * pixel : pixel;
  return c;
}

}  // namespace drapegen::diagnosis
