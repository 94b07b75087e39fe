#include "drapegen/diagnosis/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "drapegen/renderer/preview.hpp"
#include "drapegen/storage/atomic_file.hpp"
#include "drapegen/storage/png.hpp"
#include "drapegen/storage/json_text.hpp"

namespace drapegen::diagnosis {
namespace fs = std::filesystem;

sim::Status write_residual_png(const std::string& path, const std::vector<ResidualImage>& residuals, double range) {
  if (residuals.empty()) return sim::Error{path + ": nothing to draw"};
  // Every cell is the largest view's size; a smaller view sits in its cell's top left corner (views may differ).
  int width = 0, height = 0;
  for (const auto& r : residuals) {
    if (r.width <= 0 || r.height <= 0 || r.values.size() != static_cast<std::size_t>(r.width) * r.height)
      return sim::Error{path + ": bad image size"};
    width = std::max(width, r.width);
    height = std::max(height, r.height);
  }
  const int gap = 4;
  const int W = static_cast<int>(residuals.size()) * (width + gap) - gap, H = height;
  std::vector<unsigned char> rgb(static_cast<std::size_t>(W) * H * 3, 40);
  for (std::size_t k = 0; k < residuals.size(); ++k) {
    const ResidualImage& img = residuals[k];
    for (int y = 0; y < img.height; ++y) {
      for (int x = 0; x < img.width; ++x) {
        const float r = img.values[static_cast<std::size_t>(y) * img.width + x];
        unsigned char* px = &rgb[(static_cast<std::size_t>(y) * W + k * (width + gap) + x) * 3];
        if (!std::isfinite(r)) {
          px[0] = px[1] = px[2] = 0;
          continue;
        }
        const double t = std::clamp(r / range, -1.0, 1.0);
        const auto fade = static_cast<unsigned char>(std::lround(255.0 * (1.0 - std::abs(t))));
        if (t >= 0.0) {
          px[0] = 255, px[1] = fade, px[2] = fade;  // capture farther than the model: red
        } else {
          px[0] = fade, px[1] = fade, px[2] = 255;  // capture nearer: blue
        }
      }
    }
  }
  return storage::write_png_rgb(path, W, H, rgb);
}

namespace {

/// What placed the gap (place_gap), for the report's "Dominant region" line.
std::string leading_feature_text(const Localisation& L) {
  const std::string& led = L.dominant_feature;
  if (L.placed_by_views) {
    return fmt::format("the four views disagree as a sensor error makes them (the multipath test fired): where the "
                       "pixels' residuals stand furthest above their own floor ({})",
                       led.empty() ? "no shape feature above its floor" : "the shape features led by " + led);
  }
  if (led.empty()) return "nothing exceeds its floor";
  if (led == "camera") {
    return fmt::format(
        "the rigid surfaces put the camera {:.1f} mm from its calibration at the platform: a camera error",
        L.camera_moved * 1e3);
  }
  if (led == "stable") {
    const RegionShare* top = region_share(L, Region::kTop);
    const double top_mean = top ? top->mean : 0.0;
    switch (L.dominant) {
      case Region::kCylinder:
        return "led by the stable term, with the platform top within its floor: the bare cylinder";
      case Region::kTop:
        return fmt::format("the stable term above its floor with the platform top lifted by {:.1f} mm, below a camera "
                           "error's scale: the specimen's contact with the platform",
                           -top_mean * 1e3);
      default:
        return top_mean > 0.0 ? fmt::format("led by the stable term, the platform top seen {:.1f} mm farther than the "
                                            "fitted cloth: a camera error",
                                            top_mean * 1e3)
                              : "led by the stable term, the platform top lifted at a camera error's scale";
    }
  }
  if (L.moved_by_offset) {
    constexpr auto kOffCentre = static_cast<std::size_t>(FeatureGroup::kOffCentre);
    return fmt::format("led by {}, placed on the skirt; but the hem's order-1 harmonic differs from the fitted "
                       "drape's by {:.2f} mm (at least {:g} mm), as a specimen laid off centre makes it, so the hem",
                       led, L.group_difference.at(kOffCentre) * 1e3, kHemOffCentreMm);
  }
  if (L.moved_to_hem) {
    return fmt::format("led by {}, a change of the skirt; the folds' depth stands more than {} times further above "
                       "its floor than the skirt's mean height, so the folds deepen at the hem",
                       led, kFoldDepthAtHem);
  }
  for (FeatureGroup g : kFeatureGroups) {
    if (feature_group_name(g) == led && follows_skirt(g) && L.dominant == Region::kSkirt) {
      return fmt::format("led by {}, an outline group; the skirt's residual is denser than the hem's, so the outline "
                         "carries a change of the skirt",
                         led);
    }
  }
  return fmt::format("led by {}", led);
}

/// How many diagnoses of the same captures this result's runtime holds (itself and the ones it confirmed; with both
/// --confirm-resolution and --confirm-placement-rise, up to four).
int diagnoses_in(const DiagnosisResult& r) {
  int n = 1;
  if (r.mesh_confirmation && r.mesh_confirmation->other) n += diagnoses_in(*r.mesh_confirmation->other);
  if (r.placement_confirmation && r.placement_confirmation->other) n += diagnoses_in(*r.placement_confirmation->other);
  return n;
}

/// Which of two diagnoses of the same captures this is (--confirm-resolution, --confirm-placement-rise), and the
/// other's verdict (report.json holds the other whole).
std::string confirmations_markdown(const DiagnosisResult& r) {
  std::string md;
  if (const auto& m = r.mesh_confirmation; m && m->other) {
    md += m->gap_found ? fmt::format("This is the diagnosis on the {0}x{0} confirming mesh, which finds the gap above "
                                     "its floors too; on the first mesh ({1}x{1}) the verdict was {2} (report.json "
                                     "`mesh_confirmation`).\n\n",
                                     m->resolution, m->other->budgets.resolution, m->other->verdict)
                       : fmt::format("The {0}x{0} confirming mesh leaves the gap within its floors (its verdict {1}): "
                                     "this is the first mesh's diagnosis (report.json `mesh_confirmation`).\n\n",
                                     m->resolution, m->other->verdict);
  }
  if (const auto& p = r.placement_confirmation; p && p->other) {
    md += fmt::format("Without the placement drape test the verdict was {}, but the turned placement drapes {:.4f} "
                      "stiffer than the capture (drape coefficient; at least {:g}): this is the diagnosis with the "
                      "test at that floor (report.json `placement_confirmation`).\n\n",
                      p->other->verdict, p->rise, p->floor);
  }
  return md;
}

}  // namespace

std::string dominant_region_markdown(const Localisation& L) {
  return fmt::format("Dominant region: **{}** ({}).", region_name(L.dominant), leading_feature_text(L));
}

std::string runtime_markdown(const DiagnosisResult& r) {
  std::string md = fmt::format("Runtime {:.0f} s (fit {:.0f} s, floors {:.0f} s, attribution {:.0f} s); CPU {:.0f} s; "
                               "up to {} thread{}.\n",
                               r.seconds, r.seconds_fit, r.seconds_floors, r.seconds_attribution, r.cpu_seconds,
                               r.jobs, r.jobs == 1 ? "" : "s");
  if (const int n = diagnoses_in(r); n > 1) {
    md += fmt::format("Runtime and CPU are {} diagnoses' together (fit, floors and attribution: this one's).\n",
                      n == 2 ? "both" : fmt::format("all {}", n));
  }
  return md;
}

namespace {

/// The verdict line for `verdict` (the result's, or the refits' under `label` where the turn-over named yield) and
/// why a named effect was put ahead of another where that happened.
std::string refits_markdown(const DiagnosisResult& r, std::string_view verdict, std::string_view label = "Verdict") {
  std::string md;
  if (verdict == "none" && r.attribution.bar_within_floors) {
    md += fmt::format("**{}: within the floors once the bending is refitted** (the baseline fit had stopped short of "
                      "the fabric's bending; the refit of the bending alone is within sensor noise and multiple stable "
                      "drapes); no effect is named.\n\n",
                      label);
  } else if (verdict == "none" && r.attribution.common_within_floors) {
    std::string effects;
    for (Effect e : r.attribution.common_effects) effects += std::string(effects.empty() ? "" : ", ") += effect_name(e);
    md += fmt::format("**{}: within the floors once the bending is refitted** ({} unlike effects each brought the gap "
                      "within the floors: {}; what they share, the baseline's bending at x{:.2f}, does as well); no "
                      "effect is named.\n\n",
                      label, r.attribution.common_effects.size(), effects, r.attribution.common_bending->alpha_scale);
  } else if (verdict == "none") {
    md += fmt::format("**{}: the gap is within the floors** (sensor noise and multiple stable drapes); no effect is "
                      "named.\n\n",
                      label);
  } else if (verdict == "not attributed") {
    md += fmt::format("**{}: a gap above the floors; attribution was not run** (`--gap-only`).\n\n", label);
  } else if (verdict == "unexplained" && r.attribution.candidates.empty()) {
    md += fmt::format("**{}: a gap above the floors; no candidate effect was refitted.**\n\n", label);
  } else if (verdict == "unexplained") {
    // The ranking puts confirmed candidates first: the best is unconfirmed only if none is confirmed.
    const auto& best = r.attribution.candidates.front();
    md += fmt::format("**{}: a gap above the floors that no candidate effect both shrinks by {:.0f}% or more and holds "
                      "on the held-out data** (best: {}, shrinkage {:.0f}%, {}).\n\n",
                      label, 100 * r.attribution.significant_shrinkage, effect_name(best.effect), 100 * best.shrinkage,
                      best.confirmed() ? "confirmed" : "not confirmed");
  } else {
    const auto& c = r.attribution.candidates[0];
    // The shrinkage is the gate's, on drapes from fresh initial states; the held-out data only confirm it.
    const char* drapes = r.validated_second     ? "the capture's and the second capture's"
                         : r.validated_held_out ? "the capture's and the held-out capture's"
                                                : "the capture's";
    // One candidate (--candidates): nothing to be confident against. The refits' runner-up, the second candidate
    // (r.runner_up is the verdict's: the turn-over's alternation may have withdrawn this one).
    const auto& cs = r.attribution.candidates;
    const std::string against =
        cs.size() < 2 ? std::string("the only candidate refitted")
                      : fmt::format("confidence {:.2f} against the runner-up, {}", r.attribution.confidence,
                                    effect_name(cs[1].effect));
    md += fmt::format("**{}: {}** ({}); adding it shrinks the gap's excess above the floors by {:.0f}% ({} drapes "
                      "from fresh initial states) and the score on the held-out {} by {:.0f}%.\n\n",
                      label, verdict, against, 100.0 * c.shrinkage, drapes,
                      r.validated_held_out ? "capture" : "view", 100.0 * c.held_out_shrinkage);
    if (c.confirmation == Confirmation::kWithinFloors)
      md += fmt::format("It is confirmed by its drape on the held-out capture lying within the floors "
                        "(`--confirm-within-floors`); its score there is {:.0f}% above the reference's, more than the "
                        "{:g}% the score's confirmation allows.\n\n",
                        -100.0 * c.held_out_shrinkage, 100.0 * r.attribution.held_out_tolerance);
    if (r.attribution.near_tie_promoted && !r.attribution.curl_promoted && !r.attribution.sensor_promoted)
      md += fmt::format("It is named ahead of a candidate whose shrinkage is larger by less than {:.2f}, a tie within "
                        "the validation drapes' noise: the smaller refit objective names one.\n\n",
                        r.attribution.tie_margin);
    if (r.attribution.sensor_promoted)
      md += "The sensor error is named ahead of the candidate its shrinkage ranks first: on every placement the four "
            "views disagree as a multipath error makes them (view consistency, below), which no effect on the cloth "
            "does (`--multipath-first`).\n\n";
    else if (r.attribution.curl_promoted)
      md += "Curl is named ahead of the candidate its shrinkage ranks first: the capture's placements fold less "
            "alike than the fitted model's drapes do (fold repeatability, below), as rolled edges settle differently "
            "on every placement.\n\n";
  }
  return md;
}

}  // namespace

std::string verdict_markdown(const DiagnosisResult& r) {
  std::string md;
  // A signature of its own set the verdict (rules U, A, E, D and H): what it read (an open parenthesis at its end,
  // naming the option), the named effect's refit, then the refits' verdict (with the alternation's withdrawal where the
  // hem's centre named misalignment after it).
  const std::string& refits_verdict = r.refits_verdict();
  const auto withdrawal = [&r] {
    const auto& a = *r.alternation;
    return fmt::format("the turned second capture drapes {:.4f} against the mean of the capture and the third "
                       "placement, laid on the capture's face again (drape coefficient; under {:g}), as an elastic "
                       "specimen's placements differ by their noise and a plastic set stiffens the turned drape "
                       "(`--turn-over-alternation`)",
                       a.alternation, a.floor);
  };
  const auto signature = [&](std::string_view effect, const std::string& reading) {
    const CandidateResult* refit = r.named_refit();
    const std::string shrinks = refit ? fmt::format("the {} refit shrinks the excess by {:.0f}%", effect,
                                                    100.0 * refit->shrinkage)
                                      : fmt::format("no {} refit ran", effect);
    std::string refits = "The refits alone named no effect:";
    if (refits_verdict == "yield" && r.alternation) {
      refits = "The refits named yield, withdrawn: " + withdrawal() + ".";
    } else if (r.hem_tilt && refits_verdict != "none" && refits_verdict != "unexplained") {  // rule H
      refits = fmt::format("The refits named {}: a refit can stand in for an off-centre drape, which the hem's tilt on "
                           "every placement names over it (`--hem-tilt-misalignment`).",
                           refits_verdict);
    } else if (refits_verdict == "yield") {  // rule D2
      const std::string turn_over =
          r.budgets.turn_over_yield > 0.0
              ? fmt::format("which the turn-over does not name (no turned second capture drapes {:g} or more "
                            "stiffer than the capture; `--turn-over-yield`)",
                            r.budgets.turn_over_yield)
              : std::string("rule U off (`--turn-over-yield` 0)");
      refits = "The refits named yield, " + turn_over +
               ": a yield refit can stand in for an off-centre drape (`--off-centre-mm-over-yield`).";
    }
    return fmt::format("{}; {}). {}\n\n", reading, shrinks, refits) +
           refits_markdown(r, refits_verdict, "The refits' verdict");
  };
  if (const auto& h = r.hem_tilt) {
    const std::string reading = fmt::format(
        "**Verdict: misalignment, from the hem's tilt**: on each of the three placements the hem hangs lower on one "
        "side, its height's first harmonic at least {:.2f} mm (at least {:g} mm), as a specimen laid off the axis "
        "does however it is turned and a centred elastic specimen does not (`--hem-tilt-misalignment`",
        h->smallest_mm, h->floor_mm);
    md += signature("misalignment", reading);
  } else if (const auto& t = r.turn_over) {
    const std::string reading = fmt::format(
        "**Verdict: yield, from the turn-over**: the second capture, laid on the specimen's other face, drapes {:.4f} "
        "stiffer than the capture (drape coefficient; at least {:g}), as the plastic set of a drape makes a specimen "
        "drape stiffer turned over and an elastic specimen does not (`--turn-over-yield`",
        t->rise, t->floor);
    md += signature("yield", reading);
  } else if (const auto& o = r.off_centre) {
    // By the difference in mm (rules D and D2) or by the difference over its floor (rule E): the off-centre feature
    // group's RMS difference of the order-1 harmonics' amplitudes of the hem's radius and height, which grow with the
    // specimen's offset from the cylinder's axis (their phase, the offset's direction, is not compared).
    const std::string differs = o->difference() + (o->by_offset ? ", whatever its floor" : "");
    const std::string reading =
        fmt::format("**Verdict: misalignment, from the hem's centre**: the hem's order-1 harmonic (its radius and "
                    "height: how far its centre lies off) differs from the fitted drape's by {}, as a specimen laid "
                    "off centre hangs longer on one side and an elastic fabric's drape on a centred specimen does not "
                    "(`{}`",
                    differs, o->by_offset ? "--off-centre-mm" : "--off-centre-misalignment");
    md += signature("misalignment", reading);
  } else if (const auto& a = r.alternation; a && !a->withdrew()) {
    const std::string reading = fmt::format(
        "**Verdict: yield, from the turn-over's alternation**: the second capture, laid on the specimen's other face, "
        "drapes {:.4f} stiffer than the mean of the capture and the third placement, laid on the capture's face again "
        "(drape coefficient; at least {:g}), as the plastic set of a drape stiffens the turned drape and eases on the "
        "first face again while an elastic specimen's placements differ by their noise (`--turn-over-alternation`",
        a->alternation, a->floor);
    md += signature("yield", reading);
  } else if (a) {
    md += "**Verdict: unexplained, a yield without its turn-over**: the refits named yield, but " + withdrawal() +
          "; the yield refit may stand for a softer elastic fabric.\n\n" +
          refits_markdown(r, refits_verdict, "The refits' verdict");
  } else {
    md += refits_markdown(r, r.verdict);
  }
  if (r.verdict == "none") {
    // What the verdict does not say (docs/DIAGNOSIS.md, "What keeps top-1 down").
    md += "A verdict within the floors rules out no effect whose drape an elastic fabric of another bending can "
          "match (a fabric yielding in one drape drapes like a softer one); many of the benchmark's effect captures "
          "end here, yield's most often (docs/DIAGNOSIS.md). The bending that matched the capture (the baseline "
          "fit's, or the refit named in the verdict) then carries the effect; a measured bending in the capture "
          "limits how far that bending can stray from the specimen's (docs/CAPTURE.md).\n\n";
  }
  return md;
}

sim::Status write_report(const std::string& directory, const DiagnosisResult& r, const Capture& capture,
                         ForwardModel& model) {
  const fs::path dir(directory);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return sim::Error{fmt::format("{}: cannot create directory: {}", directory, ec.message()), /*io=*/true};
  // A directory reused: an earlier report's files go first (a residual_after.png of another verdict beside this one,
  // or a mix if a write fails below); report.json is written last, so that it stands only beside a complete report.
  for (const char* name : {"report.json", "report.md", "residual.png", "residual_after.png", "views.png"}) {
    fs::remove(dir / name, ec);
    if (ec) return sim::Error{fmt::format("{}: cannot remove the old {}: {}", directory, name, ec.message()), true};
  }
  const double range = model.settings().weights.truncation;
  auto residuals = [&capture](const ScoredDrape& d) {  // each view at its own size
    std::vector<ResidualImage> out;
    for (std::size_t k = 0; k < d.views.size() && k < capture.views.size(); ++k) {
      out.push_back({capture.views[k].depth.width, capture.views[k].depth.height, d.views[k].residual});
    }
    return out;
  };
  if (sim::Status s = write_residual_png((dir / "residual.png").string(), residuals(r.gap_drape()), range); !s)
    return s;
  const CandidateResult* named = r.named_refit();
  const bool after = named != nullptr && !named->validated.views.empty();
  if (after) {
    if (sim::Status s = write_residual_png((dir / "residual_after.png").string(), residuals(named->validated), range);
        !s) {
      return s;
    }
  }
  auto fitted = model.render(r.gap_drape().mesh, r.gap_drape().angle, {});
  if (!fitted) return fitted.error();
  std::vector<std::vector<renderer::DepthImage>> rows(2);
  for (const auto& v : capture.views) rows[0].push_back(v.depth);
  rows[1] = *fitted;
  if (sim::Status s = renderer::write_preview_png((dir / "views.png").string(), rows); !s) return s;

  std::string md;
  md += fmt::format("# Sim-to-real gap diagnosis of `{}`\n\n", capture.directory);
  if (r.placements.size() > 1) {
    // Which face each placement lay on: a rest shape (curl, a yield's creases) bends the other way face down.
    md += "| placement | directory | face |\n|---|---|---|\n";
    for (const auto& p : r.placements) {
      md += fmt::format("| {} | `{}` | {} |\n", p.role, p.directory, p.face_down ? "down" : "up");
    }
    md += "\n";
  }
  md += verdict_markdown(r);
  md += confirmations_markdown(r);
  md += "## Gap and floors (score in mm: stable-region RMS + 4 mm x shape-feature distance)\n\n";
  md += "| | all views | held-out view |\n|---|---|---|\n";
  md += fmt::format("| gap (baseline fit) | {:.2f} | {:.2f} |\n", r.gap_all * 1e3, r.gap_held_out * 1e3);
  md += fmt::format("| floor (x{:.2f} margin; for reference: the verdict's tests are below) | {:.2f} | {:.2f} |\n\n",
                    r.floors.margin, r.floors.all * 1e3, r.floors.held_out * 1e3);
  const GapTerms gap = r.gap();
  md += fmt::format(
      "Tests (all views{}): stable-region term {:.2f} mm against its floor {:.2f} mm; shape distance {:.2f} "
      "against its floor {:.2f}.\n\n",
      r.validated_second     ? ", mean of the capture and the second capture"
      : r.validated_held_out ? ", mean of the capture and the held-out capture"
                             : "",
      gap.stable * 1e3, r.floors.stable * 1e3, gap.shape, r.floors.shape);
  if (r.floors.placement_shape > 0.0) {
    md += fmt::format("Placement test: the larger placement's shape distance {:.2f} against its floor {:.2f}.\n\n",
                      gap.shape_max, r.floors.placement_shape);
  }
  if (r.floors.placement_dc > 0.0) {
    md += fmt::format("Placement drape test: the placements' drape-coefficient difference less the model's {:.4f} "
                      "against its floor {:.4f}.\n\n",
                      gap.placement_dc, r.floors.placement_dc);
  }
  if (r.rigid_pose) {
    const RigidPose& p = *r.rigid_pose;
    md += fmt::format(
        "Camera from the rigid surfaces (the cloth on the platform top, the bare side below the specimen's "
        "reach; {} and {} pixels): rotation ({:.1f}, {:.1f}, {:.1f}) mrad, translation ({:.1f}, {:.1f}, "
        "{:.1f}) mm in the camera frame; the pixels' RMS distance to the surfaces {:.2f} mm at the "
        "recorded camera, {:.2f} mm at this one. The sensor candidate starts from it.\n\n",
        p.top_pixels, p.side_pixels, p.pose.rotation.x() * 1e3, p.pose.rotation.y() * 1e3, p.pose.rotation.z() * 1e3,
        p.pose.translation.x() * 1e3, p.pose.translation.y() * 1e3, p.pose.translation.z() * 1e3, p.rms_recorded * 1e3,
        p.rms_estimated * 1e3);
    if (p.top_lift > 0.0) {
      md += fmt::format("The cloth on the platform top lies {:.1f} mm above its contact offset and the bare side shows "
                        "the camera where its calibration says: read as the specimen lifting off the top (one that "
                        "slid on it), not as the camera.\n\n",
                        p.top_lift * 1e3);
    }
    if (r.attribution.sensor_held)
      md += fmt::format(
          "That camera is within {:.0f} mm of its calibration at the platform: the sensor candidate keeps "
          "it, with no depth bias or slope (either would move the rigid surfaces), and refits only the "
          "multipath gain, which they cannot see.\n\n",
          kCameraMovedAtPlatform * 1e3);
  } else {
    md += fmt::format(
        "Camera from the rigid surfaces: not estimated ({}); the sensor candidate starts from the recorded "
        "camera.\n\n",
        r.rigid_pose_error);
  }
  md += fmt::format(
      "Fitted baseline: alpha = {:.0f}, {:.0f}, {:.0f} g mm^2/s^2; beta = {:.0f}, {:.0f}, {:.0f} g mm^3/s^2 "
      "({} simplex evaluations from the {}{}{}).\n\n",
      r.fitted.alpha.warp, r.fitted.alpha.bias, r.fitted.alpha.weft, r.fitted.beta.warp, r.fitted.beta.bias,
      r.fitted.beta.weft, r.baseline_evaluations, r.initial_guess_from,
      r.search_within_factor > 1.0 ? fmt::format(", searched within x{:.3g} of it", r.search_within_factor)
                                   : std::string(),
      r.start_evaluations == 0
          ? std::string()
          : fmt::format(", {} starts{}", r.start_evaluations,
                        r.restarted ? "; the second simplex, from the best start, is the fit" : ""));
  md +=
      "## Where the gap sits\n\nShape features, capture against the fitted baseline, over the largest floor sample:\n\n"
      "| feature group | region | ratio to floor |\n|---|---|---|\n";
  for (std::size_t k = 0; k < r.localisation.group_ratio.size(); ++k) {
    const FeatureGroup g = kFeatureGroups[k];
    md += fmt::format("| {} | {}{} | {:.2f} |\n", feature_group_name(g), region_name(feature_region(g)),
                      follows_skirt(g) ? " (skirt where its residual is denser)" : "", r.localisation.group_ratio[k]);
  }
  md += fmt::format("| stable term (platform top, bare cylinder) | cylinder if the top is within its floor; global if "
                    "the top is seen below the cloth or lifted from {:g}; else top | {:.2f} |\n\n",
                    kLiftedTopSensorRatio, r.localisation.stable_ratio);
  // kGlobal: no region stands out (localise, localise_against_floors).
  auto or_none = [](Region region, const std::string& none) {
    return region == Region::kGlobal ? none : std::string(region_name(region));
  };
  md += fmt::format("Pixel residuals by region (most enriched: {}; most above its own floor: {}):\n\n",
                    or_none(r.localisation.pixel_region,
                            fmt::format("none to {:g} x its pixel share", kMinRegionEnrichment)),
                    or_none(r.localisation.floor_region, "none above its floor"));
  md += "| region | energy share | pixel share | enrichment | RMS (mm) | mean (mm; > 0: the capture farther) | RMS / "
        "floor's |\n|---|---|---|---|---|---|---|\n";
  for (const auto& s : r.localisation.regions) {
    md += fmt::format("| {} | {:.2f} | {:.2f} | {:.2f} | {:.1f} | {:+.1f} | {:.2f} |\n", region_name(s.region),
                      s.energy_share, s.pixel_share, s.enrichment, s.rms * 1e3, s.mean * 1e3, s.floor_ratio);
  }
  md += "\n" + dominant_region_markdown(r.localisation) + " Per-view share of the residual energy:";
  for (double s : r.localisation.view_share) md += fmt::format(" {:.2f}", s);
  md += fmt::format(".\nFolds: capture {}, model {}; drape coefficient: capture {:.3f}, model {:.3f}.\n",
                    r.localisation.capture_folds, r.localisation.model_folds,
                    r.localisation.capture_drape_coefficient, r.localisation.model_drape_coefficient);
  if (const FoldRepeatability& f = r.fold_repeatability; f.measured()) {
    md += "Fold repeatability (the folds' correlation at the best turn; 1: folds alike): between the capture's "
          "placements";
    for (double c : f.capture) md += fmt::format(" {:.2f}", c);
    md += fmt::format("; between the fitted model's drapes from {} sine initial states: lowest {:.2f}.\n",
                      f.model_drapes, *std::min_element(f.model.begin(), f.model.end()));
  }
  if (const MultipathTest& m = r.multipath; !m.placements.empty()) {
    md += "View consistency (the multipath gain the four views' disagreement implies, about half the true gain; "
          "placements in order):";
    for (const ViewConsistency& c : m.placements) md += fmt::format(" {:.1f} mm", c.gain * 1e3);
    md += fmt::format("; the smallest {:.1f} mm against a threshold of {:.1f} mm: the multipath test {}.\n",
                      m.smallest_gain() * 1e3, m.threshold * 1e3, m.detected() ? "fired" : "did not fire");
  }
  md += "Hem radius difference (capture - model), largest harmonics:";
  auto h = r.localisation.hem_difference;
  h.erase(h.begin());
  std::sort(h.begin(), h.end(), [](const Harmonic& a, const Harmonic& b) { return a.amplitude > b.amplitude; });
  for (std::size_t k = 0; k < std::min<std::size_t>(3, h.size()); ++k)
    md += fmt::format(" order {} {:.1f} mm;", h[k].order, h[k].amplitude * 1e3);
  md +=
      "\n\n![residual maps](residual.png)\n\nResidual capture - fitted baseline per view (red: the capture is farther "
      "from the camera, blue: nearer; saturated at +-" +
      fmt::format("{:.0f}", range * 1e3) +
      " mm; black: no return).\n\n"
      "![views](views.png)\n\nTop: the capture; bottom: the fitted baseline.\n\n";
  if (!r.attribution.candidates.empty()) {
    const bool held_out = r.validated_held_out.has_value();
    md += fmt::format(
        "## Candidate effects (refitted on the fit views{}, confirmed on the held-out {})\n\n"
        "| effect | all-view score (mm) | shrinkage of the excess above the floors{} | held-out {}'s score "
        "(mm) | its shrinkage | confirmed | parameters |\n",
        r.validated_second ? " of the capture and the second capture" : "", held_out ? "capture" : "view",
        r.validated_second     ? " (mean of the capture and the second capture)"
        : r.validated_held_out ? " (mean of the capture and the held-out capture)"
                               : "",
        held_out ? "capture" : "view");
    md += "|---|---|---|---|---|---|---|\n";
    for (const auto& c : r.attribution.candidates) {
      std::string params;
      for (std::size_t k = 0; k < c.names.size(); ++k) params += fmt::format("{}={:.3g} ", c.names[k], c.parameters[k]);
      // The scores the confirmation compared: the validated drape's, on the held-out capture or the held-out view.
      const double held = confirmation_score(c.validated, c.held_out_drape());
      const char* confirmed = c.confirmation == Confirmation::kScore          ? "yes"
                              : c.confirmation == Confirmation::kWithinFloors ? "within the floors"
                                                                              : "no";
      md += fmt::format("| {} | {:.2f} | {:.0f}% | {:.2f} | {:.0f}% | {} | {}alpha x{:.2f} |\n", effect_name(c.effect),
                        c.validated.all_score * 1e3, 100 * c.shrinkage, held * 1e3, 100 * c.held_out_shrinkage,
                        confirmed, params, c.alpha_scale);
    }
    md += fmt::format("\nConfirmed: the held-out {}'s score at most {:g}% above the reference's{}.\n",
                      held_out ? "capture" : "view", 100 * r.attribution.held_out_tolerance,
                      r.attribution.confirm_within_floors
                          ? ", or (\"within the floors\") its drape on the held-out capture within the floors"
                          : "");
    if (after) md += "\n![after](residual_after.png)\n\nResidual after adding the named effect.\n";
  }
  md += '\n';
  md += runtime_markdown(r);
  if (sim::Status s = storage::write_file_atomic((dir / "report.md").string(), md); !s) return s;
  return storage::write_file_atomic((dir / "report.json").string(), storage::json_text(to_json(r, capture)) + "\n");
}

}  // namespace drapegen::diagnosis
