#pragma once
// Seeded random numbers that are the same on every platform and standard library (std::normal_distribution is
// not): xoshiro256** seeded through splitmix64, and Gaussians from a normalised inverse-CDF table.

#include <cstddef>
#include <cstdint>

#include "drapegen/sim/xoshiro.hpp"

namespace drapegen::renderer {

/// splitmix64: a good 64-bit mix, used to derive independent seeds (e.g. one per view) from a parent seed.
[[nodiscard]] std::uint64_t mix_seed(std::uint64_t seed, std::uint64_t stream);

/// Defined here so that the noise model's per-pixel loops inline them.
class Rng {
 public:
  explicit Rng(std::uint64_t seed);
  std::uint64_t next() { return generator_.next(); }
  /// Uniform in [0, 1) with 53 random bits.
  double uniform() { return generator_.uniform(); }
  /// uniform() < p, decided on the same 53 bits without converting them: `threshold` is below_threshold(p).
  bool uniform_below(std::uint64_t threshold) { return (next() >> 11) < threshold; }
  /// The integer threshold of uniform_below for a probability p: ceil(p 2^53), clamped to [0, 2^53].
  [[nodiscard]] static std::uint64_t below_threshold(double p);
  /// Standard normal from 16 random bits: the inverse normal CDF at the midpoints of 65536 equal-probability cells,
  /// rescaled to unit variance (range about +-4.3). Four per call of next().
  float gaussian() { return gaussian_table_[next_index()]; }
  /// The table indices of the next n Gaussians (gaussian() would return gaussian_of(out[0]), ... in turn), drawn in
  /// one go.
  void gaussian_indices(std::uint16_t* out, std::size_t n) {
    std::size_t k = 0;
    for (; k < n && pooled_ > 0; ++k) out[k] = next_index();
    for (; k + 4 <= n; k += 4) {
      const std::uint64_t r = next();
      for (int j = 0; j < 4; ++j) out[k + j] = static_cast<std::uint16_t>(r >> (16 * j));
    }
    for (; k < n; ++k) out[k] = next_index();
  }
  /// The Gaussian of a table index; it increases with the index.
  [[nodiscard]] float gaussian_of(std::uint16_t index) const { return gaussian_table_[index]; }

 private:
  std::uint16_t next_index() {
    if (pooled_ == 0) {
      pool_ = next();
      pooled_ = 4;
    }
    const auto index = static_cast<std::uint16_t>(pool_);
    pool_ >>= 16;
    --pooled_;
    return index;
  }

  sim::Xoshiro256 generator_;
  const float* gaussian_table_;  // 65536 entries, built once per process
  std::uint64_t pool_ = 0;
  int pooled_ = 0;
};

}  // namespace drapegen::renderer
