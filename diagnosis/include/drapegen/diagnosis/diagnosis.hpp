#pragma once
// The whole diagnosis of one capture: baseline fit, floors, localisation, attribution (docs/DIAGNOSIS.md).

#include <nlohmann/json_fwd.hpp>
#include <string>

#include "drapegen/diagnosis/attribution.hpp"
#include "drapegen/diagnosis/floors.hpp"
#include "drapegen/diagnosis/localisation.hpp"

namespace drapegen::diagnosis {

struct DiagnosisSettings {
  FitSettings fit;
  NelderMeadOptions baseline_optimiser{.max_evaluations = 40};
  int guess_levels = 4;        // simulations for the initial guess (drape coefficient against alpha)
  FloorSettings floors;
  AttributionSettings attribution;

  /// Small budgets for tests and the --quick benchmark.
  [[nodiscard]] static DiagnosisSettings quick();
};

struct DiagnosisResult {
  BendingParameters initial_guess;
  BendingParameters fitted;
  ReducedBending fitted_reduced{};
  int baseline_evaluations = 0;
  std::vector<double> baseline_history;
  Evaluation fit;
  /// The fitted parameters from the validation states (AttributionSettings): the gap is measured on its best drape,
  /// which no fit selected on (the fit's own best is the luckiest of its evaluations of a multistable objective).
  Evaluation validated;
  [[nodiscard]] const ScoredDrape& gap_drape() const { return validated.best; }
  Floors floors;
  double gap_all = 0.0, gap_fit = 0.0, gap_held_out = 0.0;
  bool within_floors = false;
  Localisation localisation;
  ShapeSet fit_target;  // the capture's shape features
  Attribution attribution;
  /// The verdict: the named effect ("none" within the floors, "unexplained" if no candidate shrinks it enough).
  std::string verdict;
  std::string runner_up;
  int simulations = 0;
  double seconds = 0.0;
  double seconds_fit = 0.0, seconds_floors = 0.0, seconds_attribution = 0.0;
};

[[nodiscard]] sim::Expected<DiagnosisResult> diagnose(const Capture& capture, const DiagnosisSettings& settings);

[[nodiscard]] nlohmann::json to_json(const DiagnosisResult& result, const Capture& capture);

}  // namespace drapegen::diagnosis
