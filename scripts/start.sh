#!/usr/bin/env bash
# Sets up, builds and serves the page on http://127.0.0.1:8080/ (PORT overrides the port).
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/tools.sh
ensure_rust_tools
build_page
# The small server crate, not the engine: serving needs none of the model code.
exec cargo run --release -q -p coma-serve -- dist --port "${PORT:-8080}"
