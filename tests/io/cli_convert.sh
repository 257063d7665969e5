#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# `hbvh convert` end to end: MJCF, URDF and meshes to survey XML, the plain-mesh option, and that the output
# reads back as a primitive set. Usage: cli_convert.sh HBVH_BINARY SOURCE_DIR WORK_DIR
set -euo pipefail
hbvh=$1 data=$2/tests/io/data work=$3
rm -rf "$work" && mkdir -p "$work"
fail() { echo "cli_convert: $*" >&2; exit 1; }
volumes() { grep -c '<volume' "$1"; }

for input in mjcf_defaults.xml urdf_chain.urdf mesh_collision_convention.obj mesh_collision_convention.gltf; do
  "$hbvh" convert "$data/$input" -o "$work/$input.out.xml" 2>"$work/$input.err" || fail "$input: convert failed"
  [ "$(volumes "$work/$input.out.xml")" -gt 0 ] || fail "$input: no volumes written"
  "$hbvh" stats "$work/$input.out.xml" --json >/dev/null || fail "$input: the output does not read back"
done

# A plain mesh is refused without the option (exit 1, the option named), and with it gives one volume per mesh node.
if "$hbvh" convert "$data/mesh_plain.gltf" -o "$work/plain.xml" 2>"$work/plain.err"; then fail "plain mesh accepted"; fi
[ ! -e "$work/plain.xml" ] || fail "a refused conversion left an output file"
grep -q -- "--format mesh-nodes" "$work/plain.err" || fail "the refusal does not name --format mesh-nodes"
"$hbvh" convert "$data/mesh_plain.gltf" --format mesh-nodes -o "$work/plain.xml"
nodes=$(grep -o '"mesh" *: *[0-9]*' "$data/mesh_plain.gltf" | wc -l)
[ "$(volumes "$work/plain.xml")" -eq "$nodes" ] || fail "mesh-nodes: $(volumes "$work/plain.xml") volumes for $nodes mesh nodes"

# An unknown --format is bad input naming the choices.
if "$hbvh" convert "$data/mesh_plain.gltf" --format stl -o - 2>"$work/format.err"; then fail "unknown format accepted"; fi
grep -q "mesh-nodes" "$work/format.err" || fail "unknown format: the message does not list the formats"
echo "cli_convert: ok"
