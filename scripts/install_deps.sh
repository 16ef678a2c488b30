#!/usr/bin/env bash
# Installs the Debian 12 packages taut needs to build, test and run its demos.
# Idempotent: asks dpkg which packages are missing and only then runs apt-get (as root, no sudo).
set -euo pipefail

# Every Debian package the project needs; extend here.
PACKAGES=(
  build-essential
  cmake
  ninja-build
  pkg-config
  ccache
  git
  libbullet-dev
  libeigen3-dev
  libgtest-dev
  libgmock-dev
  libbenchmark-dev
  libcli11-dev
  nlohmann-json3-dev
  libfcl-dev
  libccd-dev
  libtinyobjloader-dev
  libmetis-dev
  # CHOLMOD and a serial BLAS, only for the opt-in -DTAUT_WITH_CHOLMOD=ON build (GPL-2+), which
  # scripts/run_tests.sh builds and tests in build/cholmod; the default build does not link them.
  libsuitesparse-dev
  libopenblas0-serial
  libstb-dev
  gnuplot-nox
  clang
  libclang-rt-dev
  clang-format
)

cd "$(dirname "${BASH_SOURCE[0]}")/.."

# Succeeds when dpkg reports the package as installed.
is_installed() {
  [[ "$(dpkg-query -W -f='${db:Status-Status}' "$1" 2>/dev/null)" == "installed" ]]
}

echo "==> Checking ${#PACKAGES[@]} Debian packages"
missing=()
for pkg in "${PACKAGES[@]}"; do
  is_installed "${pkg}" || missing+=("${pkg}")
done

if ((${#missing[@]} == 0)); then
  echo "==> All packages already installed; nothing to do"
  exit 0
fi

echo "==> Missing: ${missing[*]}"
if ((EUID != 0)); then
  echo "error: installing packages needs root; run this script as root" >&2
  exit 1
fi
echo "==> apt-get update"
apt-get update
echo "==> apt-get install ${missing[*]}"
DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
echo "==> Installed ${#missing[@]} package(s)"
