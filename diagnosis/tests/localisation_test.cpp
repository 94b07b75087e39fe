#include <gtest/gtest.h>

#include <cmath>

#include "drapegen/diagnosis/floors.hpp"
#include "drapegen/diagnosis/localisation.hpp"

using namespace drapegen::diagnosis;

namespace {

constexpr double kR = 0.05;  // the tester's cylinder radius (m)

/// A round outline of radius r (m).
HemProfile round_outline(double r) {
  HemProfile h;
  h.radius.assign(kHemBins, r);
  return h;
}

RegionShare share(Region region, double rms, double pixel_share) {
  RegionShare s;
  s.region = region;
  s.rms = rms;
  s.pixel_share = pixel_share;
  return s;
}

std::array<double, RegionEnergy::kCount> floors_of(double top, double rim, double skirt, double hem, double cylinder) {
  std::array<double, RegionEnergy::kCount> f{};
  f[static_cast<int>(Region::kTop)] = top * top;
  f[static_cast<int>(Region::kRim)] = rim * rim;
  f[static_cast<int>(Region::kSkirt)] = skirt * skirt;
  f[static_cast<int>(Region::kHem)] = hem * hem;
  f[static_cast<int>(Region::kCylinder)] = cylinder * cylinder;
  return f;
}

/// A localisation whose feature groups all sit at `ratio` but `group` at `lead`, with the stable term at `stable`
/// and the skirt's and the hem's pixel residuals enriched `skirt` and `hem` times.
Localisation excess(FeatureGroup group, double lead, double stable, double skirt, double hem, double ratio = 0.8) {
  Localisation L;
  L.group_ratio.assign(std::size(kFeatureGroups), ratio);
  for (std::size_t k = 0; k < std::size(kFeatureGroups); ++k)
    if (kFeatureGroups[k] == group) L.group_ratio[k] = lead;
  L.stable_ratio = stable;
  RegionShare s = share(Region::kSkirt, 0.01, 0.2), h = share(Region::kHem, 0.01, 0.5);
  s.enrichment = skirt;
  h.enrichment = hem;
  L.regions = {share(Region::kTop, 0.002, 0.1), s, h};
  return L;
}

}  // namespace

TEST(ClassifyPoint, SplitsTheSpecimenIntoTopRimCylinderSkirtAndHem) {
  const HemProfile outline = round_outline(0.12);
  EXPECT_EQ(classify_point({0.02, 0.01, 0.0}, outline, kR), Region::kTop);
  EXPECT_EQ(classify_point({0.055, 0.0, -0.01}, outline, kR), Region::kRim);      // over the edge
  EXPECT_EQ(classify_point({0.051, 0.0, -0.08}, outline, kR), Region::kCylinder);  // bare side, far below the top
  EXPECT_EQ(classify_point({0.0, 0.08, -0.06}, outline, kR), Region::kSkirt);
  EXPECT_EQ(classify_point({0.0, -0.11, -0.12}, outline, kR), Region::kHem);       // within 25 mm of the outline
  EXPECT_EQ(classify_point({-0.09, 0.0, -0.10}, outline, kR), Region::kSkirt);     // 30 mm inside it
}

TEST(RegionEnergy, MeanSquareIsEnergyPerPixelAndZeroWithoutPixels) {
  RegionEnergy e;
  e.energy[static_cast<int>(Region::kHem)] = 8e-6;
  e.pixels[static_cast<int>(Region::kHem)] = 2.0;
  EXPECT_DOUBLE_EQ(e.mean_square(Region::kHem), 4e-6);
  EXPECT_EQ(e.mean_square(Region::kTop), 0.0);
  EXPECT_EQ(e.mean_square(Region::kGlobal), 0.0);
}

TEST(LocaliseAgainstFloors, NamesTheRegionFurthestAboveItsOwnFloor) {
  Localisation L;
  // The hem has the largest residual (6 mm) but its floor (stable drapes place folds differently) is 5 mm; the rim's
  // 3 mm is three times its 1 mm floor.
  L.regions = {share(Region::kTop, 0.001, 0.1), share(Region::kRim, 0.003, 0.1), share(Region::kSkirt, 0.004, 0.2),
               share(Region::kHem, 0.006, 0.5), share(Region::kCylinder, 0.001, 0.1)};
  localise_against_floors(L, floors_of(0.001, 0.001, 0.004, 0.005, 0.002));
  EXPECT_EQ(L.floor_region, Region::kRim);
  EXPECT_NEAR(L.regions[0].floor_ratio, 1.0, 1e-12);
  EXPECT_NEAR(L.regions[1].floor_ratio, 3.0, 1e-12);
  EXPECT_NEAR(L.regions[3].floor_ratio, 1.2, 1e-12);
  EXPECT_NEAR(L.regions[4].floor_ratio, 0.5, 1e-12);
}

TEST(LocaliseAgainstFloors, GlobalWhenNothingExceedsItsFloorAndIgnoresTinyOrFloorlessRegions) {
  Localisation L;
  L.regions = {share(Region::kTop, 0.001, 0.1), share(Region::kSkirt, 0.002, 0.5)};
  localise_against_floors(L, floors_of(0.002, 0.0, 0.003, 0.0, 0.0));
  EXPECT_EQ(L.floor_region, Region::kGlobal);
  // A region far above its floor on 1% of the pixels does not count; one without floor pixels has no ratio.
  L.regions = {share(Region::kTop, 0.01, 0.01), share(Region::kSkirt, 0.004, 0.5), share(Region::kHem, 0.01, 0.3)};
  localise_against_floors(L, floors_of(0.001, 0.0, 0.002, 0.0, 0.0));
  EXPECT_EQ(L.floor_region, Region::kSkirt);
  EXPECT_NEAR(L.regions[0].floor_ratio, 10.0, 1e-12);
  EXPECT_EQ(L.regions[2].floor_ratio, 0.0);
}

TEST(Floors, RegionFloorIsTheLargestSampleOfEitherKindPerRegion) {
  Floors f;
  f.noise.region_mean_square = {floors_of(0.001, 0.002, 0.003, 0.004, 0.001), floors_of(0.002, 0.001, 0.001, 0.001, 0)};
  f.multistability.region_mean_square = {floors_of(0.0005, 0.001, 0.006, 0.008, 0.0005)};
  const auto top = f.region_floor();
  const auto expected = floors_of(0.002, 0.002, 0.006, 0.008, 0.001);
  for (int k = 0; k < RegionEnergy::kCount; ++k) EXPECT_DOUBLE_EQ(top[k], expected[k]) << k;
}

/// `L` with its platform top's residual at `mean` (m) and `floor_ratio` times its floor.
Localisation with_top(Localisation L, double mean, double floor_ratio) {
  for (auto& s : L.regions) {
    if (s.region != Region::kTop) continue;
    s.mean = mean;
    s.floor_ratio = floor_ratio;
  }
  return L;
}

TEST(PlaceGap, TheStableTermSitsWhereTheRigidSurfacesSayAndLeadsOnlyAboveTheGroups) {
  // The top within its own floor: the stable term's excess is on the bare cylinder (multipath).
  Localisation L = with_top(excess(FeatureGroup::kHemHeight, 1.2, 1.6, 1.0, 1.0), -0.2e-3, 0.95);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kCylinder);
  EXPECT_EQ(L.dominant_feature, "stable");
  // The top seen below the fitted cloth (a depth bias): everywhere, whatever the stable ratio.
  L = with_top(excess(FeatureGroup::kHemHeight, 1.2, 1.6, 1.0, 1.0), 4.8e-3, 1.6);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kGlobal);
  // A lifted top (friction's wrinkles): the specimen's contact below a camera error's scale, everywhere from it.
  L = with_top(excess(FeatureGroup::kHemHeight, 1.2, 1.64, 1.0, 1.0), -5.1e-3, 1.7);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kTop);
  L = with_top(excess(FeatureGroup::kHemHeight, 1.2, kLiftedTopSensorRatio, 1.0, 1.0), -7.8e-3, 2.8);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kGlobal);
  EXPECT_EQ(stable_region(L), Region::kGlobal);
  // Below a larger group ratio the stable term does not lead...
  L = with_top(excess(FeatureGroup::kSkirtHeight, 2.5, 2.0, 1.0, 1.0), -1.5e-3, 0.9);  // the top within its floor
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kSkirt);
  EXPECT_EQ(L.dominant_feature, "skirt_height");
  L = with_top(excess(FeatureGroup::kHarmonics, 2.5, 1.3, 1.6, 1.2), -0.2e-3, 0.9);  // the top within its floor
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kSkirt);
  EXPECT_EQ(L.dominant_feature, "harmonics");
  // ... unless the rigid surfaces are the camera's: a top seen farther than the fitted cloth (a depth bias), even
  // with the stable term itself within its floor, or a stable term from a camera error's scale (a pose error).
  L = with_top(excess(FeatureGroup::kSkirtHeight, 2.5, 2.0, 1.0, 1.0), 4.8e-3, 1.6);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kGlobal);
  EXPECT_EQ(L.dominant_feature, "stable");
  L = with_top(excess(FeatureGroup::kSortedRadii, 3.5, 0.9, 1.0, 1.0), 4.8e-3, 1.1);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kGlobal);
  L = with_top(excess(FeatureGroup::kSkirtHeight, 5.6, kLiftedTopSensorRatio, 1.0, 1.0), -11.0e-3, 3.0);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kGlobal);
  L = with_top(excess(FeatureGroup::kSkirtHeight, 5.6, kLiftedTopSensorRatio, 1.0, 1.0), -0.1e-3, 0.9);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kCylinder);  // the top within its floor: the bare cylinder's (multipath)
  // ... unless it exceeds its floor with the top lifted: the specimen slid over the platform (friction), whatever
  // the outline's change.
  L = with_top(excess(FeatureGroup::kHarmonics, 2.5, 1.3, 1.6, 1.2), -3.0e-3, 1.4);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kTop);
  EXPECT_EQ(L.dominant_feature, "stable");
  L = with_top(excess(FeatureGroup::kHarmonics, 2.5, 0.95, 1.6, 1.2), -3.0e-3, 1.4);  // the stable term within
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kSkirt);
  // A top lifted by less than kLiftedTopContact is the fit's own offset (rule T): the larger group leads (seed 91's
  // shear_00, its top 0.24 mm above the fitted cloth); from it, the top does.
  L = with_top(excess(FeatureGroup::kHarmonics, 2.5, 1.3, 1.6, 1.2), -0.24e-3, 1.4);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kSkirt);
  EXPECT_EQ(L.dominant_feature, "harmonics");
  L = with_top(excess(FeatureGroup::kHarmonics, 2.5, 1.3, 1.6, 1.2), -kLiftedTopContact, 1.4);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kTop);
  // Leading on its own, the stable term places a top lifted less as before.
  L = with_top(excess(FeatureGroup::kHarmonics, 1.2, 1.3, 1.0, 1.0), -0.24e-3, 1.4);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kTop);
}

TEST(RegionEnergy, MeanIsTheSignedResidualPerPixelOverallAndPerView) {
  RegionEnergy e;
  const int top = static_cast<int>(Region::kTop);
  e.pixels[top] = 3.0;  // view 0: one pixel at +4 mm; view 1: two pixels summing to +2 mm
  e.view_sum = {{}, {}};
  e.view_pixels = {{}, {}};
  e.view_sum[0][top] = 4e-3, e.view_pixels[0][top] = 1.0;
  e.view_sum[1][top] = 2e-3, e.view_pixels[1][top] = 2.0;
  EXPECT_DOUBLE_EQ(e.mean(Region::kTop), 2e-3);
  EXPECT_DOUBLE_EQ(e.view_mean(0, Region::kTop), 4e-3);
  EXPECT_DOUBLE_EQ(e.view_mean(1, Region::kTop), 1e-3);
  EXPECT_EQ(e.view_mean(2, Region::kTop), 0.0);  // no such view
  EXPECT_EQ(e.mean(Region::kRim), 0.0);          // no pixels
  EXPECT_EQ(e.mean(Region::kGlobal), 0.0);
}

TEST(PlaceGap, TheHemsOutlineCarriesTheSkirtWhereTheSkirtsResidualIsDenser) {
  for (FeatureGroup g : {FeatureGroup::kHarmonics, FeatureGroup::kSortedRadii, FeatureGroup::kHemHeight}) {
    Localisation L = excess(g, 2.0, 0.9, 1.6, 1.2);
    place_gap(L);
    EXPECT_EQ(L.dominant, Region::kSkirt) << feature_group_name(g);
    EXPECT_EQ(L.dominant_feature, feature_group_name(g));
    L = excess(g, 2.0, 0.9, 1.1, 1.2);
    place_gap(L);
    EXPECT_EQ(L.dominant, Region::kHem) << feature_group_name(g);
  }
  // A shifted centre is the hem's own (a placement) where the skirt's residual is denser by less than rule S's 1.3.
  Localisation L = excess(FeatureGroup::kOffCentre, 2.0, 0.9, 1.5, 1.2);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kHem);
  EXPECT_EQ(L.dominant_feature, "off_centre");
  // The skirt's groups are the skirt's whatever the pixels say (the folds' depth no deeper than the mean height).
  for (FeatureGroup g : {FeatureGroup::kSkirtHeight, FeatureGroup::kSkirtSpread, FeatureGroup::kFolds}) {
    L = excess(g, 2.0, 0.9, 0.8, 1.3, 0.8);
    if (g == FeatureGroup::kSkirtSpread) L.group_ratio[static_cast<std::size_t>(FeatureGroup::kSkirtHeight)] = 1.9;
    place_gap(L);
    EXPECT_EQ(L.dominant, Region::kSkirt) << feature_group_name(g);
    EXPECT_FALSE(L.moved_to_hem);
  }
}

TEST(PlaceGap, ASkirtGapWhoseFoldsDeepenFarBeyondTheSkirtsMeanHeightIsTheHems) {
  // Led by the folds' depth at 2.0 with the mean height at 1.2: 2.0 > 1.5 x 1.2, the hem (a curled edge band).
  Localisation L = excess(FeatureGroup::kSkirtSpread, 2.0, 0.9, 0.8, 1.3);
  L.group_ratio[static_cast<std::size_t>(FeatureGroup::kSkirtHeight)] = 1.2;
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kHem);
  EXPECT_EQ(L.dominant_feature, "skirt_spread");
  EXPECT_TRUE(L.moved_to_hem);
  EXPECT_TRUE(folds_deepen_at_hem(L));
  // At exactly 1.5 times, the skirt.
  L.group_ratio[static_cast<std::size_t>(FeatureGroup::kSkirtHeight)] = 2.0 / kFoldDepthAtHem;
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kSkirt);
  EXPECT_FALSE(L.moved_to_hem);
  // An outline group the skirt carries (denser skirt residual) moves too; placed on the hem already, it stays there.
  L = excess(FeatureGroup::kHarmonics, 3.0, 0.9, 1.4, 1.2, 0.5);
  L.group_ratio[static_cast<std::size_t>(FeatureGroup::kSkirtSpread)] = 2.5;
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kHem);
  EXPECT_TRUE(L.moved_to_hem);
  L = excess(FeatureGroup::kHarmonics, 3.0, 0.9, 1.1, 1.2, 0.5);
  L.group_ratio[static_cast<std::size_t>(FeatureGroup::kSkirtSpread)] = 2.5;
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kHem);
  EXPECT_FALSE(L.moved_to_hem);
  // Neither the stable term's places nor "global" move.
  L = with_top(excess(FeatureGroup::kSkirtSpread, 0.95, 1.6, 1.0, 1.0, 0.1), -0.2e-3, 0.95);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kCylinder);
  EXPECT_FALSE(L.moved_to_hem);
}

TEST(PlaceGap, ASkirtFarDenserThanTheHemKeepsItsGap) {
  // Rule S: the skirt's pixel residual at least 1.3 times as dense as the hem's (a change of the whole skirt) keeps a
  // gap the folds' depth or the centre's offset would put at the hem on the skirt.
  const auto fold_depth_led = [](double skirt, double hem) {
    Localisation L = excess(FeatureGroup::kSkirtSpread, 2.0, 0.9, skirt, hem);
    L.group_ratio[static_cast<std::size_t>(FeatureGroup::kSkirtHeight)] = 1.2;  // 2.0 > 1.5 x 1.2: the folds deepen
    place_gap(L);
    return L;
  };
  Localisation L = fold_depth_led(1.25 * kSkirtDenseAtHem, 1.25);
  EXPECT_EQ(L.dominant, Region::kSkirt);
  EXPECT_FALSE(L.moved_to_hem);
  EXPECT_TRUE(folds_deepen_at_hem(L));
  L = fold_depth_led(1.25 * kSkirtDenseAtHem - 0.01, 1.25);
  EXPECT_EQ(L.dominant, Region::kHem);
  EXPECT_TRUE(L.moved_to_hem);
  // An outline group the skirt carries: the same.
  L = excess(FeatureGroup::kHemHeight, 3.0, 0.9, 1.2 * kSkirtDenseAtHem, 1.2, 0.5);
  L.group_ratio[static_cast<std::size_t>(FeatureGroup::kSkirtSpread)] = 2.5;
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kSkirt);
  EXPECT_FALSE(L.moved_to_hem);
  // The centre's offset: at the factor the skirt's, below it the hem's.
  L = excess(FeatureGroup::kOffCentre, 2.0, 0.9, 1.2 * kSkirtDenseAtHem, 1.2);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kSkirt);
  EXPECT_EQ(L.dominant_feature, "off_centre");
  L = excess(FeatureGroup::kOffCentre, 2.0, 0.9, 1.2 * kSkirtDenseAtHem - 0.01, 1.2);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kHem);
  // No pixels on either: the centre's offset stays the hem's.
  L = excess(FeatureGroup::kOffCentre, 2.0, 0.9, 0.0, 0.0);
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kHem);
}

TEST(PlaceGap, ASkirtGapWhoseHemCentreLiesFarOffIsTheHems) {
  // Rule O: the hem's centre 6.6 mm off the fitted drape's (at least kHemOffCentreMm) moves a skirt gap to the hem;
  // 6.4 mm leaves it.
  constexpr auto kOff = static_cast<std::size_t>(FeatureGroup::kOffCentre);
  const auto off_by = [](Localisation L, double mm) {
    L.group_difference.assign(std::size(kFeatureGroups), 1e-3);
    L.group_difference[kOff] = mm * 1e-3;
    place_gap(L);
    return L;
  };
  Localisation L = off_by(excess(FeatureGroup::kSkirtHeight, 2.0, 0.9, 1.5, 1.0), kHemOffCentreMm + 0.1);
  EXPECT_EQ(L.dominant, Region::kHem);
  EXPECT_TRUE(L.moved_by_offset);
  EXPECT_EQ(L.dominant_feature, "skirt_height");
  L = off_by(excess(FeatureGroup::kSkirtHeight, 2.0, 0.9, 1.5, 1.0), kHemOffCentreMm - 0.1);
  EXPECT_EQ(L.dominant, Region::kSkirt);
  EXPECT_FALSE(L.moved_by_offset);
  // Rule S kept a gap the centre's offset leads on the far denser skirt: the offset in mm takes it to the hem.
  L = off_by(excess(FeatureGroup::kOffCentre, 2.0, 0.9, 1.2 * kSkirtDenseAtHem, 1.2), kHemOffCentreMm + 0.1);
  EXPECT_EQ(L.dominant, Region::kHem);
  EXPECT_TRUE(L.moved_by_offset);
  // Placed on the hem already, or by the stable term, or nowhere: as before.
  L = off_by(excess(FeatureGroup::kHemHeight, 2.0, 0.9, 1.0, 1.2), kHemOffCentreMm + 0.1);
  EXPECT_EQ(L.dominant, Region::kHem);
  EXPECT_FALSE(L.moved_by_offset);
  L = off_by(with_top(excess(FeatureGroup::kSkirtSpread, 0.95, 1.6, 1.0, 1.0, 0.1), -0.2e-3, 0.95),
             kHemOffCentreMm + 0.1);
  EXPECT_EQ(L.dominant, Region::kCylinder);
  EXPECT_FALSE(L.moved_by_offset);
  L = off_by(excess(FeatureGroup::kSkirtHeight, 0.95, 0.97, 1.5, 1.0), kHemOffCentreMm + 0.1);
  EXPECT_EQ(L.dominant, Region::kGlobal);
  EXPECT_FALSE(L.moved_by_offset);
}

TEST(PlaceGap, GlobalWithNoFeatureNamedWhenNothingExceedsItsFloor) {
  Localisation L = excess(FeatureGroup::kHemHeight, 0.95, 0.97, 1.6, 1.2);
  L.dominant_feature = "left over";
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kGlobal);
  EXPECT_TRUE(L.dominant_feature.empty());
}

TEST(PlaceGap, ACameraTheRigidSurfacesMoveFromItsCalibrationPlacesTheGapEverywhere) {
  // An outline group well above its floor would place it on the skirt; a camera 3 mm off at the platform overrides.
  Localisation L = excess(FeatureGroup::kSkirtHeight, 4.0, 0.9, 1.6, 1.2);
  L.camera_moved = kCameraMovedAtPlatform;
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kGlobal);
  EXPECT_EQ(L.dominant_feature, "camera");
  // Below it (a friction specimen's cloth lifts the top: up to 2.2 mm on seeds 17-20), the features place it.
  L.camera_moved = 0.0022;
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kSkirt);
  EXPECT_EQ(L.dominant_feature, "skirt_height");
}

TEST(PlaceSensorGap, WhereTheViewsDisagreeThePixelsFurthestAboveTheirFloorPlaceTheGap) {
  // The hem's height leads the shape features and the hem's residual is the denser: place_gap says the hem.
  Localisation L = excess(FeatureGroup::kHemHeight, 1.8, 0.9, 1.1, 1.3);
  L.regions.push_back(share(Region::kCylinder, 0.006, 0.05));
  // Pixel residuals over their floors: top 2/1, skirt 10/4, hem 10/5, cylinder 6/2 (3x, the furthest).
  localise_against_floors(L, floors_of(0.001, 0.001, 0.004, 0.005, 0.002));
  ASSERT_EQ(L.floor_region, Region::kCylinder);
  place_gap(L);
  ASSERT_EQ(L.dominant, Region::kHem);
  place_sensor_gap(L);
  EXPECT_EQ(L.dominant, Region::kCylinder);
  EXPECT_TRUE(L.placed_by_views);
  EXPECT_EQ(L.dominant_feature, "hem_height");  // what led the shape features stays reported
  // place_gap places afresh (and clears the flag).
  place_gap(L);
  EXPECT_EQ(L.dominant, Region::kHem);
  EXPECT_FALSE(L.placed_by_views);
  // No region above its own floor: place_gap's region stands.
  localise_against_floors(L, floors_of(0.01, 0.01, 0.02, 0.02, 0.01));
  ASSERT_EQ(L.floor_region, Region::kGlobal);
  place_sensor_gap(L);
  EXPECT_EQ(L.dominant, Region::kHem);
  EXPECT_FALSE(L.placed_by_views);
  // A gap place_gap moved to the hem (the folds deepen there) is moved again, and no longer said to be so moved.
  L = excess(FeatureGroup::kSkirtSpread, 2.0, 0.9, 0.8, 1.3);
  L.group_ratio[static_cast<std::size_t>(FeatureGroup::kSkirtHeight)] = 1.2;
  L.regions.push_back(share(Region::kCylinder, 0.006, 0.05));
  localise_against_floors(L, floors_of(0.001, 0.001, 0.004, 0.005, 0.002));
  place_gap(L);
  ASSERT_TRUE(L.moved_to_hem);
  place_sensor_gap(L);
  EXPECT_EQ(L.dominant, Region::kCylinder);
  EXPECT_FALSE(L.moved_to_hem);
}

TEST(PlaceSensorGap, ACameraTheRigidSurfacesPutOffStaysEverywhere) {
  Localisation L = excess(FeatureGroup::kHemHeight, 1.8, 0.9, 1.1, 1.3);
  L.regions.push_back(share(Region::kCylinder, 0.006, 0.05));
  localise_against_floors(L, floors_of(0.001, 0.001, 0.004, 0.005, 0.002));
  L.camera_moved = 2.0 * kCameraMovedAtPlatform;
  place_gap(L);
  ASSERT_EQ(L.dominant_feature, "camera");
  place_sensor_gap(L);
  EXPECT_EQ(L.dominant, Region::kGlobal);
  EXPECT_FALSE(L.placed_by_views);
}
