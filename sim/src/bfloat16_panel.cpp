#include "drapegen/sim/bfloat16_panel.hpp"

#include <cstddef>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace drapegen::sim {

namespace {

const std::uint16_t* column(const std::uint16_t* a, int rows, int j) {
  return a + static_cast<std::ptrdiff_t>(j) * rows;
}

#if defined(__SSE2__)
/// Eight bfloat16 values as two vectors of four floats: each value becomes the upper half of a zero-padded word.
inline void load8(const std::uint16_t* p, __m128& lo, __m128& hi) {
  const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
  const __m128i zero = _mm_setzero_si128();
  lo = _mm_castsi128_ps(_mm_unpacklo_epi16(zero, v));
  hi = _mm_castsi128_ps(_mm_unpackhi_epi16(zero, v));
}

inline float horizontal_sum(__m128 v) {
  const __m128 pairs = _mm_add_ps(v, _mm_movehl_ps(v, v));
  return _mm_cvtss_f32(_mm_add_ss(pairs, _mm_shuffle_ps(pairs, pairs, 1)));
}
#endif

}  // namespace

void bfloat16_multiply_add(const std::uint16_t* a, int rows, int cols, const float* x, float* y) {
  int j = 0;
#if defined(__SSE2__)
  // Four columns per pass over y (y stays in registers for eight rows at a time).
  const int vector_rows = rows & ~7;
  for (; j + 3 < cols; j += 4) {
    const std::uint16_t* c0 = column(a, rows, j);
    const std::uint16_t* c1 = c0 + rows;
    const std::uint16_t* c2 = c1 + rows;
    const std::uint16_t* c3 = c2 + rows;
    const __m128 x0 = _mm_set1_ps(x[j]), x1 = _mm_set1_ps(x[j + 1]), x2 = _mm_set1_ps(x[j + 2]),
                 x3 = _mm_set1_ps(x[j + 3]);
    int i = 0;
    for (; i < vector_rows; i += 8) {
      __m128 l0, h0, l1, h1, l2, h2, l3, h3;
      load8(c0 + i, l0, h0);
      load8(c1 + i, l1, h1);
      load8(c2 + i, l2, h2);
      load8(c3 + i, l3, h3);
      const __m128 low = _mm_add_ps(_mm_add_ps(_mm_mul_ps(l0, x0), _mm_mul_ps(l1, x1)),
                                    _mm_add_ps(_mm_mul_ps(l2, x2), _mm_mul_ps(l3, x3)));
      const __m128 high = _mm_add_ps(_mm_add_ps(_mm_mul_ps(h0, x0), _mm_mul_ps(h1, x1)),
                                     _mm_add_ps(_mm_mul_ps(h2, x2), _mm_mul_ps(h3, x3)));
      _mm_storeu_ps(y + i, _mm_add_ps(_mm_loadu_ps(y + i), low));
      _mm_storeu_ps(y + i + 4, _mm_add_ps(_mm_loadu_ps(y + i + 4), high));
    }
    for (; i < rows; ++i) {
      y[i] += from_bfloat16(c0[i]) * x[j] + from_bfloat16(c1[i]) * x[j + 1] + from_bfloat16(c2[i]) * x[j + 2] +
              from_bfloat16(c3[i]) * x[j + 3];
    }
  }
#endif
  for (; j < cols; ++j) {
    const std::uint16_t* c = column(a, rows, j);
    for (int i = 0; i < rows; ++i) y[i] += from_bfloat16(c[i]) * x[j];
  }
}

void bfloat16_transpose_multiply_subtract(const std::uint16_t* a, int rows, int cols, const float* x, float* y) {
  int j = 0;
#if defined(__SSE2__)
  // Two columns per pass over x.
  const int vector_rows = rows & ~7;
  for (; j + 1 < cols; j += 2) {
    const std::uint16_t* c0 = column(a, rows, j);
    const std::uint16_t* c1 = c0 + rows;
    __m128 s0 = _mm_setzero_ps(), s1 = _mm_setzero_ps();
    int i = 0;
    for (; i < vector_rows; i += 8) {
      __m128 l0, h0, l1, h1;
      load8(c0 + i, l0, h0);
      load8(c1 + i, l1, h1);
      const __m128 xl = _mm_loadu_ps(x + i), xh = _mm_loadu_ps(x + i + 4);
      s0 = _mm_add_ps(s0, _mm_add_ps(_mm_mul_ps(l0, xl), _mm_mul_ps(h0, xh)));
      s1 = _mm_add_ps(s1, _mm_add_ps(_mm_mul_ps(l1, xl), _mm_mul_ps(h1, xh)));
    }
    float t0 = horizontal_sum(s0), t1 = horizontal_sum(s1);
    for (; i < rows; ++i) {
      t0 += from_bfloat16(c0[i]) * x[i];
      t1 += from_bfloat16(c1[i]) * x[i];
    }
    y[j] -= t0;
    y[j + 1] -= t1;
  }
#endif
  for (; j < cols; ++j) {
    const std::uint16_t* c = column(a, rows, j);
    float t = 0.0f;
    for (int i = 0; i < rows; ++i) t += from_bfloat16(c[i]) * x[i];
    y[j] -= t;
  }
}

}  // namespace drapegen::sim
