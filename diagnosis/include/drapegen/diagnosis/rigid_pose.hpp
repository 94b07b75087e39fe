#pragma once
// The camera's pose error read off the tester's rigid surfaces before any fit: the specimen lies flat on the platform
// top (a plane at the cloth's contact offset) and the platform's bare side below the skirt is a cylinder of known
// radius. Whatever the fabric, both are where the tester's geometry puts them, so a calibrated camera sees them there;
// a camera that sits elsewhere than its calibration says sees them moved. The estimate is the SensorError pose
// (renderer/sensor_error.hpp: the camera really at delta * recorded) that brings the capture's rigid pixels back onto
// the surfaces, by Levenberg-Marquardt over the pixels within a band of them that narrows as the pose improves.
// Rotation about the platform axis leaves both surfaces unchanged: the damping keeps the steps out of that
// direction (the outline turn of every drape absorbs it). A translation along the axis moves the top and not the
// side, as a specimen lifting off the top does (one that slid rises over it): a top seen above the contact offset
// whose camera the side does not confirm is read as the cloth's lift, one seen below as the camera's (no cloth lies
// inside the platform). docs/DIAGNOSIS.md, "The camera from the rigid surfaces".

#include <vector>

#include "drapegen/diagnosis/capture.hpp"
#include "drapegen/renderer/sensor_error.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::diagnosis {

struct RigidSurfaces {
  double cylinder_radius = 0.05;  // m
  /// m: the cloth's surface on the platform top (the simulator's contact offset: the cloth rests this far above).
  double top_height = 0.001;
  /// m: top pixels are those this far inside the rim (the cloth bends over the rim outside it).
  double top_inset = 0.005;
  /// m: side pixels are those this far below the top. The skirt often lies against the side (at the contact offset,
  /// 1 mm out) well down the platform, but no cloth reaches farther below the rim than the specimen's half diagonal
  /// less the platform radius: for_specimen puts the side pixels below that.
  double side_below = 0.172;

  /// The tester of a capture: its platform radius, the side below where the specimen can reach (plus 1 cm).
  [[nodiscard]] static RigidSurfaces for_specimen(const SpecimenFacts& specimen);
};

struct RigidPoseSettings {
  /// The start: camera rotations about its x and y axes on a grid of (2 grid_steps + 1)^2 points this far apart.
  int grid_steps = 15;
  double grid_spacing_mrad = 4.0;
  int iterations = 16;
  /// m: a pixel counts for a surface while its distance to it is within the band; the band narrows geometrically
  /// from the first to the last value over the first half of the iterations.
  double first_band = 0.008;
  double last_band = 0.003;
  int min_top_pixels = 100;
  int min_side_pixels = 100;
  /// The side confirms the estimate's camera when this share more of its pixels lie within the last band there than
  /// at the recorded camera (a camera error moves the side: the benchmark's pose errors and depth biases add 80% or
  /// more, the lifted top of a specimen that slid 0-3%; docs/DIAGNOSIS.md). A camera error that moves the side by
  /// well under the last band changes the count little: with a top seen lifted it is read as the cloth's.
  double side_confirms = 0.1;
  /// m: a top seen this far above the contact offset (its mean over the first band, at the recorded camera) whose
  /// estimate the side does not confirm is the cloth's lift: the estimate is the recorded camera.
  double min_lift = 0.0005;
};

struct RigidPose {
  renderer::SensorError pose;  // rotation and translation only
  /// m: RMS distance to the surfaces of the pixels within the last band, at the recorded pose and at the estimate.
  double rms_recorded = 0.0;
  double rms_estimated = 0.0;
  /// m: how far the cloth on the top lies above its contact offset when it is read as lifted (then the pose is the
  /// recorded camera's, no error, and the top's pixels and RMS are counted against the lifted top); 0 when the offset
  /// is read as the camera's.
  double top_lift = 0.0;
  int top_pixels = 0;   // at the estimate, within the last band
  int side_pixels = 0;
};

/// m: how far the pose error moves the platform's centre in the camera's frame (the largest over the views): what a
/// fit would have to absorb, blind to a turn about the platform axis.
[[nodiscard]] double platform_displacement(const renderer::SensorError& pose, const Capture& capture);

/// The pose error of the capture's camera from its rigid pixels (every view: one camera, the table turning). Fails
/// when too few pixels see either surface (e.g. a capture whose views miss the platform).
[[nodiscard]] sim::Expected<RigidPose> estimate_rigid_pose(const Capture& capture, const RigidSurfaces& surfaces = {},
                                                          const RigidPoseSettings& settings = {});

}  // namespace drapegen::diagnosis
