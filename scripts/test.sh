#!/usr/bin/env bash
# Installs what the tests need and runs every check and test of the project.
# Needs ../shared/data beside the repository (the reference files and the motion archive).
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/tools.sh
ensure_rust_tools

echo "== format and lints"
cargo fmt --all -- --check
cargo clippy --workspace --all-targets -- -D warnings
cargo clippy -p coma-web --target wasm32-unknown-unknown -- -D warnings

echo "== features against the HumanML3D reference"
cargo run --release -q -p coma -- features check ../shared/data/humanml3d-reference

echo "== unit and integration tests"
cargo test --workspace --release

echo "== the page builds"
build_page
