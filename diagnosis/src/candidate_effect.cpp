#include "drapegen/diagnosis/candidate_effect.hpp"

#include <cmath>

namespace drapegen::diagnosis {

std::string_view effect_name(Effect effect) {
  switch (effect) {
    case Effect::kYield: return "yield";
    case Effect::kShear: return "shear";
    case Effect::kCurl: return "curl";
    case Effect::kFriction: return "friction";
    case Effect::kMisalignment: return "misalignment";
    case Effect::kSensor: return "sensor";
  }
  return "?";
}

std::optional<Effect> parse_effect(std::string_view name) {
  for (Effect e : kAllEffects)
    if (effect_name(e) == name) return e;
  return std::nullopt;
}

bool needs_simulation(Effect effect) { return effect != Effect::kSensor; }

EffectSpace effect_space(Effect effect) {
  switch (effect) {
    case Effect::kYield:
      return {{"ln_yield_curvature_per_m"}, {std::log(40.0)}, {-0.8}, {std::log(3.0)}, {std::log(400.0)}};
    case Effect::kShear:
      return {{"ln_shear_stiffness_kg_per_s2"}, {std::log(3.0)}, {-1.2}, {std::log(0.05)}, {std::log(200.0)}};
    case Effect::kCurl:
      // A hanging hem flattens a gentle curl (gravity against the bending law's peak torque): the drape
      // changes little below ~100 /m and much above (docs/DIAGNOSIS.md, "Detectability"), so the search starts there.
      return {{"edge_curvature_per_m"}, {100.0}, {100.0}, {-300.0}, {300.0}};
    case Effect::kFriction:
      return {{"ln_friction_coefficient"}, {std::log(0.3)}, {-1.5}, {std::log(0.003)}, {std::log(5.0)}};
    case Effect::kMisalignment:
      return {{"drift_x_mm", "drift_y_mm"}, {0.0, 0.0}, {10.0, 10.0}, {-40.0, -40.0}, {40.0, 40.0}};
    case Effect::kSensor:
      return {{"rot_x_mrad", "rot_y_mrad", "rot_z_mrad", "t_x_mm", "t_y_mm", "t_z_mm", "bias_mm", "bias_slope_mm_per_m",
               "multipath_mm"},
              {0, 0, 0, 0, 0, 0, 0, 0, 0},
              {4, 4, 4, 4, 4, 4, 2, 10, 6},
              {-60, -60, -60, -60, -60, -60, -30, -100, 0},
              {60, 60, 60, 60, 60, 60, 30, 100, 60}};
  }
  return {};
}

void apply_effect(Effect effect, const std::vector<double>& x, ModelSetup& setup) {
  switch (effect) {
    case Effect::kYield: setup.effects.bending_yield_curvature = std::exp(x.at(0)); break;
    case Effect::kShear: setup.effects.shear_stiffness = std::exp(x.at(0)); break;
    case Effect::kCurl: setup.effects.edge_curl = sim::EdgeCurl{x.at(0), kCurlWidth}; break;
    case Effect::kFriction: {
      sim::FrictionParameters f;
      f.coefficient = std::exp(x.at(0));
      setup.effects.friction = f;
      break;
    }
    case Effect::kMisalignment: setup.drift = Eigen::Vector2d(x.at(0), x.at(1)) * 1e-3; break;
    case Effect::kSensor:
      setup.sensor.rotation = Eigen::Vector3d(x.at(0), x.at(1), x.at(2)) * 1e-3;
      setup.sensor.translation = Eigen::Vector3d(x.at(3), x.at(4), x.at(5)) * 1e-3;
      setup.sensor.bias_offset = x.at(6) * 1e-3;
      setup.sensor.bias_slope = x.at(7) * 1e-3;
      setup.sensor.multipath_gain = x.at(8) * 1e-3;
      break;
  }
}

std::string_view region_name(Region region) {
  switch (region) {
    case Region::kTop: return "top";
    case Region::kRim: return "rim";
    case Region::kSkirt: return "skirt";
    case Region::kHem: return "hem";
    case Region::kCylinder: return "cylinder";
    case Region::kGlobal: return "global";
  }
  return "?";
}

std::vector<Region> effect_regions(Effect effect) {
  switch (effect) {
    case Effect::kYield: return {Region::kSkirt};
    case Effect::kShear: return {Region::kSkirt};
    case Effect::kCurl: return {Region::kHem};
    case Effect::kFriction: return {Region::kRim, Region::kTop};
    case Effect::kMisalignment: return {Region::kHem};
    case Effect::kSensor: return {Region::kGlobal};
  }
  return {};
}

}  // namespace drapegen::diagnosis
