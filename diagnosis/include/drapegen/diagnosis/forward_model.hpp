#pragma once
// Simulation in the loop: a model setup is simulated from several initial states on a coarse mesh, each drape is
// turned to the capture's outline (the specimen's orientation on the table is arbitrary), rendered into the
// capture's cameras and compared view by view; the best initial state counts (multiple stable drapes).

#include <algorithm>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include "drapegen/diagnosis/capture.hpp"
#include "drapegen/diagnosis/depth_metric.hpp"
#include "drapegen/diagnosis/hem_profile.hpp"
#include "drapegen/diagnosis/model_setup.hpp"
#include "drapegen/diagnosis/shape_features.hpp"
#include "drapegen/renderer/depth_renderer.hpp"
#include "drapegen/sim/drape.hpp"
#include "drapegen/sim/expected.hpp"
#include "drapegen/sim/initial_state.hpp"
#include "drapegen/sim/mesh.hpp"

namespace drapegen::diagnosis {

struct FitSettings {
  int resolution = 20;                 // vertices per side of the fitting mesh
  int initial_states = 3;              // flat, then sine waves with seeds 1, 2, ...
  int max_newton_iterations = 200;
  double tolerance = 2e-3;
  std::vector<int> fit_views{0, 1, 2}; // the rest are held out
  MetricWeights weights;
  /// Computes a drape: sim::simulate_drape where unset, else e.g. a fleet of workers (coordinator::SimulationFleet;
  /// docs/DIAGNOSIS.md, "Refits on workers"). Its mesh, solve outcome and rest angles (all the forward model reads)
  /// must be simulate_drape's (the same build on the same BLAS kernels gives them), or the diagnosis is another one.
  /// Called from several threads at once.
  std::function<sim::Expected<sim::DrapeResult>(const sim::DrapeConfig&)> simulator;
};

/// The initial states of the fit: flat, then sine seeds 1.. (count in total).
[[nodiscard]] std::vector<sim::InitialStateSpec> fit_initial_states(int count, std::uint64_t first_seed = 1);

/// The shape features of one set of views (capture or model render) over the fit views, the held-out views and all.
struct ShapeSet {
  ShapeFeatures fit, held_out, all;
};

/// What a model drape is compared with: per view pixel features, the outline of the fit views, the shape features.
struct Target {
  std::vector<ViewFeatures> views;
  HemProfile outline;                 // from the fit views
  ShapeSet shape;
  /// Cusick's drape coefficient of the outline seen by every view (hem_profile_from_capture's): the placement
  /// drape-coefficient test (floors.hpp, GapTerms::placement_dc).
  double drape_coefficient = 0.0;
};

/// One drape of the model, turned to best match an outline, and how it compares with each view.
struct ScoredDrape {
  sim::ClothMesh mesh;        // as simulated (not turned)
  double angle = 0.0;         // radians: the turn applied before rendering
  int state = 0;              // index of the initial state
  bool converged = true;
  std::vector<ViewComparison> views;  // every view of the capture (pixel residuals: localisation, report)
  ShapeSet shape;                     // the model render's shape features (rendered with sensor noise)
  /// m: the mean stable-region RMS (platform top, bare cylinder) over the fit / held-out / all views.
  double stable_fit = 0.0, stable_held_out = 0.0, stable_all = 0.0;
  /// feature_distance of the capture's and the model's shape features (dimensionless, per group scale).
  double shape_fit = 0.0, shape_held_out = 0.0, shape_all = 0.0;
  /// Each: stable term + MetricWeights::shape x shape distance over the fit / held-out / all views (m). The pixel
  /// terms (where the folds fall) do not enter: two stable drapes of one fabric differ there the most.
  double fit_score = 0.0;
  double held_out_score = 0.0;
  double all_score = 0.0;
  /// A yielding setup's drape from ForwardModel::evaluate: the plastic set it leaves (empty otherwise).
  PlasticSet left;
  /// Cusick's drape coefficient of the drape as its renders (with the capture's kind of noise) show it, measured as
  /// the capture's is (ForwardModel::views_drape_coefficient), and of the capture's it was scored against
  /// (Target::drape_coefficient). Not the mesh's own outline: where the views see a hem otherwise than it lies (a
  /// face-up curled band: 0.027 lower on average on seeds 80-96's curl captures, face down 0.004; every other family
  /// within 0.006 either way), the placement test must compare like with like.
  double drape_coefficient = 0.0, capture_drape_coefficient = 0.0;
  /// The median drape coefficient of the drapes of the evaluation this one belongs to (its own where scored alone):
  /// what the setup drapes to on this placement over stable states, for the placement test (GapTerms::placement_dc).
  double median_drape_coefficient = 0.0;
};

struct Evaluation {
  ScoredDrape best;                  // the best state by fit_score
  std::vector<ScoredDrape> states;   // every state (same order as the initial states)
  /// Every state's all_score (same order).
  [[nodiscard]] std::vector<double> all_scores() const {
    std::vector<double> scores;
    for (const auto& d : states) scores.push_back(d.all_score);
    return scores;
  }
};

class ForwardModel {
 public:
  [[nodiscard]] static sim::Expected<std::unique_ptr<ForwardModel>> create(const Capture& capture,
                                                                           const FitSettings& settings);

  /// Simulates `setup` from initial state `state` (fit_initial_states order, or any spec via the overload). The
  /// specimen's triangulation is drawn from the state's seed, or is the plastic set's specimen if the setup has one.
  /// `rest_angles`: the hinges' rest angles after the drape (the plastic set it leaves).
  [[nodiscard]] sim::Expected<sim::ClothMesh> simulate(const ModelSetup& setup, const sim::InitialStateSpec& state,
                                                       bool* converged = nullptr,
                                                       Eigen::VectorXd* rest_angles = nullptr);
  /// The specimen lifted and laid again: `setup` with the plastic set (PlasticSet) that its drape from `state` leaves,
  /// so that the next drape starts from it. An elastic setup's set is all zero.
  [[nodiscard]] sim::Expected<ModelSetup> laid_again(const ModelSetup& setup, const sim::InitialStateSpec& state);
  /// The same without simulating again: `setup` with the set that `drape`, its drape from evaluate, left.
  [[nodiscard]] static ModelSetup laid_again(const ModelSetup& setup, const ScoredDrape& drape);
  /// Turns `mesh` to match `target` (the capture's outline unless given), renders with setup.sensor, compares. A mesh
  /// with a non-finite position is an error.
  [[nodiscard]] sim::Expected<ScoredDrape> score(const sim::ClothMesh& mesh, const ModelSetup& setup,
                                                 const Target& target);
  /// The target of a capture with these views (same cameras as the capture).
  [[nodiscard]] Target make_target(const std::vector<renderer::DepthImage>& depth) const;
  [[nodiscard]] sim::Expected<ScoredDrape> score(const sim::ClothMesh& mesh, const ModelSetup& setup);
  /// Cusick's drape coefficient of the outline a set of views (one image per capture view) sees, as the capture's
  /// own is measured (hem_profile_from_capture).
  [[nodiscard]] double views_drape_coefficient(const std::vector<renderer::DepthImage>& depth) const;
  /// The shape features of a set of views (one image per capture view) over the fit / held-out / all views.
  [[nodiscard]] ShapeSet shape_set(const std::vector<renderer::DepthImage>& depth) const;
  /// The noise seed of the model renders' shape features.
  static constexpr std::uint64_t kModelNoiseSeed = 0x5FEA;
  /// Every initial state simulated and scored; the best by fit score.
  [[nodiscard]] sim::Expected<Evaluation> evaluate(const ModelSetup& setup);
  /// A drape of the setup already simulated from one of the states, which evaluate scores instead of simulating again
  /// (not for a yielding setup, whose drape must also leave its plastic set).
  struct Simulated {
    std::size_t state = 0;
    sim::ClothMesh mesh;
    bool converged = true;
  };
  /// The same from other initial states (e.g. fresh ones that no fit has selected on).
  [[nodiscard]] sim::Expected<Evaluation> evaluate(const ModelSetup& setup,
                                                   const std::vector<sim::InitialStateSpec>& states,
                                                   const Simulated* simulated = nullptr);
  /// Re-scores given meshes (no simulation): the sensor candidate's refit. As evaluate, an error where no mesh scores
  /// finitely (none given included).
  [[nodiscard]] sim::Expected<Evaluation> rescore(const std::vector<sim::ClothMesh>& meshes, const ModelSetup& setup);

  /// Clean renders of `mesh` turned by `angle` in every view (with the setup's sensor error).
  [[nodiscard]] sim::Expected<std::vector<renderer::DepthImage>> render(const sim::ClothMesh& mesh, double angle,
                                                                        const renderer::SensorError& sensor);

  [[nodiscard]] const Capture& capture() const { return capture_; }
  [[nodiscard]] const FitSettings& settings() const { return settings_; }
  [[nodiscard]] const std::vector<ViewFeatures>& features() const { return target_.views; }
  [[nodiscard]] const HemProfile& outline() const { return target_.outline; }
  [[nodiscard]] const Target& target() const { return target_; }
  [[nodiscard]] const std::vector<sim::InitialStateSpec>& initial_states() const { return states_; }
  [[nodiscard]] int simulations() const { return simulations_; }
  [[nodiscard]] double simulation_seconds() const { return simulation_seconds_; }
  /// Threads that evaluate() simulates its initial states on (default 1). The drapes are scored and rendered on the
  /// calling thread, in the states' order, so the result does not depend on it.
  void set_threads(int threads) { threads_ = std::max(1, threads); }
  [[nodiscard]] int threads() const { return threads_; }
  /// Means over the fit views / held-out views / all of per-view scores.
  [[nodiscard]] double fit_mean(const std::vector<ViewComparison>& views) const;
  [[nodiscard]] double held_out_mean(const std::vector<ViewComparison>& views) const;

 private:
  ForwardModel(const Capture& capture, const FitSettings& settings, renderer::DepthRenderer renderer);
  /// The capture with these views' depth (one image per capture view) in place of its own.
  [[nodiscard]] Capture with_views(const std::vector<renderer::DepthImage>& depth) const;
  /// shape_set of a capture with_views made.
  [[nodiscard]] ShapeSet shape_set(const Capture& seen) const;
  Capture capture_;
  FitSettings settings_;
  renderer::DepthRenderer renderer_;
  Target target_;
  std::vector<sim::InitialStateSpec> states_;
  std::vector<bool> is_fit_view_;
  int threads_ = 1;
  std::mutex counters_;  // simulate() may run on several threads (set_threads)
  int simulations_ = 0;
  double simulation_seconds_ = 0.0;
};

}  // namespace drapegen::diagnosis
