#!/usr/bin/env bash
# Installs every build and test dependency from Debian 12 packages. Idempotent: it installs only
# what is missing, and does nothing (quickly) when all is present. Needs root (or sudo).
set -euo pipefail
PACKAGES=(
  build-essential cmake ninja-build git pkg-config
  libembree-dev libtbb-dev libcgal-dev libopenmesh-dev libtinygltf-dev libmeshoptimizer-dev
  libopenimageio-dev openimageio-tools libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev nlohmann-json3-dev libfmt-dev libstb-dev librecast-dev
  python3 python3-matplotlib python3-numpy help2man
  python3-dev python3-pybind11 pybind11-dev python3-pytest
  clang libclang-rt-14-dev clang-format
)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# Optional, not installed from Debian (nodejs + npm pull hundreds of packages): when node and npm
# are already present, the Khronos glTF validator for GltfExport.KhronosValidatorFindsNoError...
# (that test skips without it).
if command -v node > /dev/null && command -v npm > /dev/null &&
  ! NODE_PATH="$(npm root -g)" node -e "require('gltf-validator')" 2> /dev/null; then
  npm install -g gltf-validator > /dev/null 2>&1 || echo "install-deps: npm install -g gltf-validator failed (its test will skip)"
fi
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
