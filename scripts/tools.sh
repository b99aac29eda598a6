# Shared by start.sh and test.sh: installs the tools the build needs, only when missing or at
# the wrong version, so a machine that already has them starts at once.
# The wasm-bindgen of Cargo.lock (and of serve/src/bind.rs; a test checks that all three agree).
WASM_BINDGEN_VERSION=0.2.130

ensure_rust_tools() {
  rustup component list --installed 2>/dev/null | grep -q '^clippy' || rustup component add clippy
  rustup component list --installed 2>/dev/null | grep -q '^rustfmt' || rustup component add rustfmt
  rustup target list --installed | grep -qx wasm32-unknown-unknown || rustup target add wasm32-unknown-unknown
}

# The wasm tests' runner (wasm-bindgen-test-runner). Only the tests need it: the page's build
# writes its JavaScript glue with `coma-serve --bind` (the same library, without the runner's server).
ensure_wasm_test_runner() {
  if [ "$(wasm-bindgen-test-runner --version 2>/dev/null)" != "wasm-bindgen-test-runner $WASM_BINDGEN_VERSION" ]; then
    echo "installing wasm-bindgen-cli $WASM_BINDGEN_VERSION (a few minutes, once)"
    # Without --locked: its lock file names a crate version the registry no longer serves.
    cargo install wasm-bindgen-cli --version "$WASM_BINDGEN_VERSION" --no-default-features
  fi
}

# Debian's Chromium and its driver, Debian's Firefox ESR, Playwright's driver library,
# puppeteer-core (no browser download) and pngjs: what the browser tests need.
ensure_browser_tools() {
  local missing=()
  command -v chromium >/dev/null || missing+=(chromium)
  command -v chromedriver >/dev/null || missing+=(chromium-driver)
  command -v firefox-esr >/dev/null || missing+=(firefox-esr)
  if [ "${#missing[@]}" -gt 0 ]; then
    echo "installing ${missing[*]} (once)"
    apt-get update -q && apt-get install -y -q "${missing[@]}"
  fi
  # pngjs: the figure test decodes the canvas's screenshots.
  if [ ! -d e2e/node_modules/playwright-core ] || [ ! -d e2e/node_modules/puppeteer-core ] \
    || [ ! -d e2e/node_modules/pngjs ]; then
    (cd e2e && npm install --no-audit --no-fund)
  fi
}

# Builds the page into dist/: the wasm module, its JS glue, index.html and static/.
build_page() {
  local target_dir="${CARGO_TARGET_DIR:-target}"
  cargo build --release -p coma-web --target wasm32-unknown-unknown
  rm -rf dist && mkdir -p dist/pkg
  # The JavaScript glue, as `wasm-bindgen --target web --no-typescript --remove-name-section`.
  cargo run --release -q -p coma-serve -- --bind \
    "$target_dir/wasm32-unknown-unknown/release/coma_web.wasm" dist/pkg
  cp index.html dist/
  cp -r static dist/static
  # Compressed copies beside the files for hosts that serve them (`coma serve` does, as do
  # nginx's brotli_static and gzip_static): brotli for browsers that take it (the wasm at about
  # a tenth of its size, in half a minute), gzip for the rest (a sixth); the weights at about 0.9.
  find dist -type f \( -name '*.wasm' -o -name '*.js' -o -name '*.html' -o -name '*.json' \
    -o -name '*.bpk' -o -name '*.i8' -o -name '*.txt' -o -name '*.npy' -o -name '*.bin' \) \
    -exec gzip -9 -k -f {} +
  cargo run --release -q -p coma-serve -- --compress dist
}
