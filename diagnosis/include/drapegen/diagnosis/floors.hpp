#pragma once
// The two floors the baseline cannot go below, at the fitted parameters: the sensor-noise floor (the fitted drape
// re-rendered with other noise seeds, taken as the capture) and the multistability floor (the fitted parameters
// simulated from other initial states, rendered with noise, taken as the capture). Each sample is scored exactly as
// the capture is (best over the fit's initial-state drapes).

#include <vector>

#include "drapegen/diagnosis/forward_model.hpp"

namespace drapegen::diagnosis {

struct FloorSamples {
  std::vector<double> all;       // score over all views
  std::vector<double> held_out;  // score over the held-out views
  std::vector<double> stable;    // the stable-region term over all views (m)
  std::vector<std::vector<double>> groups;  // per sample: group_differences over all views (m)
};

struct Floors {
  FloorSamples noise;
  FloorSamples multistability;
  /// The floor a gap is compared with: the largest sample of either kind, times `margin`.
  double all = 0.0;
  double held_out = 0.0;
  double margin = 1.15;

  /// The largest sample of either kind, per feature group / of the stable term (no margin).
  [[nodiscard]] std::vector<double> group_floor() const;
  [[nodiscard]] double stable_floor() const;
};

struct FloorSettings {
  int noise_seeds = 3;
  int extra_states = 3;      // sine seeds after the fit's
  double margin = 1.15;
};

[[nodiscard]] sim::Expected<Floors> measure_floors(ForwardModel& model, const ModelSetup& fitted,
                                                   const Evaluation& fit, const FloorSettings& settings);

}  // namespace drapegen::diagnosis
