#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# A PNG of every level of a model's hierarchy, side by side (the viewer's #all mode in headless Chromium).
# Usage: tools/level_picture.sh MODEL.xml OUT.png [hbvh view options, e.g. -a two-level]
# Needs a built CLI (build/apps/hbvh/hbvh, or $HBVH) and Debian's chromium.
set -euo pipefail
cd "$(dirname "$0")/.."
model=$1 out=$2
shift 2
hbvh=${HBVH:-build/apps/hbvh/hbvh}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$hbvh" view "$model" -o "$work/view.html" "$@"
mkdir -p "$(dirname "$out")"
chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking \
  --disable-component-update --disable-sync --user-data-dir="$work/profile" --hide-scrollbars \
  --window-size=1000,500 --screenshot="$work/shot.png" "file://$work/view.html#all" >"$work/chromium.log" 2>&1 ||
  { cat "$work/chromium.log"; exit 1; }
cp "$work/shot.png" "$out"
echo "wrote $out"
