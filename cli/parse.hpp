#pragma once
// Parsing of command-line values shared by the subcommands.

#include <string>

#include "drapegen/sim/anisotropy.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::cli {

/// "W,B,F" (warp, bias, weft) or a single value for all three directions. Rejects non-numbers and non-finite values.
[[nodiscard]] sim::Expected<sim::DirectionalValues> parse_directional(const std::string& text, const std::string& what);

/// Whether a file can be created at `path` (probes with a temporary file beside it, then removes it).
[[nodiscard]] sim::Status check_writable(const std::string& path);

}  // namespace drapegen::cli
