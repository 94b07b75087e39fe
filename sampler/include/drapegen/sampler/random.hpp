#pragma once
// Deterministic random numbers for the sampler: every draw is a pure function of (seed, stream ids), computed with
// integer arithmetic and std::log/std::sqrt/std::cos only, so a run is reproducible bit for bit on the same
// platform and a coordinator can regenerate any sample or recipe without replaying the ones before it.

#include <cstdint>
#include <initializer_list>

#include "drapegen/sim/xoshiro.hpp"

namespace drapegen::sampler {

/// SplitMix64's finaliser: a bijective 64-bit mix (the project's one, sim::splitmix64_mix).
[[nodiscard]] constexpr std::uint64_t mix64(std::uint64_t x) { return sim::splitmix64_mix(x); }

/// A seed for the stream named by `ids` under `seed` (order matters; seed 0 is an ordinary seed).
[[nodiscard]] std::uint64_t derive_seed(std::uint64_t seed, std::initializer_list<std::uint64_t> ids);

/// xoshiro256** seeded through SplitMix64, with its own uniform and normal draws (the standard library's
/// distributions are implementation-defined, so they are not used).
class Random {
 public:
  explicit Random(std::uint64_t seed);
  [[nodiscard]] std::uint64_t next_u64();
  /// Uniform in [0, 1) with 53 random bits.
  [[nodiscard]] double uniform();
  /// Uniform in [low, high).
  [[nodiscard]] double uniform(double low, double high) { return low + (high - low) * uniform(); }
  /// Uniform integer in [0, n) for n >= 1 (rejection sampling, no modulo bias).
  [[nodiscard]] std::uint64_t below(std::uint64_t n);
  /// Standard normal (Box-Muller; the second value of each pair is kept for the next call).
  [[nodiscard]] double normal();

 private:
  sim::Xoshiro256 generator_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace drapegen::sampler
