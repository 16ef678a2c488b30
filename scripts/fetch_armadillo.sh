#!/usr/bin/env bash
# Fetches the Stanford armadillo (Stanford 3D Scanning Repository) as shipped in Debian's
# libcgal-demo package into data/armadillo.off. Idempotent; the scan is never committed.
#   scripts/fetch_armadillo.sh [OUT_FILE]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:-${root}/data/armadillo.off}"
if [[ -s "${out}" ]]; then
  echo "==> ${out} already present"
  exit 0
fi
work="$(mktemp -d)"
trap 'rm -rf "${work}"' EXIT
echo "==> Downloading Debian package libcgal-demo (for data/meshes/armadillo.off)"
(cd "${work}" && apt-get download libcgal-demo >/dev/null 2>&1 || {
  apt-get update -q >/dev/null && apt-get download libcgal-demo >/dev/null
})
mkdir -p "$(dirname "${out}")"
echo "==> Extracting armadillo.off into ${out}"
dpkg-deb --fsys-tarfile "${work}"/libcgal-demo_*.deb |
  tar -xO ./usr/share/doc/libcgal-dev/data.tar.gz |
  tar -xzO data/meshes/armadillo.off >"${out}.tmp"
mv "${out}.tmp" "${out}"
echo "==> $(head -c 200 "${out}" | sed -n 2p | awk '{print $1" vertices, "$2" faces"}')"
