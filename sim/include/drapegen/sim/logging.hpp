#pragma once
// The library's logger. Hosts (the CLI, workers, tests) may replace it; the library never configures sinks.

#include <memory>
#include <spdlog/logger.h>

namespace drapegen::sim {

/// The logger the library writes to: by default "drapegen.sim" on stderr at level warn.
[[nodiscard]] std::shared_ptr<spdlog::logger> logger();
/// Replaces the library's logger (nullptr restores the default).
void set_logger(std::shared_ptr<spdlog::logger> replacement);

}  // namespace drapegen::sim
