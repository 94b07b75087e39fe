#pragma once
// The service's logger ("drapegen", stderr): coordinator, workers and the local launcher log through it.

#include <memory>
#include <spdlog/logger.h>

namespace drapegen::coordinator {

/// The logger (created on first use: stderr, level info, "[time] [level] message").
[[nodiscard]] std::shared_ptr<spdlog::logger> logger();
/// On a terminal, each log line first clears the self-updating progress line.
void set_terminal_pattern(bool terminal);

}  // namespace drapegen::coordinator
