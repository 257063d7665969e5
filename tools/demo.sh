#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The main job: install, build everything (library, CLI, tests, benchmarks), then build a hierarchy over the bundled Tie-Interceptor model and print
# its build report and quality measures.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DHBVH_UNITY_BUILD=ON >/dev/null
cmake --build build
model=${1:-data/models/tie_interceptor.xml}
out=build/demo/$(basename "${model%.xml}").hbvh.xml
mkdir -p build/demo
./build/apps/hbvh/hbvh build "$model" --report --stats -o "$out"
./build/apps/hbvh/hbvh stats "$out"
echo "hierarchy written to $out"
