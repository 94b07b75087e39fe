#include "drapegen/diagnosis/fold_repeatability.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "drapegen/sim/measures.hpp"

namespace drapegen::diagnosis {

HemProfile fold_content(const HemProfile& profile) {
  const HemProfile low = low_pass(profile, kOrientationOrders);
  HemProfile folds = profile;
  for (int k = 0; k < profile.bins(); ++k) folds.radius[k] = profile.radius[k] - low.radius[k];
  return folds;
}

namespace {

/// fold_correlation of two fold contents (fold_content already taken).
double best_turn_correlation(const HemProfile& fa, const HemProfile& fb) {
  const int n = fa.bins();
  if (n == 0 || fb.bins() != n) return 0.0;
  // Fold content below a micrometre RMS is rounding, not folds.
  auto rms = [](const HemProfile& p) {
    double sum = 0.0;
    int count = 0;
    for (double r : p.radius)
      if (std::isfinite(r)) sum += r * r, ++count;
    return count > 0 ? std::sqrt(sum / count) : 0.0;
  };
  if (rms(fa) < 1e-6 || rms(fb) < 1e-6) return 0.0;
  std::optional<double> best;  // none if no turn has fold content on both
  for (int shift = 0; shift < n; ++shift) {  // b turned by `shift` bins
    double ab = 0.0, aa = 0.0, bb = 0.0;
    for (int k = 0; k < n; ++k) {
      const double x = fa.radius[k], y = fb.radius[(k + shift) % n];
      if (!std::isfinite(x) || !std::isfinite(y)) continue;
      ab += x * y, aa += x * x, bb += y * y;
    }
    if (aa > 0.0 && bb > 0.0) best = std::max(best.value_or(-1.0), ab / std::sqrt(aa * bb));
  }
  return best.value_or(0.0);
}

}  // namespace

double fold_correlation(const HemProfile& a, const HemProfile& b) {
  return best_turn_correlation(fold_content(a), fold_content(b));
}

std::vector<double> pairwise_fold_correlations(const std::vector<HemProfile>& outlines) {
  std::vector<HemProfile> folds;  // each outline's fold content once, not once per pair
  for (const HemProfile& outline : outlines) folds.push_back(fold_content(outline));
  std::vector<double> c;
  for (std::size_t i = 0; i < folds.size(); ++i)
    for (std::size_t j = i + 1; j < folds.size(); ++j) c.push_back(best_turn_correlation(folds[i], folds[j]));
  return c;
}

HemProfile specimen_frame(const HemProfile& outline, bool face_down) {
  if (!face_down) return outline;
  HemProfile mirrored = outline;  // bin k (centred at (k + 1/2) 2 pi / n) goes to the bin centred at minus that angle
  const int n = outline.bins();
  for (int k = 0; k < n; ++k) mirrored.radius[n - 1 - k] = outline.radius[k];
  return mirrored;
}

std::vector<double> drape_fold_correlations(const std::vector<sim::ClothMesh>& drapes) {
  std::vector<HemProfile> outlines;
  for (const auto& mesh : drapes)
    outlines.push_back(specimen_frame(hem_profile_from_mesh(mesh), sim::lies_face_down(mesh)));
  return pairwise_fold_correlations(outlines);
}

std::vector<double> placement_fold_correlations(const ScoredDrape& capture, const ScoredDrape* second,
                                                const ScoredDrape* held_out) {
  std::vector<sim::ClothMesh> chosen{capture.mesh};
  for (const ScoredDrape* other : {second, held_out})
    if (other) chosen.push_back(other->mesh);
  return drape_fold_correlations(chosen);
}

std::vector<sim::ClothMesh> sine_drapes(const Evaluation& evaluation,
                                        const std::vector<sim::InitialStateSpec>& states) {
  std::vector<sim::ClothMesh> sine;
  for (std::size_t k = 0; k < evaluation.states.size() && k < states.size(); ++k)
    if (states[k].shape == sim::InitialShape::kSine) sine.push_back(evaluation.states[k].mesh);
  return sine;
}

bool folds_less_alike(const FoldRepeatability& f) {
  if (!f.measured()) return false;
  std::vector<double> model = f.model;
  std::sort(model.begin(), model.end());
  const double q10 = model[static_cast<std::size_t>(0.1 * static_cast<double>(model.size()))];
  return *std::max_element(f.capture.begin(), f.capture.end()) < q10 - kFoldsUnlikeMargin;
}

FoldRepeatability fold_repeatability(const std::vector<HemProfile>& placements,
                                     const std::vector<sim::ClothMesh>& drapes) {
  return {pairwise_fold_correlations(placements), drape_fold_correlations(drapes), static_cast<int>(drapes.size()), {}};
}

}  // namespace drapegen::diagnosis
