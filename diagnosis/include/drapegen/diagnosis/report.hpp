#pragma once
// The human report of a diagnosis: report.json, report.md and the residual maps as PNG images.

#include <string>
#include <vector>

#include "drapegen/diagnosis/diagnosis.hpp"

namespace drapegen::diagnosis {

/// One view's signed residual, m, row-major, width x height.
struct ResidualImage {
  int width = 0;
  int height = 0;
  std::vector<float> values;
};

/// Signed residual images side by side, diverging colours (blue: the capture is nearer the camera than the model,
/// red: farther), saturating at +-`range` m; black where neither returns. Each in a cell of the largest image's size
/// (a capture's views may differ in size). 8-bit RGB PNG via libpng.
[[nodiscard]] sim::Status write_residual_png(const std::string& path, const std::vector<ResidualImage>& residuals,
                                             double range);

/// report.md's verdict: the verdict line, why a named effect was put ahead of another where that happened, and
/// under a verdict within the floors ("none") what it does not rule out.
[[nodiscard]] std::string verdict_markdown(const DiagnosisResult& result);

/// report.md's "Dominant region" sentence: the region place_gap chose and what placed it there (the leading feature
/// group or term, and the rule that moved it: the folds' depth, the hem's centre offset, the views' disagreement).
[[nodiscard]] std::string dominant_region_markdown(const Localisation& localisation);

/// report.md's runtime: wall and CPU seconds, and where the result confirmed other diagnoses of the same captures
/// (--confirm-resolution, --confirm-placement-rise; up to four with both) that these are all of theirs together.
[[nodiscard]] std::string runtime_markdown(const DiagnosisResult& result);

/// Writes DIR/report.json, DIR/report.md, DIR/residual.png (capture - fitted baseline per view), DIR/views.png
/// (capture over fitted drape) and DIR/residual_after.png (after adding the named effect, if any). An earlier
/// report's files in DIR are removed first; report.json comes last (present only beside a complete report).
[[nodiscard]] sim::Status write_report(const std::string& directory, const DiagnosisResult& result,
                                       const Capture& capture, ForwardModel& model);

}  // namespace drapegen::diagnosis
