#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# `hbvh export` and `hbvh view` end to end: each format from a hierarchy file and from a primitive set,
# the glTF through the Khronos validator when node and tools/node_modules have it, and the usage errors.
# Usage: cli_export.sh HBVH_BINARY SOURCE_DIR WORK_DIR
set -euo pipefail
hbvh=$1 source_dir=$2 work=$3
model="$source_dir/tests/browser/three_levels.xml"
rm -rf "$work" && mkdir -p "$work"
fail() { echo "cli_export: $*" >&2; exit 1; }

"$hbvh" export "$model" -o "$work/tree.dot"
grep -q '^digraph hbvh {' "$work/tree.dot" || fail "tree.dot is not a digraph"
grep -q 'ball' "$work/tree.dot" || fail "tree.dot lacks the primitive names"
"$hbvh" export "$model" -o "$work/levels.gltf"
grep -q '"name": "level 3"' "$work/levels.gltf" || fail "levels.gltf lacks level 3"
"$hbvh" export "$model" --format gltf -o - >"$work/stdout.gltf"
cmp -s "$work/levels.gltf" "$work/stdout.gltf" || fail "--format gltf -o - differs from the file output"
"$hbvh" view "$model" -o "$work/view.html"
grep -q 'id="hbvh-data"' "$work/view.html" || fail "view.html lacks its data"
if command -v dot >/dev/null; then
  "$hbvh" export "$model" -o "$work/tree.svg"
  grep -q '<svg' "$work/tree.svg" || fail "tree.svg is not SVG"
fi
# A primitive set is built first (the builder flags apply).
"$hbvh" export "$source_dir/data/models/chair.xml" -a two-level -o "$work/chair.gltf"
if command -v node >/dev/null && [ -d "$source_dir/tools/node_modules/gltf-validator" ]; then
  node "$source_dir/tools/validate_gltf.js" "$work/levels.gltf"
  node "$source_dir/tools/validate_gltf.js" "$work/chair.gltf"
fi

# Usage errors exit 2, bad input 1, and leave no output behind.
set +e
"$hbvh" export "$model" -o "$work/picture.png" 2>/dev/null; [ $? -eq 2 ] || fail "unknown extension should exit 2"
"$hbvh" export "$work/missing.xml" -o "$work/missing.gltf" 2>/dev/null; [ $? -eq 1 ] || fail "missing input should exit 1"
PATH=/nonexistent "$hbvh" export "$model" -o "$work/nodot.svg" 2>/dev/null; [ $? -eq 1 ] || fail "missing dot should exit 1"
set -e
[ ! -e "$work/nodot.svg" ] || fail "a failed export left a file"
echo "cli_export: ok"
