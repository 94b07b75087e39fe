#include "drapegen/sim/cantilever.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "drapegen/sim/bending.hpp"
#include "drapegen/sim/gravity.hpp"
#include "drapegen/sim/membrane.hpp"
#include "drapegen/sim/specimen.hpp"

namespace drapegen::sim {

Expected<CantileverResult> simulate_cantilever(const CantileverSpec& spec) {
  if (Status s = validate(spec.fabric, spec.bending_model); !s) return s.error();
  if (!(spec.length > 0.0) || !(spec.width > 0.0) || !std::isfinite(spec.length) || !std::isfinite(spec.width)) {
    return Error{"cantilever length and width must be positive and finite"};
  }
  if (spec.segments < 2) return Error{"cantilever needs at least 2 segments"};

  const double h = spec.length / spec.segments;
  const double row_spacing = spec.triangulation == Triangulation::kEquilateral ? h * std::sqrt(3.0) / 2.0 : h;
  const int rows = std::max(2, static_cast<int>(std::lround(spec.width / row_spacing)) + 1);
  SpecimenSpec s{spec.length + h, spec.width, spec.segments + 2, rows, spec.jitter, spec.triangulation, spec.seed,
                 spec.cut_angle};
  ClothMesh mesh;
  try {
    mesh = make_specimen(s);
  } catch (const std::invalid_argument& e) {
    return Error{e.what()};
  }
  // Shift so that the clamp line is x = 0 and the free strip runs to x = L.
  mesh.rest.row(0).array() += 0.5 * (spec.length + h) - h;
  mesh.positions.topRows<2>() = mesh.rest;
  mesh.positions.row(2).setZero();
  std::vector<bool> fixed(mesh.vertex_count(), false);
  for (int v = 0; v < mesh.vertex_count(); ++v) fixed[v] = mesh.rest(0, v) <= 1e-9 * spec.length;

  CantileverResult result;
  const double alpha_cut = interpolate_directional(
      spec.bending_model == BendingModel::kQuadratic ? spec.fabric.gamma : spec.fabric.alpha, spec.cut_angle);
  result.gamma = spec.fabric.density * spec.gravity * std::pow(spec.length, 3) / alpha_cut;
  try {
    const Topology topology = build_topology(mesh);
    CorotationalMembrane membrane(mesh, MembraneParameters{spec.membrane_stiffness, 0.99, 1.01});
    std::unique_ptr<EnergyTerm> bending;
    if (spec.bending_model == BendingModel::kQuadratic) {
      bending = std::make_unique<QuadraticBending>(mesh, topology, spec.fabric.gamma, spec.anisotropy);
    } else {
      bending = std::make_unique<DihedralBending>(mesh, topology, DihedralModuli{spec.fabric.alpha, spec.fabric.beta},
                                                  spec.anisotropy);
    }
    NewtonSolver solver(spec.solver);
    Eigen::Matrix3Xd x = mesh.positions;
    // Load stepping: a soft strip reaches its hanging state through a sequence of stiffer-looking problems.
    const int steps = result.gamma > 50.0 ? 4 : 1;
    for (int k = 1; k <= steps; ++k) {
      Gravity gravity(mesh, spec.fabric.density, spec.gravity * k / steps);
      std::vector<EnergyTerm*> terms{&membrane, bending.get(), &gravity};
      const double reference = Gravity(mesh, spec.fabric.density, spec.gravity).vertex_weights().maxCoeff();
      const SolveReport r = solver.solve(terms, fixed, reference, x);
      result.report.iterations += r.iterations;
      result.report.seconds += r.seconds;
      result.report.assembly_seconds += r.assembly_seconds;
      result.report.factorization_seconds += r.factorization_seconds;
      result.report.outcome = r.outcome;
      result.report.residual = r.residual;
      result.report.energy = r.energy;
      result.report.message = r.message;
      if (r.outcome != SolveOutcome::kConverged) break;
    }
    mesh.positions = x;
  } catch (const std::invalid_argument& e) {
    return Error{e.what()};
  }
  // Centre line: the lattice row nearest y = 0 (jitter moves vertices by at most 0.3 spacings), clamp to tip.
  const double dy = spec.width / (rows - 1);
  const double centre_y = -0.5 * spec.width + std::round(0.5 * (rows - 1)) * dy;
  std::vector<int> row;
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    if (std::abs(mesh.rest(1, v) - centre_y) < 0.4 * dy && mesh.rest(0, v) >= -1e-9 * spec.length) row.push_back(v);
  }
  std::sort(row.begin(), row.end(), [&](int a, int b) { return mesh.rest(0, a) < mesh.rest(0, b); });
  for (int v : row) result.curve.emplace_back(mesh.positions(0, v), mesh.positions(2, v));
  const Eigen::Vector2d tip = result.curve.back();
  result.height_over_width = tip.x() > 1e-12 ? -tip.y() / tip.x() : std::numeric_limits<double>::infinity();
  return result;
}

}  // namespace drapegen::sim
