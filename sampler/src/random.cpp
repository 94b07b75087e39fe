#include "drapegen/sampler/random.hpp"

#include <cmath>
#include <numbers>

namespace drapegen::sampler {

std::uint64_t derive_seed(std::uint64_t seed, std::initializer_list<std::uint64_t> ids) {
  std::uint64_t h = mix64(seed);
  for (std::uint64_t id : ids) h = mix64(h ^ mix64(id + 0x632be59bd9b4e019ULL));
  return h;
}

// The state words are SplitMix64 outputs starting one step later than sim::Xoshiro256's own seeding.
Random::Random(std::uint64_t seed) : generator_(seed + 0x9e3779b97f4a7c15ULL) {}

std::uint64_t Random::next_u64() { return generator_.next(); }

double Random::uniform() { return generator_.uniform(); }

std::uint64_t Random::below(std::uint64_t n) {
  if (n <= 1) return 0;
  const std::uint64_t limit = ~std::uint64_t{0} - (~std::uint64_t{0} % n);  // a multiple of n
  std::uint64_t v;
  do {
    v = next_u64();
  } while (v >= limit);
  return v % n;
}

double Random::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  const double u1 = 1.0 - uniform();  // (0, 1]
  const double u2 = uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  const double angle = 2.0 * std::numbers::pi * u2;
  spare_ = r * std::sin(angle);
  has_spare_ = true;
  return r * std::cos(angle);
}

}  // namespace drapegen::sampler
