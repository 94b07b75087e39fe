#pragma once
// The drape's outline as seen from above: the hem radius as a function of the angle about the axis, from a mesh or
// from a capture's back-projected depth; its angular harmonics, fold count and phase; the rotation that best aligns
// two outlines (the specimen's orientation on the table is arbitrary, paper Section 3).

#include <Eigen/Core>
#include <vector>

#include "drapegen/diagnosis/capture.hpp"
#include "drapegen/sim/mesh.hpp"

namespace drapegen::diagnosis {

struct HemProfile {
  /// Hem radius (m) in `bins` equal angle bins over [0, 2 pi), bin k centred at (k + 1/2) 2 pi / bins; NaN where
  /// nothing was seen.
  std::vector<double> radius;
  [[nodiscard]] int bins() const { return static_cast<int>(radius.size()); }
};

constexpr int kHemBins = 144;  // 2.5 degrees

/// The capture's points in the specimen frame (every returned pixel of every view, back-projected).
[[nodiscard]] Eigen::Matrix3Xd back_project(const CaptureView& view);

/// From points (specimen frame): per bin, the 98th percentile of the horizontal radius of the points below the top
/// (z < -5 mm), robust to flying pixels. Bins without points are NaN and then filled from their neighbours.
[[nodiscard]] HemProfile hem_profile_from_points(const Eigen::Matrix3Xd& points, int bins = kHemBins);
/// From a mesh: per bin, the largest radius of the boundary polyline (sampled along each boundary edge).
[[nodiscard]] HemProfile hem_profile_from_mesh(const sim::ClothMesh& mesh, int bins = kHemBins);
[[nodiscard]] HemProfile hem_profile_from_capture(const Capture& capture, int bins = kHemBins);
/// From the given views only (e.g. the fit views, keeping a held-out view out of the fit).
[[nodiscard]] HemProfile hem_profile_from_views(const Capture& capture, const std::vector<int>& views,
                                                int bins = kHemBins);
/// Distance between two outlines that ignores where the folds lie: the RMS difference of their harmonic amplitudes
/// of orders 0..max_order (m). Invariant to turning either outline.
[[nodiscard]] double spectrum_distance(const HemProfile& a, const HemProfile& b, int max_order = 12);

/// The profile of the same outline turned by `angle` (radians, counter-clockwise about +z).
[[nodiscard]] HemProfile rotate(const HemProfile& profile, double angle);

/// The rotation of `model` that best matches `target` (least squares over both profiles' bins), radians in
/// [-pi, pi), and the RMS radius difference there (m).
struct Alignment {
  double angle = 0.0;
  double rms = 0.0;
};
[[nodiscard]] Alignment align(const HemProfile& model, const HemProfile& target);
/// The turn of a model drape on the table: `align` on both outlines low-passed to orders 0..kOrientationOrders (the
/// centre offset, the anisotropy's ellipse and the square's corners), not on the folds: where the folds fall differs
/// between stable drapes, so matching them turned the low orders (an off-centre specimen's direction) at random.
constexpr int kOrientationOrders = 4;
[[nodiscard]] Alignment align_orientation(const HemProfile& model, const HemProfile& target);

/// Complex Fourier coefficients c_n of r(theta), n = 0..max_order: amplitude |c_n| (m; n >= 1 doubled so that it is
/// the cosine amplitude) and phase (radians).
struct Harmonic {
  int order = 0;
  double amplitude = 0.0;
  double phase = 0.0;
};
[[nodiscard]] std::vector<Harmonic> harmonics(const HemProfile& profile, int max_order = 12);
/// The profile rebuilt from its harmonics of orders 0..max_order (bins without a radius stay without).
[[nodiscard]] HemProfile low_pass(const HemProfile& profile, int max_order);

/// Folds: local maxima of the smoothed profile that stand out by at least `prominence` (m).
[[nodiscard]] int fold_count(const HemProfile& profile, double prominence = 0.004);

/// Area inside the outline (m^2) and Cusick's drape coefficient (A - pi R^2) / (Lx Ly - pi R^2) of a specimen of
/// size Lx x Ly on a cylinder of radius R.
[[nodiscard]] double enclosed_area(const HemProfile& profile);
[[nodiscard]] double drape_coefficient(const HemProfile& profile, const SpecimenFacts& specimen);
/// The drape coefficient of the outline a capture's views see (hem_profile_from_capture) on its specimen.
[[nodiscard]] double drape_coefficient(const Capture& capture);

/// The skirt's mean height against the radius: per 5 mm annulus from the cylinder radius + 5 mm outwards (to
/// 230 mm), the mean z of the points below the top, NaN with fewer than 10 points. Turning the drape or moving its
/// folds around leaves it nearly unchanged; stiffness, curl, yield and shear change it.
struct RadialProfile {
  std::vector<double> z;
  std::vector<int> count;
};
[[nodiscard]] RadialProfile radial_profile(const Eigen::Matrix3Xd& points, double cylinder_radius);
/// RMS height difference over the annuli both profiles have (m); 0 if none.
[[nodiscard]] double radial_distance(const RadialProfile& a, const RadialProfile& b);

}  // namespace drapegen::diagnosis
