#include "drapegen/sim/blas_kernels.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>

namespace drapegen::sim {
namespace {

constexpr CpuVectorUnits kOld{.avx2_fma = false, .avx512 = false};
constexpr CpuVectorUnits kAvx2{.avx2_fma = true, .avx512 = false};
constexpr CpuVectorUnits kAvx512{.avx2_fma = true, .avx512 = true};

TEST(BlasKernels, TheFallbackOnAModernCpuAsksForItsKernels) {
  EXPECT_EQ(openblas_coretype_to_request("Prescott", nullptr, kAvx512), "SkylakeX");
  EXPECT_EQ(openblas_coretype_to_request("Prescott", nullptr, kAvx2), "Haswell");
}

TEST(BlasKernels, NothingChangesOtherwise) {
  EXPECT_EQ(openblas_coretype_to_request("Prescott", nullptr, kOld), "");          // an old CPU: Prescott is right
  EXPECT_EQ(openblas_coretype_to_request("Prescott", "Prescott", kAvx512), "");    // the user chose
  EXPECT_EQ(openblas_coretype_to_request("Prescott", "", kAvx512), "");            // even an empty choice
  EXPECT_EQ(openblas_coretype_to_request("Haswell", nullptr, kAvx512), "");        // OpenBLAS chose well
  EXPECT_EQ(openblas_coretype_to_request("", nullptr, kAvx512), "");               // not OpenBLAS
}

/// The CPU flags the kernel reports for the first processor in /proc/cpuinfo (empty where there is none).
std::set<std::string> kernel_cpu_flags() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("flags", 0) != 0) continue;
    std::istringstream words(line.substr(line.find(':') + 1));
    return {std::istream_iterator<std::string>(words), std::istream_iterator<std::string>()};
  }
  return {};
}

TEST(BlasKernels, TheCpuReportAgreesWithTheKernels) {
#if !defined(__x86_64__)
  GTEST_SKIP() << "x86-64 only";
#endif
  const std::set<std::string> flags = kernel_cpu_flags();
  if (flags.empty()) GTEST_SKIP() << "no CPU flags in /proc/cpuinfo";
  const auto has = [&](std::initializer_list<const char*> names) {
    return std::all_of(names.begin(), names.end(), [&](const char* f) { return flags.contains(f); });
  };
  const CpuVectorUnits cpu = cpu_vector_units();
  EXPECT_EQ(cpu.avx2_fma, has({"avx2", "fma"}));
  EXPECT_EQ(cpu.avx512, has({"avx512f", "avx512dq", "avx512bw", "avx512vl"}));
}

}  // namespace
}  // namespace drapegen::sim
