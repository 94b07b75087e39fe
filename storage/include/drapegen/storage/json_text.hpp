#pragma once
// JSON text for files and standard output.
#include <string>

#include <nlohmann/json.hpp>

namespace drapegen::storage {

/// `value` as JSON text, indented by `indent` (< 0: one line). A string that is not UTF-8 (a path in another
/// encoding) is written with U+FFFD in place of its invalid bytes: nlohmann's default throws, which failed commands
/// once their work was done (a diagnosis's report.json, a reality's --json).
[[nodiscard]] inline std::string json_text(const nlohmann::json& value, int indent = 2) {
  return value.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace drapegen::storage
