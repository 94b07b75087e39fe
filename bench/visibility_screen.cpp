#include "visibility_screen.hpp"

#include "drapegen/diagnosis/diagnosis.hpp"

namespace drapegen::bench {

sim::Expected<Visibility> effect_visibility(const std::string& capture_directory,
                                            const std::string& held_out_directory,
                                            const diagnosis::BendingParameters& true_bending) {
  const auto settings = diagnosis::DiagnosisSettings::fine();
  auto capture = diagnosis::read_capture(capture_directory);
  if (!capture) return capture.error();
  auto model = diagnosis::ForwardModel::create(*capture, settings.fit);
  if (!model) return model.error();
  diagnosis::ModelSetup truth;
  truth.bending = true_bending;
  // As diagnose() measures them at its fitted parameters: the fit's states, the floors, the validation drapes.
  auto fit = (*model)->evaluate(truth);
  if (!fit) return fit.error();
  diagnosis::FloorSettings floor_settings = settings.floors;
  if (!held_out_directory.empty()) floor_settings.shape_threshold = settings.held_out_shape_threshold;
  auto floors = diagnosis::measure_floors(**model, truth, *fit, floor_settings);
  if (!floors) return floors.error();
  auto validated = (*model)->evaluate(truth, diagnosis::validation_states(settings.attribution));
  if (!validated) return validated.error();
  std::optional<diagnosis::Evaluation> second;
  if (!held_out_directory.empty()) {
    auto held_out = diagnosis::read_capture(held_out_directory);
    if (!held_out) return held_out.error();
    auto held_out_model = diagnosis::ForwardModel::create(*held_out, settings.fit);
    if (!held_out_model) return held_out_model.error();
    std::vector<sim::ClothMesh> meshes;
    for (const auto& d : validated->states) meshes.push_back(d.mesh);
    auto e = (*held_out_model)->rescore(meshes, truth);
    if (!e) return e.error();
    second = std::move(*e);
  }
  const auto gap = diagnosis::gap_terms(validated->best, second ? &second->best : nullptr);
  Visibility v;
  v.excess = diagnosis::excess_above_floors(gap, *floors);
  v.stable_mm = gap.stable * 1e3;
  v.stable_floor_mm = floors->stable * 1e3;
  v.shape = gap.shape;
  v.shape_floor = floors->shape;
  return v;
}

}  // namespace drapegen::bench
