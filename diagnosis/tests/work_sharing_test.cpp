#include "drapegen/diagnosis/work_sharing.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <new>
#include <set>
#include <thread>
#include <vector>

namespace drapegen::diagnosis {
namespace {

TEST(WorkQueue, HandsOutEachItemOnceInOrderThenNone) {
  WorkQueue queue(3);
  EXPECT_EQ(queue.take(), 0u);
  EXPECT_EQ(queue.take(), 1u);
  EXPECT_EQ(queue.take(), 2u);
  EXPECT_FALSE(queue.take().has_value());
  EXPECT_FALSE(queue.take().has_value());
  WorkQueue empty(0);
  EXPECT_FALSE(empty.take().has_value());
}

TEST(RunOnThreads, RunsEveryThreadIndexOnceTheFirstOnTheCaller) {
  std::mutex mutex;
  std::multiset<int> seen;
  std::set<std::thread::id> ids;
  int caller_index = -1;
  const auto caller = std::this_thread::get_id();
  run_on_threads(4, [&](int t) {
    std::lock_guard lock(mutex);
    seen.insert(t);
    ids.insert(std::this_thread::get_id());
    if (std::this_thread::get_id() == caller) caller_index = t;
  });
  EXPECT_EQ(seen, (std::multiset<int>{0, 1, 2, 3}));
  EXPECT_EQ(ids.size(), 4u);
  EXPECT_EQ(caller_index, 0);
  seen.clear();
  run_on_threads(0, [&](int t) { seen.insert(t); });  // fewer than one: one, on the caller
  EXPECT_EQ(seen, (std::multiset<int>{0}));
}

// An exception on a helper thread reaches the caller once every thread has returned; it ended the process before
// (std::terminate), so an out-of-memory error on a refit thread aborted the diagnosis without a message.
TEST(RunOnThreads, AnExceptionOnAHelperThreadReachesTheCaller) {
  std::atomic<int> finished{0};
  EXPECT_THROW(run_on_threads(3,
                              [&](int t) {
                                if (t == 2) throw std::bad_alloc();
                                ++finished;
                              }),
               std::bad_alloc);
  EXPECT_EQ(finished.load(), 2);  // the others ran to their end
}

TEST(RunOnThreads, SharesAQueueSoEveryItemIsDoneOnceWhileASlowItemHoldsUpItsThread) {
  // Item 0 waits until the other 49 are done (at most 10 s): only another thread taking all of them meanwhile lets
  // it finish in time (a fixed share per thread would not).
  constexpr std::size_t kItems = 50;
  WorkQueue queue(kItems);
  std::vector<int> done(kItems, 0), by(kItems, -1);
  std::atomic<std::size_t> others_done{0};
  bool waited_out = false;
  run_on_threads(2, [&](int t) {
    while (const auto k = queue.take()) {
      if (*k == 0) {
        const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
        while (others_done < kItems - 1 && std::chrono::steady_clock::now() < until)
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
        waited_out = others_done < kItems - 1;
      } else {
        ++others_done;
      }
      ++done[*k];
      by[*k] = t;
    }
  });
  EXPECT_FALSE(waited_out);
  for (std::size_t k = 0; k < kItems; ++k) EXPECT_EQ(done[k], 1) << k;
  for (std::size_t k = 1; k < kItems; ++k) EXPECT_NE(by[k], by[0]) << k;
}

}  // namespace
}  // namespace drapegen::diagnosis
