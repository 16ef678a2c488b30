// Which kernels the system OpenBLAS runs on this CPU. Debian's OpenBLAS 0.3.21 picks its core at
// load time and falls back to the generic "Prescott" kernels (SSE3) on AVX-512 Intel CPUs it does
// not know (Cooper Lake, Sapphire Rapids); OPENBLAS_CORETYPE, read when the library loads,
// overrides the choice. Only a build with CHOLMOD (TAUT_WITH_CHOLMOD) links a BLAS; there the
// check runs once at program start-up, other builds have the pure functions only.
#pragma once

#include <string>

namespace taut {

// The vector extensions OpenBLAS's x86-64 kernels need.
struct CpuVectorSupport {
  bool avx2 = false;    // AVX2 and FMA: the Haswell kernels
  bool avx512 = false;  // AVX-512 F, BW, DQ and VL: the SkylakeX kernels
};

// This CPU's support, as the OS enables it (__builtin_cpu_supports).
CpuVectorSupport DetectCpuVectorSupport();

// The OPENBLAS_CORETYPE for the CPU: "SkylakeX" with AVX-512, "Haswell" with AVX2, else "".
std::string ChooseOpenBlasCoreType(const CpuVectorSupport& cpu);

// The warning due when OpenBLAS runs core `core_name` on a CPU with `cpu`: one line naming the
// OPENBLAS_CORETYPE to set when the core is the generic "Prescott" and the CPU has AVX2 or
// AVX-512, else "".
std::string FormatOpenBlasCoreWarning(const std::string& core_name, const CpuVectorSupport& cpu);

// The core of the OpenBLAS loaded in this process (openblas_get_corename), or "" when none is
// loaded (the reference BLAS selected, or a build without CHOLMOD).
std::string GetOpenBlasCoreName();

// Prints this process's FormatOpenBlasCoreWarning on stderr, at the first call only; returns
// whether a warning was due. Builds with CHOLMOD call it at start-up.
bool WarnOnceIfOpenBlasCoreIsGeneric();

}  // namespace taut
