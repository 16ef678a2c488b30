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
  taut_stage "Configuring ${dir} ($*)"
  cmake -G Ninja -S "${TAUT_ROOT}" -B "${dir}" "$@"
}

# Configures DIR with the given cmake arguments (taut_configure), then builds all of it.
taut_configure_build() {
  taut_configure "$@"
  taut_stage "Building $1 (-j${TAUT_JOBS})"
  cmake --build "$1" -j"${TAUT_JOBS}"
}

# Release build in build/release (tests, demos and benchmarks on).
taut_build_release() {
  taut_configure_build build/release -DCMAKE_BUILD_TYPE=Release
}

# Only the demo binary (and the libraries it links) in build/release: no tests, no benchmarks.
taut_build_release_demo() {
  taut_configure build/release -DCMAKE_BUILD_TYPE=Release
  taut_stage "Building taut-demo in build/release (-j${TAUT_JOBS})"
  cmake --build build/release -j"${TAUT_JOBS}" --target taut-demo
}

# Release build with CHOLMOD (-DTAUT_WITH_CHOLMOD=ON, GPL-2+) in build/cholmod: only the test
# binary, to run CHOLMOD's tests; every object but plugin/cholmod_cholesky.cc compiles as in
# build/release, so ccache makes this build mostly links.
taut_build_cholmod_tests() {
  taut_configure build/cholmod -DCMAKE_BUILD_TYPE=Release -DTAUT_WITH_CHOLMOD=ON \
    -DTAUT_BUILD_BENCH=OFF -DTAUT_BUILD_DEMOS=OFF
  taut_stage "Building taut_tests in build/cholmod (-j${TAUT_JOBS})"
  cmake --build build/cholmod -j"${TAUT_JOBS}" --target taut_tests
}

# Debug build (assertions on, -O1 so Eigen-heavy tests finish) with AddressSanitizer and UBSan
# in build/asan (no benchmarks, no demos).
taut_build_asan() {
  taut_configure_build build/asan -DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-g -O1" -DTAUT_SANITIZE=ON \
    -DTAUT_BUILD_BENCH=OFF -DTAUT_BUILD_DEMOS=OFF
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
