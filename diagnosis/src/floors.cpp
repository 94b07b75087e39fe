#include "drapegen/diagnosis/floors.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "drapegen/renderer/noise.hpp"
#include "drapegen/renderer/random.hpp"
#include "drapegen/sim/median.hpp"

namespace drapegen::diagnosis {
namespace {

/// Scores the fit's initial-state drapes against a pseudo-capture (as the capture itself is scored): the state with
/// the best fit score counts.
sim::Status score_pseudo(ForwardModel& model, const ModelSetup& fitted, const Evaluation& fit,
                         const std::vector<renderer::DepthImage>& images, FloorSamples& samples) {
  const Target target = model.make_target(images);
  double best = std::numeric_limits<double>::infinity();
  std::optional<ScoredDrape> chosen;
  for (const auto& state : fit.states) {
    auto s = model.score(state.mesh, fitted, target);
    if (!s) return s.error();
    if (s->fit_score < best) {
      best = s->fit_score;
      chosen = std::move(*s);
    }
  }
  if (!chosen) return sim::Error{"no fitted drape to score the floor samples against"};
  samples.all.push_back(chosen->all_score);
  samples.held_out.push_back(chosen->held_out_score);
  samples.stable.push_back(chosen->stable_all);
  samples.shape.push_back(chosen->shape_all);
  samples.groups.push_back(group_differences(target.shape.all, chosen->shape.all));
  const RegionEnergy regions = region_energy(model, *chosen);
  auto& mean_square = samples.region_mean_square.emplace_back();
  for (int k = 0; k < RegionEnergy::kCount; ++k) mean_square[k] = regions.mean_square(static_cast<Region>(k));
  return {};
}

std::vector<renderer::DepthImage> with_noise(const std::vector<renderer::DepthImage>& clean, std::uint64_t seed) {
  const renderer::NoiseModel noise = renderer::NoiseModel::kinect();
  std::vector<renderer::DepthImage> out;
  for (std::size_t v = 0; v < clean.size(); ++v) out.push_back(noise.apply(clean[v], renderer::mix_seed(seed, v)));
  return out;
}

/// Both kinds of samples of one field, pooled.
std::vector<double> pooled(const Floors& floors, std::vector<double> FloorSamples::*field) {
  std::vector<double> v = floors.noise.*field;
  const auto& more = floors.multistability.*field;
  v.insert(v.end(), more.begin(), more.end());
  return v;
}

double largest(const std::vector<double>& v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); }

double median_or_zero(std::vector<double> v) { return v.empty() ? 0.0 : sim::median(std::move(v)); }

}  // namespace

std::vector<double> Floors::group_floor() const {
  std::vector<double> top(kFeatureGroupCount, 0.0);
  for (const auto* samples : {&noise, &multistability})
    for (const auto& g : samples->groups)
      for (std::size_t k = 0; k < g.size() && k < top.size(); ++k) top[k] = std::max(top[k], g[k]);
  return top;
}

std::array<double, RegionEnergy::kCount> Floors::region_floor() const {
  std::array<double, RegionEnergy::kCount> top{};
  for (const auto* samples : {&noise, &multistability})
    for (const auto& m : samples->region_mean_square)
      for (int k = 0; k < RegionEnergy::kCount; ++k) top[k] = std::max(top[k], m[k]);
  return top;
}

double Floors::stable_floor() const { return largest(pooled(*this, &FloorSamples::stable)); }

GapTerms gap_terms(const ScoredDrape& drape, const ScoredDrape* held_out_capture) {
  if (!held_out_capture) return {drape.stable_all, drape.shape_all, drape.shape_all, 0.0};
  const ScoredDrape& other = *held_out_capture;
  const double captures = other.capture_drape_coefficient - drape.capture_drape_coefficient;
  const double model = other.median_drape_coefficient - drape.median_drape_coefficient;
  return {0.5 * (drape.stable_all + other.stable_all), 0.5 * (drape.shape_all + other.shape_all),
          std::max(drape.shape_all, other.shape_all), std::abs(captures - model)};
}

double placement_dc_floor(const Evaluation& validated, double margin) {
  if (validated.states.size() < 2) return 0.0;
  const auto [lo, hi] = std::minmax_element(validated.states.begin(), validated.states.end(),
                                            [](const ScoredDrape& a, const ScoredDrape& b) {
                                              return a.drape_coefficient < b.drape_coefficient;
                                            });
  return margin * (hi->drape_coefficient - lo->drape_coefficient);
}

double excess_above_floors(const GapTerms& gap, const Floors& floors) {
  // value - floor is positive exactly when value > floor, so the sum is 0 exactly when every test passes.
  auto relative_excess = [](double value, double floor) { return value > floor ? (value - floor) / floor : 0.0; };
  const double placement =
      floors.placement_shape > 0.0 ? relative_excess(gap.shape_max, floors.placement_shape) : 0.0;
  const double coefficient = floors.placement_dc > 0.0 ? relative_excess(gap.placement_dc, floors.placement_dc) : 0.0;
  return relative_excess(gap.stable, floors.stable) + relative_excess(gap.shape, floors.shape) + placement +
         coefficient;
}

double excess_above_floors(const ScoredDrape& drape, const Floors& floors) {
  return excess_above_floors(gap_terms(drape), floors);
}

sim::Expected<Floors> measure_floors(ForwardModel& model, const ModelSetup& fitted, const Evaluation& fit,
                                     const FloorSettings& settings) {
  Floors floors;
  floors.margin = settings.margin;
  auto clean = model.render(fit.best.mesh, fit.best.angle, fitted.sensor);
  if (!clean) return clean.error();
  for (int k = 0; k < settings.noise_seeds; ++k) {
    const auto images = with_noise(*clean, 0xF100A + static_cast<std::uint64_t>(k));
    if (sim::Status s = score_pseudo(model, fitted, fit, images, floors.noise); !s) return s.error();
  }
  // Other stable drapes of the fitted parameters: sine initial states with seeds after the fit's.
  const auto states = fit_initial_states(settings.extra_states + 1, 1000);
  for (int j = 1; j <= settings.extra_states; ++j) {
    sim::InitialStateSpec spec = states[j];
    auto mesh = model.simulate(fitted, spec);
    if (!mesh) return mesh.error();
    const double angle = align_orientation(hem_profile_from_mesh(*mesh), model.outline()).angle;
    auto images = model.render(*mesh, angle, fitted.sensor);
    if (!images) return images.error();
    const auto noisy = with_noise(*images, 0x5EED + static_cast<std::uint64_t>(j));
    if (sim::Status s = score_pseudo(model, fitted, fit, noisy, floors.multistability); !s) return s.error();
  }
  floors.all = settings.margin * largest(pooled(floors, &FloorSamples::all));
  floors.held_out = settings.margin * largest(pooled(floors, &FloorSamples::held_out));
  floors.stable = settings.margin * floors.stable_floor();
  floors.shape_margin = settings.shape_margin;
  floors.shape = settings.shape_threshold > 0.0 ? settings.shape_threshold
                                                : settings.shape_margin * largest(pooled(floors, &FloorSamples::shape));
  floors.placement_shape = std::max(0.0, settings.placement_shape_threshold);
  floors.typical_all = median_or_zero(pooled(floors, &FloorSamples::all));
  floors.typical_held_out = median_or_zero(pooled(floors, &FloorSamples::held_out));
  return floors;
}

}  // namespace drapegen::diagnosis
