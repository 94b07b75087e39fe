#pragma once
// The reality generator: a capture of a drape with effects the baseline model lacks (physical ones in the
// simulation, sensor ones in the rendering), and its ground truth in a separate file the diagnosis never reads.

#include <cstdint>
#include <string>
#include <vector>

#include "drapegen/diagnosis/capture.hpp"
#include "drapegen/diagnosis/fabric_space.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::diagnosis {

/// One --effect NAME[=STRENGTH]:
///   yield=K       elastoplastic bending, hinges yield at curvature K 1/m (default 20)
///   shear=G       trellis membrane with shear stiffness G kg/s^2 (default 1)
///   curl=K[,W]    edge rest curvature K 1/m falling to 0 over a band of W mm (default 200 over 30: an edge that rolls
///                 to a 5 mm radius); the band must span at least two vertex spacings of the simulated specimen
///   friction=MU   Coulomb friction on the top instead of adhesion (default 0.05)
///   misalign=MM   specimen centre MM mm off the axis, seeded direction (default 15; the data's augmentation: 2)
///   pose=DEG      camera pose error: rotation DEG degrees about a seeded axis and translation 5*DEG mm (default 1)
///   bias=MM       depth bias MM mm (default 5)
///   multipath=MM  multipath gain MM mm (default 15)
struct RealityEffect {
  std::string name;
  double strength = 0.0;
  double width_mm = 0.0;  // curl only: the band's width (0: kCurlWidth)
};
[[nodiscard]] sim::Expected<RealityEffect> parse_reality_effect(const std::string& text);
/// The family the diagnosis should name: yield, shear, curl, friction, misalignment or sensor (pose, bias,
/// multipath).
[[nodiscard]] std::string reality_family(const std::string& effect_name);

inline constexpr int kMaxPlacement = 100;

/// The smallest nonzero measured-bending error (sigma): below it the stated precision e^(2 sigma) would round to a
/// factor of 1, which no capture may state (docs/CAPTURE.md).
inline constexpr double kMinMeasuredBendingError = 1e-3;

struct RealitySpec {
  BendingParameters bending;
  double density = 300.0;   // g/m^2
  int resolution = 30;      // the "real" specimen's mesh
  std::uint64_t seed = 0;   // initial state, orientation, drift, camera augmentation, noise
  /// Placement of the specimen on the tester: 0 is the first; K > 0 re-drapes the same specimen (same mesh, fabric,
  /// effects, misalignment distance and camera calibration error) from another initial state, orientation, drift,
  /// misalignment direction and sensor noise: a second capture of one specimen, for validation held out of a fit.
  /// A yielding specimen (yield) carries its plastic set from placement to placement: placement K starts from the
  /// rest angles placements 0 .. K-1 left, draped in turn (K + 1 drapes in all). At most kMaxPlacement.
  int placement = 0;
  /// The specimen is turned over each time it is lifted: placement K lies face down (capture.json "face": "down")
  /// when K is odd. A rest shape (edge curl, a plastic set) then bends the other way on those placements.
  bool turn_over = false;
  std::vector<RealityEffect> effects;
  bool noise = true;
  /// > 0: the capture carries a measured bending (SpecimenFacts::measured_bending), measure_bending(bending, this,
  /// seed): what a bending test of this precision would have reported of the specimen, the same on every placement.
  double measured_bending_error = 0.0;  // 0 or kMinMeasuredBendingError .. 1
};

/// A bending test's report of a specimen whose true bending is `truth`: each of the six parameters times its own
/// e^(sigma g), g standard normal (seeded by `seed`), and the precision it states, within_factor = e^(2 sigma) (each
/// parameter's 95% range). For sigma > 0 it is not the truth (but for a zero beta, which stays 0). sigma: 0 .. 1.
[[nodiscard]] MeasuredBending measure_bending(const BendingParameters& truth, double sigma, std::uint64_t seed);

struct RealityResult {
  std::string truth_path;
  double seconds = 0.0;
  bool converged = true;
};

/// Simulates and renders DIR/capture.json + DIR/view{0..3}.exr, writes the truth to DIR/truth.json and a preview to
/// DIR/preview.png.
[[nodiscard]] sim::Expected<RealityResult> generate_reality(const RealitySpec& spec, const std::string& directory);

}  // namespace drapegen::diagnosis
