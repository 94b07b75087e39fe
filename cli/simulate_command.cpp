// drapegen simulate: one drape on the drape tester.
#include <cmath>
#include <iostream>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>
#include <vector>

#include <fmt/format.h>

#include "commands.hpp"
#include "failure.hpp"
#include "drapegen/sim/blas_kernels.hpp"
#include "drapegen/sim/drape.hpp"
#include "drapegen/sim/logging.hpp"
#include "drapegen/sim/ply.hpp"
#include "drapegen/sim/xoshiro.hpp"
#include "drapegen/storage/json_text.hpp"
#include "parse.hpp"

namespace drapegen::cli {
namespace {

struct SimulateOptions {
  std::string alpha;
  std::string beta = "0";
  double density = 300.0;
  int resolution = 100;
  std::string init = "flat";
  double rotation_deg = 0.0;
  std::string drift = "0";
  std::uint64_t seed = 0;
  std::string out;
  bool json = false;
  std::string model = "dihedral";
  std::string anisotropy = "curvature";
  double sigma = 200.0;
  std::string band = "0.99,1.01";
  bool structured = false;
  std::optional<sim::Triangulation> mesh;  // a structured grid (--mesh); none: the perturbed triangulation
  int max_iterations = sim::SolverOptions{}.max_iterations;
  double tolerance = 1e-3;
  int coarse_start = sim::DrapeConfig{}.coarse_start_resolution;
  int lagged_updates = sim::SolverOptions{}.max_lagged_outer_updates;
  int load_steps = 1;
  bool verbose = false;
  std::vector<std::string> effects;
};

/// "--drift MM": a distance in a direction drawn from the seed; "--drift DX,DY": an offset. Millimetres.
sim::Expected<Eigen::Vector2d> parse_drift(const std::string& text, std::uint64_t seed) {
  const auto comma = text.find(',');
  try {
    std::size_t used = 0;
    if (comma == std::string::npos) {
      const double mm = std::stod(text, &used);
      if (used != text.size() || !std::isfinite(mm) || mm < 0.0) throw std::invalid_argument("");
      sim::Xoshiro256 rng(seed ^ 0x9e3779b97f4a7c15ULL);
      const double angle = 2.0 * M_PI * rng.uniform();
      return Eigen::Vector2d(Eigen::Vector2d(std::cos(angle), std::sin(angle)) * (mm * 1e-3));
    }
    std::size_t used_y = 0;
    const std::string xs = text.substr(0, comma), ys = text.substr(comma + 1);
    const double dx = std::stod(xs, &used), dy = std::stod(ys, &used_y);
    if (used != xs.size() || used_y != ys.size() || !std::isfinite(dx) || !std::isfinite(dy)) {
      throw std::invalid_argument("");
    }
    return Eigen::Vector2d(dx * 1e-3, dy * 1e-3);
  } catch (const std::exception&) {
    return sim::Error{"--drift: expected MM (>= 0) or DX,DY in millimetres, got '" + text + "'"};
  }
}

const Failure fail{"simulate"};

int run_simulate(const SimulateOptions& o) {
  const auto alpha = parse_directional(o.alpha, "--alpha");
  if (!alpha) return fail(alpha.error().message);
  const auto beta = parse_directional(o.beta, "--beta");
  if (!beta) return fail(beta.error().message);
  if (!(o.density >= 1.0 && o.density <= 1e5)) return fail("--density must be between 1 and 100000 g/m^2");
  if (o.resolution < 5 || o.resolution > 1000) return fail("--resolution must be between 5 and 1000");
  auto initial = sim::parse_initial_state(o.init);
  if (!initial) return fail(initial.error().message);
  const auto drift = parse_drift(o.drift, o.seed);
  if (!drift) return fail(drift.error().message);
  if (!std::isfinite(o.rotation_deg)) return fail("--rotation must be finite");
  if (!(o.tolerance > 0.0) || !std::isfinite(o.tolerance)) return fail("--tolerance must be positive");
  if (o.max_iterations < 1) return fail("--max-iterations must be at least 1");
  if (o.coarse_start != 0 && o.coarse_start < 3) return fail("--coarse-start must be 0 (off) or at least 3");
  if (o.lagged_updates < 1 || o.lagged_updates > 1000) return fail("--lagged-updates must be 1..1000");
  if (o.load_steps < 1 || o.load_steps > 100) return fail("--load-steps must be 1..100");
  const auto effects = parse_effects(o.effects);
  if (!effects) return fail(effects.error().message);

  sim::DrapeConfig config;
  config.fabric = sim::fabric_from_paper_units(*alpha, *beta, o.density);
  if (o.model == "triangle") config.bending_model = sim::BendingModel::kNonlinearTriangle;
  if (o.model == "quadratic") {
    config.bending_model = sim::BendingModel::kQuadratic;
    // The quadratic model's gamma equals alpha / 3 for identical small-angle behaviour (paper Section 4.2.1).
    config.fabric.gamma = {config.fabric.alpha.warp / 3, config.fabric.alpha.bias / 3, config.fabric.alpha.weft / 3};
  }
  config.anisotropy = o.anisotropy == "edge" ? sim::AnisotropyRule::kEdge : sim::AnisotropyRule::kCurvature;
  config.effects = *effects;
  if (config.bending_model != sim::BendingModel::kNonlinearDihedral &&
      (config.effects.edge_curl || config.effects.bending_yield_curvature)) {
    return fail("--effect curl and yield need --model dihedral");
  }
  config.membrane.stiffness = o.sigma;
  {
    const auto comma = o.band.find(',');
    // Exactly two numbers (a third one was parsed as a directional triple and dropped).
    if (comma == std::string::npos || o.band.find(',', comma + 1) != std::string::npos) {
      return fail("--band: expected LOW,HIGH, e.g. 0.99,1.01");
    }
    // One number each: the strict parser of W,B,F values accepts a single value.
    const auto low = parse_directional(o.band.substr(0, comma), "--band");
    const auto high = parse_directional(o.band.substr(comma + 1), "--band");
    if (!low || !high) return fail("--band: expected LOW,HIGH, e.g. 0.99,1.01");
    config.membrane.band_low = low->warp;
    config.membrane.band_high = high->warp;
    if (!(config.membrane.band_low > 0.0 && config.membrane.band_low <= 1.0 && config.membrane.band_high >= 1.0 &&
          std::isfinite(config.membrane.band_high))) {
      return fail("--band: need 0 < LOW <= 1 <= HIGH");
    }
  }
  if (!(o.sigma > 0.0) || !std::isfinite(o.sigma)) return fail("--sigma must be positive (kg/s^2)");
  config.specimen.vertices_x = config.specimen.vertices_y = o.resolution;
  config.specimen.seed = o.seed;
  if (o.structured || o.mesh) {
    config.specimen.jitter = 0.0;
    config.specimen.triangulation = o.mesh.value_or(sim::Triangulation::kAlternating);
  }
  initial->seed = o.seed;
  initial->rotation = o.rotation_deg * M_PI / 180.0;
  initial->drift = *drift;
  config.initial = *initial;
  config.solver.max_iterations = o.max_iterations;
  config.solver.tolerance = o.tolerance;
  config.coarse_start_resolution = o.coarse_start;
  config.solver.max_lagged_outer_updates = o.lagged_updates;
  config.load_steps = o.load_steps;
  if (sim::Status s = sim::validate(config.fabric, config.bending_model); !s) return fail(s.error().message);

  // Refuse an unwritable output before spending the simulation on it.
  if (!o.out.empty()) {
    if (sim::Status s = check_writable(o.out); !s) return fail(s.error().message, kExitIo);
  }
  std::function<void(const sim::IterationInfo&)> progress;
  if (o.verbose) {
    sim::logger()->set_level(spdlog::level::debug);
    progress = [](const sim::IterationInfo& i) {
      std::cerr << fmt::format("iter {:4d}  energy {:.9e}  residual {:.3e}  step {:.3g}  shift {:.1e}\n", i.iteration,
                               i.energy, i.residual, i.step_length, i.regularization);
    };
  }
  const auto result = sim::simulate_drape(config, progress);
  if (!result) return fail(result.error().message);
  if (!o.out.empty()) {
    if (sim::Status s = sim::write_ply(o.out, result->mesh); !s) return fail(s.error().message, kExitIo);
  }
  nlohmann::json summary = sim::to_json(*result);
  summary["alpha"] = {alpha->warp, alpha->bias, alpha->weft};
  summary["beta"] = {beta->warp, beta->bias, beta->weft};
  summary["density_g_per_m2"] = o.density;
  summary["init"] = o.init;
  summary["seed"] = o.seed;
  summary["blas_kernels"] = sim::blas_kernels_description();
  if (!o.effects.empty()) summary["effects"] = o.effects;
  if (!o.out.empty()) summary["mesh"] = o.out;
  std::ostream& out = summary_stream({o.out});  // not over a mesh written to standard output
  if (o.json) {
    out << storage::json_text(summary) << "\n";
  } else {
    const auto& r = result->report;
    const auto& c = result->coarse_report;
    out << fmt::format(
        "drape: {} in {} iterations (+{} on coarser levels), {:.2f} s (coarser levels {:.2f} s), residual {:.2e}\n"
        "  drape coefficient {:.3f}, folds {}, self-intersections {}, lowest point {:.1f} mm\n",
        sim::to_string(r.outcome), r.iterations, c.iterations, r.seconds + c.seconds, c.seconds, r.residual,
        result->measures.drape_coefficient, result->measures.folds, result->measures.self_intersections,
        result->measures.lowest_point * 1e3);
    if (!r.message.empty()) out << "  " << r.message << "\n";
    if (!o.out.empty()) out << "  mesh written to " << o.out << "\n";
  }
  return result->report.outcome == sim::SolveOutcome::kConverged ? kExitOk : kExitNotConverged;
}

}  // namespace

Runner add_simulate_command(CLI::App& app) {
  auto o = std::make_shared<SimulateOptions>();
  app.add_option("--alpha", o->alpha, "Linear bending moduli W,B,F (warp, bias, weft), g*mm^2/s^2")->required();
  app.add_option("--beta", o->beta, "Quadratic bending moduli W,B,F, g*mm^3/s^2 (usually negative)")
      ->capture_default_str();
  app.add_option("--density", o->density, "Areal density, g/m^2")->capture_default_str();
  app.add_option("--resolution", o->resolution, "Vertices per side of the 300 mm specimen")->capture_default_str();
  app.add_option("--init", o->init, "Initial state: flat, sine, fold or mesh:FILE.ply")->capture_default_str();
  app.add_option("--rotation", o->rotation_deg, "Specimen rotation about the platform axis, degrees")
      ->capture_default_str();
  app.add_option("--drift", o->drift, "Specimen centre off the axis: MM (seeded direction) or DX,DY, millimetres")
      ->capture_default_str();
  app.add_option("--seed", o->seed, "Seed of the triangulation perturbation and the initial state")
      ->check(kSeed)
      ->capture_default_str();
  app.add_option("--out", o->out, "Write the draped mesh to this PLY file");
  app.add_flag("--json", o->json, "Print the summary as JSON");
  app.add_option("--model", o->model,
                 "Bending model: dihedral (paper Eq. 1-3, curvature per hinge), triangle (the same law on per-triangle "
                 "curvature tensors, exact for quadratic surfaces on any mesh without interior vertices of valence "
                 "3) or quadratic (Eq. 4, gamma = alpha/3)")
      ->check(CLI::IsMember({"dihedral", "triangle", "quadratic"}))
      ->capture_default_str();
  app.add_option("--anisotropy", o->anisotropy, "Bending direction rule: curvature (paper) or edge (naive)")
      ->check(CLI::IsMember({"curvature", "edge"}))
      ->capture_default_str();
  app.add_option("--sigma", o->sigma, "In-plane stiffness at the standard density (300 g/m^2), kg/s^2")
      ->capture_default_str();
  app.add_option("--band", o->band, "Stretch band LOW,HIGH absorbed by the adaptive reference (1,1: none)")
      ->capture_default_str();
  std::vector<std::string> mesh_names{"perturbed"};
  for (const auto& entry : sim::structured_triangulations()) mesh_names.push_back(entry.first);
  auto* mesh = app.add_option_function<std::string>(
                     "--mesh",
                     [o](const std::string& name) {
                       if (name != "perturbed") o->mesh = sim::structured_triangulations().at(name);
                     },
                     "Triangulation: perturbed (the default: the paper's random diagonals and jittered vertices), "
                     "union-jack (alternating diagonals), uniform (every quad split along the same diagonal) or "
                     "equilateral (rows of nearly equilateral triangles, odd rows offset by half a spacing; the row "
                     "spacing is the column spacing, so 53/63/63 degrees)")
                   ->check(CLI::IsMember(mesh_names));
  app.add_flag("--structured", o->structured, "Shorthand for --mesh union-jack")->excludes(mesh);
  app.add_option("--max-iterations", o->max_iterations, "Newton iteration limit")->capture_default_str();
  app.add_option("--tolerance", o->tolerance, "Residual force over the largest vertex weight")->capture_default_str();
  app.add_option("--coarse-start", o->coarse_start,
                 "Solve first at half the resolution, recursively down to this many vertices per side, and start "
                 "from that drape (0: off; only where --resolution is at least twice it; not with --init mesh:FILE, "
                 "--effect yield or --load-steps above 1)")
      ->capture_default_str();
  app.add_option("--lagged-updates", o->lagged_updates,
                 "Outer updates of the lagged state (curvature-rule directions, plastic flow, friction's normal "
                 "forces) near equilibrium, at most; fewer once it changes by under 0.1%")
      ->capture_default_str();
  app.add_option("--load-steps", o->load_steps,
                 "Ramp gravity in this many equal steps, each solved to equilibrium (a loading history for plastic "
                 "flow; experimental; more than 1 turns the coarse start off)")
      ->capture_default_str();
  app.add_flag("-v,--verbose", o->verbose, "Print every Newton iteration on stderr");
  app.add_option("--effect", o->effects,
                 "Physical effect beyond the paper's model (repeatable): curl=K[,W] (edge rest curvature K 1/m over "
                 "W mm, default 10), yield=K (bending yields at curvature K 1/m), shear=G (woven membrane, shear "
                 "stiffness G kg/s^2), friction=MU (Coulomb friction on the top instead of adhesion)");
  return [o] { return run_simulate(*o); };
}

}  // namespace drapegen::cli
