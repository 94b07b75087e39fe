#pragma once
// How reports, truth files and captures write a bending: {"alpha": [warp, bias, weft], "beta": [warp, bias, weft]}
// in paper units.

#include <nlohmann/json.hpp>
#include <string>

#include "drapegen/diagnosis/fabric_space.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::diagnosis {

[[nodiscard]] nlohmann::json bending_json(const BendingParameters& p);

/// The "alpha" and "beta" of the object `j`. One-line errors naming `where`: a key missing, not three numbers
/// ("WHERE.alpha must be [warp, bias, weft] numbers"), alpha not positive ("WHERE.alpha must be positive").
[[nodiscard]] sim::Expected<BendingParameters> bending_from_json(const nlohmann::json& j, const std::string& where);

}  // namespace drapegen::diagnosis
