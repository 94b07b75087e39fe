#include "drapegen/diagnosis/report.hpp"

#include <gtest/gtest.h>

#include <string>

namespace drapegen::diagnosis {
namespace {

constexpr const char* kCaveat = "rules out no effect whose drape an elastic fabric of another bending can match";

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

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
  const std::string md = verdict_markdown(named);
  EXPECT_TRUE(contains(md, "**Verdict: yield** (confidence 0.90 against the runner-up, curl)")) << md;
  EXPECT_TRUE(contains(md, "by 80% (the capture's drapes from fresh initial states)")) << md;
  EXPECT_FALSE(contains(md, kCaveat));

  DiagnosisResult unexplained;
  unexplained.verdict = "unexplained";
  EXPECT_TRUE(contains(verdict_markdown(unexplained), "no candidate effect was refitted"));
  EXPECT_FALSE(contains(verdict_markdown(unexplained), kCaveat));
}

}  // namespace
}  // namespace drapegen::diagnosis
