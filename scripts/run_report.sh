#!/usr/bin/env bash
# Builds taut-report (Release, build/release or $TAUT_REPORT_BUILD) and runs the error-against-
# run-time report of every scene, on the dual and the primal solver path, into docs/report/ (one
# CSV, gnuplot script and PNG per scene) and docs/report.md:
#   scripts/run_report.sh [taut-report options]
# e.g. --quick (coarse sweep, about 10-15 minutes) or --scenes hex_beam,falling_sphere; see
# `build/release/demos/taut-report --help`. The full report takes about twice the 10-15 minutes of
# the dual-only one, or more on a shared machine.
set -euo pipefail
# shellcheck source-path=SCRIPTDIR source=build.sh
source "$(dirname "${BASH_SOURCE[0]}")/build.sh"
cd "${TAUT_ROOT}"

if [[ "${1:-}" == "-h" || "${1:-}" == "--help" ]]; then
  sed -n '2,8p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
  exit 0
fi

taut_stage "Installing dependencies"
taut_install_deps
build_dir="${TAUT_REPORT_BUILD:-build/release}"
taut_stage "Configuring ${build_dir}"
generator=(-G Ninja)
[[ -f "${build_dir}/CMakeCache.txt" ]] && generator=()  # keep the tree's own generator
cmake "${generator[@]}" -S "${TAUT_ROOT}" -B "${build_dir}" -DCMAKE_BUILD_TYPE=Release
taut_stage "Building taut-report (-j${TAUT_JOBS})"
cmake --build "${build_dir}" -j"${TAUT_JOBS}" --target taut-report

# The armadillo scene reads data/armadillo.off (Debian's libcgal-demo); without it the report says
# "not measured" for that scene.
taut_stage "Fetching the armadillo (scripts/fetch_armadillo.sh)"
bash scripts/fetch_armadillo.sh || echo "warning: armadillo download failed; the report skips it" >&2

report="${build_dir}/demos/taut-report"
taut_stage "Running ${report} --out docs/report $*"
start=${SECONDS}
nice "${report}" --out docs/report "$@"
taut_stage "Report written to docs/report.md and docs/report/ in $((SECONDS - start)) s"
