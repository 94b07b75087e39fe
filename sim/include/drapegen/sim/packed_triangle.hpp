#pragma once
// The dense lower-triangular diagonal blocks of a supernodal Cholesky factor, packed by columns in single precision,
// and the two triangular solves the preconditioner needs from them. Packing stores only the triangle (the square
// block a supernode owns in CHOLMOD is half zeros) and holds the reciprocal of each diagonal value, so a solve is a
// run of contiguous multiply-adds per column with no division; for the many small supernodes of a cloth mesh it also
// avoids the per-call overhead of a general dense solver.
//
// Layout of a triangle of order n: column j (0-based) takes n - j values, first 1 / L(j,j), then L(j+1..n-1, j).

#include <cstddef>

namespace drapegen::sim {

/// Number of values a packed lower triangle of order n takes.
[[nodiscard]] constexpr std::size_t packed_triangle_size(std::size_t n) { return n * (n + 1) / 2; }

/// Packs the lower triangle of the column-major n x n block `l` (leading dimension `ld`) into `packed`
/// (packed_triangle_size(n) values). The diagonal values must be non-zero.
void pack_lower_triangle(const double* l, int n, int ld, float* packed);

/// y <- L^-1 y for a packed triangle L of order n.
void packed_lower_solve(const float* packed, int n, float* y);

/// y <- L^-T y for a packed triangle L of order n.
void packed_lower_transpose_solve(const float* packed, int n, float* y);

}  // namespace drapegen::sim
