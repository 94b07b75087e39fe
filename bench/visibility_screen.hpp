#pragma once
// Is an effect in a benchmark capture visible at all? The capture (and its second placement, if any) is gated as
// `drapegen diagnose --fine --held-out-capture` gates its gap (the forward model, validation states, floors and shape
// floor of DiagnosisSettings::fine()), but against the specimen's true bending without the effect instead of a fitted
// one: if even the true fabric leaves no excess above the floors, the effect does not stand out from the fabric's own
// multistability. (A fit can still end above the floors, or absorb a visible effect: the screen does not predict the
// verdict.) Reads the truth, so it is a benchmark tool (diagnosis_bench --visible-only), never part of the diagnosis.

#include <string>

#include "drapegen/diagnosis/fabric_space.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::bench {

struct Visibility {
  double excess = 0.0;       // excess_above_floors of the true fabric's gap (0: the effect is within the floors)
  double stable_mm = 0.0, stable_floor_mm = 0.0;
  double shape = 0.0, shape_floor = 0.0;
  [[nodiscard]] bool visible() const { return excess > 0.0; }
};

/// `held_out_directory` empty: the capture alone.
[[nodiscard]] sim::Expected<Visibility> effect_visibility(const std::string& capture_directory,
                                                          const std::string& held_out_directory,
                                                          const diagnosis::BendingParameters& true_bending);

}  // namespace drapegen::bench
