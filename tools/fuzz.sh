#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds the libFuzzer targets in fuzz/ with clang into build-fuzz/ and runs each for N seconds
# (default 20). Fails on any crash, leak, timeout or sanitizer report. Usage: tools/fuzz.sh [seconds]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-20}"
cmake -S fuzz -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ >/dev/null
cmake --build build-fuzz
status=0
for fuzzer in build-fuzz/fuzz_*; do
  [[ -x "$fuzzer" && -f "$fuzzer" ]] || continue
  target="${fuzzer##*/fuzz_}"
  # New inputs go to a scratch copy so the committed seed corpus stays small and reviewed.
  work="build-fuzz/corpus-$target"
  mkdir -p "$work" "build-fuzz/artifacts-$target"
  echo "== fuzz_$target for ${seconds}s"
  if ! "$fuzzer" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="build-fuzz/artifacts-$target/" "$work" "fuzz/corpus/$target" \
      >"build-fuzz/fuzz_$target.log" 2>&1; then
    echo "fuzz_$target FAILED: see build-fuzz/fuzz_$target.log and build-fuzz/artifacts-$target/"
    tail -n 40 "build-fuzz/fuzz_$target.log"
    status=1
  else
    grep -E "stat::number_of_executed_units|stat::new_units_added" "build-fuzz/fuzz_$target.log" || true
  fi
done
exit "$status"
