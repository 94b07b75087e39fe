#pragma once
// Parsing of command-line values shared by the subcommands.

#include <ostream>
#include <string>
#include <vector>

#include "drapegen/sim/anisotropy.hpp"
#include "drapegen/sim/expected.hpp"
#include "drapegen/sim/physical_effects.hpp"

namespace drapegen::cli {

/// "W,B,F" (warp, bias, weft) or a single value for all three directions. Rejects non-numbers and non-finite values.
[[nodiscard]] sim::Expected<sim::DirectionalValues> parse_directional(const std::string& text, const std::string& what);

/// "--effect" values, each NAME=VALUE: curl=K[,W] (edge rest curvature K 1/m over W mm, default 10), yield=K (bending
/// yields at curvature K 1/m), shear=G (trellis membrane, shear stiffness G kg/s^2), friction=MU (Coulomb friction on
/// the platform top instead of adhesion). Each name at most once.
[[nodiscard]] sim::Expected<sim::PhysicalEffects> parse_effects(const std::vector<std::string>& items);

/// An integer option's text in base 10: leading zeros dropped ("010" -> "10", "-007" -> "-7"); anything else as it
/// is. CLI11 reads integers with strtoll's base 0, where "010" is octal 8.
[[nodiscard]] std::string decimal_integer(std::string text);
/// Whether `text` is an optional sign and decimal digits (no 0x, 0b or 0o prefix, no spaces).
[[nodiscard]] bool is_decimal_integer(const std::string& text);

/// Whether a file can be created at `path` (probes with a temporary file beside it, then removes it); a directory
/// there is an error, not a file that can be replaced.
[[nodiscard]] sim::Status check_writable(const std::string& path);

/// Whether two paths name one file (existing or not): the same path after resolving `.`, `..` and links, or one
/// existing file under two names. Two outputs of one command (or an output and an input) must not.
[[nodiscard]] bool same_file(const std::string& a, const std::string& b);

/// Where a command's summary goes: standard output, unless one of `outputs` is the file standard output writes to (an
/// output named /dev/stdout): then standard error, since the summary on the same descriptor would write over it.
[[nodiscard]] std::ostream& summary_stream(const std::vector<std::string>& outputs);

/// Creates `directory` (and its parents) for an output written later, and checks that `file` can be created in it:
/// an error now rather than after the work.
[[nodiscard]] sim::Status prepare_output_directory(const std::string& directory, const std::string& file);

}  // namespace drapegen::cli
