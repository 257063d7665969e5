#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs the Debian 12 packages hbvh builds and tests with. Safe to run twice: it asks apt only for
# what is missing, and refreshes the package lists only when something is.
set -euo pipefail
packages=(
  cmake ninja-build g++ pkg-config python3 ccache
  libeigen3-dev libpugixml-dev libcli11-dev nlohmann-json3-dev libfmt-dev
  libcgal-dev libqhull-dev libtbb-dev libnanoflann-dev
  libgtest-dev libgmock-dev libbenchmark-dev libccd-dev
  libmujoco-dev libmujoco-samples liburdfdom-dev libassimp-dev
  libbullet-dev libfcl-dev libembree-dev graphviz
  chromium
  clang-16 libclang-rt-16-dev
  pybind11-dev python3-dev python3-numpy python3-pytest
)
missing=()
# Node may come from elsewhere than Debian (its npm then comes with it): ask Debian only when absent.
command -v npm >/dev/null 2>&1 || packages+=(nodejs npm)
for package in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" || missing+=("$package")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The Khronos glTF validator, pinned by tools/package-lock.json (npm registry only).
if [ ! -d "$(dirname "$0")/node_modules/gltf-validator" ]; then
  npm ci --prefix "$(dirname "$0")" --no-audit --no-fund --loglevel=error
fi
