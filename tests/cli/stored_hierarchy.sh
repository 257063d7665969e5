#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Stored hierarchies are checked before use: a file whose inner volumes miss part of their primitives
# (the repository's own repaired appendix B) is refused by every command that queries or draws it, with
# the file, line, primitive and distance, and nothing written (convert included); --refit repairs it and the pairs then equal
# a query that never sees the stored volumes; stats reports the violations instead of failing.
# Usage: stored_hierarchy.sh HBVH_BINARY SOURCE_DIR WORK_DIR
set -euo pipefail
hbvh=$1 source_dir=$2 work=$3
broken="$source_dir/tests/io/data/survey_appendix_b_repaired.xml"
[ -f "$broken" ] || { echo "stored_hierarchy: shipped test data $broken is missing" >&2; exit 1; }
rm -rf "$work" && mkdir -p "$work"
fail() { echo "stored_hierarchy: $*" >&2; exit 1; }

# expect_refusal NAME OUTPUT ARGS...: exit 1, the message, and OUTPUT not created.
expect_refusal() {
  local name=$1 output=$2 status=0
  shift 2
  "$hbvh" "$@" 2>"$work/$name.err" >/dev/null || status=$?
  [ "$status" -eq 1 ] || fail "$name: exit $status, expected 1"
  grep -Eq "survey_appendix_b_repaired.xml:[0-9]+: volume \((aabb|obb|sphere|capsule)\) does not enclose primitive [0-9]+ by [0-9.e-]+" "$work/$name.err" ||
    fail "$name: message was: $(cat "$work/$name.err")"
  [ -z "$output" ] || [ ! -e "$output" ] || fail "$name: wrote $output although the input was refused"
}
expect_refusal collide "" collide "$broken" "$broken" --pose-b "0.5 0 0"
expect_refusal simulate "" simulate "$broken" --collisions 10
expect_refusal export "$work/x.gltf" export "$broken" -o "$work/x.gltf"
expect_refusal view "$work/x.html" view "$source_dir/tests/io/data/survey_appendix_b_repaired.xml" -o "$work/x.html"
expect_refusal build "$work/x.xml" build "$broken" -o "$work/x.xml"
expect_refusal convert "$work/x.hbvh" convert "$broken" -o "$work/x.hbvh"
# The line named is the first offending volume's own line in the file.
line=$(sed -E 's/.*repaired.xml:([0-9]+):.*/\1/' "$work/collide.err")
sed -n "${line}p" "$broken" | grep -q '<volume' || fail "line $line of the file is no <volume>"

# stats reports instead of failing, in text and JSON.
"$hbvh" stats "$broken" >"$work/stats.txt" || fail "stats failed on a non-enclosing file"
grep -Eq '^violations +[1-9][0-9]* volumes do not enclose' "$work/stats.txt" || fail "stats text: $(cat "$work/stats.txt")"
"$hbvh" stats "$broken" --json >"$work/stats.json"
python3 - "$work/stats.json" <<'PY'
import json, sys
stats = json.load(open(sys.argv[1]))
violations = stats["violations"]
assert violations, "no violations reported"
for v in violations:
    assert v["by"] > 0 and v["line"] > 0 and v["type"] in ("aabb", "obb", "sphere", "capsule"), v
PY
# A sound file has none.
"$hbvh" build "$source_dir/data/models/chair.xml" -a split -o "$work/chair.hbvh.xml"
"$hbvh" stats "$work/chair.hbvh.xml" --json | python3 -c 'import json,sys; assert json.load(sys.stdin)["violations"] == []'

# --refit: repaired, says how many, and the pairs equal a query over the bare primitives (a flat
# two-level tree built from them: it never sees the stored inner volumes).
"$hbvh" collide --refit "$broken" "$broken" --pose-b "0.5 0.2 0 0.9 0.1 0.4 0" --json >"$work/refit.json" 2>"$work/refit.err"
grep -Eq 'refitted [1-9][0-9]* of [0-9]+ volumes' "$work/refit.err" || fail "--refit did not say what it changed: $(cat "$work/refit.err")"
"$hbvh" stats --refit "$broken" >/dev/null 2>&1 && fail "stats accepted --refit (it reports, it does not repair)"
python3 - "$broken" "$work/primitives.xml" <<'PY'
# The file's leaves as a flat primitive set, in document order (the reader's primitive order).
import sys, xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
leaves = [v for v in root.iter("volume") if v.find("volume") is None]
flat = ET.Element("hierarchy")
for leaf in leaves:
    flat.append(ET.Element("volume", leaf.attrib))
ET.ElementTree(flat).write(sys.argv[2])
PY
"$hbvh" collide -a two-level "$work/primitives.xml" "$work/primitives.xml" --pose-b "0.5 0.2 0 0.9 0.1 0.4 0" --json >"$work/flat.json"
python3 - "$work/refit.json" "$work/flat.json" <<'PY'
import json, sys
refit, flat = (json.load(open(p)) for p in sys.argv[1:])
assert refit["pairs"] == flat["pairs"], (refit["pairs"], flat["pairs"])
assert refit["pairs"], "the test pose should make contact"
PY
"$hbvh" export --refit "$broken" -o "$work/refit.gltf" 2>/dev/null
[ -s "$work/refit.gltf" ] || fail "export --refit wrote nothing"
# convert --refit writes the repaired tree, which every command then accepts as it is.
"$hbvh" convert --refit "$broken" -o "$work/refit.hbvh" 2>/dev/null
"$hbvh" collide "$work/refit.hbvh" "$work/refit.hbvh" --pose-b "0.5 0.2 0 0.9 0.1 0.4 0" --json >"$work/converted.json"
python3 - "$work/refit.json" "$work/converted.json" <<'PY'
import json, sys
refit, converted = (json.load(open(p)) for p in sys.argv[1:])
assert refit["pairs"] == converted["pairs"], (refit["pairs"], converted["pairs"])
PY
echo "stored_hierarchy: ok"
