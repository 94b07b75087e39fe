#include "drapegen/diagnosis/report.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>
#include <string>
#include <utility>

#include "drapegen/renderer/preview.hpp"

namespace drapegen::diagnosis {
namespace {

constexpr const char* kCaveat = "rules out no effect whose drape an elastic fabric of another bending can match";

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// Appends a refitted candidate of `effect` with `shrinkage` to the result's attribution.
void add_candidate(DiagnosisResult& r, Effect effect, double shrinkage) {
  r.attribution.candidates.emplace_back();
  r.attribution.candidates.back().effect = effect;
  r.attribution.candidates.back().shrinkage = shrinkage;
}

/// A PNG's width and height from its IHDR chunk (big-endian, bytes 16-23).
std::array<int, 2> png_size(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char b[24] = {};
  in.read(reinterpret_cast<char*>(b), sizeof b);
  if (!in) return {0, 0};
  auto be = [&](int at) { return (b[at] << 24) | (b[at + 1] << 16) | (b[at + 2] << 8) | b[at + 3]; };
  return {be(16), be(20)};
}

TEST(VerdictMarkdown, WithinTheFloorsSaysWhatItDoesNotRuleOut) {
  DiagnosisResult r;
  r.verdict = "none";
  const std::string md = verdict_markdown(r);
  EXPECT_TRUE(contains(md, "**Verdict: the gap is within the floors**")) << md;
  EXPECT_TRUE(contains(md, kCaveat)) << md;
}

TEST(VerdictMarkdown, WithinTheFloorsOnceTheBendingIsRefittedSaysItToo) {
  DiagnosisResult bar;
  bar.verdict = "none";
  bar.attribution.bar_within_floors = true;
  const std::string by_bar = verdict_markdown(bar);
  EXPECT_TRUE(contains(by_bar, "**Verdict: within the floors once the bending is refitted** (the baseline fit"));
  EXPECT_TRUE(contains(by_bar, kCaveat));

  DiagnosisResult common;
  common.verdict = "none";
  common.attribution.common_within_floors = true;
  common.attribution.common_effects = {Effect::kYield, Effect::kShear, Effect::kCurl};
  common.attribution.common_bending = CandidateResult{};
  common.attribution.common_bending->alpha_scale = 0.5;
  const std::string by_common = verdict_markdown(common);
  EXPECT_TRUE(contains(by_common, "(3 unlike effects each brought the gap within the floors")) << by_common;
  EXPECT_TRUE(contains(by_common, "the baseline's bending at x0.50")) << by_common;
  EXPECT_TRUE(contains(by_common, kCaveat));
}

TEST(VerdictMarkdown, AGapAboveTheFloorsHasNoCaveat) {
  DiagnosisResult gap_only;
  gap_only.verdict = "not attributed";
  EXPECT_TRUE(contains(verdict_markdown(gap_only), "attribution was not run"));
  EXPECT_FALSE(contains(verdict_markdown(gap_only), kCaveat));

  DiagnosisResult named;
  named.verdict = "yield";
  named.runner_up = "curl";
  named.attribution.named = true;
  named.attribution.confidence = 0.9;
  named.attribution.candidates.emplace_back();
  named.attribution.candidates.back().shrinkage = 0.8;
  named.attribution.candidates.back().held_out_shrinkage = 0.6;
  named.attribution.candidates.emplace_back();
  named.attribution.candidates.back().effect = Effect::kCurl;
  const std::string md = verdict_markdown(named);
  EXPECT_TRUE(contains(md, "**Verdict: yield** (confidence 0.90 against the runner-up, curl)")) << md;
  EXPECT_TRUE(contains(md, "by 80% (the capture's drapes from fresh initial states)")) << md;
  EXPECT_FALSE(contains(md, kCaveat));
  EXPECT_FALSE(contains(md, "confirmed by its drape on the held-out capture")) << md;
  // Confirmed only because its drape on the held-out capture is within the floors: said, with how far its score there
  // lies above the reference's.
  named.validated_held_out = Evaluation{};
  named.attribution.held_out_tolerance = 0.1;
  named.attribution.candidates.front().confirmation = Confirmation::kWithinFloors;
  named.attribution.candidates.front().held_out_shrinkage = -0.22;
  const std::string within = verdict_markdown(named);
  EXPECT_TRUE(contains(within, "It is confirmed by its drape on the held-out capture lying within the floors "
                               "(`--confirm-within-floors`); its score there is 22% above the reference's, more than "
                               "the 10% the score's confirmation allows."))
      << within;

  DiagnosisResult unexplained;
  unexplained.verdict = "unexplained";
  EXPECT_TRUE(contains(verdict_markdown(unexplained), "no candidate effect was refitted"));
  EXPECT_FALSE(contains(verdict_markdown(unexplained), kCaveat));
}

TEST(VerdictMarkdown, YieldFromTheTurnOverSaysSoAndKeepsTheRefitsVerdict) {
  // The refits named no effect (the best, shear, unconfirmed); the turned placement drapes stiffer: yield, with the
  // yield refit's shrinkage, not the first candidate's.
  DiagnosisResult r;
  r.verdict = "yield";
  r.turn_over = DiagnosisResult::TurnOverYield{0.0312, 0.02, "unexplained"};
  r.attribution.significant_shrinkage = 0.25;
  add_candidate(r, Effect::kShear, 0.4);
  add_candidate(r, Effect::kYield, 0.3);
  EXPECT_DOUBLE_EQ(r.named_shrinkage(), 0.3);
  ASSERT_NE(r.named_refit(), nullptr);
  EXPECT_EQ(r.named_refit()->effect, Effect::kYield);
  const std::string md = verdict_markdown(r);
  EXPECT_TRUE(contains(md, "**Verdict: yield, from the turn-over**: the second capture, laid on the specimen's other "
                           "face, drapes 0.0312 stiffer than the capture (drape coefficient; at least 0.02)"))
      << md;
  EXPECT_TRUE(contains(md, "the yield refit shrinks the excess by 30%")) << md;
  EXPECT_TRUE(contains(md, "**The refits' verdict: a gap above the floors that no candidate effect both shrinks by "
                           "25% or more and holds on the held-out data** (best: shear, shrinkage 40%, not confirmed)"))
      << md;
  EXPECT_FALSE(contains(md, kCaveat)) << md;

  // Within the floors at the gate: no refit ran; the gate's verdict stays in the report under the refits'.
  DiagnosisResult gate;
  gate.verdict = "yield";
  gate.turn_over = DiagnosisResult::TurnOverYield{0.05, 0.02, "none"};
  EXPECT_DOUBLE_EQ(gate.named_shrinkage(), 0.0);
  EXPECT_EQ(gate.named_refit(), nullptr);
  const std::string within = verdict_markdown(gate);
  EXPECT_TRUE(contains(within, "no yield refit ran")) << within;
  EXPECT_TRUE(contains(within, "**The refits' verdict: the gap is within the floors**")) << within;

  // Without the turn-over: the first candidate's shrinkage, its refit the named effect's only where it was named.
  r.turn_over.reset();
  EXPECT_DOUBLE_EQ(r.named_shrinkage(), 0.4);
  EXPECT_EQ(r.named_refit(), nullptr);
  r.attribution.named = true;
  ASSERT_NE(r.named_refit(), nullptr);
  EXPECT_EQ(r.named_refit()->effect, Effect::kShear);
}

TEST(VerdictMarkdown, MisalignmentFromTheHemCentreSaysSoAndKeepsTheRefitsVerdict) {
  // The refits named no effect (curl first, unconfirmed); the hem's centre lies 3.49 times its floor off the fitted
  // drape's: misalignment, with the misalignment refit's shrinkage, not the first candidate's.
  DiagnosisResult r;
  r.verdict = "misalignment";
  r.off_centre = DiagnosisResult::OffCentreMisalignment{.ratio = 3.49, .floor = 2.5, .refits_verdict = "none"};
  add_candidate(r, Effect::kCurl, 0.5);
  add_candidate(r, Effect::kMisalignment, 0.2);
  EXPECT_DOUBLE_EQ(r.named_shrinkage(), 0.2);
  ASSERT_NE(r.named_refit(), nullptr);
  EXPECT_EQ(r.named_refit()->effect, Effect::kMisalignment);
  const std::string md = verdict_markdown(r);
  EXPECT_TRUE(contains(md, "**Verdict: misalignment, from the hem's centre**: the hem's order-1 harmonic (its radius "
                           "and height: how far its centre lies off) differs from the fitted drape's by 3.49 times its "
                           "floor (at least 2.5)"))
      << md;
  EXPECT_TRUE(contains(md, "the misalignment refit shrinks the excess by 20%")) << md;
  EXPECT_TRUE(contains(md, "**The refits' verdict: ")) << md;
  EXPECT_FALSE(contains(md, kCaveat)) << md;

  // Within the floors at the gate: no refit ran.
  DiagnosisResult gate;
  gate.verdict = "misalignment";
  gate.off_centre = DiagnosisResult::OffCentreMisalignment{.ratio = 2.7, .floor = 2.5, .refits_verdict = "none"};
  EXPECT_DOUBLE_EQ(gate.named_shrinkage(), 0.0);
  EXPECT_EQ(gate.named_refit(), nullptr);
  const std::string within = verdict_markdown(gate);
  EXPECT_TRUE(contains(within, "no misalignment refit ran")) << within;
  EXPECT_TRUE(contains(within, "**The refits' verdict: the gap is within the floors**")) << within;
}

TEST(VerdictMarkdown, MisalignmentFromTheHemTiltSaysSoOverAnyVerdict) {
  // Rule H over the refits' friction: every placement's hem tilts by 10.34 mm or more.
  DiagnosisResult r;
  r.verdict = "misalignment";
  r.placement_hem_tilt_mm = {15.1, 10.34, 17.7};
  r.hem_tilt =
      DiagnosisResult::HemTiltMisalignment{.smallest_mm = 10.34, .floor_mm = 8.0, .refits_verdict = "friction"};
  add_candidate(r, Effect::kFriction, 0.9);
  add_candidate(r, Effect::kMisalignment, 0.1);
  EXPECT_TRUE(r.signature_set());
  EXPECT_EQ(r.refits_verdict(), "friction");
  ASSERT_NE(r.named_refit(), nullptr);
  EXPECT_EQ(r.named_refit()->effect, Effect::kMisalignment);
  EXPECT_DOUBLE_EQ(r.named_shrinkage(), 0.1);
  const std::string md = verdict_markdown(r);
  EXPECT_TRUE(contains(md, "**Verdict: misalignment, from the hem's tilt**: on each of the three placements the hem "
                           "hangs lower on one side, its height's first harmonic at least 10.34 mm (at least 8 mm)"))
      << md;
  EXPECT_TRUE(contains(md, "the misalignment refit shrinks the excess by 10%). The refits named friction: a refit can "
                           "stand in for an off-centre drape, which the hem's tilt on every placement names over it"))
      << md;
  EXPECT_TRUE(contains(md, "**The refits' verdict: friction**")) << md;

  // Over the turn-over's yield: the refits' own verdict (none) is the turn-over's record's.
  DiagnosisResult turned;
  turned.verdict = "misalignment";
  turned.turn_over = DiagnosisResult::TurnOverYield{0.03, 0.02, "none"};
  turned.hem_tilt =
      DiagnosisResult::HemTiltMisalignment{.smallest_mm = 9.0, .floor_mm = 8.0, .refits_verdict = "yield"};
  EXPECT_EQ(turned.refits_verdict(), "none");
  const std::string over = verdict_markdown(turned);
  EXPECT_TRUE(contains(over, "**Verdict: misalignment, from the hem's tilt**")) << over;
  EXPECT_TRUE(contains(over, "no misalignment refit ran). The refits alone named no effect:")) << over;
  EXPECT_FALSE(contains(over, "from the turn-over**")) << over;
}

TEST(VerdictMarkdown, MisalignmentFromTheHemCentreOffsetSaysSoOverNoEffectOrTheRefitsYield) {
  // Rule D: the refits named no effect; the hem's centre lies 7.21 mm off the fitted drape's (its ratio 1.9, under
  // rule E's 2.5): misalignment by the offset, in mm.
  DiagnosisResult r;
  r.verdict = "misalignment";
  r.off_centre = DiagnosisResult::OffCentreMisalignment{.ratio = 1.9,
                                                        .floor = 2.5,
                                                        .offset_mm = 7.21,
                                                        .offset_floor_mm = 6.5,
                                                        .by_offset = true,
                                                        .refits_verdict = "unexplained"};
  add_candidate(r, Effect::kMisalignment, 0.3);
  EXPECT_EQ(r.refits_verdict(), "unexplained");
  const std::string md = verdict_markdown(r);
  EXPECT_TRUE(contains(md, "**Verdict: misalignment, from the hem's centre**: the hem's order-1 harmonic (its radius "
                           "and height: how far its centre lies off) differs from the fitted drape's by 7.21 mm (at "
                           "least 6.5 mm), whatever its floor, as a specimen laid off centre"))
      << md;
  EXPECT_TRUE(contains(md, "the misalignment refit shrinks the excess by 30%). The refits alone named no effect:"))
      << md;
  EXPECT_FALSE(contains(md, "times its floor")) << md;

  // Rule D2: over the refits' yield, which the turn-over (rule U at 0.02) does not name.
  DiagnosisResult over;
  over.verdict = "misalignment";
  over.budgets.turn_over_yield = 0.02;
  over.off_centre = DiagnosisResult::OffCentreMisalignment{.offset_mm = 8.6,
                                                           .offset_floor_mm = 6.5,
                                                           .by_offset = true,
                                                           .refits_verdict = "yield"};
  add_candidate(over, Effect::kYield, 0.5);
  EXPECT_EQ(over.refits_verdict(), "yield");
  EXPECT_EQ(over.named_refit(), nullptr);  // no misalignment refit ran
  const std::string yielded = verdict_markdown(over);
  EXPECT_TRUE(contains(yielded, "differs from the fitted drape's by 8.60 mm (at least 6.5 mm)")) << yielded;
  EXPECT_TRUE(contains(yielded, "no misalignment refit ran). The refits named yield, which the turn-over does not "
                                "name (no turned second capture drapes 0.02 or more stiffer than the capture; "
                                "`--turn-over-yield`): a yield refit can stand in for an off-centre drape"))
      << yielded;
  EXPECT_TRUE(contains(yielded, "**The refits' verdict: yield**")) << yielded;
}

TEST(VerdictMarkdown, TheAlternationNamesOrWithdrawsYieldAndSaysSo) {
  // The refits named no effect; the turned placement drapes 0.0213 stiffer than the mean of the other two: yield, with
  // the yield refit's shrinkage.
  DiagnosisResult r;
  r.verdict = "yield";
  r.alternation = DiagnosisResult::TurnOverAlternation{0.0213, 0.015, "unexplained"};
  add_candidate(r, Effect::kShear, 0.2);
  add_candidate(r, Effect::kYield, 0.1);
  EXPECT_FALSE(r.alternation->withdrew());
  EXPECT_EQ(r.refits_verdict(), "unexplained");
  EXPECT_DOUBLE_EQ(r.named_shrinkage(), 0.1);
  ASSERT_NE(r.named_refit(), nullptr);
  EXPECT_EQ(r.named_refit()->effect, Effect::kYield);
  const std::string named = verdict_markdown(r);
  EXPECT_TRUE(contains(named, "**Verdict: yield, from the turn-over's alternation**: the second capture, laid on the "
                              "specimen's other face, drapes 0.0213 stiffer than the mean of the capture and the "
                              "third placement"))
      << named;
  EXPECT_TRUE(contains(named, "the yield refit shrinks the excess by 10%). The refits alone named no effect:"))
      << named;
  EXPECT_TRUE(contains(named, "**The refits' verdict: ")) << named;

  // The refits named yield (first, 40%) without the alternation (0.0042): unexplained, no effect's refit named, the
  // shrinkage the best candidate's as with the refits' own "unexplained".
  DiagnosisResult withdrawn;
  withdrawn.verdict = "unexplained";
  withdrawn.alternation = DiagnosisResult::TurnOverAlternation{0.0042, 0.015, "yield"};
  withdrawn.attribution.named = true;
  add_candidate(withdrawn, Effect::kYield, 0.4);
  add_candidate(withdrawn, Effect::kShear, 0.0);
  withdrawn.attribution.confidence = 0.7;
  withdrawn.runner_up = "yield";  // the verdict's, as diagnose() sets it: the best candidate of an "unexplained"
  EXPECT_TRUE(withdrawn.alternation->withdrew());
  EXPECT_EQ(withdrawn.refits_verdict(), "yield");
  EXPECT_EQ(withdrawn.named_refit(), nullptr);
  EXPECT_DOUBLE_EQ(withdrawn.named_shrinkage(), 0.4);
  const std::string md = verdict_markdown(withdrawn);
  EXPECT_TRUE(contains(md, "**Verdict: unexplained, a yield without its turn-over**: the refits named yield, but the "
                           "turned second capture drapes 0.0042 against the mean of the capture and the third "
                           "placement"))
      << md;
  EXPECT_TRUE(contains(md, "**The refits' verdict: yield** (confidence 0.70 against the runner-up, shear)")) << md;

  // The hem's centre then named misalignment: its paragraph, with the withdrawal as the refits' verdict.
  withdrawn.verdict = "misalignment";
  withdrawn.off_centre =
      DiagnosisResult::OffCentreMisalignment{.ratio = 3.0, .floor = 2.5, .refits_verdict = "unexplained"};
  EXPECT_EQ(withdrawn.refits_verdict(), "yield");
  EXPECT_EQ(withdrawn.named_refit(), nullptr);  // no misalignment refit ran
  const std::string centred = verdict_markdown(withdrawn);
  EXPECT_TRUE(contains(centred, "**Verdict: misalignment, from the hem's centre**")) << centred;
  EXPECT_TRUE(contains(centred, "no misalignment refit ran). The refits named yield, withdrawn: the turned second "
                                "capture drapes 0.0042"))
      << centred;
  EXPECT_TRUE(contains(centred, "**The refits' verdict: yield**")) << centred;
}

TEST(DominantRegionMarkdown, SaysWhatPlacedTheGapAndTheRuleThatMovedIt) {
  Localisation L;
  L.dominant = Region::kGlobal;
  EXPECT_EQ(dominant_region_markdown(L), "Dominant region: **global** (nothing exceeds its floor).");

  // Rule O: a skirt group led, the hem's centre lies 7.3 mm off: the hem, and the sentence gives the offset in mm.
  L.dominant = Region::kHem;
  L.dominant_feature = "skirt_height";
  L.group_difference.assign(std::size(kFeatureGroups), 1e-3);
  L.group_difference[static_cast<std::size_t>(FeatureGroup::kOffCentre)] = 7.3e-3;
  L.moved_by_offset = true;
  const std::string moved = dominant_region_markdown(L);
  EXPECT_TRUE(contains(moved, "Dominant region: **hem** (led by skirt_height, placed on the skirt; but the hem's "
                              "order-1 harmonic differs from the fitted drape's by 7.30 mm (at least 6.5 mm)"))
      << moved;

  // The folds deepen at the hem (moved_to_hem): the folds' reason, not the offset's.
  L.moved_by_offset = false;
  L.moved_to_hem = true;
  const std::string folds = dominant_region_markdown(L);
  EXPECT_TRUE(contains(folds, "**hem** (led by skirt_height, a change of the skirt; the folds' depth stands more "
                              "than 1.5 times further above its floor than the skirt's mean height"))
      << folds;
  EXPECT_FALSE(contains(folds, "order-1 harmonic")) << folds;

  // The multipath test placed it: the views' reason first.
  L.moved_to_hem = false;
  L.placed_by_views = true;
  L.dominant = Region::kSkirt;
  EXPECT_TRUE(contains(dominant_region_markdown(L), "**skirt** (the four views disagree as a sensor error makes "
                                                    "them (the multipath test fired)"));
}

TEST(RuntimeMarkdown, CountsEveryDiagnosisTheRuntimeHolds) {
  // With --confirm-resolution and --confirm-placement-rise both on, the reported diagnosis holds the one without the
  // placement test, and each of the two may hold its other mesh's: up to four diagnoses' runtime together.
  DiagnosisResult alone;
  alone.seconds = 120.4;
  alone.cpu_seconds = 118.0;
  alone.jobs = 1;
  const std::string one = runtime_markdown(alone);
  EXPECT_TRUE(contains(one, "Runtime 120 s (fit 0 s, floors 0 s, attribution 0 s); CPU 118 s; up to 1 thread.")) << one;
  EXPECT_FALSE(contains(one, "together")) << one;

  DiagnosisResult meshes = alone;
  meshes.mesh_confirmation = DiagnosisResult::MeshConfirmation{40, true, std::make_shared<const DiagnosisResult>()};
  EXPECT_TRUE(contains(runtime_markdown(meshes), "Runtime and CPU are both diagnoses' together"));

  DiagnosisResult placed = meshes;  // the placement test's diagnosis on two meshes, holding the first's on two
  placed.placement_confirmation =
      DiagnosisResult::PlacementConfirmation{0.03, 0.02, std::make_shared<const DiagnosisResult>(meshes)};
  const std::string four = runtime_markdown(placed);
  EXPECT_TRUE(contains(four, "Runtime and CPU are all 4 diagnoses' together")) << four;
  placed.mesh_confirmation.reset();  // the placement test's diagnosis on one mesh, holding the first's on two
  EXPECT_TRUE(contains(runtime_markdown(placed), "Runtime and CPU are all 3 diagnoses' together"));
  const DiagnosisResult no_other = [] {  // a confirmation without the other diagnosis kept adds nothing
    DiagnosisResult r;
    r.mesh_confirmation = DiagnosisResult::MeshConfirmation{40, false, nullptr};
    return r;
  }();
  EXPECT_FALSE(contains(runtime_markdown(no_other), "together"));
}

TEST(ReportImages, ViewsOfDifferentSizesEachTakeACellOfTheLargestSize) {
  // A capture's views may differ in size (docs/CAPTURE.md): the residual maps and the views' preview draw each at
  // its own size in cells of the largest, instead of failing once the whole diagnosis has run.
  const std::string dir = testing::TempDir();
  std::vector<ResidualImage> residuals{{8, 6, std::vector<float>(48, 0.01f)}, {5, 9, std::vector<float>(45, -0.01f)}};
  residuals[1].values[3] = std::nanf("");
  ASSERT_TRUE(static_cast<bool>(write_residual_png(dir + "/residual_sizes.png", residuals, 0.02)));
  EXPECT_EQ(png_size(dir + "/residual_sizes.png"), (std::array<int, 2>{2 * 8 + 4, 9}));
  residuals[1].values.pop_back();  // pixels that do not match the stated size: refused
  EXPECT_FALSE(static_cast<bool>(write_residual_png(dir + "/residual_bad.png", residuals, 0.02)));

  renderer::DepthImage a(8, 6), b(5, 9);
  a.depth.assign(48, 0.5f);
  b.depth.assign(45, 0.6f);
  ASSERT_TRUE(static_cast<bool>(renderer::write_preview_png(dir + "/preview_sizes.png", {{a, b}, {b}})));
  EXPECT_EQ(png_size(dir + "/preview_sizes.png"), (std::array<int, 2>{2 * 8 + 2, 2 * 9 + 2}));
}

}  // namespace
}  // namespace drapegen::diagnosis
