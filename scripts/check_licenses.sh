#!/usr/bin/env bash
# Fails when a build links GPL code: inspects the link lines of BUILD_DIR (build.ninja) and the
# shared libraries (`ldd`) of every executable and shared object built there.
#   scripts/check_licenses.sh [BUILD_DIR]   (default build/release)
# GPL libraries looked for: SuiteSparse's CHOLMOD (its supernodal module is GPL-2+), UMFPACK and
# SPQR (GPL-2+), GSL, FFTW, readline, and anything named *gpl*. The GCC runtime (libstdc++,
# libgcc_s, libgomp: GPL-3 with the runtime library exception) is not GPL-bound and not matched.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
dir="${1:-${root}/build/release}"
if [[ ! -f "${dir}/build.ninja" ]]; then
  echo "error: ${dir}/build.ninja not found (build the tree first)" >&2
  exit 2
fi
gpl='lib(cholmod|umfpack|spqr|gsl|gslcblas|fftw3[a-z_]*|readline)[.-]|gpl'
found=0

echo "==> Link lines of ${dir}/build.ninja"
if grep -E '^ *LINK_LIBRARIES *=' "${dir}/build.ninja" | grep -Eiq "${gpl}|-l(cholmod|umfpack|spqr|gsl|fftw3|readline)\b"; then
  echo "error: a GPL library is on a link line of ${dir}:" >&2
  grep -E '^ *LINK_LIBRARIES *=' "${dir}/build.ninja" |
    grep -Eio "[^ ]*(${gpl}|-l(cholmod|umfpack|spqr|gsl|fftw3|readline)\b)[^ ]*" | sort -u >&2
  found=1
fi

binaries=()
while IFS= read -r -d '' f; do
  if head -c 4 "${f}" | grep -q 'ELF'; then binaries+=("${f}"); fi
done < <(find "${dir}" -type f \( -perm -u+x -o -name '*.so*' \) ! -path '*/CMakeFiles/*' -print0)
echo "==> ldd of ${#binaries[@]} binaries in ${dir}"
for f in "${binaries[@]}"; do
  if libs="$(ldd "${f}" 2>/dev/null | grep -Ei "${gpl}")"; then
    echo "error: ${f#"${root}"/} links GPL code:" >&2
    echo "${libs}" >&2
    found=1
  fi
done
if ((${#binaries[@]} == 0)); then
  echo "error: no binaries found in ${dir}" >&2
  exit 1
fi
if ((found)); then
  echo "==> check_licenses.sh FAILED: ${dir} links GPL code (is TAUT_WITH_CHOLMOD on?)" >&2
  exit 1
fi
echo "==> No GPL library linked by ${dir}"
