#include "drapegen/sim/drape.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include <memory>
#include <nlohmann/json.hpp>

#include "drapegen/sim/bending.hpp"
#include "drapegen/sim/trellis_membrane.hpp"
#include "drapegen/sim/gravity.hpp"
#include "drapegen/sim/measures.hpp"
#include "drapegen/sim/mesh_transfer.hpp"
#include "drapegen/sim/triangle_bending.hpp"

namespace drapegen::sim {
namespace {

/// The bending term of the configured model, with its effects.
std::vector<std::unique_ptr<EnergyTerm>> make_bending(const ClothMesh& mesh, const Topology& topology,
                                                      const FabricParameters& fabric, const DrapeConfig& config) {
  const PhysicalEffects& fx = config.effects;
  std::vector<std::unique_ptr<EnergyTerm>> terms;
  if (config.bending_model == BendingModel::kQuadratic) {
    if (fx.edge_curl || fx.bending_yield_curvature || config.rest_angles.size() > 0) {
      throw std::invalid_argument("edge curl, bending plasticity and rest angles need the dihedral bending model");
    }
    terms.push_back(std::make_unique<QuadraticBending>(mesh, topology, fabric.gamma, config.anisotropy));
    return terms;
  }
  const DihedralModuli moduli{fabric.alpha, fabric.beta};
  if (config.bending_model == BendingModel::kNonlinearTriangle) {
    if (fx.edge_curl || fx.bending_yield_curvature || config.rest_angles.size() > 0) {
      throw std::invalid_argument("edge curl, bending plasticity and rest angles need the dihedral bending model");
    }
    terms.push_back(std::make_unique<TriangleCurvatureBending>(mesh, topology, moduli, config.anisotropy));
    return terms;
  }
  auto hinges = std::make_unique<DihedralBending>(mesh, topology, moduli, config.anisotropy);
  if (config.rest_angles.size() > 0) {
    if (config.rest_angles.size() != static_cast<Eigen::Index>(topology.hinges.size())) {
      throw std::invalid_argument(fmt::format("rest angles: {} given, the specimen has {} hinges (another specimen?)",
                                              config.rest_angles.size(), topology.hinges.size()));
    }
    hinges->set_rest_angles(config.rest_angles);
  } else if (fx.edge_curl) {
    hinges->set_rest_angles(edge_curl_rest_angles(mesh, topology, *fx.edge_curl));
  }
  if (fx.bending_yield_curvature) hinges->set_yield_curvature(*fx.bending_yield_curvature);
  terms.push_back(std::move(hinges));
  return terms;
}

std::unique_ptr<EnergyTerm> make_membrane(const ClothMesh& mesh, const DrapeConfig& config) {
  if (config.effects.shear_stiffness) {
    return std::make_unique<TrellisMembrane>(mesh, TrellisParameters{config.membrane, *config.effects.shear_stiffness});
  }
  return std::make_unique<CorotationalMembrane>(mesh, config.membrane);
}

}  // namespace

Expected<DrapeResult> simulate_drape(const DrapeConfig& config,
                                     const std::function<void(const IterationInfo&)>& progress) {
  if (Status s = validate(config.fabric, config.bending_model); !s) return s.error();
  // The residual test is relative to the heaviest vertex's weight: without weight every solve would end "diverged".
  if (!(config.gravity > 0.0) || !std::isfinite(config.gravity)) return Error{"gravity must be positive and finite"};
  if (config.load_steps < 1 || config.load_steps > 100) return Error{"load steps must be 1..100"};
  if (Status s = validate(config.solver); !s) return s.error();
  DrapeResult result;
  try {
    result.mesh = make_specimen(config.specimen);
  } catch (const std::invalid_argument& e) {
    return Error{e.what()};
  }
  InitialStateSpec initial = config.initial;
  initial.platform_radius = config.platform.radius;
  initial.lift = config.platform.contact_offset;
  if (Status s = apply_initial_state(initial, result.mesh); !s) return s.error();
  ClothMesh& mesh = result.mesh;
  const FabricParameters fabric = normalized(config.fabric);  // the drape depends on k / rho only
  try {
    const Topology topology = build_topology(mesh);
    const std::unique_ptr<EnergyTerm> membrane = make_membrane(mesh, config);
    const std::vector<std::unique_ptr<EnergyTerm>> bending = make_bending(mesh, topology, fabric, config);
    Gravity gravity(mesh, fabric.density, config.gravity);
    PlatformContact contact(mesh, config.platform);

    const std::vector<int> on_top = contact.vertices_on_top(mesh.positions, 5e-4);
    if ((config.adhesion || config.effects.friction) && on_top.empty()) {
      // A mesh whose spacing exceeds the top's radius can miss it wholly (a 2 m specimen at 60 vertices per side).
      const double spacing = std::max(config.specimen.size_x / (config.specimen.vertices_x - 1),
                                      config.specimen.size_y / (config.specimen.vertices_y - 1));
      const std::string coarse =
          spacing > 0.5 * config.platform.radius
              ? fmt::format(", or the mesh's {:.0f} mm spacing too coarse for the top's {:.0f} mm radius: more "
                            "vertices per side",
                            spacing * 1e3, config.platform.radius * 1e3)
              : std::string();
      return Error{"no vertex of the initial state rests on the platform top (drift too large, or the initial mesh "
                   "is not on the platform" + coarse + ")"};
    }
    std::vector<bool> fixed(mesh.vertex_count(), false);
    std::unique_ptr<PlatformFriction> friction;
    if (config.effects.friction) {
      friction = std::make_unique<PlatformFriction>(contact, on_top, mesh.positions, *config.effects.friction);
    } else if (config.adhesion) {
      for (int v : on_top) fixed[v] = true;
    }
    result.fixed_vertices = static_cast<int>(std::count(fixed.begin(), fixed.end(), true));

    SolverOptions options = config.solver;
    if (config.effects.bending_yield_curvature || config.effects.friction) {
      // Plastic flow and the friction force are lagged forces: update them only near equilibrium (DrapeConfig).
      options.lagged_outer_below = std::min(options.lagged_outer_below, SolverOptions{}.lagged_outer_below);
    }
    NewtonSolver solver(options);
    if (progress) solver.set_progress(progress);
    std::vector<EnergyTerm*> terms{membrane.get()};
    for (const auto& term : bending) terms.push_back(term.get());
    terms.push_back(&gravity);
    terms.push_back(&contact);
    if (friction) terms.push_back(friction.get());
    Eigen::Matrix3Xd x = mesh.positions;
    const int coarse = config.coarse_start_resolution;
    // No cascade for a yielding fabric: plastic flow would start from the coarse drape interpolated piecewise flat,
    // whose fine hinges along the coarse edges carry about twice the curvature, and set that grid's pattern for good.
    if (coarse >= 3 && initial.shape != InitialShape::kMesh && config.rest_angles.size() == 0 &&
        !config.effects.bending_yield_curvature && config.load_steps == 1 && config.specimen.vertices_x >= 2 * coarse &&
        config.specimen.vertices_y >= 2 * coarse) {
      // A cascade: each level starts from the drape of one at half its resolution, down to `coarse`.
      DrapeConfig coarse_config = config;
      coarse_config.specimen.vertices_x = std::max(coarse, config.specimen.vertices_x / 2);
      coarse_config.specimen.vertices_y = std::max(coarse, config.specimen.vertices_y / 2);
      coarse_config.solver.tolerance = std::max(config.solver.tolerance, 1e-2);
      const Expected<DrapeResult> start = simulate_drape(coarse_config);
      if (start) {
        result.coarse_report = start->report;
        result.coarse_report.add_work(start->coarse_report);
        const Eigen::Matrix3Xd guess = transfer_positions(start->mesh, mesh.rest);
        for (int v = 0; v < mesh.vertex_count(); ++v) {
          if (!fixed[v]) x.col(v) = guess.col(v);
        }
      }
    }
    // A ramped load: the steps before the last solve under a fraction of gravity, carrying the lagged state along.
    // Each step is solved to equilibrium: one that does not converge ends the drape there with its report (the
    // loading history would not be the one asked for), as a single solve that does not ends with its own.
    SolveReport ramp;
    bool ramp_diverged = false;
    for (int step = 1; step < config.load_steps && !ramp_diverged; ++step) {
      Gravity partial(mesh, fabric.density, config.gravity * step / config.load_steps);
      std::vector<EnergyTerm*> step_terms = terms;
      std::replace(step_terms.begin(), step_terms.end(), static_cast<EnergyTerm*>(&gravity),
                   static_cast<EnergyTerm*>(&partial));
      SolveReport report = solver.solve(step_terms, fixed, partial.vertex_weights().maxCoeff(), x);
      if (report.outcome != SolveOutcome::kConverged || !std::isfinite(report.residual) ||
          !std::isfinite(report.energy)) {
        report.message = fmt::format("load step {} of {}: {}", step, config.load_steps, report.message);
        report.add_work(ramp);
        result.report = report;
        ramp_diverged = true;
      } else {
        ramp.add_work(report);
      }
    }
    if (!ramp_diverged) {
      result.report = solver.solve(terms, fixed, gravity.vertex_weights().maxCoeff(), x);
      result.report.add_work(ramp);
    }
    mesh.positions = x;
    if (const auto* hinges = dynamic_cast<const DihedralBending*>(bending.front().get())) {
      result.rest_angles = hinges->rest_angles();
    }
    result.measures = measure_drape(mesh, config.platform);
  } catch (const std::invalid_argument& e) {
    return Error{e.what()};
  }
  return result;
}

DrapeMeasures measure_drape(const ClothMesh& mesh, const PlatformSpec& platform) {
  DrapeMeasures m;
  m.drape_coefficient = drape_coefficient(mesh, platform.radius);
  m.folds = count_folds(hem_profile(mesh));
  m.self_intersections = count_self_intersections(mesh);
  m.max_penetration = PlatformContact(mesh, platform).max_penetration(mesh.positions);
  m.lowest_point = mesh.positions.row(2).minCoeff();
  return m;
}

nlohmann::json to_json(const DrapeResult& result) {
  const SolveReport& r = result.report;
  return nlohmann::json{
      {"outcome", std::string(to_string(r.outcome))},
      {"message", r.message},
      {"iterations", r.iterations},
      {"seconds", r.seconds + result.coarse_report.seconds},
      {"coarse_iterations", result.coarse_report.iterations},
      {"coarse_seconds", result.coarse_report.seconds},
      {"assembly_seconds", r.assembly_seconds},
      {"factorization_seconds", r.factorization_seconds},
      {"residual", r.residual},
      {"energy", r.energy},
      {"regularized_iterations", r.regularized_iterations},
      {"exact_hessian_iterations", r.exact_hessian_iterations},
      {"lagged_updates", r.lagged_updates},
      {"reused_factorizations", r.reused_factorizations},
      {"pcg_iterations", r.pcg_iterations},
      {"pcg_failures", r.pcg_failures},
      {"lagged_change", r.lagged_change},
      {"lagged_capped", r.lagged_capped},
      {"line_search_failures", r.line_search_failures},
      {"vertices", result.mesh.vertex_count()},
      {"triangles", result.mesh.triangle_count()},
      {"fixed_vertices", result.fixed_vertices},
      {"drape_coefficient", result.measures.drape_coefficient},
      {"folds", result.measures.folds},
      {"self_intersections", result.measures.self_intersections},
      {"max_penetration_m", result.measures.max_penetration},
      {"lowest_point_m", result.measures.lowest_point},
  };
}

}  // namespace drapegen::sim
