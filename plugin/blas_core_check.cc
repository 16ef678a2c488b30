#include "plugin/blas_core_check.h"

#include <cstdio>

#if TAUT_WITH_CHOLMOD
#include <dlfcn.h>
#endif

namespace taut {

CpuVectorSupport DetectCpuVectorSupport() {
  CpuVectorSupport cpu;
#if defined(__x86_64__) || defined(__i386__)
  __builtin_cpu_init();  // required when called from a static initializer
  cpu.avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  cpu.avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
               __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
#endif
  return cpu;
}

std::string ChooseOpenBlasCoreType(const CpuVectorSupport& cpu) {
  if (cpu.avx512) return "SkylakeX";
  if (cpu.avx2) return "Haswell";
  return "";
}

std::string FormatOpenBlasCoreWarning(const std::string& core_name, const CpuVectorSupport& cpu) {
  const std::string core_type = ChooseOpenBlasCoreType(cpu);
  if (core_name != "Prescott" || core_type.empty()) return "";
  return "taut: OpenBLAS runs its generic Prescott kernels on this CPU with " +
         std::string(cpu.avx512 ? "AVX-512" : "AVX2") +
         " (CHOLMOD's factorization is slower than it can be); set OPENBLAS_CORETYPE=" + core_type +
         " before starting the program (OPENBLAS_VERBOSE=2 prints the core chosen)";
}

std::string GetOpenBlasCoreName() {
#if TAUT_WITH_CHOLMOD
  // Looked up, not linked: CHOLMOD loads whichever BLAS the system selects (Debian's
  // alternatives), and only OpenBLAS has the function.
  using CoreNameFunction = const char* (*)();
  const auto core_name =
      reinterpret_cast<CoreNameFunction>(dlsym(RTLD_DEFAULT, "openblas_get_corename"));
  if (core_name != nullptr && core_name() != nullptr) return core_name();
#endif
  return "";
}

bool WarnOnceIfOpenBlasCoreIsGeneric() {
  static const bool warned = [] {
    const std::string warning =
        FormatOpenBlasCoreWarning(GetOpenBlasCoreName(), DetectCpuVectorSupport());
    if (!warning.empty()) std::fprintf(stderr, "%s\n", warning.c_str());
    return !warning.empty();
  }();
  return warned;
}

}  // namespace taut

#if TAUT_WITH_CHOLMOD
// The start-up check of builds that link BLAS; plugin/CMakeLists.txt names this symbol to the
// linker, so every program linking taut_plugin keeps it.
extern "C" const bool taut_openblas_core_checked_at_start_up =
    taut::WarnOnceIfOpenBlasCoreIsGeneric();
#endif
