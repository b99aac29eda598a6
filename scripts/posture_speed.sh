#!/usr/bin/env bash
# The posture solver's speed in milliseconds per pose, natively and in headless Chromium's wasm
# engine, on the same scripts (web/tests/posture_speed.rs: the named library, the movements' key
# poses, the 300 random scripts of `coma posture check`), printed side by side. The tests also
# assert the round trip; no time is asserted. Both runs use one thread, one after the other.
# Once the page's wasm crates are built, the test binary builds in seconds and both runs take ~20 s.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/tools.sh
ensure_rust_tools
ensure_wasm_test_runner
if ! command -v chromium >/dev/null || ! command -v chromedriver >/dev/null; then
  ensure_browser_tools
fi

out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

echo "== native (cargo test --release -p coma-web --test posture_speed -- --ignored)"
cargo test --release -q -p coma-web --test posture_speed -- --ignored --nocapture \
  --test-threads=1 >"$out/native" 2>&1 || { cat "$out/native"; exit 1; }
grep -o 'posture speed, .*' "$out/native"

echo "== wasm in headless Chromium (wasm-bindgen-test-runner)"
CHROMEDRIVER=/usr/bin/chromedriver \
  CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUNNER=wasm-bindgen-test-runner \
  WASM_BINDGEN_TEST_TIMEOUT=600 \
  cargo test --release -p coma-web --target wasm32-unknown-unknown --test posture_speed \
  -- --nocapture >"$out/wasm" 2>&1 || { cat "$out/wasm"; exit 1; }
grep -o 'posture speed, .*' "$out/wasm"

echo "== ms per pose: mean / median / max"
# Lines read "posture speed, <engine>, <what>: <n> poses, <mean> ms per pose mean, <median>
# median, <max> max; ..." (the test's print).
fields() {
  grep -o 'posture speed, .*' "$1" |
    sed -E 's/^posture speed, [^,]+, ([^:]+): ([0-9]+) poses, ([0-9.]+) ms per pose mean, ([0-9.]+) median, ([0-9.]+) max;.*/\1|\2|\3 \/ \4 \/ \5/' |
    LC_ALL=C sort -t '|' -k1,1
}
printf '%-34s %6s  %-22s %-22s\n' "scripts" "poses" "native" "wasm (Chromium)"
LC_ALL=C join -t '|' <(fields "$out/native") <(fields "$out/wasm") |
  while IFS='|' read -r what n native _ wasm; do
    printf '%-34s %6s  %-22s %-22s\n' "$what" "$n" "$native" "$wasm"
  done
