#include "drapegen/diagnosis/floors.hpp"

#include <algorithm>
#include <limits>
#include <optional>

#include "drapegen/renderer/noise.hpp"
#include "drapegen/renderer/random.hpp"

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
  return {};
}

std::vector<renderer::DepthImage> with_noise(const std::vector<renderer::DepthImage>& clean, std::uint64_t seed) {
  const renderer::NoiseModel noise = renderer::NoiseModel::kinect();
  std::vector<renderer::DepthImage> out;
  for (std::size_t v = 0; v < clean.size(); ++v) out.push_back(noise.apply(clean[v], renderer::mix_seed(seed, v)));
  return out;
}

}  // namespace

std::vector<double> Floors::group_floor() const {
  std::vector<double> top(kFeatureGroupCount, 0.0);
  for (const auto* samples : {&noise, &multistability})
    for (const auto& g : samples->groups)
      for (std::size_t k = 0; k < g.size() && k < top.size(); ++k) top[k] = std::max(top[k], g[k]);
  return top;
}

double Floors::stable_floor() const {
  double top = 0.0;
  for (double x : noise.stable) top = std::max(top, x);
  for (double x : multistability.stable) top = std::max(top, x);
  return top;
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
    const double angle = align(hem_profile_from_mesh(*mesh), model.outline()).angle;
    auto images = model.render(*mesh, angle, fitted.sensor);
    if (!images) return images.error();
    const auto noisy = with_noise(*images, 0x5EED + static_cast<std::uint64_t>(j));
    if (sim::Status s = score_pseudo(model, fitted, fit, noisy, floors.multistability); !s) return s.error();
  }
  auto top = [](const FloorSamples& a, const FloorSamples& b, bool held_out) {
    double m = 0.0;
    for (double x : held_out ? a.held_out : a.all) m = std::max(m, x);
    for (double x : held_out ? b.held_out : b.all) m = std::max(m, x);
    return m;
  };
  floors.all = settings.margin * top(floors.noise, floors.multistability, false);
  floors.held_out = settings.margin * top(floors.noise, floors.multistability, true);
  floors.stable = settings.margin * floors.stable_floor();
  floors.shape_margin = settings.shape_margin;
  double shape = 0.0;
  for (const auto* samples : {&floors.noise, &floors.multistability})
    for (double x : samples->shape) shape = std::max(shape, x);
  floors.shape = settings.shape_threshold > 0.0 ? settings.shape_threshold : settings.shape_margin * shape;
  auto median = [](std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  };
  auto pooled = [](const std::vector<double>& a, const std::vector<double>& b) {
    std::vector<double> v = a;
    v.insert(v.end(), b.begin(), b.end());
    return v;
  };
  floors.typical_all = median(pooled(floors.noise.all, floors.multistability.all));
  floors.typical_held_out = median(pooled(floors.noise.held_out, floors.multistability.held_out));
  return floors;
}

}  // namespace drapegen::diagnosis
