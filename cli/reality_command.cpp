// drapegen reality: a capture of a drape with effects the baseline model lacks, and its ground truth (issue 6).
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "commands.hpp"
#include "failure.hpp"
#include "drapegen/diagnosis/reality.hpp"
#include "drapegen/storage/json_text.hpp"
#include "parse.hpp"

namespace drapegen::cli {
namespace {

struct RealityOptions {
  std::vector<std::string> effects;
  std::string alpha;
  std::string beta = "0";
  double density = 300.0;
  int resolution = 30;
  std::uint64_t seed = 0;
  int placement = 0;
  bool turn_over = false;
  std::string out;
  bool noise = true;
  bool json = false;
  double measured_bending_error = 0.0;
};

const Failure fail{"reality"};

int run_reality(const RealityOptions& o) {
  diagnosis::RealitySpec spec;
  const auto alpha = parse_directional(o.alpha, "--alpha");
  if (!alpha) return fail(alpha.error().message);
  const auto beta = parse_directional(o.beta, "--beta");
  if (!beta) return fail(beta.error().message);
  if (!(alpha->warp > 0 && alpha->bias > 0 && alpha->weft > 0)) return fail("--alpha must be positive");
  if (!(o.density >= 1.0 && o.density <= 1e5)) return fail("--density must be between 1 and 100000 g/m^2");
  if (o.resolution < 5 || o.resolution > 200) return fail("--resolution must be between 5 and 200");
  spec.bending.alpha = *alpha;
  spec.bending.beta = *beta;
  spec.density = o.density;
  spec.resolution = o.resolution;
  spec.seed = o.seed;
  if (o.placement < 0 || o.placement > diagnosis::kMaxPlacement) {
    return fail(fmt::format("--placement must be between 0 and {}", diagnosis::kMaxPlacement));
  }
  spec.placement = o.placement;
  spec.turn_over = o.turn_over;
  spec.noise = o.noise;
  if (const double s = o.measured_bending_error;
      !(s == 0.0 || (s >= diagnosis::kMinMeasuredBendingError && s <= 1.0))) {
    return fail(
        fmt::format("--measured-bending-error must be 0 (none) or {:g} .. 1", diagnosis::kMinMeasuredBendingError));
  }
  spec.measured_bending_error = o.measured_bending_error;
  for (const auto& text : o.effects) {
    auto e = diagnosis::parse_reality_effect(text);
    if (!e) return fail(e.error().message);
    for (const auto& other : spec.effects)
      if (other.name == e->name) return fail(fmt::format("--effect {} given twice", e->name));
    spec.effects.push_back(*e);
  }
  if (sim::Status s = prepare_output_directory(o.out, "capture.json"); !s) return fail(s.error().message, kExitIo);
  auto r = diagnosis::generate_reality(spec, o.out);
  if (!r) return fail(r.error());  // exit 3 where an output could not be written, 1 otherwise
  if (o.json) {
    nlohmann::json j = {{"capture", o.out}, {"truth", r->truth_path}, {"seconds", r->seconds},
                        {"converged", r->converged}};
    std::cout << storage::json_text(j) << "\n";
  } else {
    std::cout << fmt::format("reality: capture written to {} in {:.1f} s (truth in {}, which the diagnosis never "
                             "reads){}\n",
                             o.out, r->seconds, r->truth_path, r->converged ? "" : "; the drape did not converge");
  }
  return r->converged ? kExitOk : kExitNotConverged;
}

}  // namespace

Runner add_reality_command(CLI::App& app) {
  auto o = std::make_shared<RealityOptions>();
  app.footer("Exit codes: 0 written; 1 bad input (one line on stderr says why); 2 written, but a drape did not "
             "converge (truth.json's \"converged\" says which); 3 an output could not be written.");
  app.add_option(
      "--effect", o->effects,
      "NAME[=STRENGTH], repeatable: yield=K (1/m), shear=G (kg/s^2), curl=K[,W] (1/m over W mm, default 30), "
      "friction=MU, misalign=MM, pose=DEG, bias=MM, multipath=MM (without --effect: a control)");
  app.add_option("--alpha", o->alpha, "Linear bending moduli W,B,F, g*mm^2/s^2")->required();
  app.add_option("--beta", o->beta, "Quadratic bending moduli W,B,F, g*mm^3/s^2 (use --beta=-...)")
      ->capture_default_str();
  app.add_option("--density", o->density, "Areal density, g/m^2")->capture_default_str();
  app.add_option("--resolution", o->resolution, "Vertices per side of the simulated specimen")->capture_default_str();
  app.add_option("--seed", o->seed,
                 "Seed of initial state, orientation, drift, camera, noise and the measured bending's error")
      ->check(kSeed)
      ->capture_default_str();
  app.add_option("--placement", o->placement,
                 "Placement K of the specimen: K > 0 re-drapes the same specimen (same fabric, effects and camera "
                 "calibration error) from another initial state, orientation, drift and noise: a second capture of "
                 "it. A yielding specimen keeps its plastic set: placement K starts from the set placements 0..K-1 "
                 "left (K + 1 drapes)")
      ->capture_default_str();
  app.add_flag("--turn-over", o->turn_over,
               "The specimen is turned over each time it is lifted: odd placements lie face down (capture.json "
               "\"face\": \"down\"), so a rest shape (edge curl, a yield's creases) bends the other way on them. "
               "Give it to every placement of one specimen (docs/CAPTURE.md)");
  app.add_option("--out", o->out, "Capture directory (capture.json, view0..3.exr, truth.json, preview.png); an earlier "
                                  "capture of drapegen reality there is replaced, any other refused")
      ->required();
  app.add_flag("!--no-noise", o->noise, "Clean depth (no sensor noise)");
  app.add_option("--measured-bending-error", o->measured_bending_error,
                 "SIGMA in 0.001 .. 1: the capture carries a measured bending, as a bending test (e.g. a cantilever) "
                 "of this precision would report it: each of --alpha/--beta times its own e^(SIGMA g), g standard "
                 "normal, the same on every placement, stated within a factor e^(2 SIGMA) (docs/CAPTURE.md, "
                 "\"Measured bending\"; default 0: none)");
  app.add_flag("--json", o->json, "Print the summary as JSON");
  return [o] { return run_reality(*o); };
}

}  // namespace drapegen::cli
