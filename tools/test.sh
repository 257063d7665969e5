#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The README's test command and what CI runs: installs, builds everything with warnings as errors, assertions on
# and AddressSanitizer + UndefinedBehaviorSanitizer, runs the whole test suite under the sanitizers, then runs
# each libFuzzer target briefly (tools/fuzz.sh). Usage: tools/test.sh [--ci (default: fixed seed and inputs) or fuzz seconds per target]
set -euo pipefail
cd "$(dirname "$0")/.."
fuzz_mode="${1:---ci}"
phase() { printf '== %s (%s s since start)\n' "$1" "$SECONDS"; }

phase "install dependencies"
bash tools/install-deps.sh
phase "build (gcc, ASan + UBSan)"
# -g1 (line tables, enough for sanitizer stacks) compiles about a third faster than -g. -O1 would compile faster
# still but doubled the suite's run time (831 s against ~430 s), which the exponential builders' tests dominate;
# so only the programs that drive the libraries (tests, CLI, Python module) drop to -O1 (hbvh_driver_optimisation).
cmake -S . -B build-test -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
  -DHBVH_WARNINGS_AS_ERRORS=ON -DHBVH_ENABLE_ASSERTS=ON -DHBVH_SANITIZE=ON -DHBVH_UNITY_BUILD=ON >/dev/null
cmake --build build-test
phase "test suite under the sanitizers"
# The first report is fatal, so ctest sees it; leaks fail too, except inside assimp and urdfdom (fuzz/lsan.supp).
# A 64 MB quarantine (ASan's default is 256) keeps freed memory poisoned long enough for these small tests and
# cut the fitters' time under ASan by a fifth: fewer fresh pages to fault in (docs/reliability.md §2).
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$PWD/fuzz/lsan.supp:print_suppressions=0}"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:halt_on_error=1:abort_on_error=1:quarantine_size_mb=64}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
ctest --test-dir build-test --output-on-failure -j2
phase "fuzz ($fuzz_mode)"
bash tools/fuzz.sh "$fuzz_mode"
phase "done"
