#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs, builds everything with warnings as errors and assertions on, and runs the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install-deps.sh
cmake -S . -B build-test -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DHBVH_WARNINGS_AS_ERRORS=ON -DHBVH_ENABLE_ASSERTS=ON >/dev/null
cmake --build build-test
ctest --test-dir build-test --output-on-failure -j2
