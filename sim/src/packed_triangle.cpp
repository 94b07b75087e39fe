#include "drapegen/sim/packed_triangle.hpp"

#include <cstddef>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace drapegen::sim {
namespace {

/// Sum of a[i] * x[i] over i < n.
float dot(const float* a, const float* x, int n) {
  int i = 0;
  float sum = 0.0f;
#if defined(__SSE2__)
  __m128 s0 = _mm_setzero_ps(), s1 = _mm_setzero_ps();
  for (; i + 8 <= n; i += 8) {
    s0 = _mm_add_ps(s0, _mm_mul_ps(_mm_loadu_ps(a + i), _mm_loadu_ps(x + i)));
    s1 = _mm_add_ps(s1, _mm_mul_ps(_mm_loadu_ps(a + i + 4), _mm_loadu_ps(x + i + 4)));
  }
  const __m128 s = _mm_add_ps(s0, s1);
  const __m128 pairs = _mm_add_ps(s, _mm_movehl_ps(s, s));
  sum = _mm_cvtss_f32(_mm_add_ss(pairs, _mm_shuffle_ps(pairs, pairs, 1)));
#endif
  for (; i < n; ++i) sum += a[i] * x[i];
  return sum;
}

}  // namespace

void pack_lower_triangle(const double* l, int n, int ld, float* packed) {
  for (int j = 0; j < n; ++j) {
    const double* column = l + static_cast<std::ptrdiff_t>(j) * ld;
    *packed++ = static_cast<float>(1.0 / column[j]);
    for (int i = j + 1; i < n; ++i) *packed++ = static_cast<float>(column[i]);
  }
}

void packed_lower_solve(const float* packed, int n, float* y) {
  for (int j = 0; j < n; ++j) {
    const int below = n - j - 1;
    const float xj = y[j] * packed[0];
    y[j] = xj;
    float* rest = y + j + 1;
    const float* c = packed + 1;
    for (int i = 0; i < below; ++i) rest[i] -= c[i] * xj;
    packed += below + 1;
  }
}

void packed_lower_transpose_solve(const float* packed, int n, float* y) {
  // Walk the columns backwards: column j starts where column j+1 starts minus column j's n - j values.
  std::size_t start = packed_triangle_size(static_cast<std::size_t>(n));
  for (int j = n - 1; j >= 0; --j) {
    const int below = n - j - 1;
    start -= static_cast<std::size_t>(below) + 1;
    const float* c = packed + start;
    y[j] = (y[j] - dot(c + 1, y + j + 1, below)) * c[0];
  }
}

}  // namespace drapegen::sim
