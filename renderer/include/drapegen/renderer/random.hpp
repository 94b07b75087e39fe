#pragma once
// Seeded random numbers that are the same on every platform and standard library (std::normal_distribution is
// not): xoshiro256** seeded through splitmix64, and Gaussians from a normalised inverse-CDF table.

#include <cstdint>

#include "drapegen/sim/xoshiro.hpp"

namespace drapegen::renderer {

/// splitmix64: a good 64-bit mix, used to derive independent seeds (e.g. one per view) from a parent seed.
[[nodiscard]] std::uint64_t mix_seed(std::uint64_t seed, std::uint64_t stream);

class Rng {
 public:
  explicit Rng(std::uint64_t seed);
  std::uint64_t next();
  /// Uniform in [0, 1) with 53 random bits.
  double uniform();
  /// Standard normal from 16 random bits: the inverse normal CDF at the midpoints of 65536 equal-probability cells,
  /// rescaled to unit variance (range about +-4.3). Four per call of next().
  float gaussian();

 private:
  sim::Xoshiro256 generator_;
  std::uint64_t pool_ = 0;
  int pooled_ = 0;
};

}  // namespace drapegen::renderer
