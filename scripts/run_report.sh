#!/usr/bin/env bash
# Builds taut-report (Release, build/release) and runs the error-against-run-time report of every
# scene into docs/report/ (one CSV, gnuplot script and PNG per scene) and docs/report.md:
#   scripts/run_report.sh [taut-report options]
# e.g. --quick (coarse sweep, minutes) or --scenes hex_beam,falling_sphere; see
# `build/release/demos/taut-report --help`. The full report takes 10-15 minutes on one core.
set -euo pipefail
# shellcheck source-path=SCRIPTDIR source=build.sh
source "$(dirname "${BASH_SOURCE[0]}")/build.sh"
cd "${TAUT_ROOT}"

if [[ "${1:-}" == "-h" || "${1:-}" == "--help" ]]; then
  sed -n '2,6p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
  exit 0
fi

taut_stage "Installing dependencies"
taut_install_deps
taut_stage "Configuring build/release"
generator=(-G Ninja)
[[ -f build/release/CMakeCache.txt ]] && generator=()  # keep the tree's own generator
cmake "${generator[@]}" -S "${TAUT_ROOT}" -B build/release -DCMAKE_BUILD_TYPE=Release
taut_stage "Building taut-report (-j${TAUT_JOBS})"
cmake --build build/release -j"${TAUT_JOBS}" --target taut-report

report="build/release/demos/taut-report"
taut_stage "Running ${report} --out docs/report $*"
start=${SECONDS}
nice "${report}" --out docs/report "$@"
taut_stage "Report written to docs/report.md and docs/report/ in $((SECONDS - start)) s"
