#pragma once
// Sharing a list of independent items among a few threads: each thread takes the next untaken item when it is free,
// so items that differ in cost several times over (a diagnosis's refits, a fit's drapes, a benchmark's captures)
// leave no thread idle while another has a queue.

#include <atomic>
#include <cstddef>
#include <functional>
#include <optional>

namespace drapegen::diagnosis {

/// Items 0 .. size - 1, each handed out once, in order, to whichever thread asks first.
class WorkQueue {
 public:
  explicit WorkQueue(std::size_t size) : size_(size) {}
  /// The next untaken item, or none once all are taken.
  [[nodiscard]] std::optional<std::size_t> take() {
    const std::size_t k = next_.fetch_add(1);
    return k < size_ ? std::optional<std::size_t>(k) : std::nullopt;
  }

 private:
  std::atomic<std::size_t> next_{0};
  std::size_t size_;
};

/// Runs work(thread) for thread = 0 .. threads - 1 at once, 0 on the calling thread, and returns when all have
/// returned (threads < 1: as 1). Work that shares a WorkQueue takes items from it until none are left.
void run_on_threads(int threads, const std::function<void(int thread)>& work);

}  // namespace drapegen::diagnosis
