#include "drapegen/diagnosis/work_sharing.hpp"

#include <exception>
#include <thread>
#include <vector>

namespace drapegen::diagnosis {

void run_on_threads(int threads, const std::function<void(int thread)>& work) {
  const int n = threads < 1 ? 1 : threads;
  // An exception escaping a thread would end the process (std::terminate, no message): each thread keeps its own,
  // and the first is rethrown on the calling thread once all have returned (an out-of-memory error reaches the
  // command's handler wherever it happened).
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(n));
  auto guarded = [&](int t) {
    try {
      work(t);
    } catch (...) {
      errors[static_cast<std::size_t>(t)] = std::current_exception();
    }
  };
  {
    std::vector<std::jthread> helpers;  // joined when they go out of scope
    for (int t = 1; t < n; ++t) helpers.emplace_back(guarded, t);
    guarded(0);
  }
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

}  // namespace drapegen::diagnosis
