#include "drapegen/sampler/initial_state_recipe.hpp"

#include <charconv>
#include <cmath>
#include <map>
#include <numbers>
#include <sstream>

#include <fmt/format.h>

namespace drapegen::sampler {
namespace {

sim::Expected<RecipeKind> parse_kind(const std::string& s) {
  if (s == "sine") return RecipeKind::kSine;
  if (s == "fold") return RecipeKind::kFold;
  if (s == "drape") return RecipeKind::kDrape;
  return sim::Error{"unknown recipe kind '" + s + "' (expected sine, fold or drape)"};
}

template <class T>
bool parse_number(const std::string& s, T& out) {
  if (s.empty()) return false;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && end == s.data() + s.size();
}

}  // namespace

const char* to_string(RecipeKind kind) {
  switch (kind) {
    case RecipeKind::kSine: return "sine";
    case RecipeKind::kFold: return "fold";
    case RecipeKind::kDrape: return "drape";
  }
  return "?";
}

sim::Status validate(const InitialStateRecipe& r) {
  if (r.sample < 0 || r.slot < 0) return sim::Error{"recipe sample and slot must be non-negative"};
  if (!(r.rotation >= 0.0 && r.rotation < 2.0 * std::numbers::pi))
    return sim::Error{"recipe rotation must be in [0, 2 pi)"};
  if (!std::isfinite(r.drift_x_mm) || !std::isfinite(r.drift_y_mm)) return sim::Error{"recipe drift must be finite"};
  if (r.kind == RecipeKind::kDrape) {
    if (r.source.sample < 0 || r.source.slot < 0) return sim::Error{"a drape recipe needs a source sample/slot"};
    if (r.source.sample == r.sample) return sim::Error{"a drape recipe's source must be another sample"};
  } else if (r.source != DrapeRef{}) {
    return sim::Error{"only drape recipes have a source"};
  }
  return {};
}

std::string to_text(const InitialStateRecipe& r) {
  const std::string source =
      r.kind == RecipeKind::kDrape ? fmt::format("{}/{}", r.source.sample, r.source.slot) : std::string("-");
  return fmt::format(
      "sample={} slot={} kind={} shape_seed={} triangulation_seed={} rotation={} drift_mm={},{} source={}", r.sample,
      r.slot, to_string(r.kind), r.shape_seed, r.triangulation_seed, r.rotation, r.drift_x_mm, r.drift_y_mm, source);
}

sim::Expected<InitialStateRecipe> parse_recipe_text(const std::string& text) {
  static const char* const kKeys[] = {"sample", "slot", "kind", "shape_seed", "triangulation_seed", "rotation",
                                      "drift_mm", "source"};
  std::istringstream in(text);
  std::string token;
  std::map<std::string, std::string> fields;
  std::size_t index = 0;
  while (in >> token) {
    const auto eq = token.find('=');
    if (eq == std::string::npos || index >= std::size(kKeys) || token.substr(0, eq) != kKeys[index]) {
      return sim::Error{"recipe text: expected field '" +
                        std::string(index < std::size(kKeys) ? kKeys[index] : "(end)") + "=' at '" + token + "'"};
    }
    fields[kKeys[index++]] = token.substr(eq + 1);
  }
  if (index != std::size(kKeys))
    return sim::Error{"recipe text: missing fields after '" + std::string(kKeys[index > 0 ? index - 1 : 0]) + "'"};
  InitialStateRecipe r;
  const auto kind = parse_kind(fields["kind"]);
  if (!kind) return kind.error();
  r.kind = *kind;
  const std::string& drift = fields["drift_mm"];
  const auto comma = drift.find(',');
  const std::string& source = fields["source"];
  bool ok = parse_number(fields["sample"], r.sample) && parse_number(fields["slot"], r.slot) &&
            parse_number(fields["shape_seed"], r.shape_seed) &&
            parse_number(fields["triangulation_seed"], r.triangulation_seed) &&
            parse_number(fields["rotation"], r.rotation) && comma != std::string::npos &&
            parse_number(drift.substr(0, comma), r.drift_x_mm) && parse_number(drift.substr(comma + 1), r.drift_y_mm);
  if (ok && source != "-") {
    const auto slash = source.find('/');
    ok = slash != std::string::npos && parse_number(source.substr(0, slash), r.source.sample) &&
         parse_number(source.substr(slash + 1), r.source.slot);
  }
  if (!ok) return sim::Error{"recipe text: malformed number in '" + text + "'"};
  if (sim::Status s = validate(r); !s) return s.error();
  return r;
}

nlohmann::json to_json(const InitialStateRecipe& r) {
  nlohmann::json j;
  j["sample"] = r.sample;
  j["slot"] = r.slot;
  j["kind"] = to_string(r.kind);
  j["shape_seed"] = r.shape_seed;
  j["triangulation_seed"] = r.triangulation_seed;
  j["rotation"] = r.rotation;
  j["drift_mm"] = {r.drift_x_mm, r.drift_y_mm};
  j["source"] = r.kind == RecipeKind::kDrape ? nlohmann::json{{"sample", r.source.sample}, {"slot", r.source.slot}}
                                             : nlohmann::json(nullptr);
  return j;
}

sim::Expected<InitialStateRecipe> recipe_from_json(const nlohmann::json& j) {
  try {
    InitialStateRecipe r;
    if (!j.is_object()) return sim::Error{"recipe JSON must be an object"};
    r.sample = j.at("sample").get<std::int64_t>();
    r.slot = j.at("slot").get<int>();
    const auto kind = parse_kind(j.at("kind").get<std::string>());
    if (!kind) return kind.error();
    r.kind = *kind;
    if (!j.at("shape_seed").is_number_unsigned() || !j.at("triangulation_seed").is_number_unsigned()) {
      return sim::Error{"recipe JSON: seeds must be unsigned integers"};
    }
    r.shape_seed = j.at("shape_seed").get<std::uint64_t>();
    r.triangulation_seed = j.at("triangulation_seed").get<std::uint64_t>();
    r.rotation = j.at("rotation").get<double>();
    const auto& drift = j.at("drift_mm");
    if (!drift.is_array() || drift.size() != 2) return sim::Error{"recipe JSON: drift_mm must be [dx, dy]"};
    r.drift_x_mm = drift[0].get<double>();
    r.drift_y_mm = drift[1].get<double>();
    const auto& source = j.at("source");
    if (!source.is_null()) r.source = {source.at("sample").get<std::int64_t>(), source.at("slot").get<int>()};
    if (sim::Status s = validate(r); !s) return s.error();
    return r;
  } catch (const nlohmann::json::exception& e) {
    return sim::Error{std::string("recipe JSON: ") + e.what()};
  }
}

sim::Expected<sim::InitialStateSpec> to_initial_state(const InitialStateRecipe& r, const DrapeLocator& locate) {
  if (sim::Status s = validate(r); !s) return s.error();
  sim::InitialStateSpec spec;
  switch (r.kind) {
    case RecipeKind::kSine: spec.shape = sim::InitialShape::kSine; break;
    case RecipeKind::kFold: spec.shape = sim::InitialShape::kFold; break;
    case RecipeKind::kDrape:
      if (!locate) return sim::Error{"a drape recipe needs a locator for its source drape"};
      spec.shape = sim::InitialShape::kMesh;
      spec.mesh_path = locate(r.source);
      if (spec.mesh_path.empty()) {
        return sim::Error{fmt::format("no drape stored for sample {} slot {}", r.source.sample, r.source.slot)};
      }
      break;
  }
  spec.seed = r.shape_seed;
  spec.rotation = r.rotation;
  spec.drift = Eigen::Vector2d(r.drift_x_mm * 1e-3, r.drift_y_mm * 1e-3);
  return spec;
}

void apply_triangulation(const InitialStateRecipe& r, sim::SpecimenSpec& specimen) {
  specimen.seed = r.triangulation_seed;
}

}  // namespace drapegen::sampler
