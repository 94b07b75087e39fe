#pragma once
// The project's one pseudo-random generator: xoshiro256** (Blackman and Vigna) seeded through SplitMix64. Its output
// is the same on every platform and standard library (std::mt19937 is too, but the standard distributions are not),
// which seeded data sets and replayable jobs need. The renderer and the sampler draw their own distributions from it.

#include <array>
#include <cstdint>

namespace drapegen::sim {

/// SplitMix64's finaliser: a bijective 64-bit mix (for deriving independent seeds).
[[nodiscard]] constexpr std::uint64_t splitmix64_mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

class Xoshiro256 {
 public:
  /// The four state words are consecutive SplitMix64 outputs from `seed` (any seed, including 0).
  explicit Xoshiro256(std::uint64_t seed) {
    for (std::uint64_t& s : s_) {
      s = splitmix64_mix(seed);
      seed += 0x9e3779b97f4a7c15ULL;
    }
  }

  std::uint64_t next() {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

  /// Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::array<std::uint64_t, 4> s_{};
};

}  // namespace drapegen::sim
