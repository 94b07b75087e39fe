#include "usable_cpus.hpp"

#include <sched.h>

#include <algorithm>
#include <thread>

namespace drapegen::cli {

int usable_cpus() {
  cpu_set_t mask;
  CPU_ZERO(&mask);
  if (sched_getaffinity(0, sizeof(mask), &mask) == 0) return std::max(1, CPU_COUNT(&mask));
  return std::max(1U, std::thread::hardware_concurrency());
}

}  // namespace drapegen::cli
