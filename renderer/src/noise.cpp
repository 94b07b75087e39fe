#include "drapegen/renderer/noise.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "drapegen/renderer/random.hpp"

namespace drapegen::renderer {
namespace {

/// theta / (pi/2 - theta) with theta capped just below pi/2.
double grazing_ratio(double theta) {
  const double t = std::min(theta, M_PI / 2 - 1e-3);
  return t / (M_PI / 2 - t);
}

}  // namespace

NoiseModel NoiseModel::kinect() { return NoiseModel{}; }

NoiseModel NoiseModel::none() {
  NoiseModel m;
  m.axial = m.lateral = m.grazing = m.edges = m.dropout = m.quantisation = false;
  return m;
}

double NoiseModel::axial_sigma(double z, double theta) const {
  const double r = grazing_ratio(theta);
  return axial_scale * (axial_a + axial_b * (z - axial_z0) * (z - axial_z0) + axial_c / std::sqrt(z) * r * r);
}

double NoiseModel::lateral_sigma_px(double theta) const { return lateral_l0_px + lateral_l1_px * grazing_ratio(theta); }

DepthImage NoiseModel::apply(const DepthImage& clean, std::uint64_t seed) const {
  const int W = clean.width, H = clean.height;
  const std::size_t n = clean.depth.size();
  const bool have_incidence = clean.incidence.size() == n;
  auto theta_at = [&](std::size_t i) {
    return have_incidence ? std::acos(std::clamp(static_cast<double>(clean.incidence[i]), 0.0, 1.0)) : 0.0;
  };

  // Lateral jitter: gather from a rounded Gaussian offset. `source` is the pixel each output pixel copies.
  std::vector<std::uint32_t> source(n);
  for (std::size_t i = 0; i < n; ++i) source[i] = static_cast<std::uint32_t>(i);
  if (lateral) {
    Rng rng(mix_seed(seed, 1));
    for (int v = 0; v < H; ++v) {
      for (int u = 0; u < W; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * W + u;
        const double sigma = lateral_sigma_px(clean.depth[i] > 0.0f ? theta_at(i) : 0.0);
        const int su = std::clamp(u + static_cast<int>(std::lround(sigma * rng.gaussian())), 0, W - 1);
        const int sv = std::clamp(v + static_cast<int>(std::lround(sigma * rng.gaussian())), 0, H - 1);
        source[i] = static_cast<std::uint32_t>(sv * W + su);
      }
    }
  }
  std::vector<float> z0(n);
  for (std::size_t i = 0; i < n; ++i) z0[i] = clean.depth[source[i]];

  DepthImage out(W, H);
  Rng rng(mix_seed(seed, 2));
  const double cos_grazing = std::cos(grazing_max_deg * M_PI / 180.0);
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * W + u;
      double z = z0[i];
      if (z <= 0.0) continue;
      const double cos_theta = have_incidence ? clean.incidence[source[i]] : 1.0;
      if (grazing && cos_theta < cos_grazing) continue;
      if (edges) {
        // The neighbour across the largest jump, if any jump exceeds the threshold.
        double jump = 0.0, other = 0.0;
        bool hole_side = false;
        const int du[4] = {-1, 1, 0, 0}, dv[4] = {0, 0, -1, 1};
        for (int k = 0; k < 4; ++k) {
          const int nu = u + du[k], nv = v + dv[k];
          if (nu < 0 || nu >= W || nv < 0 || nv >= H) continue;
          const double zn = z0[static_cast<std::size_t>(nv) * W + nu];
          if (zn <= 0.0) {
            hole_side = true;
          } else if (std::abs(zn - z) > std::max(jump, edge_jump)) {
            jump = std::abs(zn - z);
            other = zn;
          }
        }
        if (hole_side && rng.uniform() < edge_hole_probability) continue;
        if (jump > 0.0 && rng.uniform() < flying_probability) z += rng.uniform() * (other - z);
      }
      if (axial) z += axial_sigma(z, std::acos(std::clamp(cos_theta, 0.0, 1.0))) * rng.gaussian();
      if (quantisation) z = quantisation_step * std::round(z / quantisation_step);
      if (dropout && rng.uniform() < dropout_probability) continue;
      if (z > 0.0) out.depth[i] = static_cast<float>(z);
    }
  }
  return out;
}

std::string NoiseModel::describe() const {
  if (!any()) return "none";
  std::string s;
  auto add = [&](const std::string& term) { s += (s.empty() ? "" : "; ") + term; };
  if (axial) {
    add(fmt::format("axial sigma={}*({}+{}*(z-{})^2+{}/sqrt(z)*theta^2/(pi/2-theta)^2) m", axial_scale, axial_a,
                    axial_b, axial_z0, axial_c));
  }
  if (lateral) add(fmt::format("lateral sigma={:.4g}+{:.4g}*theta/(pi/2-theta) px", lateral_l0_px, lateral_l1_px));
  if (grazing) add(fmt::format("grazing theta>{} deg invalid", grazing_max_deg));
  if (edges) {
    add(fmt::format("edges jump>{} m hole p={} flying p={}", edge_jump, edge_hole_probability, flying_probability));
  }
  if (dropout) add(fmt::format("dropout p={}", dropout_probability));
  if (quantisation) add(fmt::format("quantisation step={} m", quantisation_step));
  return s;
}

}  // namespace drapegen::renderer
