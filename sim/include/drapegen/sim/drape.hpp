#pragma once
// The drape test (paper Section 5.2.1): a specimen on the platform, adhesive where it starts on the top, solved to
// quasistatic equilibrium; the result with its measures.

#include <functional>
#include <nlohmann/json_fwd.hpp>

#include "drapegen/sim/expected.hpp"
#include "drapegen/sim/fabric.hpp"
#include "drapegen/sim/gravity.hpp"
#include "drapegen/sim/initial_state.hpp"
#include "drapegen/sim/membrane.hpp"
#include "drapegen/sim/newton_solver.hpp"
#include "drapegen/sim/physical_effects.hpp"
#include "drapegen/sim/platform.hpp"
#include "drapegen/sim/specimen.hpp"

namespace drapegen::sim {

struct DrapeConfig {
  FabricParameters fabric;
  BendingModel bending_model = BendingModel::kNonlinearDihedral;
  AnisotropyRule anisotropy = AnisotropyRule::kCurvature;
  MembraneParameters membrane;
  PlatformSpec platform;
  /// 300 x 300 mm, 100 x 100 vertices, perturbed triangulation.
  SpecimenSpec specimen{0.3, 0.3, 100, 100, 0.2, Triangulation::kRandom, 0, 0.0};
  InitialStateSpec initial;
  /// The bending Hessian without the tau * d^2(theta) term wherever the solver does not try the exact one: fewer
  /// iterations than the eigen-projected element Hessian in our measurements (50x50, 9 drapes: 758 iterations
  /// against 878 with Gauss-Newton only above a residual of 10 and 1169 without it), and cheaper.
  ///
  /// The outer loop of the lagged anisotropy directions starts at a residual of 30 vertex weights instead of 3: the
  /// directions follow the shape, which has formed by then, and each update made at a residual under 3 threw Newton
  /// back to ~200 and cost it ~25 iterations. docs/BENCHMARKS.md (session 10): 100x100, fabrics 154-617 of the
  /// benchmark, 12 drapes: 525 full-resolution iterations against 670, the drapes 0.001-0.33 mm apart (mean vertex
  /// distance; at most 2.2 mm). Effects whose lagged state is a force (plastic flow, friction's normal force) keep
  /// the solver's default (3): simulate_drape uses the smaller of the two when one of them is on.
  SolverOptions solver{.gauss_newton_above = 0.0, .lagged_outer_below = 30.0};
  double gravity = kStandardGravity;
  /// Hold the vertices that start on the platform top (static friction, Section 5.2.1). Ignored with
  /// effects.friction, which replaces it.
  bool adhesion = true;
  /// Effects beyond the paper's model (none by default). Edge curl and bending plasticity need the dihedral model.
  PhysicalEffects effects;
  /// The dihedral hinges' rest angles the specimen starts with (empty: flat, or the edge curl's): the plastic set of
  /// an earlier drape of the same specimen (DrapeResult::rest_angles; the caller keeps the SpecimenSpec: only the
  /// hinge count is checked, and any triangulation of one grid has the same count), lifted and laid again. A
  /// real specimen keeps the creases its yielded hinges took; released, it relaxes to them, not to flat. Replaces the
  /// edge curl's rest angles (the set includes them) and turns the coarse start off (the set lives on this mesh).
  Eigen::VectorXd rest_angles;
  /// Solve first on specimens of half the resolution, recursively down to this many vertices per side, from the same
  /// initial state, and start each finer solve from the coarser drape (0: off; ignored for mesh initial states,
  /// given rest angles, bending plasticity, whose flow would set the interpolated start's coarse pattern, and
  /// specimens with fewer than twice this many vertices per side).
  int coarse_start_resolution = 25;
  /// Gravity ramped in this many equal steps, each solved to equilibrium from the last (1: all at once). A loading
  /// history for the lagged effects (plastic flow) that does not follow the Newton path of one solve; experimental
  /// (docs/PHYSICS.md, "Bending plasticity"). More than 1 turns the coarse start off. A step that does not converge
  /// ends the drape there: the report is that step's (its message names the step) with the earlier steps' work, as
  /// one solve that does not converge ends with its own report.
  int load_steps = 1;
};

struct DrapeMeasures {
  double drape_coefficient = 0.0;   // Cusick
  int folds = 0;                    // nodes of the hem
  int self_intersections = 0;       // intersecting pairs of non-adjacent triangles
  double max_penetration = 0.0;     // m, deepest vertex inside the platform's contact offset
  double lowest_point = 0.0;        // m, z of the lowest vertex
};

struct DrapeResult {
  ClothMesh mesh;
  SolveReport report;         // the full-resolution solve
  SolveReport coarse_report;  // the coarse start (iterations 0 if none)
  DrapeMeasures measures;
  int fixed_vertices = 0;
  /// The dihedral hinges' rest angles after the solve (plastic flow moves them; empty for the other bending models):
  /// DrapeConfig::rest_angles of the specimen's next drape.
  Eigen::VectorXd rest_angles;
};

/// Builds and solves the drape. Errors: invalid parameters or an unreadable initial mesh. A solve that does not
/// converge still returns a result: check report.outcome.
[[nodiscard]] Expected<DrapeResult> simulate_drape(const DrapeConfig& config,
                                                   const std::function<void(const IterationInfo&)>& progress = {});

/// Measures of a draped mesh on the given platform.
[[nodiscard]] DrapeMeasures measure_drape(const ClothMesh& mesh, const PlatformSpec& platform);

/// The JSON summary: outcome, iterations, seconds, residual, energy, drape coefficient, folds, self-intersections.
[[nodiscard]] nlohmann::json to_json(const DrapeResult& result);

}  // namespace drapegen::sim
