#include "drapegen/sim/blas_kernels.hpp"

#include <gtest/gtest.h>

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

TEST(BlasKernels, TheCpuReportIsConsistent) {
  const CpuVectorUnits cpu = cpu_vector_units();
  EXPECT_TRUE(!cpu.avx512 || cpu.avx2_fma);  // every AVX-512 CPU has AVX2 and FMA
}

}  // namespace
}  // namespace drapegen::sim
