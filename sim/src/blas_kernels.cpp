#include "drapegen/sim/blas_kernels.hpp"

#include <dlfcn.h>
#include <sys/auxv.h>
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

std::string blas_kernels_description() {
  const std::string core = openblas_core_name();
  return core.empty() ? "not OpenBLAS" : "OpenBLAS " + core;
}

void relaunch_with_blas_kernels(char** argv) {
  const std::string coretype =
      openblas_coretype_to_request(openblas_core_name(), std::getenv("OPENBLAS_CORETYPE"), cpu_vector_units());
  if (coretype.empty() || argv == nullptr || argv[0] == nullptr) return;
  // Only a program the kernel started through its ELF interpreter is /proc/self/exe: one started as
  // `ld-linux.so PROGRAM ...` is the loader there (AT_BASE 0), and restarting that would run the wrong program.
  if (getauxval(AT_BASE) == 0) return;
  // The program's own path rather than /proc/self/exe, so that the restarted process keeps its name (ps, pkill).
  char path[4096];
  const ssize_t length = readlink("/proc/self/exe", path, sizeof(path) - 1);
  if (length <= 0) return;
  path[length] = '\0';
  if (setenv("OPENBLAS_CORETYPE", coretype.c_str(), 1) != 0) return;
  execv(path, argv);
  // Still here: the restart failed (the file was replaced, say). Carry on with the kernels there are; leave the
  // variable set so that programs this one starts do not try again either.
}

}  // namespace drapegen::sim
