#pragma once
// SIGINT/SIGTERM as a stop flag for the service commands. The signals are blocked in every thread and taken by one
// thread of their own (sigwait), so no handler ever runs on a computing thread: METIS, which CHOLMOD orders with,
// installs its own SIGTERM handler while it runs (a longjmp into its own stack), and a SIGTERM delivered then crashed
// the worker (SIGSEGV) instead of stopping it. A handler that sets the same flag covers threads started before the
// mask was set (a threaded BLAS's pool). The service loops poll with timeouts of at most 100 ms.

#include <atomic>
#include <signal.h>

namespace drapegen::cli {

/// Blocks SIGINT and SIGTERM in the calling thread and every thread it starts later, and starts the thread that takes
/// them (once). Call before any other thread is started. Returns the flag a signal sets.
const std::atomic<bool>& install_stop_signals();
/// The signal that set the flag (0: none).
int stop_signal();
/// The signal mask a child process should start with: this process's, without the stop signals.
sigset_t child_signal_mask();

}  // namespace drapegen::cli
