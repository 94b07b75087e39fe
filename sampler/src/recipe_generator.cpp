#include "drapegen/sampler/recipe_generator.hpp"

#include <cmath>
#include <fmt/format.h>
#include <numbers>
#include <optional>

#include "drapegen/sampler/random.hpp"

namespace drapegen::sampler {
namespace {

constexpr std::uint64_t kRecipeStream = 2;

bool weight_ok(double w) { return w >= 0.0 && std::isfinite(w); }

/// Draws one recipe; `pick_source(rng)` returns a source drape or nothing (then sine or fold).
template <class PickSource>
InitialStateRecipe draw(const RecipeOptions& o, std::int64_t sample, int slot, PickSource pick_source) {
  Random rng(
      derive_seed(o.seed, {kRecipeStream, static_cast<std::uint64_t>(sample), static_cast<std::uint64_t>(slot)}));
  InitialStateRecipe r;
  r.sample = sample;
  r.slot = slot;
  // The same number of draws whatever the kind, so every field is a fixed function of the stream.
  const double kind_draw = rng.uniform() * (o.weight_sine + o.weight_fold + o.weight_drape);
  const double fallback_draw = rng.uniform() * (o.weight_sine + o.weight_fold);
  r.shape_seed = rng.next_u64();
  r.triangulation_seed = rng.next_u64();
  r.rotation = 2.0 * std::numbers::pi * rng.uniform();
  const double radius = o.max_drift_mm * std::sqrt(rng.uniform());
  const double angle = 2.0 * std::numbers::pi * rng.uniform();
  r.drift_x_mm = radius * std::cos(angle);
  r.drift_y_mm = radius * std::sin(angle);
  const std::uint64_t source_draw = rng.next_u64();
  const RecipeKind fallback = fallback_draw < o.weight_sine ? RecipeKind::kSine : RecipeKind::kFold;
  if (kind_draw < o.weight_sine) {
    r.kind = RecipeKind::kSine;
  } else if (kind_draw < o.weight_sine + o.weight_fold) {
    r.kind = RecipeKind::kFold;
  } else if (const auto source = pick_source(source_draw)) {
    r.kind = RecipeKind::kDrape;
    r.source = *source;
  } else {
    r.kind = fallback;
  }
  return r;
}

}  // namespace

sim::Status validate(const RecipeOptions& o) {
  if (o.states_per_sample < 1 || o.states_per_sample > kMaxStatesPerSample) {
    return sim::Error{fmt::format("states per sample must be 1..{}", kMaxStatesPerSample)};
  }
  if (!weight_ok(o.weight_sine) || !weight_ok(o.weight_fold) || !weight_ok(o.weight_drape) ||
      !(o.weight_sine + o.weight_fold > 0.0)) {
    return sim::Error{"initial-state weights must be >= 0 with sine + fold > 0"};
  }
  if (!(o.max_drift_mm >= 0.0) || !(o.max_drift_mm <= kMaxDriftMm)) {
    return sim::Error{fmt::format("max drift must be 0..{} mm", kMaxDriftMm)};
  }
  return {};
}

std::vector<InitialStateRecipe> make_recipes(const RecipeOptions& o, std::int64_t sample,
                                             std::span<const DrapeRef> existing) {
  std::vector<InitialStateRecipe> out;
  out.reserve(o.states_per_sample);
  for (int slot = 0; slot < o.states_per_sample; ++slot) {
    out.push_back(draw(o, sample, slot, [&](std::uint64_t u) -> std::optional<DrapeRef> {
      // Uniform over the existing drapes of other samples: count them, then take the (u mod count)-th.
      std::size_t count = 0;
      for (const DrapeRef& d : existing) count += d.sample != sample;
      if (count == 0) return std::nullopt;
      Random pick(u);
      std::size_t k = pick.below(count);
      for (const DrapeRef& d : existing) {
        if (d.sample == sample) continue;
        if (k-- == 0) return d;
      }
      return std::nullopt;
    }));
  }
  return out;
}

std::vector<InitialStateRecipe> make_recipes_in_order(const RecipeOptions& o, std::int64_t sample) {
  std::vector<InitialStateRecipe> out;
  out.reserve(o.states_per_sample);
  const std::uint64_t earlier = static_cast<std::uint64_t>(sample) * static_cast<std::uint64_t>(o.states_per_sample);
  for (int slot = 0; slot < o.states_per_sample; ++slot) {
    out.push_back(draw(o, sample, slot, [&](std::uint64_t u) -> std::optional<DrapeRef> {
      if (earlier == 0) return std::nullopt;
      Random pick(u);
      const std::uint64_t k = pick.below(earlier);
      return DrapeRef{static_cast<std::int64_t>(k / o.states_per_sample), static_cast<int>(k % o.states_per_sample)};
    }));
  }
  return out;
}

}  // namespace drapegen::sampler
