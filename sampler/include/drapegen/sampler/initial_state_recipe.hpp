#pragma once
// A job's initial state as a plain value (paper Section 5.2.1): what the simulator needs to rebuild it bit for bit,
// with a stable one-line text form and a JSON form (the coordinator stores recipes in its manifest and sends them to
// workers).

#include <cstdint>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "drapegen/sim/expected.hpp"
#include "drapegen/sim/initial_state.hpp"
#include "drapegen/sim/specimen.hpp"

namespace drapegen::sampler {

enum class RecipeKind {
  kSine,   // random sine waves on the flat specimen (Fig. 16a); the waves are drawn from shape_seed
  kFold,   // a fold along a random line (Fig. 16b); the line is drawn from shape_seed, then turned by rotation
  kDrape,  // the simulated drape of another sample (source_sample, source_slot)
};

[[nodiscard]] const char* to_string(RecipeKind kind);

/// Identifies one simulated drape of the data set: sample index and initial-state slot.
struct DrapeRef {
  std::int64_t sample = -1;
  int slot = -1;
  friend bool operator==(const DrapeRef&, const DrapeRef&) = default;
};

struct InitialStateRecipe {
  std::int64_t sample = 0;   // the parameter vector this job simulates
  int slot = 0;              // which of its initial states (0 .. states_per_sample - 1)
  RecipeKind kind = RecipeKind::kSine;
  std::uint64_t shape_seed = 0;          // sine waves / fold line (sim::InitialStateSpec::seed)
  std::uint64_t triangulation_seed = 0;  // perturbation of the specimen triangulation (sim::SpecimenSpec::seed)
  double rotation = 0.0;                 // radians about the platform axis, [0, 2 pi)
  double drift_x_mm = 0.0, drift_y_mm = 0.0;  // specimen centre relative to the platform axis
  DrapeRef source;                       // kDrape only: whose drape starts this one

  friend bool operator==(const InitialStateRecipe&, const InitialStateRecipe&) = default;
};

/// One line, fields in a fixed order, reals in shortest round-trip form, e.g.
/// "sample=12 slot=3 kind=fold shape_seed=... triangulation_seed=... rotation=1.25 drift_mm=0.5,-1.75 source=-"
/// ("source=7/2" for kDrape). Parsing it back gives an identical recipe.
[[nodiscard]] std::string to_text(const InitialStateRecipe& recipe);
[[nodiscard]] sim::Expected<InitialStateRecipe> parse_recipe_text(const std::string& text);

/// {"sample":12,"slot":3,"kind":"fold","shape_seed":...,"triangulation_seed":...,"rotation":1.25,
///  "drift_mm":[0.5,-1.75],"source":null | {"sample":7,"slot":2}}. Seeds are JSON integers (uint64).
[[nodiscard]] nlohmann::json to_json(const InitialStateRecipe& recipe);
[[nodiscard]] sim::Expected<InitialStateRecipe> recipe_from_json(const nlohmann::json& json);

/// Checks the fields: non-negative sample and slot, rotation in [0, 2 pi), finite drift, and a source (of another
/// sample) exactly for kDrape.
[[nodiscard]] sim::Status validate(const InitialStateRecipe& recipe);

/// Where the drape `ref` is stored (a PLY file written by `drapegen simulate --out`), for kDrape recipes.
using DrapeLocator = std::function<std::string(const DrapeRef&)>;

/// The simulator's initial state for `recipe` (kDrape needs `locate` to find the source mesh).
[[nodiscard]] sim::Expected<sim::InitialStateSpec> to_initial_state(const InitialStateRecipe& recipe,
                                                                   const DrapeLocator& locate = {});
/// Sets the triangulation seed of `specimen` from the recipe. kDrape jobs start from the source mesh, whose
/// triangulation replaces the specimen's (sim::apply_initial_state), so their own seed only matters to coarser
/// levels, which the simulator skips for mesh initial states.
void apply_triangulation(const InitialStateRecipe& recipe, sim::SpecimenSpec& specimen);

}  // namespace drapegen::sampler
