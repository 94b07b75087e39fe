#pragma once
// Which BLAS kernels the process runs on, and the host program's remedy when they are the wrong ones.
//
// CHOLMOD's supernodal factorisation spends most of its time in BLAS (dgemm, dtrsm). Debian 12's OpenBLAS (0.3.21,
// built for every x86-64 generation at once) picks its kernels from the CPU model when it is loaded, and on Intel
// models it does not know (the development machine's Xeon, family 6 model 207, for one) it falls back to its
// generic SSE3 "Prescott" kernels (the fallback of OpenMathLib/OpenBLAS#4267, fixed in 0.3.25): the factorisations
// of a 100x100 drape then take ~1.5x as long (docs/BENCHMARKS.md). OpenBLAS reads the environment variable
// OPENBLAS_CORETYPE once, when it is loaded, so only a fresh start of the program can change the choice:
// relaunch_with_blas_kernels() does that for a main(). Setting OPENBLAS_CORETYPE (to any value) turns the restart
// off, e.g. for a debugger. The variable passes on to the programs drapegen starts (its local workers: the same
// program on the same CPU).

#include <string>
#include <string_view>

namespace drapegen::sim {

/// OpenBLAS's name for the kernels this process runs ("Haswell", "SkylakeX", "Prescott", ...), or an empty string
/// when the BLAS in use is not OpenBLAS.
[[nodiscard]] std::string openblas_core_name();
/// "OpenBLAS <core name>", or "not OpenBLAS": for reports.
[[nodiscard]] std::string blas_kernels_description();

/// What the CPU offers that OpenBLAS's kernels use.
struct CpuVectorUnits {
  bool avx2_fma = false;  // AVX2 and FMA3: OpenBLAS's "Haswell" kernels
  bool avx512 = false;    // AVX-512 F, DQ, BW and VL: its "SkylakeX" kernels
};

/// The CPU this process runs on.
[[nodiscard]] CpuVectorUnits cpu_vector_units();

/// The OPENBLAS_CORETYPE to start the program with: the kernels the CPU supports when OpenBLAS fell back to
/// "Prescott" on a CPU with AVX2, empty when nothing should change (the user chose, through `user_choice`, the
/// value of OPENBLAS_CORETYPE or nullptr; the BLAS is not OpenBLAS; OpenBLAS chose other kernels; the CPU is old).
[[nodiscard]] std::string openblas_coretype_to_request(std::string_view core_name, const char* user_choice,
                                                       CpuVectorUnits cpu);

/// For a program's main(), before it does anything else: when openblas_coretype_to_request() names kernels for this
/// process, sets OPENBLAS_CORETYPE and replaces the process by the same program with the same arguments (execv of
/// the file /proc/self/exe names; same process id), which then runs on those kernels. Returns, having changed
/// nothing, when no change is due or the restart is impossible or unsafe (a program started through the dynamic
/// loader by hand). The restarted process has OPENBLAS_CORETYPE set, so it never restarts again.
void relaunch_with_blas_kernels(char** argv);

}  // namespace drapegen::sim
