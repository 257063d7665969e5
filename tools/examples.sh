#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs hbvh from a build directory into a temporary prefix, builds every examples/*/ project against it (fresh
# build directories, find_package(hbvh CONFIG) through CMAKE_PREFIX_PATH only) and checks each program's output
# against an answer found without it. The ctest test install.examples (label install) runs it.
# Usage: tools/examples.sh BUILD_DIR [WORK_DIR (default: a temporary directory, removed afterwards)]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="$(cd "${1:?usage: tools/examples.sh BUILD_DIR [WORK_DIR]}" && pwd)"
if [ -n "${2:-}" ]; then
  work="$2"
  rm -rf "$work"
  mkdir -p "$work"
else
  work="$(mktemp -d /tmp/hbvh-examples.XXXXXX)"
  trap 'rm -rf "$work"' EXIT
fi
prefix="$work/prefix"
fail() { echo "examples: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$prefix" >"$work/install.log" || { cat "$work/install.log"; fail "install failed"; }
for f in include/hbvh/hbvh.hpp include/hbvh/version.hpp lib/cmake/hbvh/hbvhConfig.cmake \
         lib/cmake/hbvh/hbvhConfigVersion.cmake bin/hbvh; do
  [ -e "$prefix/$f" ] || fail "the install has no $f"
done

# The umbrella header names every installed public header (so that a new header cannot be forgotten there).
(cd "$prefix/include" && find hbvh -name '*.hpp' ! -name hbvh.hpp) | sort | while read -r header; do
  grep -q "^#include <$header>" "$prefix/include/hbvh/hbvh.hpp" ||
    fail "include/hbvh/hbvh.hpp does not include <$header>"
done

# The consumers use the compiler (and compiler launcher, e.g. ccache) of the hbvh build they link against.
cache_value() { sed -n "s/^$1:[A-Z]*=//p" "$build/CMakeCache.txt"; }
generator=()
command -v ninja >/dev/null 2>&1 && generator=(-G Ninja)
configure_args=(-DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release
                -DCMAKE_CXX_COMPILER="$(cache_value CMAKE_CXX_COMPILER)")
launcher="$(cache_value CMAKE_CXX_COMPILER_LAUNCHER)"
[ -z "$launcher" ] || configure_args+=(-DCMAKE_CXX_COMPILER_LAUNCHER="$launcher")

for example in "$root"/examples/*/; do
  name="$(basename "$example")"
  cmake -S "$example" -B "$work/$name" "${generator[@]}" "${configure_args[@]}" >"$work/$name.log" 2>&1 &&
    cmake --build "$work/$name" >>"$work/$name.log" 2>&1 || { cat "$work/$name.log"; fail "$name does not build"; }
  echo "examples: $name builds against the installed package"
done

# collide_model: the pair count and intersection flag from the installed CLI on the same pose, and the cost
# from hbvh stats on the hierarchy hbvh build writes (same builder, auto).
chair="$root/data/models/chair.xml"
out="$("$work/collide_model/collide_model" "$chair")" || fail "collide_model failed"
read -r hit pairs cost <<<"$out"
cli_json="$("$prefix/bin/hbvh" collide "$chair" "$chair" --pose-b "0.3 0 0 0.92 0 0.38 0" --json)"
"$prefix/bin/hbvh" build "$chair" -o "$work/chair.hbvh.xml"
stats_json="$("$prefix/bin/hbvh" stats "$work/chair.hbvh.xml" --json)"
python3 - "$hit" "$pairs" "$cost" "$cli_json" "$stats_json" <<'EOF'
import json, sys
hit, pairs, cost = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])
cli, stats = json.loads(sys.argv[4]), json.loads(sys.argv[5])
want = (1 if cli["intersecting"] else 0, len(cli["pairs"]))
if (hit, pairs) != want:
    sys.exit(f"examples: collide_model says {hit} {pairs}, hbvh collide --json says {want[0]} {want[1]}")
# The XML file stores volumes in decimal, so its cost may differ in the last digits.
if abs(cost - stats["cost"]) > 1e-9 * abs(stats["cost"]):
    sys.exit(f"examples: collide_model's cost {cost!r}, hbvh stats says {stats['cost']!r}")
print(f"examples: collide_model: {hit} {pairs} {cost} matches the CLI")
EOF

# core_only: its header comment works the answer out by hand: every primitive touches its own shifted copy only.
# The tree it stores and loads back into the query layout must answer the same.
expected="shifted 6 0-0 1-1 2-2 3-3 4-4 5-5
apart 0
loaded 6 0-0 1-1 2-2 3-3 4-4 5-5"
got="$("$work/core_only/core_only")" || fail "core_only failed"
[ "$(head -n 3 <<<"$got")" = "$expected" ] || fail "core_only printed
$got
expected
$expected"
echo "examples: core_only: $(tr '\n' ';' <<<"$got")"
echo "examples: all passed"
