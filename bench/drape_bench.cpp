// Timing benchmark of the quasistatic drape (docs/BENCHMARKS.md): fabrics from sampler/data/fabrics618.csv
// spanning soft to stiff, every initial-state type, one core. Prints one line per drape and a summary.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <functional>
#include <cmath>
#include <ctime>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include <fmt/format.h>

#include "drapegen/sim/blas_kernels.hpp"
#include "drapegen/sim/drape.hpp"
#include "drapegen/sim/median.hpp"
#include "drapegen/sim/ply.hpp"

namespace {

using drapegen::sim::median;

struct Fabric {
  double density;  // kg/m^2
  drapegen::sim::DirectionalValues alpha, beta;  // paper units, normalised to 300 g/m^2
};

std::vector<Fabric> read_fabrics(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::string line;
  std::getline(in, line);  // header: density, linear warp, weft, diag, nonlinear warp, weft, diag
  std::vector<Fabric> out;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::vector<double> v;
    for (std::string cell; std::getline(ss, cell, ',');) v.push_back(std::stod(cell));
    if (v.size() != 7) continue;
    const double s = drapegen::sim::kStandardDensity / v[0];  // k / rho at the standard density
    out.push_back({v[0], {v[1] * s, v[3] * s, v[2] * s}, {v[4] * s, v[6] * s, v[5] * s}});
  }
  return out;
}

}  // namespace

/// CPU time of this process (the solver is single-threaded: OpenBLAS serial), less sensitive than wall time to
/// other programs on a shared machine.
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

int main(int argc, char** argv) {
  drapegen::sim::relaunch_with_blas_kernels(argv);  // the kernels drapegen runs on (blas_kernels.hpp)
  CLI::App app{"drape timing benchmark"};
  std::string data = DRAPEGEN_FABRIC_DATA_DEFAULT;
  int resolution = 100, fabrics = 5;
  std::vector<std::string> inits{"flat", "sine", "fold"};
  bool json = false;
  int pcg_iterations = drapegen::sim::SolverOptions{}.max_pcg_iterations;
  double pcg_tolerance = drapegen::sim::SolverOptions{}.pcg_tolerance;
  int coarse = drapegen::sim::DrapeConfig{}.coarse_start_resolution;
  app.add_option("--pcg-iterations", pcg_iterations, "SolverOptions::max_pcg_iterations (0: factorise every step)")
      ->capture_default_str();
  app.add_option("--pcg-tolerance", pcg_tolerance, "SolverOptions::pcg_tolerance")->capture_default_str();
  double outer_below = drapegen::sim::DrapeConfig{}.solver.lagged_outer_below;
  double refactor_fraction = drapegen::sim::SolverOptions{}.pcg_refactor_fraction;
  app.add_option("--pcg-refactor", refactor_fraction, "SolverOptions::pcg_refactor_fraction")->capture_default_str();
  double gn_above = drapegen::sim::DrapeConfig{}.solver.gauss_newton_above;
  app.add_option("--gn-above", gn_above, "SolverOptions::gauss_newton_above")->capture_default_str();
  app.add_option("--outer-below", outer_below,
                 "SolverOptions::lagged_outer_below (effects with lagged forces use at most 3)")
      ->capture_default_str();
  double exact_below = drapegen::sim::SolverOptions{}.exact_hessian_below;
  int max_iterations = drapegen::sim::SolverOptions{}.max_iterations;
  app.add_option("--exact-below", exact_below, "SolverOptions::exact_hessian_below")->capture_default_str();
  app.add_option("--max-iterations", max_iterations, "SolverOptions::max_iterations")->capture_default_str();
  double tolerance = drapegen::sim::SolverOptions{}.tolerance;
  app.add_option("--tolerance", tolerance, "SolverOptions::tolerance (residual relative to the largest vertex weight)")
      ->capture_default_str();
  double extrapolate = drapegen::sim::SolverOptions{}.extrapolate_above;
  app.add_option("--extrapolate", extrapolate, "SolverOptions::extrapolate_above (0: off)")->capture_default_str();
  std::string model = "dihedral";
  app.add_option("--bending-model", model, "dihedral (paper, per hinge) or triangle (per-triangle curvature tensors)")
      ->check(CLI::IsMember({"dihedral", "triangle"}))
      ->capture_default_str();
  std::vector<int> only;
  app.add_option("--only", only, "run only these of the --fabrics quantiles (0-based)")->delimiter(',');
  app.add_option("--coarse", coarse, "DrapeConfig::coarse_start_resolution (0: off)")->capture_default_str();
  app.add_option("--data", data, "fabrics618.csv")->capture_default_str();
  app.add_option("--resolution", resolution, "vertices per side")->capture_default_str();
  app.add_option("--fabrics", fabrics, "fabrics at evenly spaced quantiles of mean alpha")->capture_default_str();
  app.add_option("--inits", inits, "initial states")->delimiter(',')->capture_default_str();
  app.add_flag("--json", json, "one JSON object per drape");
  std::string save_dir;
  app.add_option("--save", save_dir,
                 "write each draped mesh to DIR/fabric<index>_<init>.ply (for comparing two builds' drapes)");
  bool verbose = false;
  app.add_flag("--verbose", verbose, "print every Newton iteration on stderr");
  CLI11_PARSE(app, argc, argv);

  std::vector<Fabric> all = read_fabrics(data);
  std::sort(all.begin(), all.end(), [](const Fabric& a, const Fabric& b) {
    return a.alpha.warp + a.alpha.bias + a.alpha.weft < b.alpha.warp + b.alpha.bias + b.alpha.weft;
  });
  std::vector<double> seconds, cpu_times, iterations, factor_share;
  int converged = 0, total = 0;
  for (int f = 0; f < fabrics; ++f) {
    const std::size_t index = fabrics == 1 ? all.size() / 2 : (all.size() - 1) * f / (fabrics - 1);
    const Fabric& fabric = all[index];
    if (!only.empty() && std::find(only.begin(), only.end(), f) == only.end()) continue;
    for (const std::string& init : inits) {
      drapegen::sim::DrapeConfig config;
      config.fabric = drapegen::sim::fabric_from_paper_units(fabric.alpha, fabric.beta, 300.0);
      config.specimen.vertices_x = config.specimen.vertices_y = resolution;
      config.specimen.seed = 100 + f;
      config.solver.max_pcg_iterations = pcg_iterations;
      config.solver.pcg_tolerance = pcg_tolerance;
      config.solver.lagged_outer_below = outer_below;
      config.solver.pcg_refactor_fraction = refactor_fraction;
      config.solver.gauss_newton_above = gn_above;
      config.solver.exact_hessian_below = exact_below;
      config.solver.max_iterations = max_iterations;
      config.solver.tolerance = tolerance;
      if (model == "triangle") config.bending_model = drapegen::sim::BendingModel::kNonlinearTriangle;
      config.solver.extrapolate_above = extrapolate;
      config.coarse_start_resolution = coarse;
      auto initial = drapegen::sim::parse_initial_state(init);
      config.initial = *initial;
      config.initial.seed = 7 + f;
      std::function<void(const drapegen::sim::IterationInfo&)> progress;
      if (verbose) {
        progress = [](const drapegen::sim::IterationInfo& i) {
          std::cerr << fmt::format("iter {:4d} energy {:.9e} residual {:.3e} step {:.3g} shift {:.1e}\n", i.iteration,
                                   i.energy, i.residual, i.step_length, i.regularization);
        };
      }
      const double cpu_start = cpu_seconds();
      const auto result = drapegen::sim::simulate_drape(config, progress);
      const double cpu = cpu_seconds() - cpu_start;
      if (!result) {
        std::cerr << "error: " << result.error().message << "\n";
        return 1;
      }
      if (!save_dir.empty()) {
        const auto saved =
            drapegen::sim::write_ply(fmt::format("{}/fabric{}_{}.ply", save_dir, index, init), result->mesh);
        if (!saved) {
          std::cerr << "error: " << saved.error().message << "\n";
          return 1;
        }
      }
      const auto& r = result->report;
      const auto& c = result->coarse_report;
      const double wall = r.seconds + c.seconds;  // the coarse-to-fine cascade is part of the drape
      ++total;
      converged += r.outcome == drapegen::sim::SolveOutcome::kConverged;
      seconds.push_back(wall);
      cpu_times.push_back(cpu);
      iterations.push_back(r.iterations);
      factor_share.push_back((r.factorization_seconds + c.factorization_seconds) / wall);
      if (json) {
        nlohmann::json j = drapegen::sim::to_json(*result);
        j["fabric_index"] = index;
        j["init"] = init;
        std::cout << j.dump() << "\n";
      } else {
        std::cout << fmt::format(
            "fabric {:3d} alpha {:7.0f},{:7.0f},{:7.0f} beta {:8.0f},{:8.0f},{:8.0f} {:5s}: {:15s} {:4d} it "
            "(+{:3d} coarse) {:6.2f} s, CPU {:6.2f} s (coarse {:4.2f} s, factorisation {:4.1f}%, PCG {:4.1f}%, "
            "assembly {:4.1f}%, {} of {} steps by PCG, {} CG it, {} failed PCG) DC {:.3f} folds {}\n",
            index, fabric.alpha.warp, fabric.alpha.bias, fabric.alpha.weft, fabric.beta.warp, fabric.beta.bias,
            fabric.beta.weft, init, drapegen::sim::to_string(r.outcome), r.iterations, c.iterations, wall, cpu,
            c.seconds, 100 * factor_share.back(), 100 * (r.pcg_seconds + c.pcg_seconds) / wall,
            100 * (r.assembly_seconds + c.assembly_seconds) / wall, r.reused_factorizations + c.reused_factorizations,
            r.iterations + c.iterations, r.pcg_iterations + c.pcg_iterations, r.pcg_failures + c.pcg_failures,
            result->measures.drape_coefficient, result->measures.folds);
      }
      std::cout.flush();
    }
  }
  std::cout << fmt::format(
      "summary: {}x{} vertices, {} drapes, {} converged; seconds median {:.2f} max {:.2f}; CPU seconds median {:.2f} "
      "max {:.2f}; full-resolution iterations median {:.0f} max {:.0f}; factorisation share median {:.0f}%; BLAS {}\n",
      resolution, resolution, total, converged, median(seconds), *std::max_element(seconds.begin(), seconds.end()),
      median(cpu_times), *std::max_element(cpu_times.begin(), cpu_times.end()),
      median(iterations), *std::max_element(iterations.begin(), iterations.end()), 100 * median(factor_share),
      drapegen::sim::blas_kernels_description());
  return converged == total ? 0 : 2;
}
