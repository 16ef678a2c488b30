#!/usr/bin/env bash
# Installs what the demos need, fetches the armadillo, builds taut-demo (Release, build/release;
# only the demo binary and the libraries it links, no tests or benchmarks) and runs every scene
# that `taut-demo --list` names:
#   scripts/run_demos.sh [--quick] [--steps N] [OUT_DIR]   (default OUT_DIR: out/demos)
#     --quick    every scene for 3 steps with --vtk: checks the set-up in about a minute (CI)
#     --steps N  every scene for N steps instead of its default
# Each scene writes OUT_DIR/<scene>/summary.json, steps.csv (plus VTK frames and their ParaView
# collections with --quick) and prints a short report. Exits non-zero if any scene fails; the
# other scenes still run; a scene skipped for missing data (the armadillo when it cannot be
# fetched) fails the command only with TAUT_REQUIRE_ALL_SCENES=1 (as in CI). Honours TAUT_JOBS
# (parallel build jobs, default 2).
set -euo pipefail
# shellcheck source-path=SCRIPTDIR source=build.sh
source "$(dirname "${BASH_SOURCE[0]}")/build.sh"

usage() {
  sed -n '2,12p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
}

steps=""
extra=()
out_arg=""
while (($# > 0)); do
  case "$1" in
    --quick)
      steps=3
      extra+=(--vtk)
      ;;
    --steps)
      if (($# < 2)) || ! [[ "$2" =~ ^[1-9][0-9]*$ ]]; then
        echo "error: --steps needs a positive whole number" >&2
        exit 2
      fi
      steps="$2"
      shift
      ;;
    -h | --help)
      usage
      exit 0
      ;;
    -*)
      echo "error: unknown option '$1' (use --quick, --steps N or an output folder)" >&2
      exit 2
      ;;
    *)
      if [[ -n "${out_arg}" ]]; then
        echo "error: more than one output folder ('${out_arg}', '$1')" >&2
        exit 2
      fi
      out_arg="$1"
      ;;
  esac
  shift
done
# A relative OUT_DIR is taken from the caller's directory, before we move to the repo root.
out_dir="${out_arg:-${TAUT_ROOT}/out/demos}"
mkdir -p "${out_dir}"
out_dir="$(cd "${out_dir}" && pwd)"
cd "${TAUT_ROOT}"

timings=()
mark=${SECONDS}
# Records the wall time since the last mark under a name.
record() {
  timings+=("$1 $((SECONDS - mark))s")
  mark=${SECONDS}
}

taut_stage "Installing dependencies"
taut_install_deps
# The armadillo scan is data Debian ships but we do not commit; without it that scene is skipped.
have_armadillo=1
taut_stage "Fetching the armadillo (scripts/fetch_armadillo.sh)"
bash scripts/fetch_armadillo.sh || have_armadillo=0
record deps
taut_build_release_demo
record build

demo="build/release/demos/taut-demo"
if [[ ! -x "${demo}" ]]; then
  echo "error: ${demo} was not built (is TAUT_BUILD_DEMOS on and demos/ populated?)" >&2
  exit 1
fi
taut_fix_openblas_coretype "${demo}"
# Pictures, when this taut-demo can render them.
if "${demo}" --help | grep -q -- '--png'; then extra+=(--png); fi

taut_stage "Listing scenes (${demo} --list)"
scene_list="$("${demo}" --list)"
scenes=()
while read -r scene _; do
  [[ -z "${scene}" || "${scene}" == \#* ]] && continue
  scenes+=("${scene}")
done <<<"${scene_list}"
if ((${#scenes[@]} == 0)); then
  echo "error: ${demo} --list named no scenes" >&2
  exit 1
fi
taut_stage "${#scenes[@]} scene(s): ${scenes[*]}"

run_args=("${extra[@]}")
if [[ -n "${steps}" ]]; then run_args+=(--steps "${steps}"); fi
failed=()
skipped=()
for scene in "${scenes[@]}"; do
  if [[ "${scene}" == armadillo ]] && ((have_armadillo == 0)); then
    echo "==> ${scene} SKIPPED: data/armadillo.off could not be fetched (needs apt access to" \
      "Debian's libcgal-demo); run scripts/fetch_armadillo.sh, then this command again" >&2
    skipped+=("${scene}")
    continue
  fi
  taut_stage "Running ${demo} ${scene} --out ${out_dir}/${scene} ${run_args[*]}"
  start=${SECONDS}
  rc=0
  "${demo}" "${scene}" --out "${out_dir}/${scene}" "${run_args[@]}" || rc=$?
  if ((rc == 0)); then
    taut_stage "${scene} done in $((SECONDS - start))s"
  else
    echo "==> ${scene} FAILED (exit ${rc}) after $((SECONDS - start))s" >&2
    failed+=("${scene}")
  fi
done
record scenes

taut_stage "Summaries:"
for scene in "${scenes[@]}"; do
  summary="${out_dir}/${scene}/summary.json"
  if [[ -f "${summary}" ]]; then
    echo "    ${summary}"
  else
    echo "    ${summary} (missing)"
  fi
done
line=""
for t in "${timings[@]}"; do line+="${line:+, }${t}"; done
taut_stage "Stage times: ${line}"
if ((${#skipped[@]} > 0)); then
  echo "==> ${#skipped[@]} scene(s) skipped: ${skipped[*]}" >&2
  if [[ "${TAUT_REQUIRE_ALL_SCENES:-0}" == 1 ]]; then
    echo "==> TAUT_REQUIRE_ALL_SCENES=1: a skipped scene is a failure" >&2
    exit 1
  fi
fi
if ((${#failed[@]} > 0)); then
  echo "==> ${#failed[@]} scene(s) failed: ${failed[*]}" >&2
  exit 1
fi
taut_stage "All $((${#scenes[@]} - ${#skipped[@]})) scene(s) ran"
