#!/usr/bin/env bash
# Builds taut-stress (Release, build/release) and runs the full stress suite (stiff and extreme
# cases: stiffness x step, impacts, limits, inverted and flat starts, slivers, fast spins, heavy
# rigid bodies on soft ones, 100,000-step runs, length scale) into docs/stress.md:
#   scripts/run_stress.sh [taut-stress options]
# e.g. --filter spin (only matching cells) or --out /tmp/stress.md; see
# `build/release/demos/taut-stress --help`. The full suite takes about a minute on one core.
# Exits non-zero when a cell is BROKEN (silent NaN, unexpected exception, crash or hang);
# degrading, loudly failing and pending cells are reported in the table, not fatal.
set -euo pipefail
# shellcheck source-path=SCRIPTDIR source=build.sh
source "$(dirname "${BASH_SOURCE[0]}")/build.sh"
cd "${TAUT_ROOT}"

if [[ "${1:-}" == "-h" || "${1:-}" == "--help" ]]; then
  sed -n '2,9p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
  exit 0
fi

taut_stage "Installing dependencies"
taut_install_deps
taut_stage "Configuring build/release"
generator=(-G Ninja)
[[ -f build/release/CMakeCache.txt ]] && generator=()  # keep the tree's own generator
cmake "${generator[@]}" -S "${TAUT_ROOT}" -B build/release -DCMAKE_BUILD_TYPE=Release
taut_stage "Building taut-stress (-j${TAUT_JOBS})"
cmake --build build/release -j"${TAUT_JOBS}" --target taut-stress

stress="build/release/demos/taut-stress"
out=(--out docs/stress.md)
for arg in "$@"; do
  [[ "${arg}" == --out* ]] && out=()  # the caller names the file
done
machine="$(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //') ($(nproc) cores)"
taut_stage "Running ${stress} ${out[*]} $*"
start=${SECONDS}
nice "${stress}" "${out[@]}" --machine "${machine}" "$@"
taut_stage "Stress suite done in $((SECONDS - start)) s"
