#include "drapegen/diagnosis/attribution.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <thread>

#include <fmt/ranges.h>

#include "drapegen/renderer/random.hpp"
#include "drapegen/sim/logging.hpp"

namespace drapegen::diagnosis {
namespace {

sim::Expected<CandidateResult> refit(ForwardModel& model, Effect effect, const ModelSetup& baseline,
                                     const Evaluation& fit, const AttributionSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  const EffectSpace space = effect_space(effect);
  CandidateResult c;
  c.effect = effect;
  c.names = space.names;
  std::vector<double> x0, step, lo, hi;
  const bool sim = needs_simulation(effect);
  if (sim) {  // the bending scale stays free: an effect may trade off against stiffness
    x0.push_back(0.0), step.push_back(0.25), lo.push_back(-1.5), hi.push_back(1.5);
  }
  const std::size_t first = x0.size();
  x0.insert(x0.end(), space.start.begin(), space.start.end());
  step.insert(step.end(), space.step.begin(), space.step.end());
  if (effect == Effect::kMisalignment) {
    // Start from the outline's centre offset that the baseline lacks (the fit views' first hem-radius harmonic, mm;
    // only its size: the turn makes the direction arbitrary). The extra cloth of an off-centre specimen partly hangs
    // down instead of out, so this underestimates the drift: a start, not an estimate.
    const auto& captured = model.target().shape.fit.off_centre;
    const auto& modelled = fit.best.shape.fit.off_centre;
    if (!captured.empty() && !modelled.empty()) {
      x0[first] = std::clamp((captured[0] - modelled[0]) * 1e3, 0.0, space.upper[0]);
    }
  }
  lo.insert(lo.end(), space.lower.begin(), space.lower.end());
  hi.insert(hi.end(), space.upper.begin(), space.upper.end());

  std::vector<sim::ClothMesh> meshes;
  if (!sim)
    for (const auto& s : fit.states) meshes.push_back(s.mesh);
  std::optional<sim::Error> error;
  double best = std::numeric_limits<double>::infinity();
  auto setup_of = [&](const std::vector<double>& x) {
    ModelSetup setup = baseline;
    std::size_t first = 0;
    if (sim) {
      const double scale = std::exp(x[0]);
      auto& a = setup.bending.alpha;
      auto& b = setup.bending.beta;
      a = {a.warp * scale, a.bias * scale, a.weft * scale};
      b = {b.warp * scale, b.bias * scale, b.weft * scale};
      first = 1;
    }
    apply_effect(effect, std::vector<double>(x.begin() + static_cast<std::ptrdiff_t>(first), x.end()), setup);
    return setup;
  };
  auto f = [&](const std::vector<double>& x) -> double {
    if (error) return std::numeric_limits<double>::infinity();
    const ModelSetup setup = setup_of(x);
    auto e = sim ? model.evaluate(setup) : model.rescore(meshes, setup);
    if (!e) {
      error = e.error();
      return std::numeric_limits<double>::infinity();
    }
    sim::logger()->debug("refit {}: {} -> {:.3f} mm (state {}, shape {:.2f})", effect_name(effect), fmt::join(x, ", "),
                         e->best.fit_score * 1e3, e->best.state, e->best.shape_fit);
    if (e->best.fit_score < best) {
      best = e->best.fit_score;
      c.drape = e->best;
    }
    return e->best.fit_score;
  };
  NelderMeadOptions options = settings.optimiser;
  if (!sim) options.max_evaluations = settings.sensor_evaluations;
  const NelderMeadResult r = nelder_mead(f, x0, step, lo, hi, options);
  if (error) return *error;
  c.alpha_scale = sim ? std::exp(r.x[0]) : 1.0;
  c.parameters.assign(r.x.begin() + (sim ? 1 : 0), r.x.end());
  c.evaluations = r.evaluations;
  c.fit_score = c.drape.fit_score;
  c.held_out_score = c.drape.held_out_score;
  c.all_score = c.drape.all_score;
  c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return c;
}

}  // namespace

double gap_shrinkage(double excess_before, double excess_after) {
  return excess_before > 0.0 ? 1.0 - excess_after / excess_before : 0.0;
}

double bootstrap_confidence(const ForwardModel& model, const ScoredDrape& a, const ScoredDrape& b, int samples,
                            int tile_px, std::uint64_t seed) {
  const auto& fit_views = model.settings().fit_views;
  std::vector<double> d;  // per tile: b's energy - a's energy
  for (std::size_t v = 0; v < a.views.size() && v < b.views.size(); ++v) {
    if (std::find(fit_views.begin(), fit_views.end(), static_cast<int>(v)) != fit_views.end()) continue;
    const auto& img = model.capture().views[v].depth;
    const int W = img.width, H = img.height;
    for (int ty = 0; ty < H; ty += tile_px) {
      for (int tx = 0; tx < W; tx += tile_px) {
        double ea = 0.0, eb = 0.0;
        bool any = false;
        for (int y = ty; y < std::min(H, ty + tile_px); ++y) {
          for (int x = tx; x < std::min(W, tx + tile_px); ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * W + x;
            const float ra = a.views[v].residual[i], rb = b.views[v].residual[i];
            if (std::isfinite(ra)) ea += static_cast<double>(ra) * ra, any = true;
            if (std::isfinite(rb)) eb += static_cast<double>(rb) * rb, any = true;
          }
        }
        if (any) d.push_back(eb - ea);
      }
    }
  }
  if (d.empty() || samples <= 0) return 0.5;
  renderer::Rng rng(seed);
  int wins = 0;
  for (int s = 0; s < samples; ++s) {
    double sum = 0.0;
    for (std::size_t k = 0; k < d.size(); ++k) sum += d[std::min(d.size() - 1, static_cast<std::size_t>(rng.uniform() * d.size()))];
    wins += sum > 0.0;
  }
  return static_cast<double>(wins) / samples;
}

sim::Expected<Attribution> attribute(ForwardModel& model, const ModelSetup& baseline, const Evaluation& fit,
                                     const Floors& floors, const AttributionSettings& settings,
                                     const std::function<sim::Expected<std::unique_ptr<ForwardModel>>()>& make_model) {
  std::vector<std::optional<sim::Expected<CandidateResult>>> results(settings.candidates.size());
  const int jobs = std::max(1, std::min<int>(settings.jobs, static_cast<int>(settings.candidates.size())));
  if (jobs == 1 || !make_model) {
    for (std::size_t k = 0; k < settings.candidates.size(); ++k)
      results[k] = refit(model, settings.candidates[k], baseline, fit, settings);
  } else {
    std::vector<std::thread> threads;
    std::mutex mutex;
    std::optional<sim::Error> error;
    for (int j = 0; j < jobs; ++j) {
      threads.emplace_back([&, j] {
        std::unique_ptr<ForwardModel> own;
        ForwardModel* m = &model;
        if (j > 0) {
          auto created = make_model();
          if (!created) {
            std::lock_guard lock(mutex);
            error = created.error();
            return;
          }
          own = std::move(*created);
          m = own.get();
        }
        for (std::size_t k = static_cast<std::size_t>(j); k < settings.candidates.size(); k += jobs) {
          auto r = refit(*m, settings.candidates[k], baseline, fit, settings);
          std::lock_guard lock(mutex);
          results[k] = std::move(r);
        }
      });
    }
    for (auto& t : threads) t.join();
    if (error) return *error;
  }
  // Shrinkage: of the excess above the floors that made the gate fire (the same two tests), once the candidate is
  // added; the held-out view (not in the refit) must confirm it, i.e. not get worse.
  Attribution a;
  const double h0 = fit.best.held_out_score;
  const double excess0 = excess_above_floors(fit.best, floors);
  for (auto& r : results) {
    if (!r || !*r) return r ? r->error() : sim::Error{"candidate refit did not run"};
    CandidateResult c = std::move(r->value());
    c.shrinkage = gap_shrinkage(excess0, excess_above_floors(c.drape, floors));
    c.held_out_shrinkage = h0 > 0.0 ? 1.0 - c.held_out_score / h0 : 0.0;
    c.confirmed = c.held_out_score <= h0;
    a.candidates.push_back(std::move(c));
  }
  std::stable_sort(a.candidates.begin(), a.candidates.end(), [](const CandidateResult& x, const CandidateResult& y) {
    if (x.confirmed != y.confirmed) return x.confirmed;
    if (x.shrinkage != y.shrinkage) return x.shrinkage > y.shrinkage;
    return x.held_out_shrinkage > y.held_out_shrinkage;
  });
  if (!a.candidates.empty()) {
    a.named = a.candidates[0].confirmed && a.candidates[0].shrinkage >= settings.significant_shrinkage;
    a.confidence = a.candidates.size() > 1
                       ? bootstrap_confidence(model, a.candidates[0].drape, a.candidates[1].drape,
                                              settings.bootstrap_samples, settings.tile_px, 0xB007)
                       : 1.0;
  }
  return a;
}

}  // namespace drapegen::diagnosis
