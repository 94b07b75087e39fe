#include "signals.hpp"

#include <pthread.h>
#include <thread>

namespace drapegen::cli {
namespace {

std::atomic<bool> g_stop{false};
std::atomic<int> g_signal{0};

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
    pthread_sigmask(SIG_BLOCK, &set, nullptr);
    std::thread([set] {
      for (;;) {
        int sig = 0;
        if (sigwait(&set, &sig) != 0) continue;
        g_signal.store(sig);
        g_stop.store(true);
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
