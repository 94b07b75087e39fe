// Do a capture's four views describe one surface? Each view's depth is carried into the other views through the
// recorded cameras and compared with what they measured there. Cloth physics moves the surface that every view sees,
// so the views stay consistent whatever the effect; a sensor error breaks that. Multipath in particular reads long
// where a view sees a valley (renderer::SensorError, concavity S), and the same patch of cloth is a valley for one view
// and not for another. With the surface normal n at a point X seen by view A at pixel p and by view B at pixel q, and
// a, b the two views' rays per unit camera depth, a gain g predicts the cross-view residual
//
//   r = D_B(q) - z_B(X_A) = g [ S_B(q) - S_A(p) (a . n) / (b . n) ],
//
// so the least-squares slope of r on the bracket estimates g from the capture alone, with no fit of the cloth
// (diagnosis/view_consistency.hpp). The sensor noise biases the slope by an amount that depends on the drape; with
// --floor-seeds the same slope is measured on the diagnosis's fitted drape (its report's bending and best initial
// state) rendered without sensor error, clean and with that many noise seeds (--noise-off drops terms of the noise
// model). Reads the truth files only to print each capture's family and multipath strength: a benchmark tool.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <iostream>
#include <optional>

#include "drapegen/diagnosis/bending_json.hpp"
#include "drapegen/diagnosis/capture.hpp"
#include "drapegen/diagnosis/diagnosis.hpp"
#include "drapegen/diagnosis/forward_model.hpp"
#include "drapegen/diagnosis/view_consistency.hpp"
#include "drapegen/renderer/noise.hpp"
#include "drapegen/renderer/random.hpp"
#include "drapegen/sim/blas_kernels.hpp"
#include "json_file.hpp"

namespace fs = std::filesystem;
using namespace drapegen;

namespace {

using diagnosis::ViewConsistency;

/// The slopes of the report's fitted drape (its bending and best initial state) rendered without sensor error: the
/// clean render's first, then `seeds` renders with the Kinect noise model minus the terms named in `noise_off`.
struct FloorSlopes {
  ViewConsistency clean;
  std::vector<ViewConsistency> noisy;
};

sim::Expected<FloorSlopes> floor_slopes(const diagnosis::Capture& capture, const fs::path& report_file, int seeds,
                                        const std::string& noise_off, const diagnosis::ViewConsistencySettings& o) {
  const auto report = bench::read_json(report_file);
  if (!report) return report.error();
  const auto settings = diagnosis::DiagnosisSettings::fine();
  auto model = diagnosis::ForwardModel::create(capture, settings.fit);
  if (!model) return model.error();
  diagnosis::ModelSetup setup;
  auto fitted = diagnosis::bending_from_json(report->at("baseline").at("fitted"), "report baseline.fitted");
  if (!fitted) return fitted.error();
  setup.bending = *fitted;
  const auto state = (*model)->initial_states().at(report->at("baseline").value("best_state", 0));
  auto e = (*model)->evaluate(setup, {state});
  if (!e) return e.error();
  auto clean = (*model)->render(e->best.mesh, e->best.angle, renderer::SensorError{});
  if (!clean) return clean.error();
  renderer::NoiseModel noise = renderer::NoiseModel::kinect();
  for (const char term : noise_off) {
    bool* off = term == 'a' ? &noise.axial : term == 'l' ? &noise.lateral : term == 'g' ? &noise.grazing
              : term == 'e' ? &noise.edges : term == 'd' ? &noise.dropout : term == 'q' ? &noise.quantisation
                            : nullptr;
    if (!off) return sim::Error{fmt::format("--noise-off: unknown term '{}' (one of a l g e d q)", term)};
    *off = false;
  }
  FloorSlopes out;
  diagnosis::Capture pseudo = capture;
  for (std::size_t v = 0; v < pseudo.views.size(); ++v) pseudo.views[v].depth = (*clean)[v];
  out.clean = diagnosis::view_consistency(pseudo, o);
  for (int k = 0; k < seeds; ++k) {
    for (std::size_t v = 0; v < pseudo.views.size(); ++v)
      pseudo.views[v].depth = noise.apply((*clean)[v], renderer::mix_seed(0xC0515 + static_cast<std::uint64_t>(k), v));
    out.noisy.push_back(diagnosis::view_consistency(pseudo, o));
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  sim::relaunch_with_blas_kernels(argv);  // the kernels drapegen runs on (blas_kernels.hpp)
  CLI::App app{"Cross-view consistency of benchmark captures: the multipath gain each capture's four views imply "
               "(docs/DIAGNOSIS_RESULTS.md, \"Session 68\")."};
  std::vector<std::string> runs;
  diagnosis::ViewConsistencySettings o;
  double kink_mm = 1e3 * o.kink, gate_mm = 1e3 * o.gate;
  int floor_seeds = 0;
  std::string reports = "diagnoses", noise_off;
  bool placements = false;
  app.add_option("runs", runs, "benchmark run directories (captures/ and truth/ inside)")->required();
  app.add_option("--kink", kink_mm, "mm: largest second difference of depth around a usable pixel")
      ->capture_default_str();
  app.add_option("--gate", gate_mm, "mm: larger cross-view residuals are another surface and skipped")
      ->capture_default_str();
  app.add_option("--min-cos", o.min_cos, "smallest cosine between either view's ray and the normal")
      ->capture_default_str();
  app.add_option("--normal-px", o.normal_px, "pixels: half-width of the normal's central differences")
      ->capture_default_str();
  app.add_option("--smooth-px", o.smooth_px, "pixels: half-width of the box filter before the concavity")
      ->capture_default_str();
  app.add_option("--floor-seeds", floor_seeds, "noise seeds of the fitted drape's floor (0: no floor; simulates)")
      ->capture_default_str();
  app.add_option("--noise-off", noise_off, "the floor's noise model without these terms: a(xial) l(ateral) "
                                           "g(razing) e(dges) d(ropout) q(uantisation), e.g. \"le\"");
  app.add_option("--reports", reports, "the runs' folder of diagnosis reports (for the floor)")->capture_default_str();
  app.add_flag("--placements", placements, "also the second and held-out placements (NAME.p1, NAME.p2)");
  CLI11_PARSE(app, argc, argv);
  o.kink = 1e-3 * kink_mm, o.gate = 1e-3 * gate_mm;

  fmt::print("{:<6} {:<18} {:<13} {:>7} {:>7} {:>6} {:>7} {:>6} {:>6} {:>7} {:>7} {:>6}\n", "run", "capture",
             "family", "true_mm", "g_mm", "se_mm", "c_mm", "rms_mm", "pixels", "clean", "floor", "sd");
  for (const std::string& run : runs) {
    std::vector<fs::path> dirs;
    for (const auto& e : fs::directory_iterator(fs::path(run) / "captures"))
      if (e.is_directory() && (placements || e.path().extension().empty())) dirs.push_back(e.path());
    std::sort(dirs.begin(), dirs.end());
    for (const fs::path& dir : dirs) {
      const auto capture = diagnosis::read_capture(dir.string());
      if (!capture) {
        std::cerr << capture.error().message << "\n";
        return 1;
      }
      const ViewConsistency s = diagnosis::view_consistency(*capture, o);
      std::string family = "?";
      double truth_mm = 0.0;
      if (const auto t = bench::read_json(fs::path(run) / "truth" / (dir.filename().string() + ".json"))) {
        family = t->value("family", "?");
        for (const auto& e : t->value("effects", nlohmann::json::array()))
          if (e.value("name", "") == "multipath") truth_mm = e.value("strength", 0.0);
      }
      double clean = std::nan(""), floor_mean = std::nan(""), floor_sd = std::nan("");
      if (floor_seeds > 0) {
        const auto f = floor_slopes(*capture, fs::path(run) / reports / (dir.filename().string() + ".json"),
                                    floor_seeds, noise_off, o);
        if (!f) {
          std::cerr << dir.string() << ": " << f.error().message << "\n";
        } else {
          const double n = static_cast<double>(f->noisy.size());
          double m = 0.0, q = 0.0;
          for (const ViewConsistency& x : f->noisy) m += x.gain / n;
          for (const ViewConsistency& x : f->noisy) q += (x.gain - m) * (x.gain - m) / std::max(1.0, n - 1.0);
          clean = f->clean.gain, floor_mean = m, floor_sd = std::sqrt(q);
        }
      }
      fmt::print("{:<6} {:<18} {:<13} {:>7.1f} {:>7.2f} {:>6.2f} {:>7.3f} {:>6.2f} {:>6} {:>7.2f} {:>7.2f} {:>6.2f}\n",
                 fs::path(run).filename().string(), dir.filename().string(), family, truth_mm, s.gain * 1e3,
                 s.standard_error * 1e3, s.offset * 1e3, s.rms * 1e3, s.pixels, clean * 1e3, floor_mean * 1e3,
                 floor_sd * 1e3);
      std::fflush(stdout);
    }
  }
  return 0;
}
