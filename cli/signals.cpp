#include "signals.hpp"

#include <pthread.h>
#include <thread>

namespace drapegen::cli {
namespace {

std::atomic<bool> g_stop{false};
std::atomic<int> g_signal{0};

void on_signal(int sig) {
  g_signal.store(sig);
  g_stop.store(true);
}

sigset_t stop_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  return set;
}

}  // namespace

const std::atomic<bool>& install_stop_signals() {
  static const bool installed = [] {
    const sigset_t set = stop_signals();
    // Also a handler, for a thread that was started before this (a threaded BLAS's pool, started when the library
    // loaded) and so does not block them: there a signal sets the flag too, rather than end the process.
    struct sigaction action{};
    action.sa_handler = on_signal;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
    pthread_sigmask(SIG_BLOCK, &set, nullptr);
    std::thread([set] {
      for (;;) {
        int sig = 0;
        if (sigwait(&set, &sig) == 0) on_signal(sig);
      }
    }).detach();
    return true;
  }();
  (void)installed;
  return g_stop;
}

int stop_signal() { return g_signal.load(); }

sigset_t child_signal_mask() {
  sigset_t mask;
  pthread_sigmask(SIG_SETMASK, nullptr, &mask);
  sigdelset(&mask, SIGINT);
  sigdelset(&mask, SIGTERM);
  return mask;
}

}  // namespace drapegen::cli
