#include "drapegen/proto/recipe.hpp"

namespace drapegen::proto {

v1::Recipe to_proto(const sampler::InitialStateRecipe& r) {
  v1::Recipe out;
  out.set_sample(r.sample);
  out.set_slot(r.slot);
  switch (r.kind) {
    case sampler::RecipeKind::kSine: out.set_kind(v1::Recipe::KIND_SINE); break;
    case sampler::RecipeKind::kFold: out.set_kind(v1::Recipe::KIND_FOLD); break;
    case sampler::RecipeKind::kDrape: out.set_kind(v1::Recipe::KIND_DRAPE); break;
  }
  out.set_shape_seed(r.shape_seed);
  out.set_triangulation_seed(r.triangulation_seed);
  out.set_rotation(r.rotation);
  out.set_drift_x_mm(r.drift_x_mm);
  out.set_drift_y_mm(r.drift_y_mm);
  out.set_source_sample(r.source.sample);
  out.set_source_slot(r.source.slot);
  return out;
}

sim::Expected<sampler::InitialStateRecipe> from_proto(const v1::Recipe& p) {
  sampler::InitialStateRecipe r;
  r.sample = p.sample();
  r.slot = p.slot();
  switch (p.kind()) {
    case v1::Recipe::KIND_SINE: r.kind = sampler::RecipeKind::kSine; break;
    case v1::Recipe::KIND_FOLD: r.kind = sampler::RecipeKind::kFold; break;
    case v1::Recipe::KIND_DRAPE: r.kind = sampler::RecipeKind::kDrape; break;
    default: return sim::Error{"recipe: unknown kind"};
  }
  r.shape_seed = p.shape_seed();
  r.triangulation_seed = p.triangulation_seed();
  r.rotation = p.rotation();
  r.drift_x_mm = p.drift_x_mm();
  r.drift_y_mm = p.drift_y_mm();
  if (r.kind == sampler::RecipeKind::kDrape) r.source = {p.source_sample(), p.source_slot()};
  if (sim::Status s = sampler::validate(r); !s) return s.error();
  return r;
}

}  // namespace drapegen::proto
