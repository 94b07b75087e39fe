#pragma once
// Everything the forward model (simulate, then render into the capture's cameras) needs besides the capture: the
// baseline's bending parameters plus any candidate effect's parameters.

#include <Eigen/Core>
#include <cstdint>

#include "drapegen/diagnosis/fabric_space.hpp"
#include "drapegen/renderer/sensor_error.hpp"
#include "drapegen/sim/physical_effects.hpp"

namespace drapegen::diagnosis {

/// The plastic set a yielding specimen carries from an earlier drape into its next placement: the hinges' rest angles
/// (sim::DrapeResult::rest_angles) on the specimen of that drape (its triangulation seed).
struct PlasticSet {
  std::uint64_t specimen_seed = 0;
  Eigen::VectorXd rest_angles;  // empty: none (the specimen starts unloaded)
};

struct ModelSetup {
  BendingParameters bending;
  sim::PhysicalEffects effects;        // none for the baseline
  Eigen::Vector2d drift = Eigen::Vector2d::Zero();  // m, specimen centre off the axis (misalignment)
  renderer::SensorError sensor;        // none for the baseline
  PlasticSet plastic_set;              // none but for a yielding candidate's second placement
};

}  // namespace drapegen::diagnosis
