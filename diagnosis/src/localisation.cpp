#include "drapegen/diagnosis/localisation.hpp"

#include <algorithm>
#include <cmath>

namespace drapegen::diagnosis {
namespace {

constexpr Region kRegions[] = {Region::kTop, Region::kRim, Region::kSkirt, Region::kHem, Region::kCylinder};

}  // namespace

Region classify_point(const Eigen::Vector3d& p, const HemProfile& model_outline, double R) {
  const double r = std::hypot(p.x(), p.y()), z = p.z();
  if (r < R - 0.005 && z > -0.006) return Region::kTop;
  if (z < -0.01 && model_outline.bins() > 0) {
    double a = std::atan2(p.y(), p.x());
    if (a < 0.0) a += 2.0 * M_PI;
    const int bin = std::min(model_outline.bins() - 1, static_cast<int>(a / (2.0 * M_PI) * model_outline.bins()));
    const double hem = model_outline.radius[bin];
    if (std::isfinite(hem) && r > hem - 0.025) return Region::kHem;
  }
  if (r < R + 0.015 && z > -0.03) return Region::kRim;
  if (r < R + 0.003 && z <= -0.03) return Region::kCylinder;
  return Region::kSkirt;
}

Region feature_region(FeatureGroup group) {
  switch (group) {
    case FeatureGroup::kHarmonics:
    case FeatureGroup::kOffCentre:
    case FeatureGroup::kSortedRadii:
    case FeatureGroup::kHemHeight: return Region::kHem;
    case FeatureGroup::kSkirtHeight:
    case FeatureGroup::kSkirtSpread:
    case FeatureGroup::kFolds: return Region::kSkirt;
  }
  return Region::kGlobal;
}

bool follows_skirt(FeatureGroup group) {
  return feature_region(group) == Region::kHem && group != FeatureGroup::kOffCentre;
}

double group_ratio_floor(std::size_t k, const std::vector<double>& group_floor) {
  static const std::vector<double> scale = default_feature_scales();
  return std::max(k < group_floor.size() ? group_floor[k] : 0.0, 0.5 * scale.at(k));
}

void localise_features(Localisation& L, const ScoredDrape& drape, const Target& capture,
                       const std::vector<double>& group_floor, double stable_floor) {
  const auto diff = group_differences(capture.shape.all, drape.shape.all);
  L.group_difference = diff;
  L.group_ratio.assign(diff.size(), 0.0);
  for (std::size_t k = 0; k < diff.size(); ++k) {
    if (diff[k] < 0.0) continue;
    L.group_ratio[k] = diff[k] / group_ratio_floor(k, group_floor);
  }
  L.stable_ratio = drape.stable_all / std::max(stable_floor, 1e-4);
  place_gap(L);
}

RegionShare share_of_region(Region region, const std::array<double, RegionEnergy::kCount>& energy,
                            const std::array<double, RegionEnergy::kCount>& pixels) {
  double total_energy = 0.0, total_pixels = 0.0;
  for (int k = 0; k < RegionEnergy::kCount; ++k) total_energy += energy[k], total_pixels += pixels[k];
  const int k = static_cast<int>(region);
  RegionShare s;
  s.region = region;
  s.energy_share = total_energy > 0.0 ? energy[k] / total_energy : 0.0;
  s.pixel_share = total_pixels > 0.0 ? pixels[k] / total_pixels : 0.0;
  s.enrichment = s.pixel_share > 0.0 ? s.energy_share / s.pixel_share : 0.0;
  return s;
}

const RegionShare* region_share(const Localisation& L, Region region) {
  const auto s =
      std::find_if(L.regions.begin(), L.regions.end(), [&](const RegionShare& x) { return x.region == region; });
  return s == L.regions.end() ? nullptr : &*s;
}

namespace {
double enrichment(const Localisation& L, Region region) {
  const RegionShare* share = region_share(L, region);
  return share ? share->enrichment : 0.0;
}
}  // namespace

Region stable_region(const Localisation& L) {
  const RegionShare* top = region_share(L, Region::kTop);
  // The top within what noise and other stable drapes leave there: the excess is on the bare cylinder below the
  // skirt (a multipath return in the corner the skirt makes with it).
  if (!top || top->floor_ratio <= 1.0) return Region::kCylinder;
  // Seen below the fitted cloth: no specimen lies inside the platform, a depth bias or a moved camera puts it there.
  if (top->mean > 0.0) return Region::kGlobal;
  // Lifted: the specimen's contact (cloth that slid rises in wrinkles over the top) unless lifted at a camera's scale.
  return L.stable_ratio < kLiftedTopSensorRatio ? Region::kTop : Region::kGlobal;
}

void place_gap(Localisation& L) {
  L.moved_to_hem = false;
  L.moved_by_offset = false;
  L.placed_by_views = false;
  if (L.camera_moved >= kCameraMovedAtPlatform) {  // the rigid surfaces show the camera elsewhere than recorded
    L.dominant_feature = "camera";
    L.dominant = Region::kGlobal;
    return;
  }
  double best = 1.0;
  std::size_t group = L.group_ratio.size();
  for (std::size_t k = 0; k < L.group_ratio.size() && k < std::size(kFeatureGroups); ++k) {
    if (L.group_ratio[k] > best) best = L.group_ratio[k], group = k;
  }
  // The stable term leads; or it exceeds its floor with the platform top lifted: under the adhesion the baseline
  // assumes, the top cannot lift, only a specimen that slid over it does, and the outline's change follows from that.
  // The rigid surfaces also place the gap whatever leads when they are the camera's (session 27): a top above its
  // own floor seen farther than the fitted cloth (no cloth lies inside the platform), or a stable term from
  // kLiftedTopSensorRatio times its floor (beyond what a specimen's contact lifts); an error of the camera moves the
  // outline as well, often further above its floor than the rigid surfaces.
  // (stable_region says kGlobal exactly for a top seen farther, or a lifted one from that ratio.)
  // A top lifted by less than kLiftedTopContact is the fit's own offset there, not cloth that slid (rule T).
  const Region stable_at = stable_region(L);
  const RegionShare* top = region_share(L, Region::kTop);
  const bool slid = stable_at == Region::kTop && top && top->mean <= -kLiftedTopContact;
  if (L.stable_ratio > best || (L.stable_ratio > 1.0 && slid) || stable_at == Region::kGlobal ||
      L.stable_ratio >= kLiftedTopSensorRatio) {
    L.dominant_feature = "stable";
    L.dominant = stable_at;
    return;
  }
  if (group == L.group_ratio.size()) {
    L.dominant_feature.clear();
    L.dominant = Region::kGlobal;
    return;
  }
  const FeatureGroup g = kFeatureGroups[group];
  L.dominant_feature = feature_group_name(g);
  L.dominant = feature_region(g);
  // The outline's shape (its harmonics, sorted radii, height) follows the skirt above it: the hem carries the skirt's
  // change where the skirt's residual is the denser one.
  const double skirt = enrichment(L, Region::kSkirt), hem = enrichment(L, Region::kHem);
  if (follows_skirt(g) && skirt > hem) L.dominant = Region::kSkirt;
  // A skirt gap whose folds deepen far more than its mean height falls is an edge band's (a curled hem), and a shift
  // of the centre is the hem's own (a placement): the hem, unless the skirt's residual is the far denser (rule S: a
  // change of the whole skirt, its shear or its yielding folds, moves the outline and its centre as well).
  const bool skirt_far_denser = skirt > 0.0 && skirt >= kSkirtDenseAtHem * hem;
  L.moved_to_hem = L.dominant == Region::kSkirt && folds_deepen_at_hem(L) && !skirt_far_denser;
  if (L.moved_to_hem || (g == FeatureGroup::kOffCentre && skirt_far_denser)) {
    L.dominant = L.moved_to_hem ? Region::kHem : Region::kSkirt;
  }
  // Rule O: a skirt gap is the hem's where the hem's centre lies kHemOffCentreMm or more off the fitted drape's.
  constexpr auto kOffCentre = static_cast<std::size_t>(FeatureGroup::kOffCentre);
  L.moved_by_offset = L.dominant == Region::kSkirt && kOffCentre < L.group_difference.size() &&
                      L.group_difference[kOffCentre] * 1e3 >= kHemOffCentreMm;
  if (L.moved_by_offset) L.dominant = Region::kHem;
}

void place_sensor_gap(Localisation& L) {
  if (L.floor_region == Region::kGlobal || L.dominant_feature == "camera") return;
  L.placed_by_views = true;
  L.moved_to_hem = false;
  L.moved_by_offset = false;
  L.dominant = L.floor_region;
}

bool folds_deepen_at_hem(const Localisation& L) {
  auto ratio = [&](FeatureGroup g) {  // group_ratio is indexed as group_differences is: by the group's value
    const auto k = static_cast<std::size_t>(g);
    return k < L.group_ratio.size() ? L.group_ratio[k] : 0.0;
  };
  return ratio(FeatureGroup::kSkirtSpread) > kFoldDepthAtHem * ratio(FeatureGroup::kSkirtHeight);
}

double RegionEnergy::mean_square(Region region) const {
  const int k = static_cast<int>(region);
  return k < kCount && pixels[k] > 0.0 ? energy[k] / pixels[k] : 0.0;
}

double RegionEnergy::mean(Region region) const {
  const int k = static_cast<int>(region);
  if (k >= kCount || pixels[k] <= 0.0) return 0.0;
  double sum = 0.0;
  for (const auto& view : view_sum) sum += view[k];
  return sum / pixels[k];
}

double RegionEnergy::view_mean(std::size_t view, Region region) const {
  const int k = static_cast<int>(region);
  if (view >= view_sum.size() || k >= kCount || view_pixels[view][k] <= 0.0) return 0.0;
  return view_sum[view][k] / view_pixels[view][k];
}

void for_each_residual_point(
    const ForwardModel& model, const ScoredDrape& drape,
    const std::function<void(std::size_t view, const Eigen::Vector3d& point, double residual)>& visit) {
  const Capture& capture = model.capture();
  for (std::size_t v = 0; v < drape.views.size(); ++v) {
    const auto& cmp = drape.views[v];
    const auto& view = capture.views[v];
    const Eigen::Isometry3d to_specimen = view.camera.world_to_camera.inverse();
    const int W = view.depth.width;
    for (std::size_t i = 0; i < cmp.residual.size(); ++i) {
      const float res = cmp.residual[i];
      if (!std::isfinite(res) || cmp.depth[i] <= 0.0f) continue;
      const int u = static_cast<int>(i % W), row = static_cast<int>(i / W);
      visit(v, to_specimen * (static_cast<double>(cmp.depth[i]) * view.camera.ray(u, row)), static_cast<double>(res));
    }
  }
}

namespace {

/// region_energy with the drape's outline (turned as rendered) given.
RegionEnergy region_energy(const ForwardModel& model, const ScoredDrape& drape, const HemProfile& model_outline) {
  RegionEnergy E;
  const double R = 0.5 * model.capture().specimen.cylinder_diameter;
  E.view_energy.assign(drape.views.size(), 0.0);
  E.view_sum.assign(drape.views.size(), {});
  E.view_pixels.assign(drape.views.size(), {});
  for_each_residual_point(model, drape, [&](std::size_t v, const Eigen::Vector3d& p, double res) {
    const int k = static_cast<int>(classify_point(p, model_outline, R));
    const double e = res * res;
    E.energy[k] += e;
    E.pixels[k] += 1.0;
    E.view_energy[v] += e;
    E.view_sum[v][k] += res;
    E.view_pixels[v][k] += 1.0;
  });
  return E;
}

}  // namespace

RegionEnergy region_energy(const ForwardModel& model, const ScoredDrape& drape) {
  return region_energy(model, drape, rotate(hem_profile_from_mesh(drape.mesh), drape.angle));
}

Localisation localise(const ForwardModel& model, const ScoredDrape& drape) {
  Localisation L;
  const Capture& capture = model.capture();
  const HemProfile model_outline = rotate(hem_profile_from_mesh(drape.mesh), drape.angle);
  const RegionEnergy E = region_energy(model, drape, model_outline);
  double total_energy = 0.0;
  for (int k = 0; k < RegionEnergy::kCount; ++k) total_energy += E.energy[k];
  double best = 0.0;
  for (Region r : kRegions) {
    RegionShare s = share_of_region(r, E.energy, E.pixels);
    s.rms = std::sqrt(E.mean_square(r));
    s.mean = E.mean(r);
    for (std::size_t v = 0; v < drape.views.size(); ++v) s.view_mean.push_back(E.view_mean(v, r));
    L.regions.push_back(s);
    if (s.pixel_share >= kMinPixelShare && s.enrichment > best) {
      best = s.enrichment;
      L.pixel_region = r;
    }
  }
  if (best < kMinRegionEnrichment) L.pixel_region = Region::kGlobal;
  for (double e : E.view_energy) L.view_share.push_back(total_energy > 0.0 ? e / total_energy : 0.0);

  const HemProfile capture_outline = hem_profile_from_capture(capture);
  HemProfile diff;
  diff.radius.resize(capture_outline.radius.size());
  for (std::size_t k = 0; k < diff.radius.size(); ++k)
    diff.radius[k] = capture_outline.radius[k] - model_outline.radius[k];
  L.hem_difference = harmonics(diff, 12);
  L.capture_folds = fold_count(capture_outline);
  L.model_folds = fold_count(model_outline);
  const auto hc = harmonics(capture_outline, 16), hm = harmonics(model_outline, 16);
  if (L.capture_folds > 0 && L.capture_folds <= 16) L.capture_fold_phase = hc[L.capture_folds].phase;
  if (L.model_folds > 0 && L.model_folds <= 16) L.model_fold_phase = hm[L.model_folds].phase;
  L.capture_drape_coefficient = drape_coefficient(capture_outline, capture.specimen);
  L.model_drape_coefficient = drape_coefficient(model_outline, capture.specimen);
  return L;
}

void localise_against_floors(Localisation& L, const std::array<double, RegionEnergy::kCount>& floor_mean_square) {
  double best = 1.0;
  L.floor_region = Region::kGlobal;
  for (auto& s : L.regions) {
    const double floor = floor_mean_square[static_cast<int>(s.region)];
    s.floor_ratio = floor > 0.0 ? s.rms / std::sqrt(floor) : 0.0;
    if (s.pixel_share >= kMinPixelShare && s.floor_ratio > best) {
      best = s.floor_ratio;
      L.floor_region = s.region;
    }
  }
}

}  // namespace drapegen::diagnosis
