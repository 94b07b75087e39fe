#pragma once
// The measured fabrics (../shared/data/fabrics618.csv, paper Section 5.1.1) as the sampler reads them.

#include <string>
#include <vector>

#include "drapegen/sampler/parameters.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::sampler {

/// One measured fabric: its density (g/m^2) and moduli at that density.
struct MeasuredFabric {
  double density_g_per_m2 = 0.0;
  ParameterVector moduli;
};

/// Reads fabrics618.csv (header line; density kg/m^2, linear warp, weft, diag, nonlinear warp, weft, diag; the
/// columns are mapped to the paper's warp, bias, weft order). Fails on a missing or unreadable file, a row without
/// seven finite numbers, a non-positive density or a zero modulus, naming the line.
[[nodiscard]] sim::Expected<std::vector<MeasuredFabric>> read_fabric_csv(const std::string& path);

/// Features of the distinct fabrics (rows repeat in the CSV) normalised to 300 g/m^2, in first-occurrence order.
[[nodiscard]] std::vector<Features> distinct_features(const std::vector<MeasuredFabric>& fabrics);

}  // namespace drapegen::sampler
