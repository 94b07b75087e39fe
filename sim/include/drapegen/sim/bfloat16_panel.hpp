#pragma once
// Dense panels stored in bfloat16 (the upper half of an IEEE single: its 8 exponent bits and 8 significant bits), and
// the two products the preconditioner's triangular solves need from them. The solves stream the whole factor twice
// per conjugate-gradient iteration and are bound by memory traffic, so halving the bytes of the panels below the
// supernodes' diagonal blocks halves that traffic; a stale factorisation is already a rougher approximation of the
// current Hessian than a relative rounding of 2^-8 (docs/BENCHMARKS.md, session 7).

#include <bit>
#include <cstdint>

namespace drapegen::sim {

/// Rounds to the nearest bfloat16 (ties to even). Finite inputs only. Inline: the copy of a factor into bfloat16
/// converts millions of values in a loop the compiler vectorises.
[[nodiscard]] inline std::uint16_t to_bfloat16(float x) {
  std::uint32_t bits = std::bit_cast<std::uint32_t>(x);
  bits += 0x7FFFu + ((bits >> 16) & 1u);
  return static_cast<std::uint16_t>(bits >> 16);
}
[[nodiscard]] inline float from_bfloat16(std::uint16_t b) {
  return std::bit_cast<float>(static_cast<std::uint32_t>(b) << 16);
}

/// y += A x, A a rows x cols column-major panel of bfloat16 values (x: cols, y: rows).
void bfloat16_multiply_add(const std::uint16_t* a, int rows, int cols, const float* x, float* y);
/// y -= A^T x, A as above (x: rows, y: cols).
void bfloat16_transpose_multiply_subtract(const std::uint16_t* a, int rows, int cols, const float* x, float* y);

}  // namespace drapegen::sim
