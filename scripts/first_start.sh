#!/usr/bin/env bash
# Times the README's start command as a new user meets it: a fresh clone of this repository's
# HEAD with an empty build cache, `bash scripts/start.sh`, until the page answers. Prints the
# seconds, then stops the server and removes the clone. crates.io's sources are not cleared
# (they download in seconds here); run it on an idle machine, the build takes both cores.
#   scripts/first_start.sh [PORT (default 8099)]
set -euo pipefail
cd "$(dirname "$0")/.."
port="${1:-8099}"
clone="$(mktemp -d)"
log="$clone/start.log"
git clone -q . "$clone/main"
start=$(date +%s)
(cd "$clone/main" && exec env -u CARGO_TARGET_DIR PORT="$port" setsid bash scripts/start.sh >"$log" 2>&1) &
starter=$!
trap 'kill -- -$(ps -o pgid= $starter | tr -d " ") 2>/dev/null || true; rm -rf "$clone"' EXIT
until curl -sf -o /dev/null "http://127.0.0.1:$port/"; do
  if ! kill -0 "$starter" 2>/dev/null; then
    cat "$log"
    echo "scripts/start.sh stopped before serving the page" >&2
    exit 1
  fi
  sleep 2
done
end=$(date +%s)
grep -E "Finished|brotli copies|wrote the page" "$log" || true
echo "first start on a fresh clone: the page served after $((end - start)) s ($(( (end - start) / 60 )) min $(( (end - start) % 60 )) s)"
