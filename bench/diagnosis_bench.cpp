// The diagnosis benchmark (issue 6, acceptance 1-3): generates captures with the reality generator (>= N per effect
// family over fabrics from fabrics618.csv, plus no-effect controls), runs `drapegen diagnose` on each (J processes
// at a time), and scores the verdicts against the truth files: confusion matrix, top-1 accuracy, controls within
// the floors, median shrinkage, region match, runtime. The diagnosis never sees the truth: it runs on a copy of
// each capture directory without truth.json.
// With --visible-only N, each effect capture is first screened (visibility_screen.hpp) and drawn again until its
// effect is visible at all to the diagnosis's gap test and its specimen settled on every placement (a drape that did
// not converge, e.g. a specimen sliding off the cylinder on a slippery top, is not a drape to diagnose).
#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <nlohmann/json.hpp>

#include "drapegen/diagnosis/bending_json.hpp"
#include "drapegen/diagnosis/reality.hpp"
#include "drapegen/diagnosis/work_sharing.hpp"
#include "drapegen/renderer/random.hpp"
#include "drapegen/sampler/fabric_data.hpp"
#include "drapegen/sim/blas_kernels.hpp"
#include "drapegen/sim/median.hpp"
#include "visibility_screen.hpp"

namespace fs = std::filesystem;
using namespace drapegen;

namespace {

struct Fabric {
  diagnosis::BendingParameters bending;
  double density = 300.0;
};

struct Case {
  std::string name, family, effect;
  double strength = 0.0;
  std::uint64_t seed = 0;
  Fabric fabric;
};

/// Strengths per effect, drawn uniformly in [lo, hi] (--strength NAME=LO:HI overrides).
const std::map<std::string, std::pair<double, double>> kDefaultStrength = {
    {"yield", {10.0, 25.0}}, {"shear", {0.3, 1.0}},       {"curl", {100.0, 300.0}}, {"friction", {0.02, 0.1}},
    {"misalign", {15.0, 30.0}}, {"pose", {1.0, 2.0}},     {"bias", {5.0, 10.0}},  {"multipath", {15.0, 30.0}}};

/// Writes `text` to `path` through a temporary file (a reader never sees half of it); false with a message on failure.
bool write_file(const fs::path& path, const std::string& text) {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    f << text;
    if (!f.flush()) {
      std::cerr << "diagnosis_bench: cannot write " << tmp.string() << "\n";
      return false;
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) std::cerr << "diagnosis_bench: cannot write " << path.string() << ": " << ec.message() << "\n";
  return !ec;
}

/// Moves `from` to `to`, replacing it; if `from` is gone but `to` exists, an earlier run moved it already.
void move_into(const fs::path& from, const fs::path& to) {
  if (!fs::exists(from) && fs::exists(to)) return;
  fs::remove_all(to);
  fs::rename(from, to);
}

/// A case's diagnosis claimed by this process: an exclusive flock on RESULT.lock, held until destruction (the kernel
/// drops it when a process ends, so a stopped run leaves nothing stale). Several benchmark processes can then diagnose
/// one directory, each taking the cases no other holds (scripts/diagnosis_set.sh's lanes).
class CaseLock {
 public:
  explicit CaseLock(fs::path path) : path_(std::move(path)) {
    fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ >= 0 && ::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd_);
      fd_ = -1;
    }
  }
  CaseLock(const CaseLock&) = delete;
  CaseLock& operator=(const CaseLock&) = delete;
  ~CaseLock() {
    if (fd_ < 0) return;
    std::error_code ec;
    fs::remove(path_, ec);  // a process that opened it meanwhile finds the result on its second look
    ::close(fd_);
  }
  [[nodiscard]] bool held() const { return fd_ >= 0; }

 private:
  fs::path path_;
  int fd_ = -1;
};

}  // namespace

int main(int argc, char** argv) {
  drapegen::sim::relaunch_with_blas_kernels(argv);  // the kernels drapegen runs on (blas_kernels.hpp)
  CLI::App app{"drapegen diagnosis benchmark: reality captures, diagnoses, confusion matrix"};
  std::string out = "out/diagnosis_bench", fabrics_path = DRAPEGEN_FABRIC_DATA_DEFAULT, drapegen;
  int per_family = 5, controls = 5, jobs = 1, resolution = 60, diagnose_jobs = 1, placements = 1;
  bool turn_over = false;
  bool quick = false, generate_only = false, score_only = false, held_out_placement = false, second_placement = false;
  std::uint64_t seed = 1;
  std::vector<std::string> families{"yield", "shear", "curl", "friction", "misalignment", "sensor"};
  std::vector<std::string> sensor_kinds{"pose", "bias", "multipath"};
  app.add_option("--out", out,
                 "Benchmark directory (diagnoses already in it are kept: a rerun resumes; runs sharing it take the "
                 "cases no other has taken)")
      ->capture_default_str();
  app.add_option("--fabrics", fabrics_path, "fabrics618.csv")->capture_default_str();
  app.add_option("--drapegen", drapegen, "The drapegen program (default: beside this program)");
  app.add_option("--per-family", per_family, "Captures per effect family")->capture_default_str();
  app.add_option("--controls", controls, "No-effect captures (sensor noise only)")->capture_default_str();
  app.add_option("--families", families, "Effect families to include")->capture_default_str();
  app.add_option("--jobs", jobs, "Diagnoses run at once (processes)")->capture_default_str();
  app.add_option("--diagnose-jobs", diagnose_jobs,
                 "--jobs of each diagnosis (its threads: the fit's states, then the refits)")
      ->capture_default_str();
  std::string diagnose_args;
  app.add_option("--diagnose-args", diagnose_args, "More options for drapegen diagnose (e.g. \"--shape-floor 0\")");
  // 60x60 (5 mm spacing): real cloth is continuous, so the reality mesh must resolve what the coarse fitting mesh
  // cannot: a 30 mm curl band (6 spacings; at 30x30, 3) and a slide on the rim's 2 mm fillet, on which a 10 mm mesh
  // cogs (docs/DIAGNOSIS.md, "Detectability").
  app.add_option("--resolution", resolution, "Reality mesh resolution")->capture_default_str();
  app.add_option("--seed", seed, "Seed of fabrics, strengths and captures")->capture_default_str();
  app.add_option("--placements", placements,
                 "Captures per specimen: placement 0 in captures/NAME, placement K > 0 (drapegen reality --placement) "
                 "in captures/NAME.pK, truth in truth/NAME.pK.json; the diagnoses use placement 0 only (and placement "
                 "1 with --held-out-placement)")
      ->capture_default_str()
      ->check(CLI::Range(1, 10));
  std::vector<std::string> strength_overrides;
  app.add_option("--sensor-kinds", sensor_kinds,
                 "The sensor family's errors, drawn in turn over its captures (pose, bias, multipath; give the same "
                 "list to --score-only)")
      ->capture_default_str();
  app.add_option("--strength", strength_overrides, "NAME=LO:HI: draw that effect's strength in [LO, HI]");
  int screen_draws = 0;
  app.add_option("--visible-only", screen_draws,
                 "Screen every effect capture (visibility_screen.hpp: gated as `drapegen diagnose --fine` gates its "
                 "gap, with placement 1 as the held-out capture if generated, the true fabric without the effect must "
                 "leave an excess above the floors, and the drape of every placement must have converged: a specimen "
                 "that slides off the top has no drape) and draw another fabric, strength and seed until it passes, at "
                 "most N draws (the last is kept either way); the draws are logged in OUT/screen/NAME.json; controls "
                 "are screened once and kept (0: no screen)")
      ->capture_default_str()
      ->check(CLI::Range(0, 100));
  double measured_bending_error = 0.0;
  app.add_option("--measured-bending-error", measured_bending_error,
                 "SIGMA in 0.001 .. 1: every capture carries a measured bending, as drapegen reality "
                 "--measured-bending-error SIGMA writes it (the true fabric times e^(SIGMA g) per parameter, stated "
                 "within e^(2 SIGMA)); "
                 "captures generated without one get it from their truth file (the same draw); diagnose with "
                 "--diagnose-args --ignore-measured-bending for the protocol without it (default 0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0))
      ->check([](const std::string& text) {
        const double sigma = std::stod(text);  // a number: the range check before this one has read it
        return sigma == 0.0 || sigma >= diagnosis::kMinMeasuredBendingError ? std::string()
                                                                            : std::string("0 (none) or 0.001 .. 1");
      });
  app.add_flag("--quick", quick, "Diagnose with --quick");
  app.add_flag("--generate-only", generate_only, "Only generate the captures");
  app.add_flag("--score-only", score_only, "Only score existing diagnoses");
  app.add_flag("--held-out-placement", held_out_placement,
               "Diagnose with placement 1 (captures/NAME.p1, made with --placements 2) as the held-out capture");
  app.add_flag("--second-placement", second_placement,
               "Diagnose with placement 1 as the second capture (in the candidate refits and the gate) and placement 2 "
               "(captures/NAME.p2, made with --placements 3) as the held-out capture")
      ->excludes("--held-out-placement");
  app.add_flag("--turn-over", turn_over,
               "Generate with drapegen reality --turn-over: the specimen is turned over each time it is lifted, so "
               "placement 1 lies face down (a rest shape, such as a yield's creases, bends the other way there)");
  CLI11_PARSE(app, argc, argv);
  if (drapegen.empty()) drapegen = (fs::path(argv[0]).parent_path() / "drapegen").string();
  if (sensor_kinds.empty()) {
    std::cerr << "diagnosis_bench: error: --sensor-kinds: give at least one of pose, bias, multipath\n";
    return 1;
  }
  for (const auto& k : sensor_kinds) {
    if (k != "pose" && k != "bias" && k != "multipath") {
      std::cerr << "diagnosis_bench: error: --sensor-kinds: unknown sensor error '" << k
                << "' (pose, bias, multipath)\n";
      return 1;
    }
  }
  auto strength_range = kDefaultStrength;
  for (const auto& o : strength_overrides) {
    const auto eq = o.find('='), colon = o.find(':');
    const std::string name = o.substr(0, eq);
    if (eq == std::string::npos || colon == std::string::npos || colon < eq || !strength_range.contains(name)) {
      std::cerr << "diagnosis_bench: error: --strength " << o << ": expected NAME=LO:HI with a known effect\n";
      return 1;
    }
    try {
      strength_range[name] = {std::stod(o.substr(eq + 1, colon - eq - 1)), std::stod(o.substr(colon + 1))};
    } catch (const std::exception&) {
      std::cerr << "diagnosis_bench: error: --strength " << o << ": LO and HI must be numbers\n";
      return 1;
    }
  }

  std::vector<Fabric> fabrics;
  if (auto measured = sampler::read_fabric_csv(fabrics_path); !measured) {
    std::cerr << "diagnosis_bench: error: " << measured.error().message << "\n";
    return 1;
  } else {
    for (const auto& f : *measured) fabrics.push_back({{f.moduli.alpha, f.moduli.beta}, f.density_g_per_m2});
  }
  if (fabrics.empty()) {
    std::cerr << "diagnosis_bench: error: no fabrics in " << fabrics_path << "\n";
    return 1;
  }
  // A fabric of fabrics618 and an effect's strength, drawn from `r` (for the cases as drawn and for the screen's
  // draws).
  const auto draw_fabric = [&](renderer::Rng& r) {
    return fabrics[static_cast<std::size_t>(r.uniform() * fabrics.size()) % fabrics.size()];
  };
  const auto draw_strength = [&](const std::string& effect, renderer::Rng& r) {
    const auto [lo, hi] = strength_range.at(effect);
    return lo + (hi - lo) * r.uniform();
  };
  renderer::Rng rng(seed);
  std::vector<Case> cases;
  int sensor_kind = 0;
  auto add = [&](const std::string& family, int index) {
    Case c;
    c.family = family;
    c.seed = seed * 1000 + cases.size();
    c.fabric = draw_fabric(rng);
    if (family == "none") {
      c.effect = "";
    } else if (family == "sensor") {
      c.effect = sensor_kinds[static_cast<std::size_t>(sensor_kind++) % sensor_kinds.size()];
    } else if (family == "misalignment") {
      c.effect = "misalign";
    } else {
      c.effect = family;
    }
    if (!c.effect.empty()) c.strength = draw_strength(c.effect, rng);
    c.name = fmt::format("{}_{:02d}", family, index);
    cases.push_back(c);
  };
  for (int k = 0; k < controls; ++k) add("none", k);
  for (const auto& f : families)
    for (int k = 0; k < per_family; ++k) add(f, k);

  fs::create_directories(out);
  // 1. Generate (truth in OUT/truth/NAME.json; the capture directories hold no truth).
  const auto generate = [&](const Case& c, const fs::path& root) -> bool {
    for (int p = 0; p < placements; ++p) {
      const std::string name = p == 0 ? c.name : fmt::format("{}.p{}", c.name, p);
      const fs::path dir = root / "captures" / name;
      if (fs::exists(dir / "capture.json")) continue;
      diagnosis::RealitySpec spec;
      spec.bending = c.fabric.bending;
      spec.density = c.fabric.density;
      spec.resolution = resolution;
      spec.seed = c.seed;
      spec.placement = p;
      spec.turn_over = turn_over;
      spec.measured_bending_error = measured_bending_error;
      if (!c.effect.empty()) spec.effects.push_back({c.effect, c.strength});
      auto r = diagnosis::generate_reality(spec, dir.string());
      if (!r) {
        std::cerr << "diagnosis_bench: " << name << ": " << r.error().message << "\n";
        return false;
      }
      fs::create_directories(root / "truth");
      fs::rename(r->truth_path, root / "truth" / (name + ".json"));
      std::cout << fmt::format("generated {} ({} {:.3g}) in {:.1f} s\n", name, c.effect, c.strength, r->seconds);
    }
    return true;
  };
  // Another draw of an effect case: fabric, strength and seed from a stream of its own (draw 0 is the case as drawn).
  const auto redraw = [&](const Case& c, int draw) {
    Case d = c;
    if (draw == 0) return d;
    renderer::Rng r(c.seed * 1000003ULL + static_cast<std::uint64_t>(draw));
    d.seed = c.seed + 100000ULL * static_cast<std::uint64_t>(draw);
    d.fabric = draw_fabric(r);
    d.strength = draw_strength(c.effect, r);
    return d;
  };
  // Whether the drape of every placement of a case generated under `root` converged (its truth files: placement 0
  // and every later one there is).
  const auto settled = [](const Case& c, const fs::path& root) {
    for (int p = 0; p < diagnosis::kMaxPlacement; ++p) {
      const fs::path path = root / "truth" / (p == 0 ? c.name + ".json" : fmt::format("{}.p{}.json", c.name, p));
      if (p > 0 && !fs::exists(path)) break;
      const auto truth = nlohmann::json::parse(std::ifstream(path), nullptr, false);
      if (truth.is_discarded() || !truth.value("converged", false)) return false;
    }
    return true;
  };
  // The screen of one draw generated under `root`: its record, or nothing on an error.
  const auto screen = [&](const Case& d, const fs::path& root, int k) -> std::optional<nlohmann::json> {
    const fs::path first = root / "captures" / d.name;
    const std::string second = placements > 1 ? (root / "captures" / (d.name + ".p1")).string() : std::string();
    auto v = bench::effect_visibility(first.string(), second, d.fabric.bending);
    if (!v) {
      std::cerr << "diagnosis_bench: screen " << d.name << ": " << v.error().message << "\n";
      return std::nullopt;
    }
    const bool settles = settled(d, root);
    std::cout << fmt::format("screen {} draw {}: {} {:.3g}, {:.0f} g/m^2: true fabric's shape {:.2f} / {:.2f}, stable "
                             "{:.1f} / {:.1f} mm: {}{}\n",
                             d.name, k, d.effect.empty() ? "none" : d.effect, d.strength, d.fabric.density, v->shape,
                             v->shape_floor, v->stable_mm, v->stable_floor_mm,
                             v->visible() ? "visible" : "within the floors", settles ? "" : "; did not settle")
              << std::flush;
    return nlohmann::json{
        {"draw", k}, {"seed", d.seed}, {"density", d.fabric.density}, {"strength", d.strength},
        {"alpha", {d.fabric.bending.alpha.warp, d.fabric.bending.alpha.bias, d.fabric.bending.alpha.weft}},
        {"excess", v->excess}, {"stable_mm", v->stable_mm}, {"stable_floor_mm", v->stable_floor_mm},
        {"shape", v->shape}, {"shape_floor", v->shape_floor}, {"visible", v->visible()}, {"settled", settles}};
  };
  // The screen: draws until the true fabric without the effect leaves an excess above the floors and the specimen
  // settled on every placement. A control is screened once and kept (the share of controls it passes is the screen's
  // false-positive rate).
  const auto generate_visible = [&](const Case& c) -> bool {
    nlohmann::json draws = nlohmann::json::array();
    if (c.effect.empty()) {
      if (!generate(c, out)) return false;
      auto record = screen(c, out, 0);
      if (!record) return false;
      draws.push_back(*record);
    }
    for (int k = 0; k < screen_draws && !c.effect.empty(); ++k) {
      const Case d = redraw(c, k);
      const fs::path root = fs::path(out) / "screen" / fmt::format("{}.d{}", c.name, k);
      if (!generate(d, root)) return false;
      auto record = screen(d, root, k);
      if (!record) return false;
      draws.push_back(*record);
      if (((*record)["visible"].get<bool>() && (*record)["settled"].get<bool>()) || k + 1 == screen_draws) {
        // The log first, then the kept draw's files, placement 0's capture last: its presence marks the case as
        // generated. A run stopped in between screens the case again on resume (the same draws) and completes the
        // move: a file already moved stays.
        if (!write_file(fs::path(out) / "screen" / (c.name + ".json"), draws.dump(2) + "\n")) return false;
        try {
          for (int p = placements - 1; p >= 0; --p) {
            const std::string name = p == 0 ? c.name : fmt::format("{}.p{}", c.name, p);
            move_into(root / "truth" / (name + ".json"), fs::path(out) / "truth" / (name + ".json"));
            move_into(root / "captures" / name, fs::path(out) / "captures" / name);
          }
        } catch (const fs::filesystem_error& e) {
          std::cerr << "diagnosis_bench: screen " << c.name << ": " << e.what() << "\n";
          return false;
        }
        return true;
      }
    }
    return write_file(fs::path(out) / "screen" / (c.name + ".json"), draws.dump(2) + "\n");
  };
  if (!score_only) {
    fs::create_directories(fs::path(out) / "captures");
    fs::create_directories(fs::path(out) / "truth");
    if (screen_draws > 0) fs::create_directories(fs::path(out) / "screen");
    for (const auto& c : cases) {
      // A case generated already keeps its draw (a rerun resumes), a control its screen record.
      const bool done = c.effect.empty() ? fs::exists(fs::path(out) / "screen" / (c.name + ".json"))
                                         : fs::exists(fs::path(out) / "captures" / c.name / "capture.json");
      const bool ok = screen_draws > 0 && !done ? generate_visible(c) : generate(c, out);
      if (!ok) return 1;
    }
  }
  if (!score_only && measured_bending_error > 0.0) {
    // Captures generated without a measured bending get the one drapegen reality would have written: the kept draw's
    // fabric and seed are in its truth file.
    for (const auto& c : cases) {
      for (int p = 0; p < placements; ++p) {
        const std::string name = p == 0 ? c.name : fmt::format("{}.p{}", c.name, p);
        const fs::path dir = fs::path(out) / "captures" / name;
        auto capture = diagnosis::read_capture(dir.string());
        if (!capture) {
          std::cerr << "diagnosis_bench: " << capture.error().message << "\n";
          return 1;
        }
        if (const auto& m = capture->specimen.measured_bending) {
          if (std::abs(m->within_factor - std::exp(2.0 * measured_bending_error)) > 1e-12) {
            std::cerr << fmt::format("diagnosis_bench: {}: carries a measured bending within {:.4g}, not the e^(2 x "
                                     "{}) of --measured-bending-error\n",
                                     name, m->within_factor, measured_bending_error);
            return 1;
          }
          continue;
        }
        const fs::path truth_path = fs::path(out) / "truth" / (name + ".json");
        const auto truth = nlohmann::json::parse(std::ifstream(truth_path), nullptr, false);
        auto bending = diagnosis::bending_from_json(truth, truth_path.string());
        if (!bending || !truth.contains("seed") || !truth["seed"].is_number_unsigned()) {
          std::cerr << "diagnosis_bench: " << truth_path.string() << ": no truth file with alpha, beta and seed"
                    << (bending ? "" : " (" + bending.error().message + ")") << "\n";
          return 1;
        }
        capture->specimen.measured_bending =
            diagnosis::measure_bending(*bending, measured_bending_error, truth["seed"].get<std::uint64_t>());
        if (sim::Status st = diagnosis::write_capture_json(dir.string(), *capture); !st) {
          std::cerr << "diagnosis_bench: " << st.error().message << "\n";
          return 1;
        }
        std::cout << fmt::format("{}: measured bending added (sigma {})\n", name, measured_bending_error);
      }
    }
  }
  if (generate_only) return 0;
  const int placements_used = second_placement ? 3 : held_out_placement ? 2 : 1;
  if (!score_only) {
    for (const auto& c : cases) {
      for (int p = 1; p < placements_used; ++p) {
        const fs::path other = fs::path(out) / "captures" / fmt::format("{}.p{}", c.name, p);
        if (!fs::is_directory(other)) {
          std::cerr << fmt::format("diagnosis_bench: {}: {} is missing (generate with --placements {})\n",
                                   second_placement ? "--second-placement" : "--held-out-placement", other.string(),
                                   placements_used);
          return 2;
        }
      }
    }
  }

  // 2. Diagnose, J at a time.
  if (!score_only) {
    diagnosis::WorkQueue queue(cases.size());
    std::mutex io;
    diagnosis::run_on_threads(jobs, [&](int) {
      while (const auto k = queue.take()) {
        const auto& c = cases[*k];
        const fs::path dir = fs::path(out) / "captures" / c.name;
        const fs::path result = fs::path(out) / "diagnoses" / (c.name + ".json");
        const auto done = [&] { return fs::exists(result) && fs::file_size(result) > 0; };
        if (done()) continue;
        fs::create_directories(result.parent_path());
        const CaseLock claim(result.string() + ".lock");
        if (!claim.held() || done()) continue;  // another process diagnoses it, or has
        const std::string second =
            second_placement     ? fmt::format(" --second-capture '{0}.p1' --held-out-capture '{0}.p2'", dir.string())
            : held_out_placement ? fmt::format(" --held-out-capture '{}.p1'", dir.string())
                                 : std::string();
        const std::string cmd =
            fmt::format("'{}' diagnose --capture '{}'{} --json{} --jobs {} {} > '{}.tmp' 2> '{}.err'", drapegen,
                        dir.string(), second, quick ? " --quick" : "", diagnose_jobs, diagnose_args,
                        result.string(), result.string());
        const auto t0 = std::chrono::steady_clock::now();
        const int rc = std::system(cmd.c_str());
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (rc == 0) fs::rename(result.string() + ".tmp", result);
        std::lock_guard lock(io);
        std::cout << fmt::format("diagnosed {} in {:.0f} s (exit {})\n", c.name, s, rc) << std::flush;
      }
    });
  }

  // 3. Score.
  const std::vector<std::string> columns{"none",     "unexplained",  "not attributed", "yield", "shear",
                                         "curl",     "friction",     "misalignment",   "sensor"};
  std::vector<std::string> rows{"none"};
  for (const auto& f : families) rows.push_back(f);
  std::map<std::string, std::map<std::string, int>> confusion;
  int effect_total = 0, effect_correct = 0, control_total = 0, control_within = 0, region_total = 0, region_match = 0;
  // The region furthest above its own floor (localisation.floor_region, since session 22; absent in older reports).
  int floor_region_total = 0, floor_region_match = 0;
  std::map<std::string, std::pair<int, int>> region_by_family;  // localised region: matched, scored
  // The screen (--visible-only): per family, draws made and draws visible; the verdicts on visible captures.
  std::map<std::string, std::pair<int, int>> screen_draws_by_family;
  int visible_total = 0, visible_correct = 0;
  // Top-1 by how far the kept draw's true fabric without the effect stood above the floors at the screen (its
  // excess_above_floors: relative, summed over the stable and shape terms): named right, scored; bins [0, 0.1),
  // [0.1, 0.3), [0.3, inf).
  const std::array<double, 2> excess_edges{0.1, 0.3};
  std::array<std::pair<int, int>, 3> by_excess{};
  // Detection and attribution apart: effect captures reported within the floors at the gate, within them once the
  // bending alone is refitted (the refits' verdict "none" either way, whatever the turn-over named), and the rest
  // (detected) with their correct verdicts.
  int within_at_gate = 0, within_after_bending = 0, detected_correct = 0;
  // The region over the detected captures alone: within the floors a report localises noise, not an effect.
  int detected_region_match = 0;
  std::vector<double> shrinkages, named_shrinkages, seconds, cpu_seconds;
  std::map<std::string, int> starts;
  nlohmann::json per_case = nlohmann::json::array();
  for (const auto& c : cases) {
    const fs::path result = fs::path(out) / "diagnoses" / (c.name + ".json");
    const fs::path truth_path = fs::path(out) / "truth" / (c.name + ".json");
    if (!fs::exists(result) || !fs::exists(truth_path)) continue;
    nlohmann::json d, t;
    try {
      d = nlohmann::json::parse(std::ifstream(result));
      t = nlohmann::json::parse(std::ifstream(truth_path));
    } catch (const std::exception&) {
      continue;
    }
    if (!d.is_object() || !d.value("localisation", nlohmann::json()).is_object() ||
        !d.value("runtime", nlohmann::json()).is_object() || !t.is_object()) {
      std::cerr << fmt::format("diagnosis_bench: {}: not a drapegen diagnose report (no localisation or runtime): "
                               "not scored\n",
                               result.string());
      continue;
    }
    const std::string verdict = d.value("verdict", "?");
    // The refits' own verdict where a signature set the verdict (drapegen diagnose --turn-over-yield: "turn_over";
    // --turn-over-alternation: "alternation"; --off-centre-misalignment, --off-centre-mm: "off_centre";
    // --hem-tilt-misalignment: "hem_tilt", in the order diagnose() lays them): the first one's refits_verdict; whether
    // the gap was found above the floors is theirs. The label is the last one's, which set the verdict.
    std::string signature, refits_verdict = verdict;
    for (const auto& [key, label] : {std::pair{"turn_over", "turn-over"}, std::pair{"alternation", "alternation"},
                                     std::pair{"off_centre", "hem centre"}, std::pair{"hem_tilt", "hem tilt"}}) {
      if (!d.contains(key) || !d[key].is_object()) continue;
      if (signature.empty()) refits_verdict = d[key].value("refits_verdict", "?");
      signature = label;
    }
    const std::string family = t.value("family", "none");
    nlohmann::json screened = nullptr;  // the kept draw passed the screen (visible, settled), if it was screened
    if (const fs::path log = fs::path(out) / "screen" / (c.name + ".json"); fs::exists(log)) {
      try {
        const auto draws = nlohmann::json::parse(std::ifstream(log));
        for (const auto& draw : draws) {
          screen_draws_by_family[family].first++;
          screen_draws_by_family[family].second += draw.value("visible", false);
        }
        // The kept draw's truth files tell whether it settled (logs written before the check have no "settled").
        if (!draws.empty()) screened = draws.back().value("visible", false) && settled(c, out);
        if (!draws.empty() && family != "none" && draws.back().contains("excess")) {
          const double excess = draws.back()["excess"].get<double>();
          const auto bin = std::upper_bound(excess_edges.begin(), excess_edges.end(), excess) - excess_edges.begin();
          by_excess[bin].first += verdict == family;
          by_excess[bin].second++;
        }
      } catch (const std::exception&) {
      }
    }
    if (family != "none" && screened.is_boolean() && screened.get<bool>()) {
      ++visible_total;
      visible_correct += verdict == family;
    }
    const std::string region = d["localisation"].value("region", "?");
    // Where the fit started (a measured bending or not): the protocol a diagnosis ran under, counted per start.
    const std::string started =
        d.contains("baseline") ? d["baseline"].value("initial_guess_from", "drape coefficient") : "?";
    starts[started]++;
    confusion[family][verdict]++;
    seconds.push_back(d["runtime"].value("seconds", 0.0));
    if (d["runtime"].contains("cpu_seconds")) cpu_seconds.push_back(d["runtime"]["cpu_seconds"].get<double>());
    double shrink = std::numeric_limits<double>::quiet_NaN();
    bool region_ok = false;
    if (family == "none") {
      ++control_total;
      control_within += verdict == "none";
    } else {
      ++effect_total;
      effect_correct += verdict == family;
      if (refits_verdict == "none") {
        (d.value("within_floors", false) ? within_at_gate : within_after_bending)++;
      } else {
        detected_correct += verdict == family;
      }
      // Shrinkage once the named effect is added: its refit's (0 when nothing is named).
      shrink = verdict != "none" && verdict != "unexplained" ? d.value("shrinkage", 0.0) : 0.0;
      shrinkages.push_back(shrink);
      if (verdict == family) named_shrinkages.push_back(shrink);
      auto is_true_region = [&t](const std::string& name) {
        for (const auto& r : t["regions"])
          if (r.get<std::string>() == name) return true;
        return false;
      };
      ++region_total;
      region_ok = is_true_region(region);
      region_match += region_ok;
      if (refits_verdict != "none") detected_region_match += region_ok;
      region_by_family[family].first += region_ok;
      region_by_family[family].second++;
      if (d["localisation"].contains("floor_region")) {
        ++floor_region_total;
        floor_region_match += is_true_region(d["localisation"]["floor_region"].get<std::string>());
      }
    }
    // The effect and its strength as generated (the truth file), not as this run would draw them: a run may score
    // captures an earlier run generated with other --controls or --seed, whose draws differ.
    std::string effect;
    double strength = 0.0;
    if (t.contains("effects") && t["effects"].is_array() && !t["effects"].empty()) {
      effect = t["effects"][0].value("name", "");
      strength = t["effects"][0].value("strength", 0.0);
    }
    per_case.push_back({{"case", c.name}, {"family", family}, {"effect", effect}, {"strength", strength},
                        {"verdict", verdict}, {"signature", signature}, {"runner_up", d.value("runner_up", "")},
                        {"confidence", d.value("confidence", nlohmann::json())}, {"region", region},
                        {"region_ok", region_ok},
                        {"gap_mm", d["gap_mm"]["all_views"]}, {"floor_mm", d["floors"]["all_views_mm"]},
                        {"tests", d.value("gap_tests", nlohmann::json::object())},
                        {"shrinkage", family == "none" ? nlohmann::json(nullptr) : nlohmann::json(shrink)},
                        {"visible", screened}, {"fit_started_from", started},
                        {"seconds", d["runtime"]["seconds"]}});
  }
  using sim::median;
  const std::string options = fmt::format("{}{}{}", quick ? "--quick" : "", quick && !diagnose_args.empty() ? " " : "",
                                          diagnose_args);
  std::string md = fmt::format("Cases scored: {} effect captures, {} controls (diagnose {}{}).\n\n", effect_total,
                               control_total, options.empty() ? "defaults" : options,
                               second_placement     ? ", placement 1 as the second capture, 2 held out"
                               : held_out_placement ? ", placement 1 as the held-out capture"
                                                    : "");
  md += "Baseline fits started from:";
  for (const auto& [from, n] : starts) md += fmt::format(" {} {},", from, n);
  md.back() = '.';
  md += starts.size() > 1 ? " (a mix of protocols)\n\n" : "\n\n";
  md += "| truth \\ verdict |";
  for (const auto& c : columns) md += " " + c + " |";
  md += "\n|---|";
  for (std::size_t k = 0; k < columns.size(); ++k) md += "---|";
  md += "\n";
  for (const auto& r : rows) {
    md += "| " + r + " |";
    for (const auto& c : columns) md += fmt::format(" {} |", confusion[r][c]);
    md += "\n";
  }
  md += fmt::format("\n- top-1 correct on effect captures: {}/{} ({:.0f}%)\n", effect_correct, effect_total,
                    effect_total ? 100.0 * effect_correct / effect_total : 0.0);
  const int detected = effect_total - within_at_gate - within_after_bending;  // found above the floors
  if (effect_total > 0) {
    md += fmt::format("- detection and attribution apart: {} effect captures within the floors at the gate, {} once "
                      "the bending alone is refitted; of the {} found above them, named correctly: {} ({:.0f}%)\n",
                      within_at_gate, within_after_bending, detected, detected_correct,
                      detected ? 100.0 * detected_correct / detected : 0.0);
  }
  if (!screen_draws_by_family.empty()) {
    md += fmt::format("- top-1 correct on the effect captures the screen passed (visible): {}/{}; screen draws "
                      "visible / made per family (none: controls the screen passes, its false positives):",
                      visible_correct, visible_total);
    for (const auto& [family, n] : screen_draws_by_family) md += fmt::format(" {} {}/{},", family, n.second, n.first);
    md.back() = '\n';
    md += fmt::format("- top-1 by the kept draw's excess above the floors at the screen (its true fabric without "
                      "the effect; relative, stable and shape terms summed): below {}: {}/{}; {} to {}: {}/{}; from "
                      "{}: {}/{}\n",
                      excess_edges[0], by_excess[0].first, by_excess[0].second, excess_edges[0], excess_edges[1],
                      by_excess[1].first, by_excess[1].second, excess_edges[1], by_excess[2].first,
                      by_excess[2].second);
  }
  md += fmt::format("- controls within the floors: {}/{} ({:.0f}%)\n", control_within, control_total,
                    control_total ? 100.0 * control_within / control_total : 0.0);
  auto median_percent = [](const std::vector<double>& v) {
    return v.empty() ? std::string("n/a") : fmt::format("{:.0f}%", 100.0 * median(v));
  };
  md += fmt::format("- median shrinkage of the excess above the floors once the named effect is added (0 when "
                    "none is named): {}; over the correctly named captures alone: {}\n",
                    median_percent(shrinkages), median_percent(named_shrinkages));
  md += fmt::format("- localised region matches the effect's region: {}/{}", region_match, region_total);
  if (!region_by_family.empty()) {
    md += " (";
    for (const auto& [family, n] : region_by_family) md += fmt::format("{} {}/{}, ", family, n.first, n.second);
    md.resize(md.size() - 2);
    md += ")";
  }
  if (detected > 0) {
    md += fmt::format("; on the {} found above the floors: {}", detected, detected_region_match);
  }
  md += "\n";
  if (floor_region_total > 0) {
    md += fmt::format("- the region furthest above its own floor (floor_region) matches it: {}/{}\n",
                      floor_region_match, floor_region_total);
  }
  md += fmt::format("- runtime per capture: median {:.0f} s, max {:.0f} s", median(seconds),
                    seconds.empty() ? 0.0 : *std::max_element(seconds.begin(), seconds.end()));
  // CPU time leaves out waiting for a core and time a run was stopped; reports older than session 46 lack it.
  if (!cpu_seconds.empty()) {
    md += fmt::format("; CPU median {:.0f} s, max {:.0f} s ({} of {} reports)", median(cpu_seconds),
                      *std::max_element(cpu_seconds.begin(), cpu_seconds.end()), cpu_seconds.size(), seconds.size());
  }
  md += "\n";
  md += "\n| case | effect | strength | verdict | stable / floor (mm) | shape / floor | region | region ok | "
        "shrinkage | s |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& c : per_case) {
    const auto& t = c["tests"];
    const std::string shrink =
        c["shrinkage"].is_null() ? "-" : fmt::format("{:.0f}%", 100.0 * c["shrinkage"].get<double>());
    const std::string effect = c["effect"].get<std::string>();
    const std::string signature = c["signature"].get<std::string>();  // what named the effect, where not the refits
    md += fmt::format("| {} | {} | {:.3g} | {} | {:.1f} / {:.1f} | {:.2f} / {:.2f} | {} | {} | {} | {:.0f} |\n",
                      c["case"].get<std::string>(), effect.empty() ? "-" : effect,
                      c["strength"].get<double>(),
                      c["verdict"].get<std::string>() + (signature.empty() ? "" : " (" + signature + ")"),
                      t.value("stable_mm", 0.0),
                      t.value("stable_floor_mm", 0.0), t.value("shape", 0.0), t.value("shape_floor", 0.0),
                      c["region"].get<std::string>(), c["region_ok"].get<bool>() ? "yes" : "no", shrink,
                      c["seconds"].get<double>());
  }
  std::ofstream(fs::path(out) / "summary.md") << md;
  std::ofstream(fs::path(out) / "cases.json") << per_case.dump(2) << "\n";
  std::cout << md;
  return 0;
}
