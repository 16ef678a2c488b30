#!/usr/bin/env bash
# Shared helpers for the set-up scripts: `source scripts/build.sh` from another script, or run it
# directly to install dependencies and build one configuration:
#   scripts/build.sh [release|asan]     (default release; build dirs build/release, build/asan)
# Honours TAUT_JOBS (parallel build jobs, default 2).

# Repository root, from this file's own path.
TAUT_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
TAUT_JOBS="${TAUT_JOBS:-2}"

# Prints a stage banner.
taut_stage() {
  echo "==> $*"
}

# OpenBLAS picks its kernels when it loads and falls back to its generic Prescott ones on CPUs it
# does not know (Debian's 0.3.21 on some AVX-512 Intel Xeons). Only builds with
# -DTAUT_WITH_CHOLMOD=ON link a BLAS: when BINARY loads OpenBLAS, OPENBLAS_CORETYPE is unset and
# the core it picks is Prescott, this exports the widest core the CPU runs (SkylakeX: AVX-512 F,
# BW, DQ, VL; Haswell: AVX2 and FMA). A default build loads no BLAS and is left as it is.
taut_fix_openblas_coretype() {
  local binary="$1" core flags
  [[ -z "${OPENBLAS_CORETYPE:-}" ]] || return 0
  ldd "${binary}" 2>/dev/null | grep -q 'libopenblas' || return 0
  # With OPENBLAS_VERBOSE=2 the library prints "Core: <name>" on stderr as it loads.
  core="$(OPENBLAS_VERBOSE=2 "${binary}" --help 2>&1 >/dev/null)" || true
  core="$(sed -n '/^Core: /{s///p;q}' <<<"${core}")"
  [[ "${core}" == Prescott ]] || return 0
  flags=" $(grep -m 1 '^flags' /proc/cpuinfo) "
  if [[ "${flags}" == *" avx512f "* && "${flags}" == *" avx512bw "* &&
    "${flags}" == *" avx512dq "* && "${flags}" == *" avx512vl "* ]]; then
    export OPENBLAS_CORETYPE=SkylakeX
  elif [[ "${flags}" == *" avx2 "* && "${flags}" == *" fma "* ]]; then
    export OPENBLAS_CORETYPE=Haswell
  else
    return 0
  fi
  taut_stage "OpenBLAS chose its generic Prescott kernels; OPENBLAS_CORETYPE=${OPENBLAS_CORETYPE}"
}

# Installs the Debian packages (no-op when all are present).
taut_install_deps() {
  bash "${TAUT_ROOT}/scripts/install_deps.sh"
}

# Configures DIR with Ninja and the given cmake arguments. DIR is reused; a DIR configured with
# another generator is removed first, since cmake refuses to switch generators.
taut_configure() {
  local dir="$1"
  shift
  local cache="${dir}/CMakeCache.txt"
  if [[ -f "${cache}" ]] && ! grep -qx 'CMAKE_GENERATOR:INTERNAL=Ninja' "${cache}"; then
    taut_stage "${dir} was configured with another generator; removing it"
    rm -rf "${dir}"
  fi
  # The same for another compiler (cmake keeps the first one a build dir was configured with).
  local arg compiler
  for arg in "$@"; do
    [[ "${arg}" == -DCMAKE_CXX_COMPILER=* ]] || continue
    compiler="$(command -v "${arg#-DCMAKE_CXX_COMPILER=}")"
    if [[ -f "${cache}" ]] && ! grep -qx "CMAKE_CXX_COMPILER:[A-Z]*=${compiler}" "${cache}"; then
      taut_stage "${dir} was configured with another compiler; removing it"
      rm -rf "${dir}"
    fi
  done
  taut_stage "Configuring ${dir} ($*)"
  cmake -G Ninja -S "${TAUT_ROOT}" -B "${dir}" "$@"
}

# Configures DIR with the given cmake arguments (taut_configure), then builds all of it.
taut_configure_build() {
  taut_configure "$@"
  taut_stage "Building $1 (-j${TAUT_JOBS})"
  cmake --build "$1" -j"${TAUT_JOBS}"
}

# Release build in build/release (tests, demos and benchmarks on; the test files compiled in
# batches, TAUT_UNITY_TESTS, as in the sanitizer build: a fresh machine compiles the suite in
# less than half the time, and CI's two builds of it see the same batches).
taut_build_release() {
  taut_configure_build build/release -DCMAKE_BUILD_TYPE=Release -DTAUT_UNITY_TESTS=ON
}

# Only the demo binary (and the libraries it links) in build/release: no tests, no benchmarks.
taut_build_release_demo() {
  taut_configure build/release -DCMAKE_BUILD_TYPE=Release
  taut_stage "Building taut-demo in build/release (-j${TAUT_JOBS})"
  cmake --build build/release -j"${TAUT_JOBS}" --target taut-demo
}

# Release build with CHOLMOD (-DTAUT_WITH_CHOLMOD=ON, GPL-2+) in build/cholmod: only the test
# binary, with only the test files of the suites CI runs there (TAUT_TEST_FILTER); the library
# objects but plugin/cholmod_cholesky.cc compile as in build/release (ccache hits).
taut_build_cholmod_tests() {
  local tests="cholmod_cholesky_test;linear_solver_choice_test;sparse_ldlt_test"
  tests+=";supernodal_cholesky_test;determinism_test"
  taut_configure build/cholmod -DCMAKE_BUILD_TYPE=Release -DTAUT_WITH_CHOLMOD=ON \
    -DTAUT_BUILD_BENCH=OFF -DTAUT_BUILD_DEMOS=OFF "-DTAUT_TEST_FILTER=${tests}"
  taut_stage "Building taut_tests in build/cholmod (-j${TAUT_JOBS})"
  cmake --build build/cholmod -j"${TAUT_JOBS}" --target taut_tests
}

# Debug build (assertions on, -O1 so Eigen-heavy tests finish, -g1: line tables for the sanitizers'
# stack traces, a quarter less compile time than -g) with AddressSanitizer and UBSan in build/asan
# (no benchmarks, no demos; the test files compiled in batches, TAUT_UNITY_TESTS: 2.4x less
# compile time for the suite). Compiled by clang (installed for the fuzz stage): GCC took 1.6x
# the time on the largest test batch (98 s against 62 s, AMD EPYC), and this build is the
# longest stage of CI; the Release build keeps the default compiler, so both compilers build the
# project in CI.
taut_build_asan() {
  taut_configure_build build/asan -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Debug \
    "-DCMAKE_CXX_FLAGS_DEBUG=-g1 -O1" -DTAUT_SANITIZE=ON -DTAUT_BUILD_BENCH=OFF \
    -DTAUT_BUILD_DEMOS=OFF -DTAUT_UNITY_TESTS=ON
}

# Debug build with ThreadSanitizer in build/tsan, test binary only (flags as taut_build_asan): the
# check of DeformableWorld::SetThreadCount's island and body tasks (opt-in, not part of CI).
taut_build_tsan_tests() {
  taut_configure build/tsan -DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-g1 -O1" \
    -DTAUT_SANITIZE_THREAD=ON -DTAUT_BUILD_BENCH=OFF -DTAUT_BUILD_DEMOS=OFF -DTAUT_UNITY_TESTS=ON
  taut_stage "Building taut_tests in build/tsan (-j${TAUT_JOBS})"
  cmake --build build/tsan -j"${TAUT_JOBS}" --target taut_tests
}

if [[ "${BASH_SOURCE[0]}" == "$0" ]]; then
  set -euo pipefail
  cd "${TAUT_ROOT}"
  config="${1:-release}"
  case "${config}" in
    release | asan) ;;
    *)
      echo "usage: $0 [release|asan]" >&2
      exit 2
      ;;
  esac
  taut_stage "Installing dependencies"
  taut_install_deps
  "taut_build_${config}"
fi
