// ForwardModel::laid_again: the specimen lifted after a drape and laid again keeps what the drape did to it (simulated
// again, or kept by evaluate).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "drapegen/diagnosis/forward_model.hpp"
#include "drapegen/diagnosis/hem_profile.hpp"
#include "drapegen/renderer/noise.hpp"
#include "drapegen/renderer/random.hpp"
#include "drapegen/sim/measures.hpp"
#include "small_reality.hpp"

namespace drapegen::diagnosis {
namespace {

namespace fs = std::filesystem;

/// A noiseless capture of the fixture's fabric (generated into a directory named `name`) and a 12x12 forward model
/// of it; unset, with the reason reported as a test failure, if either fails.
struct SmallModel {
  fixture::SmallReality made;
  std::unique_ptr<ForwardModel> model;
};
std::optional<SmallModel> small_model(const std::string& name) {
  RealitySpec spec = fixture::small_reality_spec();
  spec.noise = false;
  auto made = fixture::generate_small_reality(name, spec);
  if (!made) return std::nullopt;
  FitSettings settings;
  settings.resolution = 12;
  auto model = ForwardModel::create(made->capture, settings);
  EXPECT_TRUE(model.has_value()) << (model ? "" : model.error().message);
  if (!model) return std::nullopt;
  return SmallModel{std::move(*made), std::move(*model)};
}

TEST(ForwardModel, LaidAgainCarriesAYieldingSpecimensSetAndNothingOfAnElasticOne) {
  auto small = small_model("laid_again");
  ASSERT_TRUE(small.has_value());
  const RealitySpec& spec = small->made.spec;
  auto& model = small->model;
  const auto states = fit_initial_states(2, 7);

  ModelSetup elastic;
  elastic.bending = spec.bending;
  auto elastic_again = model->laid_again(elastic, states[1]);
  ASSERT_TRUE(elastic_again.has_value()) << elastic_again.error().message;
  const Eigen::VectorXd& none = elastic_again->plastic_set.rest_angles;
  ASSERT_GT(none.size(), 0);
  EXPECT_EQ(none.cwiseAbs().maxCoeff(), 0.0);  // an elastic specimen springs back flat
  EXPECT_EQ(elastic_again->plastic_set.specimen_seed, states[1].seed);

  ModelSetup yielding = elastic;
  yielding.effects.bending_yield_curvature = 10.0;  // 1/m: the drape's folds bend well past it
  auto once = model->laid_again(yielding, states[1]);
  ASSERT_TRUE(once.has_value()) << once.error().message;
  EXPECT_GT(once->plastic_set.rest_angles.cwiseAbs().maxCoeff(), 0.1);
  EXPECT_EQ(once->plastic_set.specimen_seed, states[1].seed);
  // Laid a second time from another state: still the first drape's specimen, its set grown from the first one's.
  auto twice = model->laid_again(*once, states[0]);
  ASSERT_TRUE(twice.has_value()) << twice.error().message;
  EXPECT_EQ(twice->plastic_set.specimen_seed, states[1].seed);
  EXPECT_EQ(twice->plastic_set.rest_angles.size(), once->plastic_set.rest_angles.size());
  EXPECT_GT((twice->plastic_set.rest_angles - once->plastic_set.rest_angles).cwiseAbs().maxCoeff(), 0.0);

  // evaluate keeps the set each yielding drape leaves, so laying it again needs no second simulation: the same set as
  // laid_again's from that state; an elastic setup's drapes keep none.
  auto evaluated = model->evaluate(yielding, states);
  ASSERT_TRUE(evaluated.has_value()) << evaluated.error().message;
  const ModelSetup kept = ForwardModel::laid_again(yielding, evaluated->states[1]);
  EXPECT_EQ(kept.plastic_set.specimen_seed, once->plastic_set.specimen_seed);
  EXPECT_EQ(kept.plastic_set.rest_angles, once->plastic_set.rest_angles);
  auto evaluated_elastic = model->evaluate(elastic, states);
  ASSERT_TRUE(evaluated_elastic.has_value()) << evaluated_elastic.error().message;
  EXPECT_EQ(evaluated_elastic->best.left.rest_angles.size(), 0);
  fs::remove_all(small->made.dir);
}

TEST(ForwardModel, LaysTheSpecimenOnTheCapturesFace) {
  // A capture stating "face": "down" is simulated turned over: its drapes lie face down, an elastic one as the mirror
  // image of the face-up drape from the same state, and a yielding specimen's set bends the other way there.
  auto small = small_model("face");
  ASSERT_TRUE(small.has_value());
  Capture turned_capture = small->made.capture;
  turned_capture.face_down = true;
  FitSettings settings;
  settings.resolution = 12;
  auto turned = ForwardModel::create(turned_capture, settings);
  ASSERT_TRUE(turned.has_value()) << turned.error().message;
  const auto states = fit_initial_states(2, 7);
  ModelSetup elastic;
  elastic.bending = small->made.spec.bending;
  auto up = small->model->simulate(elastic, states[1]);
  auto down = (*turned)->simulate(elastic, states[1]);
  ASSERT_TRUE(up.has_value() && down.has_value());
  EXPECT_FALSE(sim::lies_face_down(*up));
  EXPECT_TRUE(sim::lies_face_down(*down));
  // states[1] has no drift: the face-down drape is the face-up one mirrored across the specimen's u axis turned by the
  // state's rotation (0 here).
  ASSERT_EQ(states[1].rotation, 0.0);
  Eigen::Matrix3Xd mirrored = up->positions;
  mirrored.row(1) *= -1.0;
  EXPECT_LT((down->positions - mirrored).colwise().norm().maxCoeff(), 1e-9);

  ModelSetup yielding = elastic;
  yielding.effects.bending_yield_curvature = 10.0;
  auto set = small->model->laid_again(yielding, states[1]);
  ASSERT_TRUE(set.has_value()) << set.error().message;
  auto again_up = small->model->simulate(*set, states[0]);
  auto again_down = (*turned)->simulate(*set, states[0]);
  ASSERT_TRUE(again_up.has_value() && again_down.has_value());
  Eigen::Matrix3Xd again_mirrored = again_up->positions;
  again_mirrored.row(1) *= -1.0;
  EXPECT_GT((again_down->positions - again_mirrored).colwise().norm().maxCoeff(), 5e-3);
  fs::remove_all(small->made.dir);
}

TEST(ForwardModel, AViewWhoseCaptureSeesNoRigidSurfaceHasNoStableTerm) {
  // The capture's view 3 (the held-out one: the outline the drape is turned to is the fit views') with every pixel on
  // the platform top or the bare cylinder side cleared (as a view blocked there, or aimed past them): the stable
  // term's mean is over the other three views, each compared as before, not over four with 0 (or the truncation) for
  // the view that has none.
  auto small = small_model("no_rigid_view");
  ASSERT_TRUE(small.has_value());
  Capture blocked = small->made.capture;
  const MetricWeights weights = FitSettings{}.weights;
  CaptureView& view = blocked.views[3];
  const ViewFeatures features = view_features(view.depth, view.camera, weights);
  int cleared = 0;
  for (int v = 0; v < view.depth.height; ++v) {
    for (int u = 0; u < view.depth.width; ++u) {
      const float z = view.depth.at(u, v);
      if (z > 0.0f && stable_pixel(features, u, v, z, weights)) view.depth.at(u, v) = 0.0f, ++cleared;
    }
  }
  ASSERT_GT(cleared, 100);
  FitSettings settings;
  settings.resolution = 12;
  auto model = ForwardModel::create(blocked, settings);
  ASSERT_TRUE(model.has_value()) << model.error().message;

  ModelSetup elastic;
  elastic.bending = small->made.spec.bending;
  auto drape = small->model->simulate(elastic, fit_initial_states(1, 3)[0]);
  ASSERT_TRUE(drape.has_value()) << drape.error().message;
  drape->positions.row(2).array() += 0.003;  // 3 mm above: every view's rigid surfaces disagree
  auto all = small->model->score(*drape, elastic);
  auto three = (*model)->score(*drape, elastic);
  ASSERT_TRUE(all.has_value() && three.has_value());
  EXPECT_EQ(three->angle, all->angle);
  EXPECT_EQ(three->views[3].captured_stable_pixels, 0);
  EXPECT_GT(all->views[3].captured_stable_pixels, 100);
  double others = 0.0;
  for (int v : {0, 1, 2}) {
    EXPECT_EQ(three->views[v].stable_rms, all->views[v].stable_rms) << "view " << v;
    EXPECT_GT(all->views[v].stable_rms, 1e-3) << "view " << v;
    others += all->views[v].stable_rms;
  }
  EXPECT_NEAR(three->stable_all, others / 3.0, 1e-12);
  EXPECT_NEAR(all->stable_all, (others + all->views[3].stable_rms) / 4.0, 1e-12);
  EXPECT_EQ(three->stable_fit, all->stable_fit);
  fs::remove_all(small->made.dir);
}

TEST(ForwardModel, EvaluatesOnSeveralThreadsAsOnOne) {
  // The initial states simulated on three threads: the same drapes, scores, best state and plastic sets as on one,
  // each state simulated once.
  auto small = small_model("threads");
  ASSERT_TRUE(small.has_value());
  auto& model = small->model;
  const auto states = fit_initial_states(3, 5);
  ModelSetup yielding;
  yielding.bending = small->made.spec.bending;
  yielding.effects.bending_yield_curvature = 10.0;

  auto one = model->evaluate(yielding, states);
  ASSERT_TRUE(one.has_value()) << one.error().message;
  const int simulations = model->simulations();
  model->set_threads(3);
  auto three = model->evaluate(yielding, states);
  ASSERT_TRUE(three.has_value()) << three.error().message;
  EXPECT_EQ(model->simulations(), 2 * simulations);
  EXPECT_EQ(three->best.state, one->best.state);
  ASSERT_EQ(three->states.size(), states.size());
  for (std::size_t k = 0; k < states.size(); ++k) {
    EXPECT_EQ(three->states[k].state, static_cast<int>(k));
    EXPECT_EQ(three->states[k].mesh.positions, one->states[k].mesh.positions) << "state " << k;
    EXPECT_EQ(three->states[k].fit_score, one->states[k].fit_score) << "state " << k;
    EXPECT_EQ(three->states[k].left.rest_angles, one->states[k].left.rest_angles) << "state " << k;
  }
  fs::remove_all(small->made.dir);
}

TEST(ForwardModel, EveryDrapeCarriesItsDrapeCoefficientTheCapturesAndTheEvaluationsMedian) {
  // The placement drape test's inputs (floors.hpp, GapTerms::placement_dc): each drape's drape coefficient measured
  // as the capture's is, from the outline its noisy renders show in every view; the capture's from its own views;
  // the median over the evaluation's drapes.
  auto small = small_model("coefficients");
  ASSERT_TRUE(small.has_value());
  auto& model = small->model;
  ModelSetup elastic;
  elastic.bending = small->made.spec.bending;
  auto e = model->evaluate(elastic, fit_initial_states(3, 7));
  ASSERT_TRUE(e.has_value()) << e.error().message;
  const SpecimenFacts& specimen = model->capture().specimen;
  const double capture = drape_coefficient(hem_profile_from_capture(model->capture()), specimen);
  EXPECT_GT(capture, 0.0);
  EXPECT_LT(capture, 1.0);
  EXPECT_EQ(drape_coefficient(model->capture()), capture);  // the capture's overload: the outline its views see
  std::vector<renderer::DepthImage> own_views;
  for (const auto& view : model->capture().views) own_views.push_back(view.depth);
  EXPECT_EQ(model->views_drape_coefficient(own_views), capture);
  EXPECT_EQ(model->target().drape_coefficient, capture);
  const renderer::NoiseModel noise = renderer::NoiseModel::kinect();
  std::vector<double> own;
  for (const auto& d : e->states) {
    auto clean = model->render(d.mesh, d.angle, elastic.sensor);
    ASSERT_TRUE(clean.has_value()) << clean.error().message;
    std::vector<renderer::DepthImage> noisy;
    for (std::size_t v = 0; v < clean->size(); ++v)
      noisy.push_back(noise.apply((*clean)[v], renderer::mix_seed(ForwardModel::kModelNoiseSeed, v)));
    EXPECT_EQ(d.drape_coefficient, model->views_drape_coefficient(noisy));
    // An elastic drape's hem is seen where it lies: the views' measure is the mesh outline's, to the views' pixels.
    EXPECT_NEAR(d.drape_coefficient, drape_coefficient(hem_profile_from_mesh(d.mesh), specimen), 0.03);
    EXPECT_EQ(d.capture_drape_coefficient, capture);
    own.push_back(d.drape_coefficient);
  }
  std::sort(own.begin(), own.end());
  for (const auto& d : e->states) EXPECT_EQ(d.median_drape_coefficient, own[1]);
  EXPECT_EQ(e->best.median_drape_coefficient, own[1]);
  auto alone = model->score(e->states[0].mesh, elastic);  // scored alone: its own
  ASSERT_TRUE(alone.has_value()) << alone.error().message;
  EXPECT_EQ(alone->median_drape_coefficient, alone->drape_coefficient);
  fs::remove_all(small->made.dir);
}

TEST(ForwardModel, RescoresDrapesAsEvaluatedAndRefusesNonFiniteOnes) {
  // rescore scores given drapes as evaluate scored them. A drape with a non-finite position, and no drape that scores
  // finitely, are errors: never an empty best drape scored 0 (a perfect fit to whatever optimiser asked).
  auto small = small_model("rescore");
  ASSERT_TRUE(small.has_value());
  auto& model = small->model;
  ModelSetup elastic;
  elastic.bending = small->made.spec.bending;
  auto evaluated = model->evaluate(elastic, fit_initial_states(1, 3));
  ASSERT_TRUE(evaluated.has_value()) << evaluated.error().message;
  const sim::ClothMesh& drape = evaluated->best.mesh;

  auto again = model->rescore({drape}, elastic);
  ASSERT_TRUE(again.has_value()) << again.error().message;
  EXPECT_EQ(again->best.fit_score, evaluated->best.fit_score);
  EXPECT_GT(again->best.fit_score, 0.0);

  // A drape with a NaN position (a diverged simulation's) is an error, not a score.
  sim::ClothMesh broken = drape;
  broken.positions(2, 0) = std::numeric_limits<double>::quiet_NaN();
  auto nan = model->rescore({drape, broken}, elastic);
  ASSERT_FALSE(nan.has_value()) << "a drape with a NaN position scored " << nan->states[1].fit_score;
  EXPECT_NE(nan.error().message.find("non-finite positions"), std::string::npos) << nan.error().message;
  // No drape at all: no best one.
  auto none = model->rescore({}, elastic);
  ASSERT_FALSE(none.has_value());
  EXPECT_NE(none.error().message.find("finite score"), std::string::npos) << none.error().message;
  fs::remove_all(small->made.dir);
}

}  // namespace
}  // namespace drapegen::diagnosis
