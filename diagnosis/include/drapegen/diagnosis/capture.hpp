#pragma once
// A capture: what a drape tester (or the reality generator) recorded of one specimen, and all the diagnosis reads.
// Format: docs/CAPTURE.md (a directory with capture.json, one depth EXR per view, optionally a scanned mesh).

#include <optional>
#include <string>
#include <vector>

#include "drapegen/diagnosis/fabric_space.hpp"
#include "drapegen/renderer/camera.hpp"
#include "drapegen/renderer/depth_image.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::diagnosis {

/// The specimen's bending as another test measured it (e.g. a cantilever test), and how precise that test is.
struct MeasuredBending {
  BendingParameters bending;
  /// The test's precision: each of the six true parameters lies within this factor of the measured one (> 1; e.g.
  /// e^(2 x 0.1) = 1.22, the 95% range of a test with a 10% lognormal error). The diagnosis's fits stay within it.
  double within_factor = 1.25;
  std::string method;  // free text, e.g. "cantilever (ASTM D1388)"
};

/// Facts about the specimen and the tester that the operator knows.
struct SpecimenFacts {
  double size_x = 0.3;             // m
  double size_y = 0.3;             // m
  double density = 300.0;          // g/m^2
  double cylinder_diameter = 0.1;  // m
  std::optional<MeasuredBending> measured_bending;  // optional: docs/CAPTURE.md, "Measured bending"
};

struct CaptureView {
  std::string file;  // relative to the capture directory
  /// Camera-space z, metres, 0 = no return.
  renderer::DepthImage depth;
  /// Intrinsics and pose in the specimen frame (platform top in z = 0, axis along z, as drapegen::sim).
  renderer::Camera camera;
};

struct Capture {
  std::string directory;
  SpecimenFacts specimen;
  std::vector<CaptureView> views;
  std::optional<std::string> scan_mesh;  // a PLY file, relative to the directory
  std::string source;                    // free text, e.g. "drapegen reality"
  /// The specimen lay turned over, its back face up ("face": "down"; default "up"). Only the faces of one specimen's
  /// captures relative to each other matter: a rest shape (edge curl, creases a yield left) bends the other way.
  bool face_down = false;
};

/// The number of views a capture must have (the tester's four).
constexpr int kCaptureViews = 4;
/// m: no depth and no camera of a drape tester lies farther than this from the specimen (a depth beyond it is a
/// sensor's "no return" sentinel, or another unit); the farthest depth the diagnosis's renderer draws
/// (renderer::DepthRange's far plane): a camera is accepted where the whole specimen and platform lie within it.
constexpr double kFarthestDepth = 10.0;

/// Reads DIR/capture.json and its depth files. Every failure is one line naming the file and the problem: missing
/// capture.json or view, malformed JSON, wrong view count, depth size not the camera's, NaN/infinite/negative depth
/// or depth beyond kFarthestDepth, a view without any return, a camera that is not one (focal lengths not positive, a
/// pose not rigid or farther than kFarthestDepth), implausible specimen facts.
[[nodiscard]] sim::Expected<Capture> read_capture(const std::string& directory);

/// Writes the depth EXRs (float) and capture.json into `directory` (created if needed), as one set
/// (storage::write_files_atomic): a failed write leaves an earlier capture there whole. capture.directory is ignored.
[[nodiscard]] sim::Status write_capture(const std::string& directory, const Capture& capture);
/// capture.json's text for `capture`, naming the depth files write_capture writes.
[[nodiscard]] std::string capture_json_text(const Capture& capture);
/// Writes capture.json alone (through a temporary file), naming the depth files write_capture would: for a capture
/// read from `directory` whose description changes (e.g. a measured bending added), the depth files stay as they are.
[[nodiscard]] sim::Status write_capture_json(const std::string& directory, const Capture& capture);

/// Checks one view's depth: size, finite, non-negative, within kFarthestDepth, some return.
[[nodiscard]] sim::Status check_view(const CaptureView& view);

}  // namespace drapegen::diagnosis
