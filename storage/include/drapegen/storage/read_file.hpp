#pragma once
// Reading a whole file, with errors that say why (the OS's reason; a directory, which opens as an empty stream).

#include <string>

#include "drapegen/sim/expected.hpp"

namespace drapegen::storage {

/// The bytes of the file at `path`. Errors: "cannot read PATH: REASON" (missing, unreadable, a directory, an I/O
/// error part way).
[[nodiscard]] sim::Expected<std::string> read_file(const std::string& path);

}  // namespace drapegen::storage
