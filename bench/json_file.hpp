// A JSON file read whole (the benchmark tools' truth files and reports), or why it could not be.
#pragma once

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "drapegen/sim/expected.hpp"

namespace drapegen::bench {

inline sim::Expected<nlohmann::json> read_json(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return sim::Error{"cannot read " + path.string()};
  nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded()) return sim::Error{"not JSON: " + path.string()};
  return j;
}

}  // namespace drapegen::bench
