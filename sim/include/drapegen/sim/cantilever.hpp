#pragma once
// The cantilever test (paper Section 4.2.1, Fig. 10): a strip clamped horizontally at one end, hanging under its
// own weight, simulated with the same model and solver as the drape.

#include <Eigen/Core>
#include <vector>

#include "drapegen/sim/expected.hpp"
#include "drapegen/sim/fabric.hpp"
#include "drapegen/sim/newton_solver.hpp"
#include "drapegen/sim/specimen.hpp"

namespace drapegen::sim {

struct CantileverSpec {
  double length = 0.1;   // m, free length beyond the clamp
  double width = 0.02;   // m
  FabricParameters fabric;
  BendingModel bending_model = BendingModel::kNonlinearDihedral;
  AnisotropyRule anisotropy = AnisotropyRule::kCurvature;
  /// Warp direction relative to the strip's long axis, radians (a strip cut at angle phi, Fig. 13).
  double cut_angle = 0.0;
  int segments = 40;        // free lattice spacings along the length (spacing L / (segments + 1/2))
  /// Nearly equilateral triangles by default: every edge then has its wing tips symmetric about it, which the
  /// dihedral model needs to be consistent (on right-triangle grids a free strip is ~20% too soft; docs/PHYSICS.md).
  Triangulation triangulation = Triangulation::kEquilateral;
  double jitter = 0.0;      // triangulation perturbation (fraction of the spacing)
  std::uint64_t seed = 0;
  double membrane_stiffness = 200.0;
  double gravity = 9.81;
  SolverOptions solver;
};

struct CantileverResult {
  double gamma = 0.0;              // rho g L^3 / alpha(cut direction)
  double height_over_width = 0.0;  // tip drop / horizontal reach of the tip
  /// Centre line (x along the strip from the clamp face, z up), m: one point per lattice row from the last clamped
  /// row (x = h/2, horizontal tangent, where the bending hinges begin) to the tip (x = L before deformation).
  std::vector<Eigen::Vector2d> curve;
  SolveReport report;
};

/// Simulates the strip: lattice rows across the strip at x = -h/2 + i h, h = L / (segments + 1/2), i = 0 ..
/// segments + 1 (the tip row at x = L). The rows at -h/2 and h/2 are clamped (a horizontal tangent), which puts the
/// clamp face at x = 0: the hinges of the row at h/2 stand for the strip's curvature over [0, h]. With the default
/// equilateral triangulation the rows are straight lines of edges (the lattice is rotated so that its rows run
/// across the strip), the grid triangulations use their columns. Soft strips (Gamma > 50) are loaded in a few
/// increments of gravity. The centre line is interpolated at y = 0 in the rest triangles (no lattice line needs to
/// lie there, and it works with jitter).
///
/// Accuracy against the planar elastica (master curve): the bending model is a plate, not a rod. On the equilateral
/// lattice the dihedral energy tends to (alpha / 2) (k1^2 + k2^2 - (2/3) k1 k2) per unit area for principal
/// curvatures k1, k2, a plate of bending stiffness alpha and Poisson ratio -1/3. Held flat across (near the clamp,
/// on wide strips, or at large deflection where curving across needs stretching beyond the membrane's dead band)
/// the strip bends with stiffness alpha; a long narrow strip curls across the same way (k2 = k1 / 3) and bends with
/// (8/9) alpha, so at small Gamma its H/W is up to 12.5 % above the master curve and a regression of its centre line
/// finds ~0.9 alpha. Strips at least twice as wide as long stay within ~1 % of the master curve for Gamma <= 100 at
/// 20 segments (sim/tests/cantilever_test.cpp) and within 1.4 % for Gamma = 0.01 ... 1000 at 80 segments
/// (bench/cantilever_sweep.cpp); large Gamma needs segments >> Gamma^(1/3) to resolve the bending boundary layer at
/// the clamp. On such wide strips the regression finds ~3 % too much alpha at large Gamma (the centre line of a
/// plate that does not bend uniformly across is not quite the rod of the regression).
[[nodiscard]] Expected<CantileverResult> simulate_cantilever(const CantileverSpec& spec);

}  // namespace drapegen::sim
