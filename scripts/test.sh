#!/usr/bin/env bash
# Installs what the tests need and runs every check and test of the project.
# Needs ../shared/data beside the repository (the reference files and the motion archive).
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/tools.sh
ensure_rust_tools
ensure_wasm_test_runner

echo "== format and lints"
cargo fmt --all -- --check
cargo clippy --workspace --all-targets -- -D warnings
cargo clippy -p coma-web --target wasm32-unknown-unknown -- -D warnings

echo "== features against the HumanML3D reference"
cargo run --release -q -p coma -- features check ../shared/data/humanml3d-reference

echo "== unit and integration tests (with a real local LLM server for tests/local_llm.rs)"
# SmolLM2-135M under llama-cpp-python checks the client's plumbing against a real server; the
# first run on a machine compiles llama.cpp once into a wheel cache (several minutes). It stays
# up for the page tests too (one of them plans through it from the page); the trap stops it.
COMA_LOCAL_LLM="$(scripts/llm_server.sh)"
export COMA_LOCAL_LLM
# An absolute path: the trap may run after a step changed directory.
trap "'$PWD/scripts/llm_server.sh' stop" EXIT
cargo test --workspace --release

echo "== the page builds"
build_page

ensure_browser_tools
echo "== wasm tests in headless Chromium (the link decoder against a corpus of broken links; the"
echo "   posture solver's round trip, timed: scripts/posture_speed.sh prints the times)"
# posture_speed: about 3 s to build beside links and 10 s to run; the runner's 20 s default
# budget per test binary is too tight for it on a busy machine.
CHROMEDRIVER=/usr/bin/chromedriver \
  CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUNNER=wasm-bindgen-test-runner \
  WASM_BINDGEN_TEST_TIMEOUT=300 \
  cargo test --release -p coma-web --target wasm32-unknown-unknown --test links --test posture_speed

echo "== the page in headless Chromium"
target_dir="${CARGO_TARGET_DIR:-target}"
if [ ! -f dist/static/models/spam.json ]; then
  # No trained SPAM is committed yet: the suite checks the page's plumbing with random
  # weights of the default sizes (never shipped as the default model).
  "$target_dir/release/coma" export random --data ../shared/data/humanml3d-reference --out dist/static/models
fi
coma_bin="$(realpath "$target_dir/release/coma")"
shots="$(realpath -m "$target_dir/e2e-screenshots")"
mkdir -p "$shots"
(cd e2e && COMA="$coma_bin" DIST=../dist SHOTS="$shots" node --test --test-concurrency=1 page.test.mjs)

echo "== the page in headless Firefox ESR (the core test: load, generate, the share link rebuilds it)"
(cd e2e && COMA="$coma_bin" DIST=../dist node --test --test-concurrency=1 firefox.test.mjs)
