#!/usr/bin/env bash
# Builds the libFuzzer targets of the mesh readers (tests/fuzz/<reader>_fuzz.cc) with clang++
# -fsanitize=fuzzer,address,undefined into build/fuzz/ and runs each for SECONDS (default 20)
# from a scratch copy of its seed corpus tests/data/fuzz/<reader>/ (the repository corpus is never
# written). Crash inputs land in build/fuzz/artifacts/<reader>/; exits non-zero if any target
# crashed (a sanitizer report, an exception other than InputError, a failed invariant, a leak, a
# timeout or an out-of-memory).
#   scripts/run_fuzz.sh [SECONDS]
# Honours TAUT_JOBS (parallel compile jobs, default 2) and CXX (default clang++).
set -euo pipefail
# shellcheck source-path=SCRIPTDIR source=build.sh
source "$(dirname "${BASH_SOURCE[0]}")/build.sh"
cd "${TAUT_ROOT}"

seconds="${1:-20}"
if ! [[ "${seconds}" =~ ^[1-9][0-9]*$ ]]; then
  echo "usage: $0 [SECONDS]  (a positive whole number of seconds per target, default 20)" >&2
  exit 2
fi

readers=(tetgen gmsh vtk off obj)
# Plugin sources the readers and the checks in tests/fuzz/fuzz_checks.h need.
sources=(mesh_text_scanner tet_mesh tet_rest_data tetgen_reader gmsh_reader vtk_reader off_reader
  obj_surface_reader surface_mesh hex_lattice hex_voxelizer)
cxx="${CXX:-clang++}"
if ! command -v "${cxx}" >/dev/null; then
  echo "error: ${cxx} not found; run scripts/install_deps.sh (packages clang, libclang-rt-dev)" >&2
  exit 1
fi
launcher=()
if command -v ccache >/dev/null; then launcher=(ccache); fi
sanitize=("-fsanitize=address,undefined" -fno-sanitize-recover=all -fno-omit-frame-pointer)
flags=(-std=c++17 -O1 -g "${sanitize[@]}" -I"${TAUT_ROOT}" -isystem /usr/include/eigen3
  -DTINYOBJLOADER_USE_DOUBLE)
out="${TAUT_ROOT}/build/fuzz"
mkdir -p "${out}/obj"

# tinyobjloader's implementation sits in its header: compile it here, instrumented, so the OBJ
# target covers and sanitizes that parser too (the Debian library is not instrumented).
printf '#define TINYOBJLOADER_IMPLEMENTATION\n#include <tiny_obj_loader.h>\n' \
  >"${out}/tinyobjloader_impl.cc"

# Compiles one source into build/fuzz/obj/<name>.o with coverage instrumentation.
compile() {
  local src="$1" name
  name="$(basename "${src}" .cc)"
  "${launcher[@]}" "${cxx}" "${flags[@]}" -fsanitize=fuzzer-no-link -c "${src}" \
    -o "${out}/obj/${name}.o"
}

taut_stage "Compiling ${#sources[@]} plugin sources and ${#readers[@]} fuzz targets with ${cxx}"
start=${SECONDS}
to_compile=("${out}/tinyobjloader_impl.cc")
for s in "${sources[@]}"; do to_compile+=("plugin/${s}.cc"); done
for r in "${readers[@]}"; do to_compile+=("tests/fuzz/${r}_fuzz.cc"); done
running=0
for src in "${to_compile[@]}"; do
  if ((running >= TAUT_JOBS)); then
    wait -n
    running=$((running - 1))
  fi
  compile "${src}" &
  running=$((running + 1))
done
while ((running > 0)); do
  wait -n
  running=$((running - 1))
done
common=("${out}/obj/tinyobjloader_impl.o")
for s in "${sources[@]}"; do common+=("${out}/obj/${s}.o"); done
for r in "${readers[@]}"; do
  "${cxx}" "${flags[@]}" -fsanitize=fuzzer "${out}/obj/${r}_fuzz.o" "${common[@]}" \
    -o "${out}/${r}_fuzz"
done
echo "==> Built in $((SECONDS - start)) s"

failed=()
summary=()
for r in "${readers[@]}"; do
  corpus="${out}/corpus/${r}"
  artifacts="${out}/artifacts/${r}/"
  rm -rf "${corpus}"
  mkdir -p "${corpus}" "${artifacts}"
  cp tests/data/fuzz/"${r}"/* "${corpus}/"
  dict=()
  if [[ -f "tests/fuzz/${r}.dict" ]]; then dict=(-dict="tests/fuzz/${r}.dict"); fi
  taut_stage "Fuzzing ${r} for ${seconds} s"
  log="${out}/${r}.log"
  rc=0
  UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
    "${out}/${r}_fuzz" "${corpus}" "${dict[@]}" -max_total_time="${seconds}" -timeout=10 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="${artifacts}" >"${log}" 2>&1 ||
    rc=$?
  runs="$(grep -o 'stat::number_of_executed_units: *[0-9]*' "${log}" | grep -o '[0-9]*$' || true)"
  cov="$(grep -o 'cov: [0-9]*' "${log}" | tail -1 | grep -o '[0-9]*' || true)"
  summary+=("${r}: ${runs:-?} runs, cov ${cov:-?}, exit ${rc}")
  if ((rc != 0)); then
    failed+=("${r}")
    echo "==> ${r}: FAILED (exit ${rc}); last lines of ${log}:" >&2
    tail -n 40 "${log}" >&2
  fi
done

echo "==> Fuzz summary (${seconds} s each): ${summary[*]/%/;}"
if ((${#failed[@]} > 0)); then
  echo "==> run_fuzz.sh FAILED: ${failed[*]} (inputs in build/fuzz/artifacts/)" >&2
  exit 1
fi
echo "==> No crashes"
