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
  int segments = 40;        // elements along the length
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
  std::vector<Eigen::Vector2d> curve;  // centre line (x along the strip, z up), clamp to tip, m
  SolveReport report;
};

/// Simulates the strip: `segments` spacings along its length, rows of nearly equilateral triangles across it. The
/// clamp holds every vertex at x <= 0 (two lattice columns: a horizontal tangent). Soft strips (Gamma > 50) are
/// loaded in a few increments of gravity. The curve is the lattice row nearest the centre line, clamp to tip.
[[nodiscard]] Expected<CantileverResult> simulate_cantilever(const CantileverSpec& spec);

}  // namespace drapegen::sim
