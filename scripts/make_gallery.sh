#!/usr/bin/env bash
# Regenerates the README gallery: runs every scene with --png into out/gallery/<scene>/ and copies
# its figure.png (the scene's key frames side by side, docs/pictures.md) to docs/gallery/<scene>.png.
#   scripts/make_gallery.sh [SCENE...]      (default: every scene of `taut-demo --list`)
# TAUT_DEMO=path/to/taut-demo uses that binary instead of building build/release.
# The limited tet scenes are slow today (a solver rewrite is under way), so they run shortened:
# tet_beam 240 of its 480 steps (1 s: the first swing, the largest sag), vertical_beam 60 of 120
# (every mode's first violation happens by step 25). Every image must stay under 150 kB.
set -euo pipefail
# shellcheck source-path=SCRIPTDIR source=build.sh
source "$(dirname "${BASH_SOURCE[0]}")/build.sh"
cd "${TAUT_ROOT}"

demo="${TAUT_DEMO:-}"
if [[ -z "${demo}" ]]; then
  taut_stage "Installing dependencies"
  taut_install_deps
  taut_build_release_demo
  demo="build/release/demos/taut-demo"
fi
bash scripts/fetch_armadillo.sh

scenes=("$@")
if ((${#scenes[@]} == 0)); then
  while read -r scene _; do
    [[ -n "${scene}" ]] && scenes+=("${scene}")
  done < <("${demo}" --list)
fi

declare -A gallery_steps=([tet_beam]=240 [vertical_beam]=60)
mkdir -p docs/gallery
failed=()
for scene in "${scenes[@]}"; do
  args=()
  if [[ -n "${gallery_steps[${scene}]:-}" ]]; then args=(--steps "${gallery_steps[${scene}]}"); fi
  taut_stage "${scene} ${args[*]} --png -> out/gallery/${scene}"
  if ! "${demo}" "${scene}" --png --out "out/gallery/${scene}" "${args[@]}" >/dev/null; then
    failed+=("${scene}")
    continue
  fi
  cp "out/gallery/${scene}/figure.png" "docs/gallery/${scene}.png"
  size=$(stat -c %s "docs/gallery/${scene}.png")
  echo "    docs/gallery/${scene}.png: $((size / 1024)) kB"
  if ((size > 150 * 1024)); then
    echo "error: docs/gallery/${scene}.png is over 150 kB" >&2
    failed+=("${scene}")
  fi
done
if ((${#failed[@]} > 0)); then
  echo "==> failed: ${failed[*]}" >&2
  exit 1
fi
taut_stage "Gallery: docs/gallery/ (${#scenes[@]} scene(s))"
