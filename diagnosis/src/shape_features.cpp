#include "drapegen/diagnosis/shape_features.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drapegen::diagnosis {
namespace {

constexpr double kBelowTop = -0.005;   // m: the skirt and cylinder side
constexpr double kHemBand = 0.010;     // m: points within this of the outline belong to the hem
constexpr double kAnnulus = 0.010;     // m
constexpr double kOuter = 0.23;        // m
constexpr int kMinAnnulusPoints = 20;
constexpr int kMaxOrder = 12;

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const double x = q * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(std::floor(x));
  const std::size_t j = std::min(v.size() - 1, i + 1);
  return v[i] + (x - static_cast<double>(i)) * (v[j] - v[i]);
}

double rms_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < a.size() && k < b.size(); ++k) {
    if (!std::isfinite(a[k]) || !std::isfinite(b[k])) continue;
    s += (a[k] - b[k]) * (a[k] - b[k]);
    ++n;
  }
  return n > 0 ? std::sqrt(s / n) : -1.0;
}

}  // namespace

std::string_view feature_group_name(FeatureGroup group) {
  switch (group) {
    case FeatureGroup::kHarmonics: return "harmonics";
    case FeatureGroup::kOffCentre: return "off_centre";
    case FeatureGroup::kSortedRadii: return "sorted_radii";
    case FeatureGroup::kHemHeight: return "hem_height";
    case FeatureGroup::kSkirtHeight: return "skirt_height";
    case FeatureGroup::kSkirtSpread: return "skirt_spread";
    case FeatureGroup::kFolds: return "folds";
  }
  return "?";
}

ShapeFeatures shape_features(const Eigen::Matrix3Xd& points, double cylinder_radius, bool full_outline) {
  ShapeFeatures f;
  // Per angle bin: the seen outline radius (98th percentile, as hem_profile_from_points) and the hem's height.
  const HemProfile outline = hem_profile_from_points(points, kHemBins);
  std::vector<int> seen(kHemBins, 0);
  std::vector<double> hem_z(kHemBins, 0.0);
  std::vector<int> hem_n(kHemBins, 0);
  const int annuli = static_cast<int>((kOuter - cylinder_radius - 0.005) / kAnnulus);
  std::vector<double> sum(std::max(annuli, 0), 0.0), sum_sq(std::max(annuli, 0), 0.0);
  std::vector<int> count(std::max(annuli, 0), 0);
  auto bin_of = [](double x, double y) {
    double a = std::atan2(y, x);
    if (a < 0.0) a += 2.0 * M_PI;
    return std::min(kHemBins - 1, static_cast<int>(a / (2.0 * M_PI) * kHemBins));
  };
  for (int i = 0; i < points.cols(); ++i) {
    const Eigen::Vector3d p = points.col(i);
    if (!p.allFinite() || p.z() >= kBelowTop) continue;  // a non-finite point has no bin
    const double r = std::hypot(p.x(), p.y());
    const int b = bin_of(p.x(), p.y());
    ++seen[b];
    if (std::isfinite(outline.radius[b]) && r > outline.radius[b] - kHemBand) {
      hem_z[b] += p.z();
      ++hem_n[b];
    }
    const double t = (r - cylinder_radius - 0.005) / kAnnulus;
    if (!(t >= 0.0 && t < annuli)) continue;  // compared before the cast: a far point's t is beyond an int
    const int k = static_cast<int>(t);
    sum[k] += p.z(), sum_sq[k] += p.z() * p.z(), ++count[k];
  }
  std::vector<double> radii, heights;
  HemProfile height_profile;  // the hem's height against angle, as a profile (for its first harmonic)
  height_profile.radius.assign(kHemBins, std::numeric_limits<double>::quiet_NaN());
  for (int b = 0; b < kHemBins; ++b) {
    if (seen[b] < 3) continue;
    radii.push_back(outline.radius[b]);
    if (hem_n[b] > 0) {
      heights.push_back(hem_z[b] / hem_n[b]);
      height_profile.radius[b] = heights.back();
    }
  }
  if (radii.size() < 8) return f;
  for (int q = 0; q < 10; ++q) f.sorted_radii.push_back(quantile(radii, 0.05 + 0.1 * q));
  double mean_height = 0.0;
  for (double h : heights) mean_height += h;
  mean_height /= std::max<std::size_t>(1, heights.size());
  f.hem_height = {mean_height, quantile(heights, 0.1), quantile(heights, 0.9)};
  f.skirt_height.assign(sum.size(), std::numeric_limits<double>::quiet_NaN());
  f.skirt_spread.assign(sum.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t k = 0; k < sum.size(); ++k) {
    if (count[k] < kMinAnnulusPoints) continue;
    const double m = sum[k] / count[k];
    f.skirt_height[k] = m;
    f.skirt_spread[k] = std::sqrt(std::max(0.0, sum_sq[k] / count[k] - m * m));
  }
  if (full_outline) {
    const auto h = harmonics(outline, kMaxOrder);
    for (const auto& c : h) {
      if (c.order == 1) {
        f.off_centre.push_back(c.amplitude);
      } else {
        f.harmonics.push_back(c.amplitude);
      }
    }
    f.off_centre.push_back(harmonics(height_profile, 1)[1].amplitude);
    f.folds = fold_count(outline);
  }
  f.valid = true;
  return f;
}

ShapeFeatures shape_features(const Capture& capture, const std::vector<int>& views) {
  std::vector<Eigen::Matrix3Xd> clouds;
  Eigen::Index total = 0;
  for (int k : views) {
    clouds.push_back(back_project(capture.views.at(static_cast<std::size_t>(k))));
    total += clouds.back().cols();
  }
  Eigen::Matrix3Xd all(3, total);
  Eigen::Index at = 0;
  for (const auto& c : clouds) {
    all.middleCols(at, c.cols()) = c;
    at += c.cols();
  }
  return shape_features(all, 0.5 * capture.specimen.cylinder_diameter, views.size() >= 3);
}

std::vector<double> group_differences(const ShapeFeatures& a, const ShapeFeatures& b) {
  std::vector<double> d(kFeatureGroupCount, -1.0);
  if (!a.valid || !b.valid) return d;
  const bool outline = !a.harmonics.empty() && !b.harmonics.empty();
  d[static_cast<int>(FeatureGroup::kHarmonics)] = outline ? rms_difference(a.harmonics, b.harmonics) : -1.0;
  d[static_cast<int>(FeatureGroup::kOffCentre)] = outline ? rms_difference(a.off_centre, b.off_centre) : -1.0;
  d[static_cast<int>(FeatureGroup::kSortedRadii)] = rms_difference(a.sorted_radii, b.sorted_radii);
  d[static_cast<int>(FeatureGroup::kHemHeight)] = rms_difference(a.hem_height, b.hem_height);
  d[static_cast<int>(FeatureGroup::kSkirtHeight)] = rms_difference(a.skirt_height, b.skirt_height);
  d[static_cast<int>(FeatureGroup::kSkirtSpread)] = rms_difference(a.skirt_spread, b.skirt_spread);
  d[static_cast<int>(FeatureGroup::kFolds)] = outline ? kFoldScale * std::abs(a.folds - b.folds) : -1.0;
  return d;
}

double feature_distance(const ShapeFeatures& a, const ShapeFeatures& b, const std::vector<double>& scale) {
  const auto d = group_differences(a, b);
  double s = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < d.size() && k < scale.size(); ++k) {
    if (d[k] < 0.0 || !(scale[k] > 0.0)) continue;
    s += (d[k] / scale[k]) * (d[k] / scale[k]);
    ++n;
  }
  return n > 0 ? std::sqrt(s / n) : 0.0;
}

std::vector<double> default_feature_scales() {
  // harmonics, off-centre, sorted radii, hem height, skirt height, skirt spread, folds: about the median difference
  // between two controls (no effect, other seed) of the same fabric, bench/effect_probe.cpp on fabrics 0 and 2.
  return {0.005, 0.004, 0.006, 0.005, 0.009, 0.004, kFoldScale};
}

}  // namespace drapegen::diagnosis
