#include "drapegen/sim/blas_kernels.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <cstdlib>

namespace drapegen::sim {

std::string openblas_core_name() {
  // Looked up at run time: the program links the system's BLAS (Debian's alternatives decide which), and only
  // OpenBLAS has this function.
  using CoreName = char* (*)();
  const auto get = reinterpret_cast<CoreName>(dlsym(RTLD_DEFAULT, "openblas_get_corename"));
  if (get == nullptr) return {};
  const char* name = get();
  return name != nullptr ? std::string(name) : std::string();
}

CpuVectorUnits cpu_vector_units() {
  CpuVectorUnits cpu;
#if defined(__x86_64__) && defined(__GNUC__)
  __builtin_cpu_init();
  cpu.avx2_fma = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  cpu.avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
               __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl");
#endif
  return cpu;
}

std::string openblas_coretype_to_request(std::string_view core_name, const char* user_choice, CpuVectorUnits cpu) {
  if (user_choice != nullptr || core_name != "Prescott" || !cpu.avx2_fma) return {};
  return cpu.avx512 ? "SkylakeX" : "Haswell";
}

void relaunch_with_blas_kernels(char** argv) {
  const std::string coretype =
      openblas_coretype_to_request(openblas_core_name(), std::getenv("OPENBLAS_CORETYPE"), cpu_vector_units());
  if (coretype.empty() || argv == nullptr || argv[0] == nullptr) return;
  if (setenv("OPENBLAS_CORETYPE", coretype.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
  // Still here: the restart failed (no /proc, say). Carry on with the kernels there are; leave the variable set so
  // that programs this one starts do not try again either.
}

}  // namespace drapegen::sim
