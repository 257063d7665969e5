#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The .hbvh binary format through the CLI: build, convert and generate write it by extension, every command reads it
# (by extension, or by its magic bytes on stdin), stats and collide on it equal stats and collide on the same
# tree as XML, and a truncated, corrupted or non-enclosing binary file is refused like a bad XML one.
# Usage: binary_format.sh HBVH_BINARY SOURCE_DIR WORK_DIR
set -euo pipefail
hbvh=$1 source_dir=$2 work=$3
model="$source_dir/data/models/chair.xml"
[ -f "$model" ] || { echo "binary_format: shipped model $model is missing" >&2; exit 1; }
rm -rf "$work" && mkdir -p "$work"
fail() { echo "binary_format: $*" >&2; exit 1; }
pose="0.3 0.1 0 0.92 0 0.38 0"

# The same split tree as binary and as XML.
"$hbvh" build "$model" -a split -o "$work/chair.hbvh"
"$hbvh" build "$model" -a split -o "$work/chair.xml"
head -c 8 "$work/chair.hbvh" | od -An -tx1 | grep -q '89 48 42 56 48 0d 0a 1a' || fail "chair.hbvh does not start with the magic"

# stats: the same numbers (the file name aside), in text and JSON.
"$hbvh" stats "$work/chair.hbvh" | sed 's/chair\.hbvh/FILE/g' >"$work/stats_binary.txt"
"$hbvh" stats "$work/chair.xml" | sed 's/chair\.xml/FILE/g' >"$work/stats_xml.txt"
diff "$work/stats_binary.txt" "$work/stats_xml.txt" || fail "stats on .hbvh differ from stats on the XML"
"$hbvh" stats "$work/chair.hbvh" --json | sed 's/chair\.hbvh/FILE/g' >"$work/stats_binary.json"
"$hbvh" stats "$work/chair.xml" --json | sed 's/chair\.xml/FILE/g' >"$work/stats_xml.json"
# JSON prints full precision, and reading XML re-orthonormalises rotations (the last bit may change): equal to 1e-9.
python3 - "$work/stats_binary.json" "$work/stats_xml.json" <<'PY' || fail "stats --json on .hbvh differ from the XML's"
import json, sys
def same(a, b):
    if isinstance(a, dict): return isinstance(b, dict) and a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list): return isinstance(b, list) and len(a) == len(b) and all(map(same, a, b))
    if isinstance(a, float) or isinstance(b, float): return abs(a - b) <= 1e-9 * max(1.0, abs(a), abs(b))
    return a == b
sys.exit(0 if same(json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))) else 1)
PY

# collide: the XML numbers its primitives in tree order, the binary file keeps the input order. So the binary
# file equals a query over the input (built the same way), and the XML equals the binary file converted from it.
"$hbvh" collide "$work/chair.hbvh" "$work/chair.hbvh" --pose-b "$pose" --json >"$work/collide_binary.json"
"$hbvh" collide "$model" "$model" -a split --pose-b "$pose" --json >"$work/collide_input.json"
diff "$work/collide_binary.json" "$work/collide_input.json" || fail "collide on .hbvh differs from collide on the input"
python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); assert r["intersecting"] and r["pairs"], r' \
  "$work/collide_binary.json" || fail "the pose should make the chairs touch"
"$hbvh" convert "$work/chair.xml" -o "$work/from_xml.hbvh"
"$hbvh" collide "$work/from_xml.hbvh" "$work/from_xml.hbvh" --pose-b "$pose" --json >"$work/collide_from_xml.json"
"$hbvh" collide "$work/chair.xml" "$work/chair.xml" --pose-b "$pose" --json >"$work/collide_xml.json"
diff "$work/collide_from_xml.json" "$work/collide_xml.json" || fail "collide on converted .hbvh differs from the XML"

# convert back to XML gives the build's own XML, byte for byte; stdin is recognised by the magic bytes.
"$hbvh" convert "$work/chair.hbvh" -o "$work/back.xml"
cmp "$work/back.xml" "$work/chair.xml" || fail "convert .hbvh -> XML differs from build -o .xml"
"$hbvh" stats - <"$work/chair.hbvh" | sed 's/<stdin>/FILE/g' >"$work/stats_stdin.txt"
diff "$work/stats_stdin.txt" "$work/stats_binary.txt" || fail "stats on .hbvh from stdin differ"

# A primitive set round-trips as one (node count 0): building over it gives the same tree.
"$hbvh" convert "$model" -o "$work/set.hbvh"
"$hbvh" build "$work/set.hbvh" -a split -o "$work/from_set.xml"
cmp "$work/from_set.xml" "$work/chair.xml" || fail "building over a binary primitive set gave another tree"

# Refusals: exit 1, file and offset in the message, nothing written.
expect_refusal() {
  local name=$1 pattern=$2 status=0
  shift 2
  "$hbvh" "$@" 2>"$work/$name.err" >/dev/null || status=$?
  [ "$status" -eq 1 ] || fail "$name: exit $status, expected 1"
  grep -Eq "$pattern" "$work/$name.err" || fail "$name: message was: $(cat "$work/$name.err")"
}
head -c 100 "$work/chair.hbvh" >"$work/truncated.hbvh"
expect_refusal truncated "^hbvh: .*truncated\.hbvh: offset 100: file is truncated" stats "$work/truncated.hbvh"
python3 - "$work/chair.hbvh" "$work/corrupted.hbvh" <<'PY'
import sys
data = bytearray(open(sys.argv[1], "rb").read())
data[200] ^= 0x04
open(sys.argv[2], "wb").write(data)
PY
expect_refusal corrupted "corrupted\.hbvh: offset [0-9]+: checksum mismatch" collide "$work/corrupted.hbvh" "$model"
printf 'not a hierarchy' >"$work/text.hbvh"
expect_refusal magic "text\.hbvh: offset 0: not an \.hbvh file" stats "$work/text.hbvh"
# A sound checksum over a root volume shrunk to a tenth: the same containment check as for XML refuses it,
# and --refit repairs it. (CRC-64/XZ recomputed here, independently of the library.)
python3 - "$work/chair.hbvh" "$work/shrunk.hbvh" <<'PY'
import struct, sys
data = bytearray(open(sys.argv[1], "rb").read())
kind = data[40]
numbers = {0: 6, 1: 15, 2: 4, 3: 7}[kind]
values = list(struct.unpack_from("<%dd" % numbers, data, 41))
if kind == 0:   # aabb: min, max -> around the centre, a tenth of the size
    c = [(values[i] + values[i + 3]) / 2 for i in range(3)]
    h = [(values[i + 3] - values[i]) / 20 for i in range(3)]
    values = [c[i] - h[i] for i in range(3)] + [c[i] + h[i] for i in range(3)]
elif kind == 1: # obb: half extents last
    values[12:15] = [v / 10 for v in values[12:15]]
else:           # sphere, capsule: radius last
    values[-1] /= 10
struct.pack_into("<%dd" % numbers, data, 41, *values)
def crc64(b):
    crc = 0xFFFFFFFFFFFFFFFF
    for x in b:
        crc ^= x
        for _ in range(8):
            crc = (crc >> 1) ^ 0xC96C5795D7870F42 if crc & 1 else crc >> 1
    return crc ^ 0xFFFFFFFFFFFFFFFF
struct.pack_into("<Q", data, len(data) - 8, crc64(bytes(data[:-8])))
open(sys.argv[2], "wb").write(data)
PY
expect_refusal shrunk "shrunk\.hbvh: volume \((aabb|obb|sphere|capsule)\) does not enclose primitive" \
  collide "$work/shrunk.hbvh" "$model"
expect_refusal shrunk_build "shrunk\.hbvh: volume" build "$work/shrunk.hbvh" -o "$work/never.hbvh"
[ ! -e "$work/never.hbvh" ] || fail "build wrote its output although the input was refused"
"$hbvh" collide --refit "$work/shrunk.hbvh" "$model" >/dev/null 2>"$work/refit.err" || fail "--refit did not repair"
grep -q "refitted" "$work/refit.err" || fail "--refit did not say what it changed: $(cat "$work/refit.err")"
# generate writes the binary format by extension too, and the set it writes is the one it writes as XML.
"$hbvh" generate --count 40 --seed 5 -o "$work/generated.hbvh"
"$hbvh" generate --count 40 --seed 5 -o "$work/generated.xml"
head -c 8 "$work/generated.hbvh" | od -An -tx1 | grep -q '89 48 42 56 48 0d 0a 1a' || fail "generated.hbvh does not start with the magic"
"$hbvh" convert "$work/generated.hbvh" -o "$work/generated_again.xml"
cmp -s "$work/generated.xml" "$work/generated_again.xml" || fail "generate -o .hbvh holds another set than generate -o .xml"
echo "binary_format: ok"
