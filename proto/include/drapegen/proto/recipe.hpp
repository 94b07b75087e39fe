#pragma once
// Conversions between the sampler's initial-state recipe and its wire form (v1::Recipe), field for field.

#include "drapegen/proto/codec.hpp"
#include "drapegen/sampler/initial_state_recipe.hpp"

namespace drapegen::proto {

[[nodiscard]] v1::Recipe to_proto(const sampler::InitialStateRecipe& recipe);
/// Errors on an unknown kind or a recipe that breaks sampler::validate.
[[nodiscard]] sim::Expected<sampler::InitialStateRecipe> from_proto(const v1::Recipe& recipe);

}  // namespace drapegen::proto
