#pragma once
// Where an error injected into depth images lies on the specimen: its squared depth error and pixels per region
// (classify_point with the drape's own outline). The reality generator's truth for a sensor error that acts in
// places rather than everywhere (multipath: the valleys the camera sees).

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
  /// Per region (kTop .. kCylinder): energy_share, pixel_share and enrichment (the other fields 0).
  [[nodiscard]] std::vector<RegionShare> shares() const;
  /// Every region where the error stands out: a pixel share of at least kMinPixelShare and an enrichment of at least
  /// `min_enrichment` (the test Localisation::pixel_region applies, which keeps the most enriched one alone);
  /// {kGlobal} if none passes, or there is no error.
  [[nodiscard]] std::vector<Region> regions(double min_enrichment = kMinRegionEnrichment) const;
};

}  // namespace drapegen::diagnosis
