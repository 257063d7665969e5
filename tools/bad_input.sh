#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Runs `hbvh build` on every bad or degenerate input in tests/cli/inputs/ (survey XML) and tests/cli/inputs/import/
# (MJCF, URDF, meshes) plus a few generated at run time (10^6 coincident spheres) and prints a markdown table:
# input, exit code, wall time, first stderr line.
# Usage: tools/bad_input.sh [path/to/hbvh] > docs/bad-input.md
set -uo pipefail
cd "$(dirname "$0")/.."
cli="${1:-build/apps/hbvh/hbvh}"
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT

# Generated inputs are too big to commit.
python3 - "$scratch/coincident_1e6_spheres.xml" <<'PY'
import sys
with open(sys.argv[1], "w") as f:
    f.write("<hierarchy>\n")
    f.write('<volume type="sphere" pos="0 0 0" radius="1"/>\n' * 1000000)
    f.write("</hierarchy>\n")
PY

run() {  # run <label> <args...>
  local label="$1"; shift
  local start end code first
  start=$(date +%s%N)
  timeout 600 "$cli" "$@" -o "$scratch/out.xml" >/dev/null 2>"$scratch/err"
  code=$?
  end=$(date +%s%N)
  # The first line that is not a warning (warnings come first), else the first line; scratch paths shortened.
  first="$( (grep -v -m 1 ': warning: ' "$scratch/err" || head -n 1 "$scratch/err") | sed -e "s|$scratch|<scratch>|g" -e 's/|/\\|/g' | cut -c1-170)"
  [[ -n "$first" ]] || first="(none)"
  printf '| %s | %s | %d.%03d | `%s` |\n' "$label" "$code" $(((end - start) / 1000000000)) \
    $((((end - start) / 1000000) % 1000)) "$first"
}

echo "| input | exit | seconds | first line of stderr |"
echo "|---|---:|---:|---|"
for input in tests/cli/inputs/*.xml tests/cli/inputs/import/*; do
  run "${input#tests/cli/inputs/}" build "$input"
done
run "coincident_1e6_spheres.xml (generated)" build "$scratch/coincident_1e6_spheres.xml"
run "missing file" build "$scratch/does-not-exist.xml"
run "directory as input" build "$scratch"
run "unknown --format" build data/models/chair.xml --format obj
run "unknown algorithm" build data/models/chair.xml -a no-such-builder
run "empty stdin" build - < /dev/null
