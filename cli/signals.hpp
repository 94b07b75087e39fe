#pragma once
// SIGINT/SIGTERM as a stop flag for the service commands (no SA_RESTART, so blocking polls return at once).

#include <atomic>

namespace drapegen::cli {

/// Installs the handlers (once) and returns the flag they set.
const std::atomic<bool>& install_stop_signals();
/// The signal that set the flag (0: none).
int stop_signal();

}  // namespace drapegen::cli
