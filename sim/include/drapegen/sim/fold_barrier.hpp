#pragma once
// Contact between the two wings of a hinge folded nearly flat onto itself.
//
// A hinge's dihedral angle lives in (-pi, pi]: at +-pi the two triangles lie on each other and the angle wraps. Real
// cloth cannot get there (it has thickness: the wings touch first), but a coarse mesh, a soft or plastic fabric and
// gravity can drive a hinge towards it, and the bending energy has a ridge (flat rest) or a jump (curled or plastic
// rest angles) at the wrap, where Newton stalls. This barrier, a function of the gap g = pi - |theta| only, is zero
// for g >= width and grows like -log g as the wings close:
//
//   b(g) = -k (g - width)^2 log(g / width)   for 0 < g < width,
//
// twice continuously differentiable at g = width, convex in g, infinite at g = 0; so no hinge reaches the wrap and a
// drape whose hinges stay below pi - width (nearly all: width 0.5 rad is a fold of 150 degrees at one edge) is
// unchanged. k is an energy: the hinge takes k = e * c * alpha, its linear bending stiffness in theta. A state with
// a hinge exactly at +-pi (an input mesh folded flat onto itself) has infinite energy: the solve ends "diverged" at
// its first iteration.

namespace drapegen::sim {

struct FoldBarrier {
  /// Gap (rad) below which the barrier acts.
  static constexpr double kWidth = 0.5;

  /// Barrier energy at dihedral angle `theta` for stiffness `k`; writes d b / d theta and d^2 b / d theta^2 (>= 0).
  /// Infinite energy (and zero derivatives) at |theta| >= pi.
  [[nodiscard]] static double energy(double theta, double k, double* first = nullptr, double* second = nullptr);
};

}  // namespace drapegen::sim
