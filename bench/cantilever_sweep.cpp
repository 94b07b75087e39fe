// drapegen_cantilever_sweep: the simulated cantilever against the heavy elastica (the master curve of the paper's
// Fig. 10) over a range of Gamma = rho g L^3 / alpha, and the regression of Section 4.3.1 on strips cut at angles
// phi from the warp (Fig. 13) against Eq. 8. A plain program: prints tables, optionally JSON or CSV.
//
//   drapegen_cantilever_sweep [--segments 80] [--points 13] [--gamma-min 0.01] [--gamma-max 1000]
//                             [--length 0.1] [--width W] [--eq8-segments 40] [--tolerance 1e-3]
//                             [--skip-master] [--skip-eq8] [--json FILE] [--csv FILE]
//
// The master-curve sweep keeps L and the width fixed and sets alpha = rho g L^3 / Gamma (rho = 0.3 kg/m^2). The
// default width is 2 L: such a strip is held flat across by its clamp and behaves as the rod of the elastica; a
// narrow strip curls across and is softer (the lattice's Poisson ratio is -1/3, see cantilever.hpp), which
// --width 0.02 shows. The Eq. 8 strips (L = 0.05 m, width 2 L unless --width) are fitted by the regression and
// compared with Eq. 8 and with an isotropic strip of modulus Eq. 8(phi), which takes out the regression's
// coarse-curve bias.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "drapegen/sim/anisotropy.hpp"
#include "drapegen/sim/blas_kernels.hpp"
#include "drapegen/sim/cantilever.hpp"
#include "drapegen/sim/cantilever_fit.hpp"
#include "drapegen/sim/elastica.hpp"

namespace {

using namespace drapegen::sim;

struct Options {
  int segments = 80;
  int points = 13;
  double gamma_min = 0.01;
  double gamma_max = 1000.0;
  double length = 0.1;
  double width = 0.0;  // 0: twice the length
  int eq8_segments = 40;
  double density = kStandardDensity;
  double tolerance = 1e-3;
  bool master = true;
  bool eq8 = true;
  BendingModel model = BendingModel::kNonlinearDihedral;
  std::string json_path;
  std::string csv_path;
};

[[noreturn]] void usage(const char* program, int code) {
  std::fprintf(code == 0 ? stdout : stderr,
               "usage: %s [--segments N] [--points N] [--gamma-min G] [--gamma-max G] [--length m] [--width m]\n"
               "          [--eq8-segments N] [--tolerance t] [--model dihedral|triangle] [--skip-master] [--skip-eq8]\n"
               "          [--json FILE] [--csv FILE]\n",
               program);
  std::exit(code);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(argv[0], 2);
      return argv[++i];
    };
    try {
      if (a == "--segments") o.segments = std::stoi(value());
      else if (a == "--points") o.points = std::stoi(value());
      else if (a == "--gamma-min") o.gamma_min = std::stod(value());
      else if (a == "--gamma-max") o.gamma_max = std::stod(value());
      else if (a == "--length") o.length = std::stod(value());
      else if (a == "--width") o.width = std::stod(value());
      else if (a == "--eq8-segments") o.eq8_segments = std::stoi(value());
      else if (a == "--tolerance") o.tolerance = std::stod(value());
      else if (a == "--model") {
        const std::string m = value();
        if (m != "dihedral" && m != "triangle") usage(argv[0], 2);
        o.model = m == "triangle" ? BendingModel::kNonlinearTriangle : BendingModel::kNonlinearDihedral;
      } else if (a == "--skip-master") o.master = false;
      else if (a == "--skip-eq8") o.eq8 = false;
      else if (a == "--json") o.json_path = value();
      else if (a == "--csv") o.csv_path = value();
      else if (a == "--help" || a == "-h") usage(argv[0], 0);
      else usage(argv[0], 2);
    } catch (const std::exception&) {
      usage(argv[0], 2);
    }
  }
  if (o.segments < 2 || o.eq8_segments < 2 || o.points < 1 || !(o.gamma_min > 0.0) || !(o.gamma_max >= o.gamma_min) ||
      !(o.length > 0.0) || !(o.width >= 0.0) || !(o.tolerance > 0.0)) {
    usage(argv[0], 2);
  }
  return o;
}

struct MasterRow {
  double gamma = 0.0, hw_sim = 0.0, hw_ref = 0.0, alpha = 0.0, alpha_fit = 0.0;
  int iterations = 0;
  double seconds = 0.0;
  std::string outcome;
};

struct Eq8Row {
  double bias = 0.0, phi_deg = 0.0, gamma = 0.0, alpha_eq8 = 0.0, alpha_fit = 0.0, alpha_fit_isotropic = 0.0;
  double hw_sim = 0.0, hw_isotropic = 0.0, hw_ref = 0.0;
  int iterations = 0;
  double seconds = 0.0;
  std::string outcome;
};

double wall_seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

int main(int argc, char** argv) {
  drapegen::sim::relaunch_with_blas_kernels(argv);  // the kernels drapegen runs on (blas_kernels.hpp)
  const Options o = parse(argc, argv);
  constexpr double g = 9.81;
  const double width = o.width > 0.0 ? o.width : 2.0 * o.length;
  nlohmann::json out{{"segments", o.segments}, {"eq8_segments", o.eq8_segments}, {"length_m", o.length},
                     {"width_m", width},         {"density_kg_m2", o.density},   {"tolerance", o.tolerance}};
  std::vector<MasterRow> master;
  std::vector<Eq8Row> eq8;
  bool all_converged = true;

  if (o.master) {
    std::printf("Master curve: L = %g m, width = %g m, %d segments, rho = %g kg/m^2, tolerance %g\n", o.length,
                width, o.segments, o.density, o.tolerance);
    std::printf("%10s %12s %12s %9s %11s %6s %8s  %s\n", "Gamma", "H/W sim", "H/W elastica", "rel.err",
                "fit alpha", "iters", "seconds", "outcome");
    for (int k = 0; k < o.points; ++k) {
      const double t = o.points == 1 ? 0.0 : static_cast<double>(k) / (o.points - 1);
      const double gamma = o.gamma_min * std::pow(o.gamma_max / o.gamma_min, t);
      const double alpha = o.density * g * std::pow(o.length, 3) / gamma;
      CantileverSpec spec;
      spec.length = o.length;
      spec.width = width;
      spec.segments = o.segments;
      spec.bending_model = o.model;
      spec.fabric.alpha = {alpha, alpha, alpha};
      spec.fabric.density = o.density;
      spec.solver.tolerance = o.tolerance;
      const auto start = std::chrono::steady_clock::now();
      const Expected<CantileverResult> r = simulate_cantilever(spec);
      const double seconds = wall_seconds(start);
      if (!r) {
        std::fprintf(stderr, "Gamma %g: %s\n", gamma, r.error().message.c_str());
        all_converged = false;
        continue;
      }
      MasterRow row;
      row.gamma = r->gamma;
      row.hw_sim = r->height_over_width;
      const Expected<double> ref = master_curve_height_over_width(r->gamma);
      row.hw_ref = ref ? *ref : std::nan("");
      const Expected<BendingFit> fit = fit_bending_moduli(r->curve, o.density, g, false);
      row.alpha = alpha;
      row.alpha_fit = fit ? fit->alpha : std::nan("");
      row.iterations = r->report.iterations;
      row.seconds = seconds;
      row.outcome = std::string(to_string(r->report.outcome));
      all_converged = all_converged && r->report.outcome == SolveOutcome::kConverged;
      std::printf("%10.4g %12.6g %12.6g %+8.2f%% %+10.2f%% %6d %8.2f  %s\n", row.gamma, row.hw_sim, row.hw_ref,
                  100.0 * (row.hw_sim / row.hw_ref - 1.0), 100.0 * (row.alpha_fit / row.alpha - 1.0), row.iterations,
                  row.seconds,
                  row.outcome.c_str());
      std::fflush(stdout);
      master.push_back(row);
    }
  }

  if (o.eq8) {
    // Fig. 13, beta = 0, strips cut at phi from the warp. The first set has bias = (warp + weft) / 2, where Eq. 8
    // equals Eq. 7 (cos^2 warp + sin^2 weft); the second has a soft bias, where they differ by up to 30 %.
    const double length = 0.05;
    const double eq8_width = o.width > 0.0 ? o.width : 2.0 * length;
    const auto simulate = [&](const DirectionalValues& alpha, double phi) {
      CantileverSpec spec;
      spec.length = length;
      spec.width = eq8_width;
      spec.segments = o.eq8_segments;
      spec.bending_model = o.model;
      spec.fabric.alpha = alpha;
      spec.fabric.density = o.density;
      spec.cut_angle = phi;
      spec.anisotropy = AnisotropyRule::kCurvature;
      spec.solver.tolerance = o.tolerance;
      return simulate_cantilever(spec);
    };
    const DirectionalValues sets[] = {{1e-5, 2e-5, 3e-5}, {1e-5, 1.4e-5, 3e-5}};
    for (const DirectionalValues& alpha : sets) {
      std::printf("\nEq. 8 strips: alpha warp/bias/weft = %g/%g/%g N*m, L = %g m, width = %g m, %d segments, "
                  "curvature rule\n",
                  alpha.warp, alpha.bias, alpha.weft, length, eq8_width, o.eq8_segments);
      std::printf("%5s %7s %11s %11s %8s %9s %9s %9s %9s %5s %7s  %s\n", "phi", "Gamma", "alpha Eq.8", "alpha fit",
                  "fit/Eq8", "fit/iso", "H/W", "H/W/iso", "H/W/elas", "iters", "seconds", "outcome");
      for (int deg = 0; deg <= 90; deg += 15) {
        const double phi = deg * std::numbers::pi / 180.0;
        const double expected = interpolate_directional(alpha, phi);
        const auto start = std::chrono::steady_clock::now();
        const Expected<CantileverResult> r = simulate(alpha, phi);
        const double seconds = wall_seconds(start);
        const Expected<CantileverResult> iso = simulate(DirectionalValues{expected, expected, expected}, 0.0);
        if (!r || !iso) {
          std::fprintf(stderr, "phi %d: %s\n", deg, (!r ? r.error() : iso.error()).message.c_str());
          all_converged = false;
          continue;
        }
        Eq8Row row;
        row.bias = alpha.bias;
        row.phi_deg = deg;
        row.gamma = r->gamma;
        row.alpha_eq8 = expected;
        const Expected<BendingFit> fit = fit_bending_moduli(r->curve, o.density, g, false);
        const Expected<BendingFit> iso_fit = fit_bending_moduli(iso->curve, o.density, g, false);
        row.alpha_fit = fit ? fit->alpha : std::nan("");
        row.alpha_fit_isotropic = iso_fit ? iso_fit->alpha : std::nan("");
        row.hw_sim = r->height_over_width;
        row.hw_isotropic = iso->height_over_width;
        const Expected<double> ref = master_curve_height_over_width(r->gamma);
        row.hw_ref = ref ? *ref : std::nan("");
        row.iterations = r->report.iterations;
        row.seconds = seconds;
        row.outcome = std::string(to_string(r->report.outcome));
        all_converged = all_converged && r->report.outcome == SolveOutcome::kConverged &&
                        iso->report.outcome == SolveOutcome::kConverged;
        std::printf("%5.0f %7.4g %11.4g %11.4g %+7.2f%% %+8.2f%% %9.5g %+8.2f%% %+8.2f%% %5d %7.2f  %s\n", row.phi_deg,
                    row.gamma, row.alpha_eq8, row.alpha_fit, 100.0 * (row.alpha_fit / row.alpha_eq8 - 1.0),
                    100.0 * (row.alpha_fit / row.alpha_fit_isotropic - 1.0), row.hw_sim,
                    100.0 * (row.hw_sim / row.hw_isotropic - 1.0), 100.0 * (row.hw_sim / row.hw_ref - 1.0),
                    row.iterations, row.seconds, row.outcome.c_str());
        std::fflush(stdout);
        eq8.push_back(row);
      }
    }
  }

  if (!o.json_path.empty()) {
    nlohmann::json m = nlohmann::json::array(), e = nlohmann::json::array();
    for (const MasterRow& r : master) {
      m.push_back({{"gamma", r.gamma}, {"height_over_width", r.hw_sim}, {"elastica_height_over_width", r.hw_ref},
                   {"relative_error", r.hw_sim / r.hw_ref - 1.0}, {"alpha", r.alpha}, {"alpha_fit", r.alpha_fit},
                   {"iterations", r.iterations}, {"seconds", r.seconds}, {"outcome", r.outcome}});
    }
    for (const Eq8Row& r : eq8) {
      e.push_back({{"alpha_bias", r.bias}, {"phi_deg", r.phi_deg}, {"gamma", r.gamma}, {"alpha_eq8", r.alpha_eq8},
                   {"alpha_fit", r.alpha_fit}, {"alpha_fit_isotropic", r.alpha_fit_isotropic},
                   {"height_over_width", r.hw_sim}, {"isotropic_height_over_width", r.hw_isotropic},
                   {"elastica_height_over_width", r.hw_ref},
                   {"iterations", r.iterations}, {"seconds", r.seconds}, {"outcome", r.outcome}});
    }
    out["master_curve"] = m;
    out["eq8_strips"] = e;
    std::ofstream(o.json_path) << out.dump(2) << "\n";
  }
  if (!o.csv_path.empty()) {
    std::ofstream csv(o.csv_path);
    csv << "table,gamma,phi_deg,height_over_width,reference_height_over_width,alpha_expected,alpha_fit,iterations,"
           "seconds,outcome\n";
    for (const MasterRow& r : master) {
      csv << fmt::format("master,{},,{},{},{},{},{},{},{}\n", r.gamma, r.hw_sim, r.hw_ref, r.alpha, r.alpha_fit,
                         r.iterations, r.seconds, r.outcome);
    }
    for (const Eq8Row& r : eq8) {
      // For the Eq. 8 strips the reference H/W is that of the isotropic strip of modulus Eq. 8(phi).
      csv << fmt::format("eq8_bias_{},{},{},{},{},{},{},{},{},{}\n", r.bias, r.gamma, r.phi_deg, r.hw_sim,
                         r.hw_isotropic, r.alpha_eq8, r.alpha_fit, r.iterations, r.seconds, r.outcome);
    }
  }
  return all_converged ? 0 : 1;
}
