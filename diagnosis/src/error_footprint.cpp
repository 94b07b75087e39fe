#include "drapegen/diagnosis/error_footprint.hpp"

namespace drapegen::diagnosis {

void ErrorFootprint::add_view(const renderer::DepthImage& clean, const renderer::DepthImage& injected,
                              const renderer::Camera& camera, const HemProfile& outline, double cylinder_radius) {
  if (clean.width != injected.width || clean.height != injected.height) return;
  const Eigen::Isometry3d to_specimen = camera.world_to_camera.inverse();
  for (int row = 0; row < clean.height; ++row) {
    for (int u = 0; u < clean.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(row) * clean.width + u;
      const double z = clean.depth[i];
      if (z <= 0.0) continue;
      const double error = injected.depth[i] > 0.0f ? injected.depth[i] - z : 0.0;
      const int k = static_cast<int>(classify_point(to_specimen * (z * camera.ray(u, row)), outline, cylinder_radius));
      energy[k] += error * error;
      pixels[k] += 1.0;
    }
  }
}

std::vector<RegionShare> ErrorFootprint::shares() const {
  std::vector<RegionShare> out;
  for (int k = 0; k < kCount; ++k) out.push_back(share_of_region(static_cast<Region>(k), energy, pixels));
  return out;
}

std::vector<Region> ErrorFootprint::regions(double min_enrichment) const {
  std::vector<Region> out;
  for (const RegionShare& s : shares())
    if (s.pixel_share >= kMinPixelShare && s.enrichment >= min_enrichment && s.energy_share > 0.0)
      out.push_back(s.region);
  if (out.empty()) out.push_back(Region::kGlobal);
  return out;
}

}  // namespace drapegen::diagnosis
