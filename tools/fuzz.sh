#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Builds the libFuzzer targets in fuzz/ with Debian 12's clang-16 into build-fuzz/ (clang 14 cannot compile
# src/fit: it lacks C++20 lambda captures of structured bindings) and runs each from its seed corpus
# fuzz/corpus/<target>/ with the dictionary fuzz/dict/<target>.dict.
# Fails on any crash, leak, timeout, out-of-memory or sanitizer report.
# Usage: tools/fuzz.sh [seconds] [target...]   explore for N seconds per target (default 20), random seed
#        tools/fuzz.sh --ci [target...]         what CI runs: a fixed seed and a fixed number of inputs per target,
#                                               so every run is as long and a failure's input is kept to replay
#                                               (docs/reliability.md §3); new bugs are hunted with the timed mode.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=timed
seconds=20
if [ "${1:-}" = "--ci" ]; then
  mode=ci
  shift
elif [ $# -gt 0 ]; then
  seconds="$1"
  shift
fi
# Inputs per target in --ci mode: about 10 s each on the 2-core CI machine (the readers differ 100x in speed;
# collide builds two hierarchies and runs two queries per input, about 15 s).
declare -A ci_runs=([collide]=1200 [gltf]=1500 [mjcf]=15000 [obj]=300 [ply]=2500 [urdf]=20000 [xml]=150000 [binary]=400000)
# -O1 and line tables only: the targets compiled in 191 s at RelWithDebInfo's -O2 -g and in 120 s so, and the
# fixed-count runs took 82 s one after another against 75 s (docs/reliability.md §1); line tables are all a
# sanitizer's stack needs.
cmake -S fuzz -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" -DCMAKE_CXX_COMPILER=clang++-16 >/dev/null
cmake --build build-fuzz
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for fuzzer in build-fuzz/fuzz_*; do
    [[ -x "$fuzzer" && -f "$fuzzer" ]] && targets+=("${fuzzer##*/fuzz_}")
  done
fi
# Leaks inside assimp and urdfdom are suppressed (each is described in fuzz/lsan.supp); stacks are symbolised with
# llvm-symbolizer when installed, else binutils' addr2line.
export LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
symbolizer="$(command -v llvm-symbolizer || command -v addr2line || true)"
[ -z "$symbolizer" ] || export ASAN_SYMBOLIZER_PATH="${ASAN_SYMBOLIZER_PATH:-$symbolizer}"
# One target per core: each fuzzer is single-threaded, and the targets share nothing but the machine (their inputs
# and logs are per target), so running them side by side halves the phase on two cores; each still runs its fixed
# seed and count. The summaries are printed once all have ended, in the targets' order, so no lines interleave.
jobs="${HBVH_FUZZ_JOBS:-$(nproc)}"
run_target() {
  local target="$1"
  local fuzzer="build-fuzz/fuzz_$target"
  # New inputs go to a scratch copy so the committed seed corpus stays small and reviewed.
  local work="build-fuzz/corpus-$target"
  rm -f "build-fuzz/fuzz_$target.summary"
  mkdir -p "$work" "build-fuzz/artifacts-$target"
  local dict=()
  [ -f "fuzz/dict/$target.dict" ] && dict=(-dict="fuzz/dict/$target.dict")
  local budget limit heading
  if [ "$mode" = ci ]; then
    budget=(-seed=1 -runs="${ci_runs[$target]:-2000}")
    limit=600
    # A fresh scratch corpus, so the run depends on the commit only.
    rm -rf "$work" && mkdir -p "$work"
    heading="== fuzz_$target: ${ci_runs[$target]:-2000} inputs, seed 1"
  else
    budget=(-max_total_time="$seconds")
    limit=$((seconds + 60))
    heading="== fuzz_$target for ${seconds}s"
  fi
  # -timeout: one input taking over 10 s is a hang; -rss_limit_mb also caps single allocations (malloc_limit_mb).
  # The outer timeout is a backstop: libFuzzer's own hang report can deadlock in its alarm handler (seen with
  # clang 16 when the hang is inside an allocation), and CI must not wait forever.
  if ! timeout -k 10 "$limit" "$fuzzer" "${budget[@]}" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 "${dict[@]}" \
      -artifact_prefix="build-fuzz/artifacts-$target/" "$work" "fuzz/corpus/$target" \
      >"build-fuzz/fuzz_$target.log" 2>&1; then
    { echo "$heading"
      echo "fuzz_$target FAILED: see build-fuzz/fuzz_$target.log and build-fuzz/artifacts-$target/"
      tail -n 40 "build-fuzz/fuzz_$target.log"; } >"build-fuzz/fuzz_$target.summary"
    return 1
  fi
  { echo "$heading"
    grep -E "stat::number_of_executed_units|stat::new_units_added" "build-fuzz/fuzz_$target.log" || true; } \
    >"build-fuzz/fuzz_$target.summary"
}
status=0
running=0
for target in "${targets[@]}"; do
  if [ "$running" -ge "$jobs" ]; then
    wait -n || status=1
    running=$((running - 1))
  fi
  run_target "$target" &
  running=$((running + 1))
done
while [ "$running" -gt 0 ]; do
  wait -n || status=1
  running=$((running - 1))
done
for target in "${targets[@]}"; do
  cat "build-fuzz/fuzz_$target.summary" 2>/dev/null || { echo "fuzz_$target: ended without a summary"; status=1; }
done
exit "$status"
