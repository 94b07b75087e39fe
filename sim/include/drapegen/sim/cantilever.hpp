#pragma once
// The cantilever test (paper Section 4.2.1, Fig. 10): a strip clamped horizontally at one end, hanging under its
// own weight, simulated with the same model and solver as the drape.

#include <Eigen/Core>
#include <vector>

#include "drapegen/sim/expected.hpp"
#include "drapegen/sim/fabric.hpp"
#include "drapegen/sim/newton_solver.hpp"

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
  int width_vertices = 5;
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

/// Simulates the strip. The clamp holds the two first columns of vertices (a horizontal tangent). Loads are applied
/// in a few increments of gravity so that very soft strips (Gamma up to ~1e3) are reached robustly.
[[nodiscard]] Expected<CantileverResult> simulate_cantilever(const CantileverSpec& spec);

}  // namespace drapegen::sim
