#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "drapegen/diagnosis/attribution.hpp"
#include "drapegen/diagnosis/floors.hpp"

using namespace drapegen::diagnosis;

namespace {

/// Floors as the gate sees them: the stable-region term's floor (m) and the shape distance's floor.
Floors floors_of(double stable, double shape) {
  Floors f;
  f.stable = stable;
  f.shape = shape;
  return f;
}

/// A drape with the two gated terms set (m, dimensionless) and an all-view score that the excess must ignore.
ScoredDrape drape_of(double stable_all, double shape_all, double all_score = 0.0) {
  ScoredDrape d;
  d.stable_all = stable_all;
  d.shape_all = shape_all;
  d.all_score = all_score;
  return d;
}

/// A refitted candidate with the terms the attribution ranks by (objective in m).
CandidateResult ranked(Effect effect, bool confirmed, double shrinkage, double objective, double held_out) {
  CandidateResult c;
  c.effect = effect;
  c.confirmation = confirmed ? Confirmation::kScore : Confirmation::kNone;
  c.shrinkage = shrinkage;
  c.objective = objective;
  c.held_out_shrinkage = held_out;
  return c;
}

}  // namespace

TEST(ExcessAboveFloors, IsZeroExactlyWhenBothTestsPass) {
  const Floors f = floors_of(2e-3, 1.15);
  EXPECT_EQ(excess_above_floors(drape_of(1e-3, 0.9), f), 0.0);
  EXPECT_EQ(excess_above_floors(drape_of(2e-3, 1.15), f), 0.0);  // at the floor is within it
  EXPECT_GT(excess_above_floors(drape_of(2e-3, std::nextafter(1.15, 2.0)), f), 0.0);
  EXPECT_GT(excess_above_floors(drape_of(std::nextafter(2e-3, 1.0), 1.15), f), 0.0);
}

TEST(ExcessAboveFloors, SumsEachTermsExcessRelativeToItsFloor) {
  const Floors f = floors_of(2e-3, 1.15);
  EXPECT_NEAR(excess_above_floors(drape_of(1e-3, 1.38), f), 0.2, 1e-12);  // shape only: 1.38 / 1.15 - 1
  EXPECT_NEAR(excess_above_floors(drape_of(3e-3, 0.5), f), 0.5, 1e-12);   // stable only: 3 / 2 - 1
  EXPECT_NEAR(excess_above_floors(drape_of(3e-3, 1.38), f), 0.7, 1e-12);  // both
}

TEST(ExcessAboveFloors, IgnoresTheAllViewScore) {
  // Run B's shear_00 in kind: the refit lowers the all-view score below the typical floor sample's, which the old
  // definition (all-view score above the median floor sample) could not see; only the gated terms count.
  const Floors f = floors_of(2e-3, 1.15);
  const double baseline = excess_above_floors(drape_of(1e-3, 1.22, 7.81e-3), f);
  EXPECT_EQ(baseline, excess_above_floors(drape_of(1e-3, 1.22, 6.26e-3), f));
  EXPECT_GT(baseline, 0.0);
}

TEST(GapTerms, AreTheMeanOfTheCaptureAndTheHeldOutCapture) {
  const ScoredDrape a = drape_of(2e-3, 0.6), b = drape_of(4e-3, 1.4);
  const GapTerms one = gap_terms(a);
  EXPECT_EQ(one.stable, 2e-3);
  EXPECT_EQ(one.shape, 0.6);
  const GapTerms both = gap_terms(a, &b);
  EXPECT_NEAR(both.stable, 3e-3, 1e-15);
  EXPECT_NEAR(both.shape, 1.0, 1e-15);
  // The gate on the mean: b alone is above a 1.15 shape floor, the mean of the two placements is not.
  const Floors f = floors_of(5e-3, 1.15);
  EXPECT_GT(excess_above_floors(b, f), 0.0);
  EXPECT_EQ(excess_above_floors(both, f), 0.0);
}

// The placement test (off unless its floor is set): the larger placement's shape distance against its own floor, so
// an effect that shows on one placement and not the other (a plastic set carried to the next placement) is not lost
// in the mean; its excess adds to the others'.
TEST(GapTerms, TheLargerPlacementHasATestOfItsOwn) {
  const ScoredDrape a = drape_of(2e-3, 0.4), b = drape_of(2e-3, 1.5);
  const GapTerms both = gap_terms(a, &b), reversed = gap_terms(b, &a);
  EXPECT_EQ(both.shape_max, 1.5);
  EXPECT_EQ(reversed.shape_max, 1.5);
  EXPECT_EQ(gap_terms(a).shape_max, 0.4);  // one placement: its own
  Floors f = floors_of(5e-3, 1.15);
  EXPECT_EQ(excess_above_floors(both, f), 0.0);  // the mean, 0.95, is within; no placement test
  f.placement_shape = 1.2;
  EXPECT_NEAR(excess_above_floors(both, f), 0.25, 1e-12);  // 1.5 / 1.2 - 1
  f.placement_shape = 1.5;
  EXPECT_EQ(excess_above_floors(both, f), 0.0);  // at its floor is within it
  const GapTerms far = gap_terms(drape_of(2e-3, 1.3), &b);  // mean 1.4: 1.4 / 1.15 - 1, and 1.5 / 1.2 - 1
  f.placement_shape = 1.2;
  EXPECT_NEAR(excess_above_floors(far, f), 1.4 / 1.15 - 1.0 + 0.25, 1e-12);
}

/// A drape on a placement whose capture has drape coefficient `capture` and whose setup's drapes have the median
/// `model` there (the gated terms within any floor).
ScoredDrape placed(double capture, double model) {
  ScoredDrape d = drape_of(1e-3, 0.5);
  d.capture_drape_coefficient = capture;
  d.median_drape_coefficient = model;
  return d;
}

// The placement drape test (off unless its floor is set): the captures' drape-coefficient difference less the
// model's, either sign, against a floor from the fitted fabric's stable drapes; its excess adds to the others'.
TEST(GapTerms, ThePlacementsDrapeCoefficientsHaveATestOfTheirOwn) {
  // A yielding specimen turned over drapes less (0.25 -> 0.33); an elastic model drapes alike on both (0.24).
  const ScoredDrape first = placed(0.25, 0.24), second = placed(0.33, 0.24), shifted = placed(0.33, 0.31);
  EXPECT_NEAR(gap_terms(first, &second).placement_dc, 0.08, 1e-12);
  EXPECT_NEAR(gap_terms(second, &first).placement_dc, 0.08, 1e-12);  // either order, either sign
  EXPECT_EQ(gap_terms(first).placement_dc, 0.0);                      // one placement: no test
  // A model whose drapes shift as the captures do (its plastic set laid again) explains the difference.
  EXPECT_NEAR(gap_terms(first, &shifted).placement_dc, 0.01, 1e-12);
  Floors f = floors_of(5e-3, 1.15);
  EXPECT_EQ(excess_above_floors(gap_terms(first, &second), f), 0.0);  // no floor: no test
  f.placement_dc = 0.02;
  EXPECT_NEAR(excess_above_floors(gap_terms(first, &second), f), 3.0, 1e-9);            // 0.08 / 0.02 - 1
  EXPECT_EQ(excess_above_floors(gap_terms(first, &shifted), f), 0.0);                   // 0.01: within
  EXPECT_NEAR(gap_shrinkage(excess_above_floors(gap_terms(first, &second), f),
                            excess_above_floors(gap_terms(first, &shifted), f)),
              1.0, 1e-12);
}

// Its floor: the largest difference two of the fitted fabric's stable drapes show, times the margin.
TEST(GapTerms, ThePlacementDrapeFloorIsTheStableDrapesRange) {
  Evaluation e;
  for (double dc : {0.21, 0.19, 0.23, 0.20}) {
    e.states.push_back(placed(0.2, 0.2));
    e.states.back().drape_coefficient = dc;
  }
  EXPECT_NEAR(placement_dc_floor(e, 1.15), 1.15 * 0.04, 1e-12);
  e.states.resize(1);
  EXPECT_EQ(placement_dc_floor(e, 1.15), 0.0);  // one drape: no range, no test
}

TEST(GapShrinkage, CreditsRemovingTheReasonTheGateFired) {
  const Floors f = floors_of(2e-3, 1.15);
  const double before = excess_above_floors(drape_of(1e-3, 1.38), f);  // the gate fired on the shape test
  EXPECT_DOUBLE_EQ(gap_shrinkage(before, excess_above_floors(drape_of(1e-3, 1.1), f)), 1.0);    // within: full
  EXPECT_NEAR(gap_shrinkage(before, excess_above_floors(drape_of(1e-3, 1.265), f)), 0.5, 1e-12);  // half way
  EXPECT_DOUBLE_EQ(gap_shrinkage(before, excess_above_floors(drape_of(1e-3, 1.38, 1e-3), f)), 0.0);  // unchanged
  // Trading the shape excess for a new stable-term excess of the same relative size earns nothing.
  EXPECT_NEAR(gap_shrinkage(before, excess_above_floors(drape_of(2.4e-3, 1.1), f)), 0.0, 1e-12);
  EXPECT_LT(gap_shrinkage(before, excess_above_floors(drape_of(1e-3, 1.5), f)), 0.0);  // worse: negative
}

TEST(GapShrinkage, IsZeroWhenThereWasNoExcess) { EXPECT_EQ(gap_shrinkage(0.0, 0.3), 0.0); }

TEST(RanksBefore, ConfirmedFirstThenShrinkageThenPhysicalEffectsThenObjectiveAmongEqualShrinkages) {
  // A confirmed candidate outranks an unconfirmed one whatever their shrinkages.
  EXPECT_TRUE(ranks_before(ranked(Effect::kCurl, true, 0.3, 9e-3, 0.0), ranked(Effect::kShear, false, 1.0, 1e-3, 0.5)));
  // The larger shrinkage first, whatever the objective.
  EXPECT_TRUE(ranks_before(ranked(Effect::kCurl, true, 0.8, 9e-3, 0.0), ranked(Effect::kShear, true, 0.7, 1e-3, 0.5)));
  // Both within the floors (shrinkage 1): the clipped excess cannot rank them, the smaller refit objective does,
  // ahead of the held-out shrinkage (seed 6's friction captures, docs/DIAGNOSIS_RESULTS.md "Session 19").
  const CandidateResult friction = ranked(Effect::kFriction, true, 1.0, 4.74e-3, 0.31);
  const CandidateResult shear = ranked(Effect::kShear, true, 1.0, 5.50e-3, 0.32);
  EXPECT_TRUE(ranks_before(friction, shear));
  EXPECT_FALSE(ranks_before(shear, friction));
  // A physical effect before the sensor error at equal shrinkage, even at a larger objective (seed 13's friction_02,
  // docs/DIAGNOSIS_RESULTS.md "Session 25")...
  const CandidateResult sensor = ranked(Effect::kSensor, true, 1.0, 4.0e-3, 0.4);
  EXPECT_TRUE(ranks_before(friction, sensor));
  EXPECT_FALSE(ranks_before(sensor, friction));
  // ... but not at a smaller shrinkage.
  EXPECT_TRUE(ranks_before(ranked(Effect::kSensor, true, 0.9, 6e-3, 0.0), ranked(Effect::kCurl, true, 0.8, 4e-3, 0.5)));
  // Equal objectives as well: the larger held-out shrinkage.
  EXPECT_TRUE(ranks_before(ranked(Effect::kCurl, true, 1.0, 5e-3, 0.4), ranked(Effect::kShear, true, 1.0, 5e-3, 0.3)));
  // A strict weak order: nothing ranks before itself.
  EXPECT_FALSE(ranks_before(friction, friction));
}

TEST(Confirms, AllowsTheToleranceAboveTheReferenceAndNoMore) {
  EXPECT_TRUE(confirms(5.0e-3, 6.0e-3, 0.0));   // better
  EXPECT_TRUE(confirms(6.0e-3, 6.0e-3, 0.0));   // equal
  EXPECT_FALSE(confirms(6.1e-3, 6.0e-3, 0.0));  // worse, no tolerance
  // 10%: 9.7% worse on the held-out capture (seed 10's yield_04, docs/DIAGNOSIS_RESULTS.md "Session 23") is
  // confirmed ...
  EXPECT_TRUE(confirms(5.968e-3, 5.44e-3, 0.1));
  // ... 10.5% worse is not.
  EXPECT_FALSE(confirms(6.012e-3, 5.44e-3, 0.1));
  // The default since session 74 (rule W), 20%: seed 93's friction_01 in kind, its refit 12.3% worse there than the
  // reference, is confirmed; 21% worse is not.
  EXPECT_EQ(AttributionSettings{}.held_out_tolerance, 0.2);
  EXPECT_TRUE(confirms(1.123 * 5.44e-3, 5.44e-3, 0.2));
  EXPECT_FALSE(confirms(1.21 * 5.44e-3, 5.44e-3, 0.2));
}

TEST(Confirmation, WithinTheFloorsOnTheHeldOutCaptureConfirmsOnlyWhenAskedAndOnlyWhereTheScoreDoesNot) {
  // Seed 57's curl_00 in kind (docs/DIAGNOSIS_RESULTS.md, "Session 61"): the curl refit's drape on the held-out
  // capture is within the floors (shape 0.90, stable 2.86 mm), yet its score there, 6.45 mm, is more than 10% above
  // the reference's 5.30 mm.
  const Floors f = floors_of(3.0e-3, 1.0);
  const ScoredDrape within = drape_of(2.86e-3, 0.90, 6.45e-3);
  AttributionSettings settings;
  EXPECT_FALSE(settings.confirm_within_floors);  // off by default
  EXPECT_EQ(confirmation(6.45e-3, 5.30e-3, &within, f, settings), Confirmation::kNone);
  settings.confirm_within_floors = true;
  EXPECT_EQ(confirmation(6.45e-3, 5.30e-3, &within, f, settings), Confirmation::kWithinFloors);
  // Confirmed by the score: so reported, within the floors or not.
  EXPECT_EQ(confirmation(5.0e-3, 5.30e-3, &within, f, settings), Confirmation::kScore);
  // Above either floor, or at a held-out view (no held-out capture): not confirmed.
  const ScoredDrape above_shape = drape_of(2.86e-3, std::nextafter(1.0, 2.0));
  const ScoredDrape above_stable = drape_of(std::nextafter(3.0e-3, 1.0), 0.90);
  EXPECT_EQ(confirmation(6.45e-3, 5.30e-3, &above_shape, f, settings), Confirmation::kNone);
  EXPECT_EQ(confirmation(6.45e-3, 5.30e-3, &above_stable, f, settings), Confirmation::kNone);
  EXPECT_EQ(confirmation(6.45e-3, 5.30e-3, nullptr, f, settings), Confirmation::kNone);
  // At both floors is within them.
  const ScoredDrape at = drape_of(3.0e-3, 1.0);
  EXPECT_EQ(confirmation(6.45e-3, 5.30e-3, &at, f, settings), Confirmation::kWithinFloors);
}

TEST(ValidationStates, AreFreshStatesNoFitOrFloorSelectsOn) {
  // The gap and every refitted candidate are judged from these: none may be one of the fit's states (flat and sine
  // from seed 1) or the floors' (sine from seed 1000), or the comparison inherits the fit's luckiest draw.
  AttributionSettings settings;
  const auto states = validation_states(settings);
  ASSERT_EQ(static_cast<int>(states.size()), settings.validation_states);
  const auto fit = fit_initial_states(16);
  const auto floors = fit_initial_states(17, 1000);
  for (const auto& v : states) {
    for (const auto& f : fit) EXPECT_FALSE(v.shape == f.shape && v.seed == f.seed);
    for (const auto& f : floors) EXPECT_FALSE(v.shape == f.shape && v.seed == f.seed);
  }
}

TEST(SensorBendingGrid, IsTheScalesTimesTheGainsInOrderWithinTheBoundsAndTheBudget) {
  using V = std::vector<std::vector<double>>;
  // The default bounds (ln x0.22 .. x4.5) and a gain bound above both gains: all six points, scales first.
  EXPECT_EQ(sensor_bending_grid(-1.5, 1.5, 50.0, 14),
            (V{{0.5, 15.0}, {0.5, 30.0}, {1.0, 15.0}, {1.0, 30.0}, {1.5, 15.0}, {1.5, 30.0}}));
  // A budget below six keeps the first points; none at all still scores one.
  EXPECT_EQ(sensor_bending_grid(-1.5, 1.5, 50.0, 4), (V{{0.5, 15.0}, {0.5, 30.0}, {1.0, 15.0}, {1.0, 30.0}}));
  EXPECT_EQ(sensor_bending_grid(-1.5, 1.5, 50.0, 0), (V{{0.5, 15.0}}));
  // A measured bending's narrow box clamps the three scales to one: two distinct points, not six.
  EXPECT_EQ(sensor_bending_grid(-0.1, 0.2, 50.0, 14), (V{{0.2, 15.0}, {0.2, 30.0}}));
  // A gain bound below 30 mm clamps the second gain; both gains clamped to it coincide.
  EXPECT_EQ(sensor_bending_grid(-0.1, 0.2, 20.0, 14), (V{{0.2, 15.0}, {0.2, 20.0}}));
  EXPECT_EQ(sensor_bending_grid(-0.1, 0.2, 10.0, 14), (V{{0.2, 10.0}}));
}

TEST(PromoteFirst, MovesAConfirmedSignificantCandidateToTheFrontKeepingTheOthersOrder) {
  std::vector<CandidateResult> order{
      ranked(Effect::kYield, true, 0.9, 5e-3, 0.0), ranked(Effect::kShear, true, 0.5, 5e-3, 0.0),
      ranked(Effect::kCurl, true, 0.76, 5e-3, 0.0), ranked(Effect::kSensor, false, 0.3, 5e-3, 0.0)};
  ASSERT_TRUE(promote_first(order, Effect::kCurl, 0.25));
  EXPECT_EQ(order[0].effect, Effect::kCurl);
  EXPECT_EQ(order[1].effect, Effect::kYield);
  EXPECT_EQ(order[2].effect, Effect::kShear);
  EXPECT_EQ(order[3].effect, Effect::kSensor);
  EXPECT_FALSE(promote_first(order, Effect::kCurl, 0.25));  // already first
  // Unconfirmed, or below the significant shrinkage: nothing moves.
  std::vector<CandidateResult> weak{ranked(Effect::kYield, true, 0.9, 5e-3, 0.0),
                                    ranked(Effect::kCurl, false, 0.8, 5e-3, 0.0)};
  EXPECT_FALSE(promote_first(weak, Effect::kCurl, 0.25));
  EXPECT_EQ(weak[0].effect, Effect::kYield);
  weak = {ranked(Effect::kYield, true, 0.9, 5e-3, 0.0), ranked(Effect::kCurl, true, 0.2, 5e-3, 0.0)};
  EXPECT_FALSE(promote_first(weak, Effect::kCurl, 0.25));
  std::vector<CandidateResult> none{ranked(Effect::kYield, true, 0.9, 5e-3, 0.0)};
  EXPECT_FALSE(promote_first(none, Effect::kCurl, 0.25));
}

TEST(NearTiesFirst, NamesTheSmallestObjectiveOfTheSignificantConfirmedCandidatesWithinTheMargin) {
  // Seed 28's sensor_04 in kind (a depth bias): shear 0.0003 ahead of the sensor error, which fits with the smaller
  // objective.
  std::vector<CandidateResult> order{ranked(Effect::kShear, true, 0.4446, 10.69e-3, 0.08),
                                     ranked(Effect::kSensor, true, 0.4443, 10.17e-3, 0.33),
                                     ranked(Effect::kFriction, true, 0.29, 13.29e-3, 0.14)};
  std::vector<CandidateResult> exact = order;
  EXPECT_FALSE(near_ties_first(exact, 0.0, 0.25));  // a margin of 0: exact ties only (ranks_before's)
  EXPECT_EQ(exact[0].effect, Effect::kShear);
  ASSERT_TRUE(near_ties_first(order, 0.1, 0.25));
  EXPECT_EQ(order[0].effect, Effect::kSensor);
  EXPECT_EQ(order[1].effect, Effect::kShear);  // the others keep their order
  EXPECT_EQ(order[2].effect, Effect::kFriction);
  EXPECT_FALSE(near_ties_first(order, 0.1, 0.25));  // already first
  // Seed 20's curl_04 in kind: two physical effects 0.10 apart, the second with the smaller objective; just outside
  // the margin, or with the larger objective, the first stays.
  std::vector<CandidateResult> physical{ranked(Effect::kYield, true, 0.674, 8.77e-3, 0.081),
                                        ranked(Effect::kCurl, true, 0.578, 7.95e-3, 0.172)};
  std::vector<CandidateResult> outside = physical;
  EXPECT_FALSE(near_ties_first(outside, 0.09, 0.25));
  ASSERT_TRUE(near_ties_first(physical, 0.1, 0.25));
  EXPECT_EQ(physical[0].effect, Effect::kCurl);
  std::vector<CandidateResult> larger{ranked(Effect::kYield, true, 0.674, 7e-3, 0.0),
                                      ranked(Effect::kCurl, true, 0.6, 8e-3, 0.0)};
  EXPECT_FALSE(near_ties_first(larger, 0.1, 0.25));
  // A first tied exactly keeps ranks_before's order (friction before the sensor error at 1.0 on seeds 22-28), even
  // with a third within the margin that fits better.
  std::vector<CandidateResult> tied{ranked(Effect::kFriction, true, 1.0, 5.79e-3, 0.03),
                                    ranked(Effect::kSensor, true, 1.0, 5.85e-3, 0.07),
                                    ranked(Effect::kShear, true, 0.95, 5.2e-3, 0.19)};
  EXPECT_FALSE(near_ties_first(tied, 0.1, 0.25));
  EXPECT_EQ(tied[0].effect, Effect::kFriction);
  // Only a confirmed candidate that is significant itself, and only behind a confirmed first.
  std::vector<CandidateResult> unconfirmed{ranked(Effect::kSensor, true, 0.9, 8e-3, 0.0),
                                           ranked(Effect::kCurl, false, 0.88, 7e-3, 0.0)};
  EXPECT_FALSE(near_ties_first(unconfirmed, 0.1, 0.25));
  std::vector<CandidateResult> weak{ranked(Effect::kYield, true, 0.3, 8e-3, 0.0),
                                    ranked(Effect::kCurl, true, 0.22, 7e-3, 0.0)};
  EXPECT_FALSE(near_ties_first(weak, 0.1, 0.25));
  std::vector<CandidateResult> none_confirmed{ranked(Effect::kSensor, false, 0.9, 8e-3, 0.0),
                                              ranked(Effect::kCurl, false, 0.88, 7e-3, 0.0)};
  EXPECT_FALSE(near_ties_first(none_confirmed, 0.1, 0.25));
  std::vector<CandidateResult> empty;
  EXPECT_FALSE(near_ties_first(empty, 0.1, 0.25));
}

TEST(CommonBending, TheMedianScaleOfConfirmedCandidatesWithinTheFloors) {
  // Seed 22's none_01 in kind: four unlike effects each within the floors at x1.80 .. x2.72, a fifth confirmed above
  // them, a sixth within them but not confirmed (it must not count).
  const Floors f = floors_of(3e-3, 1.15);
  auto candidate = [&](Effect effect, bool confirmed, double scale, double shape) {
    CandidateResult c = ranked(effect, confirmed, 0.0, 0.0, 0.0);
    c.alpha_scale = scale;
    c.validated = drape_of(2e-3, shape);
    return c;
  };
  std::vector<CandidateResult> cs{
      candidate(Effect::kShear, true, 2.72, 1.0), candidate(Effect::kYield, true, 2.25, 1.1),
      candidate(Effect::kCurl, true, 2.12, 0.9),  candidate(Effect::kFriction, true, 1.80, 1.15),
      candidate(Effect::kSensor, true, 1.0, 1.3), candidate(Effect::kMisalignment, false, 1.0, 0.5)};
  const auto shared = common_bending(cs, f, 3);
  ASSERT_TRUE(shared);
  EXPECT_EQ(shared->effects, (std::vector<Effect>{Effect::kShear, Effect::kYield, Effect::kCurl, Effect::kFriction}));
  EXPECT_NEAR(shared->ln_scale, 0.5 * (std::log(2.12) + std::log(2.25)), 1e-12);  // the middle two of four
  EXPECT_TRUE(common_bending(cs, f, 4));
  EXPECT_FALSE(common_bending(cs, f, 5));  // four, not five
  EXPECT_FALSE(common_bending(cs, f, 0));  // off
  // Three: the middle one's scale.
  cs.erase(cs.begin());
  const auto three = common_bending(cs, f, 3);
  ASSERT_TRUE(three);
  EXPECT_NEAR(three->ln_scale, std::log(2.12), 1e-12);
  // Two within the floors are not enough (friction and the sensor error often both are: seeds 17 and 19).
  cs.erase(cs.begin());
  EXPECT_FALSE(common_bending(cs, f, 3));
}
