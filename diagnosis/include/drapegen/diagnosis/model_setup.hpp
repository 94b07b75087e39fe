#pragma once
// Everything the forward model (simulate, then render into the capture's cameras) needs besides the capture: the
// baseline's bending parameters plus any candidate effect's parameters.

#include <Eigen/Core>

#include "drapegen/diagnosis/fabric_space.hpp"
#include "drapegen/renderer/sensor_error.hpp"
#include "drapegen/sim/physical_effects.hpp"

namespace drapegen::diagnosis {

struct ModelSetup {
  BendingParameters bending;
  sim::PhysicalEffects effects;        // none for the baseline
  Eigen::Vector2d drift = Eigen::Vector2d::Zero();  // m, specimen centre off the axis (misalignment)
  renderer::SensorError sensor;        // none for the baseline
};

}  // namespace drapegen::diagnosis
