#include "drapegen/renderer/noise.hpp"

#include <algorithm>
#include <utility>
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

namespace {

/// The grazing ratio r = theta / (pi/2 - theta) and r^2 tabulated over cos(theta) in [0, 1] (4097 samples, linear
/// interpolation: exact at the samples, within 1e-4 relative between them for theta below 80 degrees).
struct AngleTables {
  static constexpr int kSize = 4096;
  std::vector<float> ratio, ratio_sq;
  AngleTables() : ratio(kSize + 1), ratio_sq(kSize + 1) {
    for (int i = 0; i <= kSize; ++i) {
      const double r = grazing_ratio(std::acos(static_cast<double>(i) / kSize));
      ratio[i] = static_cast<float>(r);
      ratio_sq[i] = static_cast<float>(r * r);
    }
  }
  static float lookup(const std::vector<float>& t, float c) {
    const float x = std::clamp(c, 0.0f, 1.0f) * kSize;
    const int i = std::min(static_cast<int>(x), kSize - 1);
    const float f = x - static_cast<float>(i);
    return t[i] + f * (t[i + 1] - t[i]);
  }
  static const AngleTables& get() {
    static const AngleTables tables;
    return tables;
  }
};

/// floor(x + 0.5) as an int for |x| < 2^30: truncation, one down for negative non-integers (the same value as
/// std::floor without its generic code).
int round_to_int(float x) {
  const float y = x + 0.5f;
  const int t = static_cast<int>(y);
  return t - (static_cast<float>(t) > y);
}

/// std::nearbyint in the default rounding mode (to nearest, ties to even) without a library call: adding and
/// subtracting 2^52 leaves no fraction bits. Numbers of 2^52 and more are integers already.
double round_to_nearest(double x) {
  constexpr double kBig = 0x1p52;
  if (!(std::abs(x) < kBig)) return x;
  return x >= 0.0 ? (x + kBig) - kBig : (x - kBig) + kBig;
}

/// The first k in [0, 65536) where `reached` holds, which is false below some k and true from there on; 65536 if
/// none.
template <class Predicate>
int first_index(Predicate reached) {
  int lo = 0, hi = 65536;
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    if (reached(mid)) {
      hi = mid;
    } else {
      lo = mid + 1;
    }
  }
  return lo;
}

}  // namespace

DepthImage NoiseModel::apply(const DepthImage& clean, std::uint64_t seed) const {
  const int W = clean.width, H = clean.height;
  const std::size_t n = clean.depth.size();
  const bool have_incidence = clean.incidence.size() == n;
  auto cos_at = [&](std::size_t i) { return have_incidence ? clean.incidence[i] : 1.0f; };
  const AngleTables& tables = AngleTables::get();
  const float l0 = static_cast<float>(lateral_l0_px), l1 = static_cast<float>(lateral_l1_px);

  // The box of pixels with a return, grown by `reach` pixels: outside it nothing can change (a lateral offset beyond
  // `reach` has probability < 1e-9 for sigma_L < 0.8 px), so the noise neither visits nor draws numbers there.
  constexpr int reach = 5;
  const PixelBox returns = clean.foreground_box();
  DepthImage out(W, H);
  if (returns.empty()) return out;
  const int bx0 = std::max(0, returns.u0 - reach), by0 = std::max(0, returns.v0 - reach);
  const int bx1 = std::min(W - 1, returns.u1 + reach), by1 = std::min(H - 1, returns.v1 + reach);

  // Lateral jitter: each pixel copies the clean pixel at a rounded Gaussian offset. The jittered images are scratch
  // reused by every call on this thread (no allocation per view).
  // Only pixels of the box are read from c0, and (with their 4-neighbours) from z0, which is 0 outside the box.
  thread_local std::vector<float> z0, c0;
  thread_local std::vector<std::uint16_t> indices;
  z0.assign(clean.depth.begin(), clean.depth.end());
  if (lateral) {
    c0.resize(n);
  } else if (have_incidence) {
    c0.assign(clean.incidence.begin(), clean.incidence.end());
  } else {
    c0.assign(n, 1.0f);
  }
  if (lateral) {
    // Two unit Gaussians per pixel of the box, u then v, in row order, as table indices drawn in one go.
    const int box_width = bx1 - bx0 + 1;
    indices.resize(2 * static_cast<std::size_t>(box_width) * (by1 - by0 + 1));
    Rng rng(mix_seed(seed, 1));
    rng.gaussian_indices(indices.data(), indices.size());
    const auto offset = [&](float sigma, std::uint16_t index) { return round_to_int(sigma * rng.gaussian_of(index)); };
    // Most pixels do not move: a pixel moves only where a Gaussian rounds to a non-zero offset at its sigma. For a
    // sigma, the indices whose Gaussian rounds to no offset are one range (the Gaussian increases with the index),
    // and that range only shrinks as sigma grows. Found once for the sigma of pixels without a return (all the
    // same; such a pixel keeps no return if it does not move: z0 is 0 there and c0 is not read) and for the
    // largest sigma of pixels with a return that face the camera within 80 degrees (one that does not move keeps
    // its own depth, already in z0, and incidence).
    const auto still_range = [&](float sigma) {
      if (!(sigma >= 0.0f)) return std::pair{0, 0};
      return std::pair{first_index([&](int k) { return offset(sigma, static_cast<std::uint16_t>(k)) >= 0; }),
                       first_index([&](int k) { return offset(sigma, static_cast<std::uint16_t>(k)) >= 1; })};
    };
    const auto in = [](const std::pair<int, int>& range, std::uint16_t index) {
      return static_cast<unsigned>(index - range.first) < static_cast<unsigned>(range.second - range.first);
    };
    const float background_sigma = static_cast<float>(lateral_sigma_px(0.0));
    const auto background_still = still_range(background_sigma);
    const float facing_cos = static_cast<float>(std::cos(80.0 * M_PI / 180.0));
    // sigma = l0 + l1 r increases with r, which decreases as cos grows (and so does its interpolation).
    const auto facing_still =
        l1 >= 0.0f ? still_range(l0 + l1 * AngleTables::lookup(tables.ratio, facing_cos)) : std::pair{0, 0};
    const std::uint16_t* g = indices.data();
    for (int v = by0; v <= by1; ++v) {
      for (int u = bx0; u <= bx1; ++u, g += 2) {
        const std::size_t i = static_cast<std::size_t>(v) * W + u;
        float sigma = background_sigma;
        if (clean.depth[i] > 0.0f) {
          const float cos_theta = cos_at(i);
          if (cos_theta >= facing_cos && in(facing_still, g[0]) && in(facing_still, g[1])) {
            c0[i] = cos_theta;
            continue;
          }
          sigma = l0 + l1 * AngleTables::lookup(tables.ratio, cos_theta);
        } else if (in(background_still, g[0]) && in(background_still, g[1])) {
          continue;
        }
        const int su = std::clamp(u + offset(sigma, g[0]), 0, W - 1);
        const int sv = std::clamp(v + offset(sigma, g[1]), 0, H - 1);
        const std::size_t s = static_cast<std::size_t>(sv) * W + su;
        z0[i] = clean.depth[s];
        c0[i] = cos_at(s);
      }
    }
  }

  Rng rng(mix_seed(seed, 2));
  const float cos_grazing = static_cast<float>(std::cos(grazing_max_deg * M_PI / 180.0));
  const double a = axial_scale * axial_a, b = axial_scale * axial_b, c = axial_scale * axial_c;
  const double per_step = 1.0 / quantisation_step;
  const std::uint64_t hole_threshold = Rng::below_threshold(edge_hole_probability),
                      flying_threshold = Rng::below_threshold(flying_probability),
                      dropout_threshold = Rng::below_threshold(dropout_probability);
  for (int v = by0; v <= by1; ++v) {
    for (int u = bx0; u <= bx1; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * W + u;
      double z = z0[i];
      if (z <= 0.0) continue;
      const float cos_theta = c0[i];
      if (grazing && cos_theta < cos_grazing) continue;
      if (edges) {
        // The neighbour across the largest jump, if any jump exceeds the threshold.
        double jump = 0.0, other = 0.0;
        bool hole_side = false;
        const auto neighbour = [&](double zn) {
          if (zn <= 0.0) {
            hole_side = true;
          } else if (std::abs(zn - z) > std::max(jump, edge_jump)) {
            jump = std::abs(zn - z);
            other = zn;
          }
        };
        // Left, right, up, down (within the image).
        if (u > 0) neighbour(z0[i - 1]);
        if (u + 1 < W) neighbour(z0[i + 1]);
        if (v > 0) neighbour(z0[i - W]);
        if (v + 1 < H) neighbour(z0[i + W]);
        if (hole_side && rng.uniform_below(hole_threshold)) continue;
        if (jump > 0.0 && rng.uniform_below(flying_threshold)) z += rng.uniform() * (other - z);
      }
      if (axial) {
        const double sigma = a + b * (z - axial_z0) * (z - axial_z0) +
                             c / std::sqrt(z) * AngleTables::lookup(tables.ratio_sq, cos_theta);
        z += sigma * rng.gaussian();
      }
      if (quantisation) z = quantisation_step * round_to_nearest(z * per_step);
      if (dropout && rng.uniform_below(dropout_threshold)) continue;
      if (z > 0.0) out.depth[i] = static_cast<float>(z);
    }
  }
  return out;
}

std::string NoiseModel::describe() const {
  if (!any()) return "none";
  // Compact (it goes into every file's header); the formulas are in noise.hpp and docs/RENDERER.md.
  std::string s;
  auto add = [&](const std::string& term) { s += (s.empty() ? "" : " ") + term; };
  if (axial) add(fmt::format("axial:a={},b={},z0={},c={},scale={}", axial_a, axial_b, axial_z0, axial_c, axial_scale));
  if (lateral) add(fmt::format("lateral:l0={:.4g},l1={:.4g}", lateral_l0_px, lateral_l1_px));
  if (grazing) add(fmt::format("grazing:max_deg={}", grazing_max_deg));
  if (edges) add(fmt::format("edges:jump={},hole={},flying={}", edge_jump, edge_hole_probability, flying_probability));
  if (dropout) add(fmt::format("dropout:p={}", dropout_probability));
  if (quantisation) add(fmt::format("quantisation:step={}", quantisation_step));
  return s;
}

}  // namespace drapegen::renderer
