#pragma once
// Fabric parameters, their units, and the bending model that uses them.

#include "drapegen/sim/anisotropy.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::sim {

/// The paper's standard areal density (Section 5.1.2): 300 g/m^2.
constexpr double kStandardDensity = 0.3;  // kg/m^2

enum class BendingModel {
  kNonlinearDihedral,  // paper Eq. 1-3 (default)
  kQuadratic,          // Bergou et al. 2006, paper Eq. 4
  kNonlinearTriangle,  // the Eq. 1-3 torque law on per-triangle curvature tensors (triangle_bending.hpp)
};

/// Bending parameters in SI units: alpha in N*m (= 1e9 g*mm^2/s^2), beta in N*m^2 (= 1e12 g*mm^3/s^2),
/// gamma (quadratic model) in N*m, density in kg/m^2.
struct FabricParameters {
  DirectionalValues alpha{1e-5, 1e-5, 1e-5};
  DirectionalValues beta{0.0, 0.0, 0.0};
  DirectionalValues gamma{0.0, 0.0, 0.0};
  double density = kStandardDensity;
};

/// Converts from the paper's units: alpha in g*mm^2/s^2, beta in g*mm^3/s^2, density in g/m^2.
[[nodiscard]] FabricParameters fabric_from_paper_units(const DirectionalValues& alpha_paper,
                                                       const DirectionalValues& beta_paper, double density_g_per_m2);

/// The same fabric at the standard density: moduli times kStandardDensity / density (Section 5.1.2). The drape
/// simulator works in these normalised units, and every other stiffness of the simulator (the in-plane stiffness
/// sigma, the contact penalty) is given for the standard density: a drape therefore depends on k / rho only.
[[nodiscard]] FabricParameters normalized(const FabricParameters& fabric);

/// Checks that every modulus is finite, alpha (and gamma for the quadratic model) positive and density positive.
[[nodiscard]] Status validate(const FabricParameters& fabric, BendingModel model);

}  // namespace drapegen::sim
