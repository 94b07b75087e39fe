#pragma once
// The unmodelled effects the diagnosis can add to the baseline, each with its own parameters, their search space,
// and the specimen region where it acts.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drapegen/diagnosis/model_setup.hpp"

namespace drapegen::diagnosis {

enum class Effect { kYield, kShear, kCurl, kFriction, kMisalignment, kSensor };
inline constexpr Effect kAllEffects[] = {Effect::kYield,    Effect::kShear,        Effect::kCurl,
                                         Effect::kFriction, Effect::kMisalignment, Effect::kSensor};

/// "yield", "shear", "curl", "friction", "misalignment", "sensor".
[[nodiscard]] std::string_view effect_name(Effect effect);
[[nodiscard]] std::optional<Effect> parse_effect(std::string_view name);
/// Whether the effect changes the simulation (else only the rendering: the sensor).
[[nodiscard]] bool needs_simulation(Effect effect);

/// The effect's parameters in the refit: start, initial simplex step, bounds, names (with units).
struct EffectSpace {
  std::vector<std::string> names;
  std::vector<double> start, step, lower, upper;
};
[[nodiscard]] EffectSpace effect_space(Effect effect);
/// Puts the effect with parameters x (as in effect_space) into `setup`.
void apply_effect(Effect effect, const std::vector<double>& x, ModelSetup& setup);
/// Edge curl's band width in the refit (the reality generator's default too), m.
constexpr double kCurlWidth = 0.03;

/// Specimen regions of the localisation.
enum class Region { kTop, kRim, kSkirt, kHem, kCylinder, kGlobal };
[[nodiscard]] std::string_view region_name(Region region);
/// Where each effect acts (the truth the localisation is checked against): yield and shear the skirt's folds, curl
/// and misalignment the hem, friction the rim and the platform top, sensor errors everywhere (kGlobal; the reality
/// generator's truth for multipath is where its rendered error stands out: ErrorFootprint::regions).
[[nodiscard]] std::vector<Region> effect_regions(Effect effect);

}  // namespace drapegen::diagnosis
