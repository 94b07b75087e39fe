#pragma once
// Where an error in depth images lies on the specimen: its squared depth error and pixels per region (classify_point
// with a drape's outline). The reality generator's truth for an effect that acts in places rather than on every pixel:
// a multipath error (the valleys the camera sees: add_view) and a physical effect (where the drape with it differs
// from the same specimen's drape without it, as the diagnosis's residual maps measure a difference: add_comparison).

#include <array>
#include <vector>

#include "drapegen/diagnosis/hem_profile.hpp"
#include "drapegen/diagnosis/localisation.hpp"
#include "drapegen/renderer/camera.hpp"
#include "drapegen/renderer/depth_image.hpp"

namespace drapegen::diagnosis {

struct ErrorFootprint {
  static constexpr int kCount = RegionEnergy::kCount;
  std::array<double, kCount> energy{}, pixels{};  // m^2 and pixels per region (indexed by Region)

  /// Adds one view: the error (injected - clean depth) of every pixel where the clean image has a return, at the
  /// point that pixel sees (back-projected with `camera`, the camera that took the image, into the specimen's frame,
  /// the frame of `outline`); a pixel the injected image lost counts as no error. Images of two sizes add nothing.
  void add_view(const renderer::DepthImage& clean, const renderer::DepthImage& injected,
                const renderer::Camera& camera, const HemProfile& outline, double cylinder_radius);
  /// Adds one view of a comparison (compare_view of an image with the effect against one without it, seen by
  /// `camera`): every residual at the point the comparison places it (for_each_residual_point), classified with
  /// `outline`, the drape's without the effect (as the localisation classifies with the fitted drape's).
  void add_comparison(const ViewComparison& comparison, const renderer::Camera& camera, const HemProfile& outline,
                      double cylinder_radius);
  /// m: the RMS error over every pixel added (0 if none).
  [[nodiscard]] double rms() const;
  /// Per region (kTop .. kCylinder): energy_share, pixel_share and enrichment (the other fields 0).
  [[nodiscard]] std::vector<RegionShare> shares() const;
  /// Every region where the error stands out: a pixel share of at least kMinPixelShare and an enrichment of at least
  /// `min_enrichment` (the test Localisation::pixel_region applies, which keeps the most enriched one alone);
  /// {kGlobal} if none passes, or there is no error.
  [[nodiscard]] std::vector<Region> regions(double min_enrichment = kMinRegionEnrichment) const;
};

}  // namespace drapegen::diagnosis
