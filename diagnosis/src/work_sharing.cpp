#include "drapegen/diagnosis/work_sharing.hpp"

#include <thread>
#include <vector>

namespace drapegen::diagnosis {

void run_on_threads(int threads, const std::function<void(int thread)>& work) {
  std::vector<std::jthread> helpers;  // joined when they go out of scope
  for (int t = 1; t < threads; ++t) helpers.emplace_back(work, t);
  work(0);
}

}  // namespace drapegen::diagnosis
