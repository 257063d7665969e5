#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# A run ended by a signal in the middle of writing its output (Ctrl-C, kill, a closed terminal) leaves neither a
# partial output nor its hidden temporary file, and ends as that signal ends a process. SIGTERM here: a background
# job of a non-interactive shell starts with SIGINT ignored, and hbvh leaves an ignored signal ignored.
# Usage: interrupted_write.sh HBVH_BINARY WORK_DIR
set -euo pipefail
hbvh=$1 work=$2
rm -rf "$work" && mkdir -p "$work"
fail() { echo "interrupted_write: $*" >&2; exit 1; }

# 10^6 primitives: about 230 MB of XML, long enough to be caught while it is written.
"$hbvh" generate --count 1000000 --seed 5 -o "$work/scene.xml" &
pid=$!
seen=""
for _ in $(seq 1 12000); do
  if compgen -G "$work/.scene.xml.tmp-*" >/dev/null; then seen=yes; break; fi
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.01
done
[ -n "$seen" ] || { wait "$pid" || true; fail "the write ended (or never began) before its temporary file was seen"; }
kill -TERM "$pid"
status=0
wait "$pid" || status=$?
[ "$status" -eq 143 ] || fail "exit status $status, expected 143 (ended by SIGTERM)"
leftover=$(find "$work" -mindepth 1 | head -5)
[ -z "$leftover" ] || fail "left behind: $leftover"
echo "interrupted_write: the temporary file went with the process"
