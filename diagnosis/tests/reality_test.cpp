// Placements of one specimen by the reality generator: a second capture of the same specimen keeps what belongs to
// the specimen and the tester (mesh, fabric, effects, camera calibration and its error) and changes what a
// re-placement changes (initial state, orientation, drift, misalignment direction, noise).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <unistd.h>
#include <vector>

#include "drapegen/diagnosis/capture.hpp"
#include "drapegen/diagnosis/reality.hpp"

namespace drapegen::diagnosis {
namespace {

namespace fs = std::filesystem;

struct Placed {
  Capture capture;
  nlohmann::json truth;
};

Placed place(int placement, const fs::path& dir,
             const std::vector<std::string>& effects = {"misalign=15", "pose=2"}, bool turn_over = false) {
  RealitySpec spec;
  spec.bending.alpha = {13923, 11455, 8821};
  spec.bending.beta = {-35390, -29660, -22042};
  spec.resolution = 12;
  spec.seed = 21;
  spec.placement = placement;
  spec.turn_over = turn_over;
  spec.noise = false;  // so that a difference between two placements is the drape's, not the noise's
  spec.measured_bending_error = 0.1;
  for (const auto& e : effects) spec.effects.push_back(*parse_reality_effect(e));
  auto r = generate_reality(spec, dir.string());
  EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message);
  if (!r) return {};
  Placed p;
  auto capture = read_capture(dir.string());
  EXPECT_TRUE(capture.has_value()) << (capture ? "" : capture.error().message);
  if (capture) p.capture = std::move(capture).value();
  std::ifstream in(r->truth_path);
  p.truth = nlohmann::json::parse(in);
  return p;
}

TEST(Reality, ASecondPlacementKeepsTheSpecimenAndTheRigAndMovesTheDrape) {
  const fs::path root = fs::temp_directory_path() / ("drapegen_reality_test_" + std::to_string(::getpid()));
  fs::remove_all(root);
  const Placed first = place(0, root / "first"), again = place(0, root / "again"), second = place(1, root / "second");
  ASSERT_EQ(first.capture.views.size(), 4u);
  ASSERT_EQ(second.capture.views.size(), 4u);
  // Deterministic: placement 0 twice is the same capture.
  EXPECT_EQ(first.capture.views[0].depth.depth, again.capture.views[0].depth.depth);
  EXPECT_EQ(first.truth["placement"], 0);
  // Placement 0 is the capture the generator made before placements existed (values from the build of a979b0a, the
  // same specification): the same draws in the same order.
  EXPECT_NEAR(first.truth["initial_state"]["rotation_rad"].get<double>(), 0.1749647207392716, 1e-12);
  EXPECT_NEAR(first.truth["drift_mm"][0].get<double>(), 14.580290290608785, 1e-9);
  EXPECT_NEAR(first.truth["drift_mm"][1].get<double>(), -0.19503230291819967, 1e-9);
  EXPECT_NEAR(first.truth["sensor"]["rotation_rad"][0].get<double>(), -0.010656690438273227, 1e-12);
  EXPECT_NEAR(first.truth["sensor"]["rotation_rad"][1].get<double>(), 0.027208705510405388, 1e-12);
  EXPECT_NEAR(first.truth["sensor"]["rotation_rad"][2].get<double>(), 0.019094265434880863, 1e-12);
  EXPECT_EQ(second.truth["placement"], 1);
  // The rig and its error are the tester's: the same calibration and the same (unknown) pose error.
  for (int v = 0; v < 4; ++v) {
    EXPECT_TRUE(first.capture.views[v].camera.world_to_camera.isApprox(second.capture.views[v].camera.world_to_camera))
        << "view " << v;
  }
  EXPECT_EQ(first.truth["sensor"], second.truth["sensor"]);
  EXPECT_EQ(first.truth["family"], second.truth["family"]);
  EXPECT_EQ(first.truth["effects"], second.truth["effects"]);
  // So is the bending test's report of the specimen (not the truth).
  ASSERT_TRUE(first.capture.specimen.measured_bending && second.capture.specimen.measured_bending);
  const BendingParameters& m1 = first.capture.specimen.measured_bending->bending;
  const BendingParameters& m2 = second.capture.specimen.measured_bending->bending;
  EXPECT_EQ(m1.alpha.warp, m2.alpha.warp);
  EXPECT_EQ(m1.beta.weft, m2.beta.weft);
  EXPECT_NE(m1.alpha.warp, first.truth["alpha"][0].get<double>());
  EXPECT_NEAR(first.capture.specimen.measured_bending->within_factor, std::exp(0.2), 1e-12);
  // The placement is new: initial state, orientation and drift; the misalignment keeps its distance (15 mm plus
  // the augmentation's up to 2 mm) but not its direction.
  EXPECT_NE(first.truth["initial_state"]["seed"], second.truth["initial_state"]["seed"]);
  EXPECT_NE(first.truth["initial_state"]["rotation_rad"], second.truth["initial_state"]["rotation_rad"]);
  auto offset = [](const nlohmann::json& t) {
    return std::hypot(t["drift_mm"][0].get<double>(), t["drift_mm"][1].get<double>());
  };
  EXPECT_NEAR(offset(first.truth), 15.0, 2.0);
  EXPECT_NEAR(offset(second.truth), 15.0, 2.0);
  EXPECT_NE(first.truth["drift_mm"], second.truth["drift_mm"]);
  // And so is the drape the cameras see.
  int differing = 0;
  const auto& a = first.capture.views[0].depth.depth;
  const auto& b = second.capture.views[0].depth.depth;
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) differing += std::abs(a[i] - b[i]) > 1e-3f;
  EXPECT_GT(differing, static_cast<int>(a.size() / 100));
  fs::remove_all(root);
}

TEST(Reality, AMeasuredBendingHasTheStatedLognormalError) {
  // 6 parameters x 400 specimens: ln(measured / truth) has mean 0 and deviation sigma; about 95% lie within the
  // stated factor e^(2 sigma); the sign of beta is kept; the same seed gives the same report.
  const BendingParameters truth{.alpha = {13923, 11455, 8821}, .beta = {-35390, 2000, -22042}};
  const double sigma = 0.12;
  double sum = 0.0, sum2 = 0.0;
  int n = 0, within = 0;
  for (std::uint64_t seed = 0; seed < 400; ++seed) {
    const MeasuredBending m = measure_bending(truth, sigma, seed);
    EXPECT_NEAR(m.within_factor, std::exp(2.0 * sigma), 1e-12);
    const BendingParameters& b = m.bending;
    for (auto [t, x] : {std::pair{truth.alpha.warp, b.alpha.warp}, std::pair{truth.alpha.bias, b.alpha.bias},
                        std::pair{truth.alpha.weft, b.alpha.weft}, std::pair{truth.beta.warp, b.beta.warp},
                        std::pair{truth.beta.bias, b.beta.bias}, std::pair{truth.beta.weft, b.beta.weft}}) {
      ASSERT_GT(x / t, 0.0);
      const double e = std::log(x / t);
      sum += e, sum2 += e * e, ++n;
      within += std::abs(e) <= std::log(m.within_factor);
    }
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_LT(std::abs(mean), 3.0 * sigma / std::sqrt(n));
  EXPECT_NEAR(sd, sigma, 0.1 * sigma);
  EXPECT_NEAR(static_cast<double>(within) / n, 0.954, 0.02);
  EXPECT_EQ(measure_bending(truth, sigma, 7).bending.beta.bias, measure_bending(truth, sigma, 7).bending.beta.bias);
  EXPECT_NE(measure_bending(truth, sigma, 7).bending.beta.bias, measure_bending(truth, sigma, 8).bending.beta.bias);
}

TEST(Reality, AYieldingSpecimenCarriesItsPlasticSetToTheNextPlacement) {
  const fs::path root = fs::temp_directory_path() / ("drapegen_reality_set_" + std::to_string(::getpid()));
  fs::remove_all(root);
  const Placed first = place(0, root / "first", {"yield=20"});
  const Placed second = place(1, root / "second", {"yield=20"});
  const Placed third = place(2, root / "third", {"yield=20"});
  const Placed elastic = place(1, root / "elastic");
  EXPECT_EQ(first.truth["plastic_set"]["from_placements"], 0);
  EXPECT_EQ(second.truth["plastic_set"]["from_placements"], 1);
  EXPECT_EQ(third.truth["plastic_set"]["from_placements"], 2);
  EXPECT_EQ(elastic.truth["plastic_set"]["from_placements"], 0);
  // A fold's worth of set (the first drape bends its hinges well past 20 /m).
  EXPECT_GT(second.truth["plastic_set"]["largest_rest_angle_rad"].get<double>(), 0.1);
  EXPECT_GT(third.truth["plastic_set"]["largest_rest_angle_rad"].get<double>(), 0.1);
  EXPECT_TRUE(third.truth["plastic_set"]["earlier_drapes_converged"].get<bool>());
  // The third placement's set is the one its two earlier drapes left, not the second placement's carried over: the
  // second drape (from a new state and orientation) sets its own hinges further.
  EXPECT_NE(second.truth["plastic_set"]["largest_rest_angle_rad"].get<double>(),
            third.truth["plastic_set"]["largest_rest_angle_rad"].get<double>());
  fs::remove_all(root);
}

TEST(Reality, ASpecimenTurnedOverLiesFaceDownOnOddPlacementsWithItsSet) {
  const fs::path root = fs::temp_directory_path() / ("drapegen_reality_face_" + std::to_string(::getpid()));
  fs::remove_all(root);
  const Placed yield_kept = place(1, root / "yield_kept", {"yield=20"});
  const Placed yield_turned = place(1, root / "yield_turned", {"yield=20"}, true);
  const Placed third = place(2, root / "third", {"yield=20"}, true);
  const Placed elastic_kept = place(1, root / "elastic_kept", {});
  const Placed elastic_turned = place(1, root / "elastic_turned", {}, true);
  EXPECT_FALSE(yield_kept.capture.face_down);
  EXPECT_TRUE(yield_turned.capture.face_down);
  EXPECT_FALSE(third.capture.face_down);  // turned over twice
  EXPECT_EQ(yield_turned.truth["face"], "down");
  EXPECT_EQ(third.truth["face"], "up");
  // The set the first drape left is carried to the turned-over placement (the sim's tests check that it bends the
  // other way there: Effects.ASpecimenLaidFaceDownDrapesAsItsMirrorImageWithItsRestShapeTurned).
  EXPECT_EQ(yield_turned.truth["plastic_set"]["from_placements"], 1);
  EXPECT_EQ(yield_turned.truth["plastic_set"]["largest_rest_angle_rad"],
            yield_kept.truth["plastic_set"]["largest_rest_angle_rad"]);
  EXPECT_NE(yield_turned.truth["drape_coefficient"], yield_kept.truth["drape_coefficient"]);
  EXPECT_EQ(elastic_turned.truth["face"], "down");
  EXPECT_EQ(elastic_kept.truth["face"], "up");
  fs::remove_all(root);
}

TEST(Reality, RejectsANegativePlacement) {
  RealitySpec spec;
  spec.bending.alpha = {13923, 11455, 8821};
  spec.placement = -1;
  EXPECT_FALSE(generate_reality(spec, (fs::temp_directory_path() / "drapegen_reality_bad").string()).has_value());
  spec.placement = kMaxPlacement + 1;
  EXPECT_FALSE(generate_reality(spec, (fs::temp_directory_path() / "drapegen_reality_bad").string()).has_value());
}

// An effect of strength 0 is no effect (its capture a control whose truth names a family) and is refused for every
// effect, as a strength in another base is (stod read bias=0x10 as 16 mm); a signed effect keeps its sign.
TEST(Reality, AnEffectOfStrengthZeroOrNotDecimalIsRefused) {
  for (const char* name : {"yield", "shear", "curl", "friction", "misalign", "pose", "bias", "multipath"}) {
    const auto zero = parse_reality_effect(std::string(name) + "=0");
    ASSERT_FALSE(zero) << name;
    EXPECT_NE(zero.error().message.find("=0 changes nothing"), std::string::npos) << zero.error().message;
  }
  const auto hex = parse_reality_effect("bias=0x10");
  ASSERT_FALSE(hex);
  EXPECT_NE(hex.error().message.find("'0x10' is not a number"), std::string::npos) << hex.error().message;
  const auto negative = parse_reality_effect("bias=-4");
  ASSERT_TRUE(negative) << negative.error().message;
  EXPECT_DOUBLE_EQ(negative->strength, -4.0);
  EXPECT_DOUBLE_EQ(parse_reality_effect("curl=-150")->strength, -150.0);
}

}  // namespace
}  // namespace drapegen::diagnosis
