#include "drapegen/diagnosis/bending_json.hpp"

#include <fmt/format.h>

namespace drapegen::diagnosis {
namespace {

sim::Expected<sim::DirectionalValues> directional_from(const nlohmann::json& j, const std::string& what) {
  if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number()) {
    return sim::Error{fmt::format("{} must be [warp, bias, weft] numbers", what)};
  }
  return sim::DirectionalValues{j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

}  // namespace

nlohmann::json bending_json(const BendingParameters& p) {
  return {{"alpha", {p.alpha.warp, p.alpha.bias, p.alpha.weft}}, {"beta", {p.beta.warp, p.beta.bias, p.beta.weft}}};
}

sim::Expected<BendingParameters> bending_from_json(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object() || !j.contains("alpha") || !j.contains("beta")) {
    return sim::Error{where + " needs \"alpha\" and \"beta\""};
  }
  auto alpha = directional_from(j["alpha"], where + ".alpha");
  if (!alpha) return alpha.error();
  auto beta = directional_from(j["beta"], where + ".beta");
  if (!beta) return beta.error();
  if (!(alpha->warp > 0.0 && alpha->bias > 0.0 && alpha->weft > 0.0)) {
    return sim::Error{where + ".alpha must be positive"};
  }
  return BendingParameters{.alpha = *alpha, .beta = *beta};
}

}  // namespace drapegen::diagnosis
