// drapegen cantilever: the physical-validation strip of the paper's Fig. 10.
#include <cmath>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "commands.hpp"
#include "failure.hpp"
#include "drapegen/sim/cantilever.hpp"
#include "drapegen/sim/cantilever_fit.hpp"
#include "drapegen/sim/elastica.hpp"
#include "drapegen/storage/json_text.hpp"

namespace drapegen::cli {
namespace {

struct CantileverOptions {
  double length = 0.0;
  double alpha = 0.0;
  double beta = 0.0;
  double density = 300.0;
  double width = 0.0;  // 0: twice the length
  int segments = 40;
  bool json = false;
};

const Failure fail{"cantilever"};

int run_cantilever(const CantileverOptions& o) {
  // Beyond a few metres no fabric strip stays in the validated Gamma range, and the solve runs for minutes.
  if (!(o.length > 0.0 && o.length <= 10.0)) return fail("--length must be positive and at most 10 (m)");
  if (!(o.alpha > 0.0) || !std::isfinite(o.alpha)) return fail("--alpha must be positive (g*mm^2/s^2)");
  if (!std::isfinite(o.beta)) return fail("--beta must be finite (g*mm^3/s^2)");
  if (!(o.density > 0.0) || !std::isfinite(o.density)) return fail("--density must be positive (g/m^2)");
  if (!(o.width >= 0.0) || !std::isfinite(o.width)) return fail("--width must be positive (m), or 0 for 2 x length");
  if (o.segments < 4 || o.segments > 2000) return fail("--segments must be between 4 and 2000");
  if (o.width > 20.0 * o.length) return fail("--width must be at most 20 x --length");
  if (!(o.density >= 1.0 && o.density <= 1e5)) return fail("--density must be between 1 and 100000 g/m^2");

  sim::CantileverSpec spec;
  spec.length = o.length;
  spec.width = o.width > 0.0 ? o.width : 2.0 * o.length;
  spec.segments = o.segments;
  spec.fabric = sim::fabric_from_paper_units({o.alpha, o.alpha, o.alpha}, {o.beta, o.beta, o.beta}, o.density);
  const auto result = sim::simulate_cantilever(spec);
  if (!result) return fail(result.error().message);

  // docs/PHYSICS.md: within 1.5% of the elastica's master curve for Gamma 0.01 .. 1000; outside it, said.
  const bool validated = result->gamma >= 0.01 && result->gamma <= 1000.0;
  nlohmann::json out{{"gamma", result->gamma},
                     {"gamma_within_validated_range", validated},
                     {"height_over_width", result->height_over_width},
                     {"outcome", std::string(sim::to_string(result->report.outcome))},
                     {"iterations", result->report.iterations},
                     {"seconds", result->report.seconds}};
  nlohmann::json curve = nlohmann::json::array();
  for (const auto& p : result->curve) curve.push_back({p.x(), p.y()});
  out["deflection_curve_m"] = curve;
  const auto reference = sim::solve_heavy_cantilever(o.length, spec.fabric.alpha.warp, spec.fabric.beta.warp,
                                                     spec.fabric.density);
  if (reference) out["elastica_height_over_width"] = reference->height_over_width;
  const auto fit = sim::fit_bending_moduli(result->curve, spec.fabric.density, spec.gravity, o.beta != 0.0);
  if (fit) {
    out["fitted_alpha"] = fit->alpha * 1e9;
    out["fitted_beta"] = fit->beta * 1e12;
  }
  if (o.json) {
    std::cout << storage::json_text(out) << "\n";
  } else {
    std::cout << fmt::format("cantilever: {} ({} iterations), Gamma = {:.4g}, H/W = {:.4f}",
                             out["outcome"].get<std::string>(), result->report.iterations, result->gamma,
                             result->height_over_width);
    if (reference) std::cout << fmt::format(" (elastica {:.4f})", reference->height_over_width);
    std::cout << "\n";
    if (!validated) {
      std::cout << "  note: Gamma outside 0.01 .. 1000, where the lattice is validated against the elastica "
                   "(docs/PHYSICS.md); the regression below may not recover the moduli\n";
    }
    if (fit)
      std::cout << fmt::format("  regression: alpha {:.6g} g*mm^2/s^2, beta {:.6g} g*mm^3/s^2\n", fit->alpha * 1e9,
                               fit->beta * 1e12);
  }
  return result->report.outcome == sim::SolveOutcome::kConverged ? kExitOk : kExitNotConverged;
}

}  // namespace

Runner add_cantilever_command(CLI::App& app) {
  auto o = std::make_shared<CantileverOptions>();
  app.add_option("--length", o->length, "Free length of the strip, m (at most 10)")->required();
  app.add_option("--alpha", o->alpha, "Linear bending modulus, g*mm^2/s^2")->required();
  app.add_option("--beta", o->beta, "Quadratic bending modulus, g*mm^3/s^2")->capture_default_str();
  app.add_option("--density", o->density, "Areal density, g/m^2")->capture_default_str();
  app.add_option("--width", o->width,
                 "Strip width, m (default 0: twice the length; the hinge model curls narrow strips across and makes "
                 "them up to ~8% softer, see docs/PHYSICS.md)");
  app.add_option("--segments", o->segments, "Elements along the length")->capture_default_str();
  app.add_flag("--json", o->json, "Print JSON: gamma, height_over_width, deflection curve, elastica reference, fit");
  return [o] { return run_cantilever(*o); };
}

}  // namespace drapegen::cli
