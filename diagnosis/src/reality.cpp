#include "drapegen/diagnosis/reality.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "drapegen/diagnosis/bending_json.hpp"
#include "drapegen/diagnosis/candidate_effect.hpp"
#include "drapegen/diagnosis/error_footprint.hpp"
#include "drapegen/renderer/depth_renderer.hpp"
#include "drapegen/renderer/noise.hpp"
#include "drapegen/renderer/preview.hpp"
#include "drapegen/renderer/random.hpp"
#include "drapegen/renderer/rig.hpp"
#include "drapegen/renderer/sensor_error.hpp"
#include "drapegen/sim/drape.hpp"
#include "drapegen/storage/atomic_file.hpp"
#include "drapegen/storage/json_text.hpp"

namespace drapegen::diagnosis {
namespace fs = std::filesystem;
namespace {

constexpr const char* kRealitySource = "drapegen reality";  // capture.json's "source"

const std::map<std::string, double>& defaults() {
  static const std::map<std::string, double> d = {{"yield", 20.0}, {"shear", 1.0},     {"curl", 200.0},
                                                  {"friction", 0.05}, {"misalign", 15.0}, {"pose", 1.0},
                                                  {"bias", 5.0},   {"multipath", 15.0}};
  return d;
}

Eigen::Vector3d random_unit(renderer::Rng& rng) {
  Eigen::Vector3d v(rng.gaussian(), rng.gaussian(), rng.gaussian());
  return v.norm() > 0.0 ? Eigen::Vector3d(v.normalized()) : Eigen::Vector3d::UnitX();
}

/// The random stream of placement K > 0 (its draws and its noise).
std::uint64_t placement_stream(int placement) { return 0x9A1E0000u + static_cast<std::uint64_t>(placement); }

}  // namespace

std::string reality_family(const std::string& name) {
  if (name == "misalign") return "misalignment";
  if (name == "pose" || name == "bias" || name == "multipath") return "sensor";
  return name;
}

sim::Expected<RealityEffect> parse_reality_effect(const std::string& text) {
  const auto eq = text.find('=');
  RealityEffect e;
  e.name = text.substr(0, eq);
  if (e.name == "misalignment") e.name = "misalign";
  const auto it = defaults().find(e.name);
  if (it == defaults().end()) {
    return sim::Error{fmt::format("--effect: unknown effect '{}' (yield, shear, curl, friction, misalign, pose, bias, "
                                  "multipath)", e.name)};
  }
  e.strength = it->second;
  if (eq != std::string::npos) {
    const std::string v = text.substr(eq + 1);
    const auto comma = v.find(',');
    if (comma != std::string::npos && e.name != "curl") {
      return sim::Error{fmt::format("--effect {}: one value expected (only curl=K,W takes two)", e.name)};
    }
    auto number = [&](const std::string& s, double& out) {
      if (s.find_first_of("xX") != std::string::npos) return false;  // decimal only (stod reads 0x10 as 16)
      try {
        std::size_t used = 0;
        out = std::stod(s, &used);
        return used == s.size() && std::isfinite(out);
      } catch (const std::exception&) {
        return false;
      }
    };
    if (!number(v.substr(0, comma), e.strength)) {
      return sim::Error{fmt::format("--effect {}: '{}' is not a number", e.name, v.substr(0, comma))};
    }
    if (comma != std::string::npos) {
      const std::string w = v.substr(comma + 1);
      if (!number(w, e.width_mm) || !(e.width_mm > 0.0) || e.width_mm > 150.0) {
        return sim::Error{fmt::format("--effect curl: the band width '{}' must be a number of mm in (0, 150]", w)};
      }
    }
  }
  // Zero is no effect at all: its capture would be a control whose truth names a family.
  if (e.strength == 0.0) {
    return sim::Error{fmt::format("--effect {}=0 changes nothing (a control is a capture without --effect)", e.name)};
  }
  const bool positive = e.name == "yield" || e.name == "shear" || e.name == "friction";
  if (positive && !(e.strength > 0.0)) return sim::Error{fmt::format("--effect {}: must be positive", e.name)};
  if ((e.name == "misalign" || e.name == "pose" || e.name == "multipath") && e.strength < 0.0) {
    return sim::Error{fmt::format("--effect {}: must not be negative", e.name)};
  }
  if (e.name == "misalign" && e.strength > 60.0) return sim::Error{"--effect misalign: at most 60 mm"};
  if (e.name == "pose" && e.strength > 10.0) return sim::Error{"--effect pose: at most 10 degrees"};
  if (std::abs(e.strength) > 1000.0) return sim::Error{fmt::format("--effect {}: implausibly large", e.name)};
  return e;
}

MeasuredBending measure_bending(const BendingParameters& truth, double sigma, std::uint64_t seed) {
  renderer::Rng rng(renderer::mix_seed(seed, 0xBE4D));
  auto scaled = [&](double x) { return x * std::exp(sigma * rng.gaussian()); };
  MeasuredBending m;
  for (auto [from, to] : {std::pair{&truth.alpha, &m.bending.alpha}, std::pair{&truth.beta, &m.bending.beta}}) {
    to->warp = scaled(from->warp), to->bias = scaled(from->bias), to->weft = scaled(from->weft);
  }
  m.within_factor = std::exp(2.0 * sigma);
  m.method = fmt::format("drapegen reality: the truth times e^({} g) per parameter", sigma);
  return m;
}

namespace {

/// What one placement of the specimen is: the drape's configuration (without a plastic set), the sensor's error and
/// the truth's description of the effects.
struct Placement {
  sim::DrapeConfig config;
  renderer::SensorError sensor;
  nlohmann::json effects = nlohmann::json::array();
  std::string family = "none";
  std::vector<std::string> regions{"global"};
  bool regions_from_footprint = false;  // multipath: regions are where its rendered error stands out (ErrorFootprint)
};

sim::Expected<Placement> make_placement(const RealitySpec& spec, int placement) {
  // `rng` draws the first placement and the sensor's error; a later placement takes its own draws from `moved` for
  // what a re-placement changes, after drawing (and discarding) the first placement's from `rng`, so that the
  // sensor's error stays the first placement's.
  renderer::Rng rng(renderer::mix_seed(spec.seed, 0x4EA1));
  const bool replaced = placement > 0;
  const std::uint64_t placement_seed = renderer::mix_seed(spec.seed, placement_stream(placement));
  renderer::Rng moved(placement_seed);
  auto placement_draw = [&] {
    const double first = rng.uniform();
    return replaced ? moved.uniform() : first;
  };
  Placement p;
  sim::DrapeConfig& config = p.config;
  config.fabric = sim::fabric_from_paper_units(spec.bending.alpha, spec.bending.beta, spec.density);
  if (sim::Status s = sim::validate(config.fabric, config.bending_model); !s) return s.error();
  config.specimen.vertices_x = config.specimen.vertices_y = spec.resolution;
  config.specimen.seed = spec.seed;
  config.initial.shape = sim::InitialShape::kSine;
  config.initial.seed = replaced ? placement_seed : spec.seed;
  config.initial.rotation = 2.0 * M_PI * placement_draw();
  config.initial.face_down = spec.turn_over && placement % 2 == 1;
  const double small = 2e-3 * placement_draw();  // the data's augmentation range: up to 2 mm off centre
  const double phi = 2.0 * M_PI * placement_draw();
  config.initial.drift = small * Eigen::Vector2d(std::cos(phi), std::sin(phi));

  renderer::SensorError& sensor = p.sensor;
  for (const auto& e : spec.effects) {
    p.effects.push_back({{"name", e.name}, {"strength", e.strength}});
    if (p.family == "none") p.family = reality_family(e.name);
    if (e.name == "yield") {
      config.effects.bending_yield_curvature = e.strength;
    } else if (e.name == "shear") {
      config.effects.shear_stiffness = e.strength;
    } else if (e.name == "curl") {
      const double curl_width_mm = e.width_mm > 0.0 ? e.width_mm : kCurlWidth * 1e3;
      p.effects.back()["width_mm"] = curl_width_mm;
      // The band needs two vertex spacings at least, or the mesh cannot bend within it.
      const double spacing_mm = config.specimen.size_x * 1e3 / (spec.resolution - 1);
      if (curl_width_mm < 2.0 * spacing_mm) {
        return sim::Error{fmt::format("--effect curl: a band of {:g} mm spans fewer than two vertex spacings of the "
                                      "{}x{} specimen ({:.1f} mm): raise --resolution to at least {}",
                                      curl_width_mm, spec.resolution, spec.resolution, spacing_mm,
                                      static_cast<int>(std::ceil(2.0 * config.specimen.size_x * 1e3 / curl_width_mm)) +
                                          1)};
      }
      config.effects.edge_curl = sim::EdgeCurl{e.strength, curl_width_mm * 1e-3};
    } else if (e.name == "friction") {
      sim::FrictionParameters f;
      f.coefficient = e.strength;
      config.effects.friction = f;
    } else if (e.name == "misalign") {
      const double a = 2.0 * M_PI * placement_draw();
      config.initial.drift += e.strength * 1e-3 * Eigen::Vector2d(std::cos(a), std::sin(a));
    } else if (e.name == "pose") {
      sensor.rotation = e.strength * M_PI / 180.0 * random_unit(rng);
      sensor.translation = 5.0 * e.strength * 1e-3 * random_unit(rng);
    } else if (e.name == "bias") {
      sensor.bias_offset = e.strength * 1e-3;
    } else if (e.name == "multipath") {
      sensor.multipath_gain = e.strength * 1e-3;
    }
  }
  if (!spec.effects.empty()) {
    const std::string& first = spec.effects.front().name;
    if (first == "multipath") {
      p.regions_from_footprint = true;
    } else if (auto eff = parse_effect(reality_family(first))) {
      p.regions.clear();
      for (Region r : effect_regions(*eff)) p.regions.emplace_back(region_name(r));
    }
  }
  return p;
}

}  // namespace

sim::Expected<RealityResult> generate_reality(const RealitySpec& spec, const std::string& directory) {
  const auto start = std::chrono::steady_clock::now();
  if (spec.resolution < 5 || spec.resolution > 200) return sim::Error{"resolution must be 5 .. 200"};
  if (const double s = spec.measured_bending_error; !(s == 0.0 || (s >= kMinMeasuredBendingError && s <= 1.0))) {
    return sim::Error{
        fmt::format("the measured bending's error must be 0 (none) or {:g} .. 1", kMinMeasuredBendingError)};
  }
  if (spec.placement < 0 || spec.placement > kMaxPlacement) {
    return sim::Error{fmt::format("placement must be 0 .. {}", kMaxPlacement)};
  }
  // Only a capture this generator wrote is replaced: a real tester's in the same directory would be lost.
  if (const fs::path listed = fs::path(directory) / "capture.json"; fs::exists(listed)) {
    std::ifstream in(listed);
    const nlohmann::json old = nlohmann::json::parse(in, nullptr, false);
    const std::string source = old.is_object() && old.contains("source") && old["source"].is_string()
                                   ? old["source"].get<std::string>()
                                   : std::string();
    if (source != kRealitySource) {
      return sim::Error{fmt::format("{} holds a capture that drapegen reality did not write (source \"{}\"); it "
                                    "replaces only its own: choose another --out",
                                    directory, source)};
    }
  }
  auto made = make_placement(spec, spec.placement);
  if (!made) return made.error();
  Placement& p = *made;
  sim::DrapeConfig& config = p.config;
  const renderer::SensorError& sensor = p.sensor;
  const bool replaced = spec.placement > 0;

  // A yielding specimen keeps its plastic set from one placement to the next (lifted and laid again): placement K
  // starts from the set placements 0 .. K-1 left, each draped in turn.
  double largest_set = 0.0;
  bool set_converged = true;  // every earlier placement's drape converged
  if (config.effects.bending_yield_curvature && replaced) {
    Eigen::VectorXd set;
    for (int k = 0; k < spec.placement; ++k) {
      auto earlier = make_placement(spec, k);
      if (!earlier) return earlier.error();
      earlier->config.rest_angles = set;
      auto drape = sim::simulate_drape(earlier->config);
      if (!drape) return sim::Error{fmt::format("placement {} (for its plastic set): {}", k, drape.error().message)};
      set_converged = set_converged && drape->report.outcome == sim::SolveOutcome::kConverged;
      set = std::move(drape->rest_angles);
    }
    largest_set = set.cwiseAbs().maxCoeff();
    config.rest_angles = std::move(set);
  }

  auto drape = sim::simulate_drape(config);
  if (!drape) return sim::Error{fmt::format("placement {}: {}", spec.placement, drape.error().message)};
  const bool converged = drape->report.outcome == sim::SolveOutcome::kConverged;

  auto cloth = renderer::cloth_triangles(drape->mesh);
  if (!cloth) return cloth.error();
  renderer::RigSpec rig;
  renderer::AugmentationSpec augmentation;
  augmentation.orientations = 1;
  const auto setups = renderer::plan_data_points(rig, augmentation, spec.seed);
  auto renderer = renderer::DepthRenderer::create();
  if (!renderer) return renderer.error();
  if (sim::Status s = renderer->set_scene(renderer::tester_scene(*cloth, rig)); !s) return s.error();
  const renderer::NoiseModel noise = spec.noise ? renderer::NoiseModel::kinect() : renderer::NoiseModel::none();

  Capture capture;
  capture.source = kRealitySource;
  capture.face_down = config.initial.face_down;
  capture.specimen.size_x = config.specimen.size_x;
  capture.specimen.size_y = config.specimen.size_y;
  capture.specimen.density = spec.density;
  capture.specimen.cylinder_diameter = 2.0 * rig.cylinder.radius;
  if (spec.measured_bending_error > 0.0) {
    capture.specimen.measured_bending = measure_bending(spec.bending, spec.measured_bending_error, spec.seed);
  }
  std::vector<std::vector<renderer::DepthImage>> preview(1);
  const auto& setup = setups.front();
  // Where the sensor's depth error lies on the specimen (truth.json's sensor_footprint; a multipath capture's regions).
  const bool depth_error = sensor.changes_depth();
  const HemProfile outline = hem_profile_from_mesh(drape->mesh);
  ErrorFootprint footprint;
  for (int v = 0; v < static_cast<int>(setup.views.size()); ++v) {
    CaptureView view;
    view.file = fmt::format("view{}.exr", v);
    view.camera.intrinsics = setup.views[v].camera.intrinsics;
    view.camera.world_to_camera = setup.views[v].mesh_to_camera();  // what the calibration says
    const renderer::Camera truth = sensor.true_camera(view.camera);
    auto clean = renderer->render(truth);
    if (!clean) return clean.error();
    renderer::DepthImage biased = depth_error ? sensor.apply(*clean, view.camera.intrinsics) : *clean;
    if (depth_error) footprint.add_view(*clean, biased, truth, outline, rig.cylinder.radius);
    const std::uint64_t noise_seed =
        replaced ? renderer::mix_seed(setup.noise_seed(v), placement_stream(spec.placement)) : setup.noise_seed(v);
    view.depth = noise.any() ? noise.apply(biased, noise_seed) : biased;
    view.depth.incidence.clear();
    if (sim::Status s = check_view(view); !s) return sim::Error{fmt::format("rendered {}", s.error().message)};
    preview[0].push_back(view.depth);
    capture.views.push_back(std::move(view));
  }
  // A directory written before holds another capture's truth and preview: gone first, so that a write failing below
  // cannot leave them beside this capture.
  for (const char* stale : {"truth.json", "preview.png"}) {
    std::error_code ec;
    fs::remove(fs::path(directory) / stale, ec);
    if (ec) return sim::Error{fmt::format("cannot remove {}'s old {}: {}", directory, stale, ec.message()), true};
  }
  if (sim::Status s = write_capture(directory, capture); !s) return s.error();
  if (sim::Status s = renderer::write_preview_png((fs::path(directory) / "preview.png").string(), preview); !s) {
    return s.error();
  }

  if (p.regions_from_footprint) {
    p.regions.clear();
    for (Region r : footprint.regions()) p.regions.emplace_back(region_name(r));
  }
  nlohmann::json truth = {
      {"warning", "ground truth: the diagnosis never reads this file"},
      {"family", p.family},
      {"effects", p.effects},
      {"regions", p.regions},
      {"density_g_per_m2", spec.density},
      {"resolution", spec.resolution},
      {"seed", spec.seed},
      {"placement", spec.placement},
      {"face", config.initial.face_down ? "down" : "up"},
      {"plastic_set", {{"from_placements", config.rest_angles.size() > 0 ? spec.placement : 0},
                       {"largest_rest_angle_rad", largest_set},
                       {"earlier_drapes_converged", set_converged}}},
      {"initial_state", {{"shape", "sine"}, {"seed", config.initial.seed}, {"rotation_rad", config.initial.rotation}}},
      {"drift_mm", {config.initial.drift.x() * 1e3, config.initial.drift.y() * 1e3}},
      {"sensor",
       {{"rotation_rad", {sensor.rotation.x(), sensor.rotation.y(), sensor.rotation.z()}},
        {"translation_m", {sensor.translation.x(), sensor.translation.y(), sensor.translation.z()}},
        {"bias_offset_m", sensor.bias_offset},
        {"bias_slope", sensor.bias_slope},
        {"multipath_gain_m", sensor.multipath_gain}}},
      {"noise", noise.describe()},
      {"converged", converged},
      {"lagged_capped", drape->report.lagged_capped},
      {"drape_coefficient", drape->measures.drape_coefficient},
      {"folds", drape->measures.folds}};
  truth.update(bending_json(spec.bending));  // "alpha", "beta"
  if (depth_error) {
    nlohmann::json& f = truth["sensor_footprint"] = nlohmann::json::object();
    for (const RegionShare& s : footprint.shares()) {
      f[std::string(region_name(s.region))] = {
          {"energy_share", s.energy_share}, {"pixel_share", s.pixel_share}, {"enrichment", s.enrichment}};
    }
  }
  RealityResult result;
  result.truth_path = (fs::path(directory) / "truth.json").string();
  if (sim::Status s = storage::write_file_atomic(result.truth_path, storage::json_text(truth) + "\n"); !s) {
    return s.error();
  }
  result.converged = converged;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace drapegen::diagnosis
