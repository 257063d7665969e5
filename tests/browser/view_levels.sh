#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Renders `hbvh view` output in headless Chromium at two levels (#level=0 and #level=2) and checks that
# both pictures show something and that they differ. Exit 77 (CTest's skip) when Chromium is absent.
# Usage: view_levels.sh HBVH_BINARY SOURCE_DIR WORK_DIR
set -euo pipefail
hbvh=$1 source_dir=$2 work=$3
browser=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$browser" ]; then
  echo "view_levels: chromium is not installed (apt-get install chromium): skipped"
  exit 77
fi
mkdir -p "$work"
"$hbvh" view "$source_dir/tests/browser/three_levels.xml" --title "three levels" -o "$work/view.html"

shoot() {  # level, output png
  local profile
  profile=$(mktemp -d)
  # Flags keep Chromium offline and quiet: no sync, updates, first-run or background fetches.
  timeout 60 "$browser" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync --user-data-dir="$profile" \
    --screenshot="$2" --window-size=800,600 "file://$work/view.html#level=$1" >"$work/chromium-$1.log" 2>&1 || {
    cat "$work/chromium-$1.log"
    rm -rf "$profile"
    return 1
  }
  rm -rf "$profile"
}
rm -f "$work/level0.png" "$work/level2.png"
# Chromium spends most of its ~7 s waiting, not computing: take both pictures at once.
shoot 0 "$work/level0.png" &
first=$!
shoot 2 "$work/level2.png" &
second=$!
wait "$first"
wait "$second"
python3 "$source_dir/tests/browser/compare_screenshots.py" "$work/level0.png" "$work/level2.png"
