#pragma once
// Do a capture's views describe one surface? Each view's depth is carried into the other views through the recorded
// cameras and compared with what they measured there. Cloth physics moves the surface that every view sees, so the
// views stay consistent whatever the effect; a sensor error breaks that. Multipath in particular reads long where a
// view sees a valley (renderer::SensorError: z' = z + g S, S the concavity seen from the camera), and the same patch
// of cloth is a valley for one view and not for another. At a point X that view A sees at pixel p and view B at
// pixel q, with the surface normal n and the views' rays a, b per unit camera depth, a gain g predicts the residual
//
//   r = D_B(q) - z_B(X_A) = g [ S_B(q) - S_A(p) (a . n) / (b . n) ]
//
// (X_A sits g S_A(p) along A's ray behind the surface; B's ray through it meets the surface that much nearer, over
// the ratio of the two rays' slopes to the surface; B's own reading adds g S_B(q)). The least-squares slope of r on
// the bracket over every pair of views estimates g from the capture alone, with no fit of the cloth.
//
// It is a detector more than a measurement. Without multipath the slope is not 0: the sensor noise leaves a bias
// that depends on the drape (the fitted drapes of 48 benchmark captures read -0.3-2.5 mm rendered clean, 0.9-5.6 mm
// with the Kinect noise model: drapegen_view_consistency_probe --floor-seeds 2). With multipath it follows the gain
// while the residuals stay within the gate, then saturates (clean renders of a folded skirt: 5 -> 3.4, 10 -> 7.0,
// 20 -> 12.0, 40 -> 13.0 mm; view_consistency_test.cpp); on benchmark captures it reads about half the true gain.
// A multipath test therefore reads it on every placement of the specimen (the sensor is the same, the drapes differ)
// and asks the smallest to reach a threshold calibrated on benchmark captures (docs/DIAGNOSIS_RESULTS.md,
// "Session 68").

#include <vector>

#include "drapegen/diagnosis/capture.hpp"
#include "drapegen/renderer/camera.hpp"
#include "drapegen/renderer/depth_image.hpp"

namespace drapegen::diagnosis {

struct ViewConsistencySettings {
  /// m: the largest second difference of depth (rows, columns, diagonals) around a compared pixel: a slanted surface
  /// passes, a silhouette, an occluding fold or a flying pixel does not.
  double kink = 0.06;
  /// m: larger cross-view residuals are another surface (an occlusion) and are skipped.
  double gate = 0.012;
  /// The smallest cosine between either view's ray and the surface normal (no grazing views).
  double min_cos = 0.3;
  int normal_px = 2;   // half-width of the normal's central differences
  int smooth_px = 2;   // half-width of the box filter before the concavity (the raw depth's own noise is concave)
  int concavity_radius_px = 4;  // as renderer::SensorError::multipath_radius_px
  /// m: the multipath test fires where every placement's slope reaches this. Calibrated on seeds 58-72 of the
  /// diagnosis benchmark (turned protocol, 3 placements, the Kinect noise model): the smallest of the three was
  /// 0.6-4.8 mm on 136 captures of the five physical families and controls (and below 3.3 mm on 8 with a camera pose
  /// error or a depth bias), 7.2-11.5 mm on 22 captures with 16-30 mm of multipath (docs/DIAGNOSIS_RESULTS.md,
  /// "Session 68"). With one placement the test is weaker: 11 of those 432 placements without multipath read 6 mm
  /// or more.
  double multipath_gain = 0.006;
};

struct ViewConsistency {
  double gain = 0.0;            // m: the slope g
  double standard_error = 0.0;  // m: its least-squares standard error (the pixels taken as independent)
  double offset = 0.0;          // m: the intercept (a depth bias or a pose error shifts it)
  double rms = 0.0;             // m: the residuals' root mean square
  long pixels = 0;              // compared pixel pairs over all ordered pairs of views
};

/// The multipath test over a specimen's placements (the capture first, then the second and held-out captures).
struct MultipathTest {
  std::vector<ViewConsistency> placements;
  double threshold = 0.0;  // m: ViewConsistencySettings::multipath_gain
  [[nodiscard]] double smallest_gain() const;  // m; 0 without placements
  /// Every placement's slope at least the threshold (false without placements).
  [[nodiscard]] bool detected() const { return !placements.empty() && smallest_gain() >= threshold; }
};

/// The cross-view slope of `depth[v]` seen by `cameras[v]` (one camera per image, same sizes).
[[nodiscard]] ViewConsistency view_consistency(const std::vector<renderer::DepthImage>& depth,
                                               const std::vector<renderer::Camera>& cameras,
                                               const ViewConsistencySettings& settings = {});

/// The same of a capture's views (their depth seen by their recorded cameras).
[[nodiscard]] ViewConsistency view_consistency(const Capture& capture, const ViewConsistencySettings& settings = {});

}  // namespace drapegen::diagnosis
