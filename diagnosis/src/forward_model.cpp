#include "drapegen/diagnosis/forward_model.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "drapegen/diagnosis/work_sharing.hpp"
#include "drapegen/renderer/noise.hpp"
#include "drapegen/renderer/random.hpp"
#include "drapegen/renderer/rig.hpp"
#include "drapegen/renderer/scene.hpp"
#include "drapegen/sim/drape.hpp"
#include "drapegen/sim/median.hpp"

namespace drapegen::diagnosis {

std::vector<sim::InitialStateSpec> fit_initial_states(int count, std::uint64_t first_seed) {
  std::vector<sim::InitialStateSpec> states;
  for (int k = 0; k < count; ++k) {
    sim::InitialStateSpec s;
    if (k == 0) {
      s.shape = sim::InitialShape::kFlat;
      s.seed = first_seed;
    } else {
      s.shape = sim::InitialShape::kSine;
      s.seed = first_seed + static_cast<std::uint64_t>(k);
    }
    states.push_back(s);
  }
  return states;
}

ForwardModel::ForwardModel(const Capture& capture, const FitSettings& settings, renderer::DepthRenderer renderer)
    : capture_(capture), settings_(settings), renderer_(std::move(renderer)) {}

sim::Expected<std::unique_ptr<ForwardModel>> ForwardModel::create(const Capture& capture, const FitSettings& settings) {
  if (static_cast<int>(capture.views.size()) != kCaptureViews) {
    return sim::Error{fmt::format("capture has {} views, need {}", capture.views.size(), kCaptureViews)};
  }
  if (settings.resolution < 5 || settings.resolution > 200) return sim::Error{"fit resolution must be 5 .. 200"};
  if (settings.initial_states < 1) return sim::Error{"need at least one initial state"};
  for (int v : settings.fit_views) {
    if (v < 0 || v >= kCaptureViews) return sim::Error{fmt::format("fit view {} out of range", v)};
  }
  auto renderer = renderer::DepthRenderer::create();
  if (!renderer) return renderer.error();
  FitSettings s = settings;
  s.weights.cylinder_radius = 0.5 * capture.specimen.cylinder_diameter;
  std::unique_ptr<ForwardModel> m(new ForwardModel(capture, s, std::move(*renderer)));
  m->is_fit_view_.assign(kCaptureViews, false);
  for (int v : settings.fit_views) m->is_fit_view_[v] = true;
  std::vector<renderer::DepthImage> depth;
  for (const auto& v : capture.views) depth.push_back(v.depth);
  m->target_ = m->make_target(depth);
  if (!m->target_.shape.all.valid) {
    return sim::Error{fmt::format("{}: the capture shows no skirt hanging below the platform top (too few points below "
                                  "it in the views): not a drape capture, or the camera poses do not match the depth",
                                  capture.directory.empty() ? "capture" : capture.directory)};
  }
  m->states_ = fit_initial_states(settings.initial_states);
  for (auto& s : m->states_) s.platform_radius = 0.5 * capture.specimen.cylinder_diameter;
  return m;
}

sim::Expected<sim::ClothMesh> ForwardModel::simulate(const ModelSetup& setup, const sim::InitialStateSpec& state,
                                                     bool* converged, Eigen::VectorXd* rest_angles) {
  const auto start = std::chrono::steady_clock::now();
  sim::DrapeConfig config;
  config.fabric = sim::fabric_from_paper_units(setup.bending.alpha, setup.bending.beta, capture_.specimen.density);
  if (sim::Status s = sim::validate(config.fabric, config.bending_model); !s) return s.error();
  config.platform.radius = 0.5 * capture_.specimen.cylinder_diameter;
  config.specimen.size_x = capture_.specimen.size_x;
  config.specimen.size_y = capture_.specimen.size_y;
  config.specimen.vertices_x = config.specimen.vertices_y = settings_.resolution;
  const bool set = setup.plastic_set.rest_angles.size() > 0;
  config.specimen.seed = set ? setup.plastic_set.specimen_seed : state.seed;
  config.rest_angles = setup.plastic_set.rest_angles;
  config.initial = state;
  config.initial.face_down = capture_.face_down;  // the specimen as this capture saw it laid
  config.initial.platform_radius = config.platform.radius;
  config.initial.drift += setup.drift;
  config.effects = setup.effects;
  config.solver.max_iterations = settings_.max_newton_iterations;
  config.solver.tolerance = settings_.tolerance;
  auto result = settings_.simulator ? settings_.simulator(config) : sim::simulate_drape(config);
  {
    std::lock_guard lock(counters_);
    ++simulations_;
    simulation_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  if (!result) return result.error();
  if (converged != nullptr) *converged = result->report.outcome == sim::SolveOutcome::kConverged;
  if (rest_angles != nullptr) *rest_angles = std::move(result->rest_angles);
  return std::move(result->mesh);
}

namespace {
/// The set a drape of `setup` from `state` leaves: its rest angles, on the set's specimen if `setup` had one, else on
/// the state's.
PlasticSet set_left(const ModelSetup& setup, const sim::InitialStateSpec& state, Eigen::VectorXd rest_angles) {
  const bool had = setup.plastic_set.rest_angles.size() > 0;
  return {had ? setup.plastic_set.specimen_seed : state.seed, std::move(rest_angles)};
}

/// Every state's scored drape, in the states' order, and the first with the smallest fit score as the best. An error
/// if no state scored finitely (the best would be an empty drape with a score of 0, a perfect fit).
sim::Expected<Evaluation> evaluation_of(std::vector<ScoredDrape> states) {
  double best_score = std::numeric_limits<double>::infinity();
  std::size_t best = states.size();
  for (std::size_t k = 0; k < states.size(); ++k) {
    if (states[k].fit_score < best_score) {
      best_score = states[k].fit_score;
      best = k;
    }
  }
  if (!std::isfinite(best_score)) return sim::Error{"no initial state's drape has a finite score"};
  std::vector<double> coefficients;
  for (const auto& d : states) coefficients.push_back(d.drape_coefficient);
  const double median = sim::median(std::move(coefficients));
  for (auto& d : states) d.median_drape_coefficient = median;
  Evaluation e;
  e.best = states[best];
  e.states = std::move(states);
  return e;
}
}  // namespace

sim::Expected<ModelSetup> ForwardModel::laid_again(const ModelSetup& setup, const sim::InitialStateSpec& state) {
  Eigen::VectorXd rest_angles;
  auto mesh = simulate(setup, state, nullptr, &rest_angles);
  if (!mesh) return mesh.error();
  ModelSetup next = setup;
  next.plastic_set = set_left(setup, state, std::move(rest_angles));
  return next;
}

ModelSetup ForwardModel::laid_again(const ModelSetup& setup, const ScoredDrape& drape) {
  ModelSetup next = setup;
  next.plastic_set = drape.left;
  return next;
}

sim::Expected<std::vector<renderer::DepthImage>> ForwardModel::render(const sim::ClothMesh& mesh, double angle,
                                                                      const renderer::SensorError& sensor) {
  sim::ClothMesh turned = mesh;
  turned.positions = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix() * mesh.positions;
  auto cloth = renderer::cloth_triangles(turned);
  if (!cloth) return cloth.error();
  renderer::RigSpec rig;
  rig.cylinder.radius = 0.5 * capture_.specimen.cylinder_diameter;
  if (sim::Status s = renderer_.set_scene(renderer::tester_scene(*cloth, rig)); !s) return s.error();
  std::vector<renderer::DepthImage> images;
  for (const auto& view : capture_.views) {
    const renderer::Camera camera = sensor.true_camera(view.camera);
    auto image = renderer_.render(camera);
    if (!image) return image.error();
    images.push_back(sensor.changes_depth() ? sensor.apply(*image, view.camera.intrinsics) : std::move(*image));
  }
  return images;
}

double ForwardModel::fit_mean(const std::vector<ViewComparison>& views) const {
  double s = 0.0;
  int n = 0;
  for (std::size_t v = 0; v < views.size(); ++v)
    if (is_fit_view_[v]) s += views[v].score, ++n;
  return n > 0 ? s / n : 0.0;
}

double ForwardModel::held_out_mean(const std::vector<ViewComparison>& views) const {
  double s = 0.0;
  int n = 0;
  for (std::size_t v = 0; v < views.size(); ++v)
    if (!is_fit_view_[v]) s += views[v].score, ++n;
  return n > 0 ? s / n : 0.0;
}

Capture ForwardModel::with_views(const std::vector<renderer::DepthImage>& depth) const {
  Capture c = capture_;
  for (std::size_t v = 0; v < depth.size(); ++v) c.views[v].depth = depth[v];
  return c;
}

double ForwardModel::views_drape_coefficient(const std::vector<renderer::DepthImage>& depth) const {
  return drape_coefficient(with_views(depth));
}

ShapeSet ForwardModel::shape_set(const std::vector<renderer::DepthImage>& depth) const {
  return shape_set(with_views(depth));
}

ShapeSet ForwardModel::shape_set(const Capture& seen) const {
  std::vector<int> held, all;
  for (int v = 0; v < kCaptureViews; ++v) {
    all.push_back(v);
    if (!is_fit_view_[v]) held.push_back(v);
  }
  ShapeSet s;
  s.fit = shape_features(seen, settings_.fit_views);
  s.held_out = held.empty() ? ShapeFeatures{} : shape_features(seen, held);
  s.all = shape_features(seen, all);
  return s;
}

Target ForwardModel::make_target(const std::vector<renderer::DepthImage>& depth) const {
  Target t;
  Capture c = capture_;
  for (std::size_t v = 0; v < depth.size(); ++v) {
    c.views[v].depth = depth[v];
    c.views[v].depth.incidence.clear();
    t.views.push_back(view_features(c.views[v].depth, c.views[v].camera, settings_.weights));
  }
  t.outline = hem_profile_from_views(c, settings_.fit_views);
  t.shape = shape_set(depth);
  t.drape_coefficient = drape_coefficient(c);
  return t;
}

sim::Expected<ScoredDrape> ForwardModel::score(const sim::ClothMesh& mesh, const ModelSetup& setup,
                                               const Target& target) {
  if (!mesh.positions.allFinite()) return sim::Error{"the drape to score has non-finite positions"};
  ScoredDrape d;
  d.mesh = mesh;
  const HemProfile outline = hem_profile_from_mesh(mesh);
  d.angle = align_orientation(outline, target.outline).angle;
  d.capture_drape_coefficient = target.drape_coefficient;
  auto images = render(mesh, d.angle, setup.sensor);
  if (!images) return images.error();
  // The shape features of the model are taken from renders with the capture's kind of noise (a fixed seed), so
  // that noise-sensitive features (the hem's 98th percentile, the skirt's spread) compare like with like.
  const renderer::NoiseModel noise = renderer::NoiseModel::kinect();
  std::vector<renderer::DepthImage> noisy;
  for (std::size_t v = 0; v < images->size(); ++v) {
    d.views.push_back(compare_view(target.views[v], (*images)[v], settings_.weights));
    noisy.push_back(noise.apply((*images)[v], renderer::mix_seed(kModelNoiseSeed, v)));
  }
  const Capture seen = with_views(noisy);  // the drape as the capture's views would see it
  d.shape = shape_set(seen);
  d.drape_coefficient = drape_coefficient(seen);
  d.median_drape_coefficient = d.drape_coefficient;
  const std::vector<double> scales = default_feature_scales();
  d.shape_fit = feature_distance(target.shape.fit, d.shape.fit, scales);
  d.shape_held_out = feature_distance(target.shape.held_out, d.shape.held_out, scales);
  d.shape_all = feature_distance(target.shape.all, d.shape.all, scales);
  double fit = 0.0, held = 0.0, all = 0.0;
  int nf = 0, nh = 0;
  int na = 0;
  for (std::size_t v = 0; v < d.views.size(); ++v) {
    if (d.views[v].captured_stable_pixels == 0) continue;  // the capture sees no rigid surface there: no stable term
    const double s = d.views[v].stable_rms;
    all += s, ++na;
    if (is_fit_view_[v]) {
      fit += s, ++nf;
    } else {
      held += s, ++nh;
    }
  }
  d.stable_fit = nf > 0 ? fit / nf : 0.0;
  d.stable_held_out = nh > 0 ? held / nh : 0.0;
  d.stable_all = na > 0 ? all / na : 0.0;
  const double w = settings_.weights.shape;
  d.fit_score = d.stable_fit + w * d.shape_fit;
  d.held_out_score = d.stable_held_out + w * d.shape_held_out;
  d.all_score = d.stable_all + w * d.shape_all;
  return d;
}

sim::Expected<ScoredDrape> ForwardModel::score(const sim::ClothMesh& mesh, const ModelSetup& setup) {
  return score(mesh, setup, target_);
}

sim::Expected<Evaluation> ForwardModel::evaluate(const ModelSetup& setup) { return evaluate(setup, states_); }

sim::Expected<Evaluation> ForwardModel::evaluate(const ModelSetup& setup,
                                                 const std::vector<sim::InitialStateSpec>& states,
                                                 const Simulated* simulated) {
  const bool yields = setup.effects.bending_yield_curvature.has_value();
  if (yields && simulated) return sim::Error{"evaluate: a yielding setup's drapes are always simulated"};
  // Every drape first (on threads_ threads, each taking the next state), then scored in the states' order.
  struct Drape {
    sim::Expected<sim::ClothMesh> mesh = sim::ClothMesh{};
    bool converged = true;
    Eigen::VectorXd rest_angles;
  };
  std::vector<Drape> drapes(states.size());
  WorkQueue queue(states.size());
  run_on_threads(std::min(threads_, static_cast<int>(states.size())), [&](int) {
    while (const auto k = queue.take()) {
      Drape& d = drapes[*k];
      if (simulated && simulated->state == *k) {
        *d.mesh = simulated->mesh;
        d.converged = simulated->converged;
      } else {
        d.mesh = simulate(setup, states[*k], &d.converged, yields ? &d.rest_angles : nullptr);
      }
    }
  });
  std::vector<ScoredDrape> scored_states;
  for (std::size_t k = 0; k < states.size(); ++k) {
    auto& [mesh, converged, rest_angles] = drapes[k];
    if (!mesh) return mesh.error();
    auto scored = score(*mesh, setup);
    if (!scored) return scored.error();
    scored->state = static_cast<int>(k);
    scored->converged = converged;
    if (yields) scored->left = set_left(setup, states[k], std::move(rest_angles));
    scored_states.push_back(std::move(*scored));
  }
  return evaluation_of(std::move(scored_states));
}

sim::Expected<Evaluation> ForwardModel::rescore(const std::vector<sim::ClothMesh>& meshes, const ModelSetup& setup) {
  std::vector<ScoredDrape> scored_states;
  for (std::size_t k = 0; k < meshes.size(); ++k) {
    auto scored = score(meshes[k], setup);
    if (!scored) return scored.error();
    scored->state = static_cast<int>(k);
    scored_states.push_back(std::move(*scored));
  }
  return evaluation_of(std::move(scored_states));
}

}  // namespace drapegen::diagnosis
