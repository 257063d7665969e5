#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds everything with AddressSanitizer + UndefinedBehaviorSanitizer in build-asan/ and runs the test suite.
# Usage: tools/sanitize.sh [ctest arguments...]
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHBVH_SANITIZE=ON \
  -DHBVH_WARNINGS_AS_ERRORS=ON -DHBVH_ENABLE_ASSERTS=ON -DHBVH_BUILD_BENCH=OFF >/dev/null
cmake --build build-asan
# Leaks fail the run too (except inside assimp and urdfdom, fuzz/lsan.supp); halt_on_error makes the first
# report fatal so ctest sees it.
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$PWD/fuzz/lsan.supp:print_suppressions=0}"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:halt_on_error=1:abort_on_error=1:quarantine_size_mb=64}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
ctest --test-dir build-asan --output-on-failure -j2 "$@"
