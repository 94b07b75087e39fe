#pragma once
// Physical effects the paper's baseline model leaves out, each switched on separately: the reality generator and the
// gap diagnosis (issue 6) simulate with them; the data generator does not.

#include <optional>

#include "drapegen/sim/edge_curl.hpp"
#include "drapegen/sim/platform_friction.hpp"

namespace drapegen::sim {

struct PhysicalEffects {
  /// Rest curvature near the free edges (DihedralBending rest angles).
  std::optional<EdgeCurl> edge_curl;
  /// Elastoplastic bending: hinges yield at this curvature, 1/m (DihedralBending::set_yield_curvature).
  std::optional<double> bending_yield_curvature;
  /// Woven in-plane behaviour with this shear stiffness, kg/s^2 at the standard density, instead of the isotropic
  /// corotational membrane (TrellisMembrane; the yarns keep DrapeConfig::membrane).
  std::optional<double> shear_stiffness;
  /// Coulomb friction on the platform top instead of the adhesive boundary condition.
  std::optional<FrictionParameters> friction;

  [[nodiscard]] bool any() const {
    return edge_curl.has_value() || bending_yield_curvature.has_value() || shear_stiffness.has_value() ||
           friction.has_value();
  }
};

}  // namespace drapegen::sim
