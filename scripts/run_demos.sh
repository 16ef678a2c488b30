#!/usr/bin/env bash
# Builds the Release tree and runs every scene that `taut-demo --list` names.
#   scripts/run_demos.sh [OUT_DIR]     (default out/demos under the repository root)
# Each scene writes OUT_DIR/<scene>/summary.json (plus its CSV and optional frames).
# Exits non-zero if any scene fails; the other scenes still run.
set -euo pipefail
# shellcheck source-path=SCRIPTDIR source=build.sh
source "$(dirname "${BASH_SOURCE[0]}")/build.sh"

if (($# > 1)); then
  echo "usage: $0 [OUT_DIR]" >&2
  exit 2
fi
# A relative OUT_DIR is taken from the caller's directory, before we move to the repo root.
out_dir="${1:-${TAUT_ROOT}/out/demos}"
mkdir -p "${out_dir}"
out_dir="$(cd "${out_dir}" && pwd)"
cd "${TAUT_ROOT}"

taut_stage "Installing dependencies"
taut_install_deps
taut_build_release

demo="build/release/demos/taut-demo"
if [[ ! -x "${demo}" ]]; then
  echo "error: ${demo} was not built (is TAUT_BUILD_DEMOS on and demos/ populated?)" >&2
  exit 1
fi

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

failed=()
for scene in "${scenes[@]}"; do
  taut_stage "Running ${scene} -> ${out_dir}/${scene}"
  start=${SECONDS}
  rc=0
  "${demo}" "${scene}" --out "${out_dir}/${scene}" || rc=$?
  if ((rc == 0)); then
    taut_stage "${scene} done in $((SECONDS - start))s"
  else
    echo "==> ${scene} FAILED (exit ${rc}) after $((SECONDS - start))s" >&2
    failed+=("${scene}")
  fi
done

taut_stage "Summaries:"
for scene in "${scenes[@]}"; do
  summary="${out_dir}/${scene}/summary.json"
  if [[ -f "${summary}" ]]; then
    echo "    ${summary}"
  else
    echo "    ${summary} (missing)"
  fi
done
if ((${#failed[@]} > 0)); then
  echo "==> ${#failed[@]} scene(s) failed: ${failed[*]}" >&2
  exit 1
fi
taut_stage "All ${#scenes[@]} scene(s) ran"
