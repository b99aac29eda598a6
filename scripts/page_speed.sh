#!/usr/bin/env bash
# Generation time in the page for builds of it, side by side in one run.
#
#   scripts/page_speed.sh ROUNDS DIST [DIST...]   (e.g. 2 dist /tmp/old-dist)
#
# Serves each built page (a folder like dist/, from scripts/tools.sh build_page) on its own
# port and, ROUNDS times, runs e2e/page_speed.mjs on each in turn, so every build sees the
# same machine load: 196-frame walks without review (first cold) and with two review rounds,
# in headless Chromium on the CPU backend. Needs what the e2e needs (scripts/test.sh installs it).
set -euo pipefail
cd "$(dirname "$0")/.."
rounds="$1"
shift
cargo build --release -q -p coma-serve
serve="${CARGO_TARGET_DIR:-target}/release/coma-serve"
pids=()
trap 'kill "${pids[@]}" 2>/dev/null || true' EXIT
port=8140
for dist in "$@"; do
    "$serve" "$dist" --port "$port" >/dev/null 2>&1 &
    pids+=($!)
    port=$((port + 1))
done
sleep 1
for round in $(seq "$rounds"); do
    port=8140
    for dist in "$@"; do
        (cd e2e && node page_speed.mjs "http://127.0.0.1:$port/" "round $round, $dist")
        port=$((port + 1))
    done
done
