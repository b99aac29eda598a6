//! The page's JavaScript glue, written from the built wasm by wasm-bindgen's own library (the
//! code its command line runs). Starting the page then needs no `wasm-bindgen` command: that
//! crate also builds an argument parser and its test runner's web server and HTTP client, and
//! only the tests need the runner.

use anyhow::{Context, Result};
use std::path::Path;

/// The wasm-bindgen version the page's wasm is built with (`Cargo.lock`): the glue writer
/// refuses a module from any other, so `scripts/tools.sh` installs the same command-line
/// version for the tests.
pub const WASM_BINDGEN_VERSION: &str = "0.2.130";

/// Writes `<stem>.js` and `<stem>_bg.wasm` into `out_dir` from the wasm that
/// `cargo build --target wasm32-unknown-unknown` left at `wasm`: the same files as
/// `wasm-bindgen --target web --no-typescript --remove-name-section`. An ES module the page
/// and its workers import; no TypeScript declarations; no name section (function names for
/// stack traces, megabytes every visitor would download).
pub fn bind_page(wasm: &Path, out_dir: &Path) -> Result<()> {
    if !wasm.is_file() {
        anyhow::bail!(
            "{} does not exist: build the page first (cargo build --release -p coma-web --target wasm32-unknown-unknown)",
            wasm.display()
        );
    }
    std::fs::create_dir_all(out_dir).with_context(|| format!("creating {}", out_dir.display()))?;
    let mut bindgen = wasm_bindgen_cli_support::Bindgen::new();
    bindgen.input_path(wasm).web(true)?;
    // Bindgen's library defaults differ from its command line's on these; the command line's
    // are what the page was built and tested with.
    #[allow(deprecated)]
    bindgen
        .typescript(false)
        .remove_name_section(true)
        .omit_default_module_path(false)
        .reference_types(false);
    bindgen.generate(out_dir).with_context(|| {
        format!(
            "writing the page's JavaScript glue from {} (it must be built with wasm-bindgen {WASM_BINDGEN_VERSION})",
            wasm.display()
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_wasm_says_to_build_the_page_first() {
        let out = tempfile::tempdir().unwrap();
        let err = bind_page(&out.path().join("coma_web.wasm"), out.path()).unwrap_err();
        let message = format!("{err:#}");
        assert!(
            message.contains("does not exist: build the page first"),
            "{message}"
        );
    }

    #[test]
    fn a_file_that_is_not_wasm_is_an_error_not_a_panic() {
        let out = tempfile::tempdir().unwrap();
        let wasm = out.path().join("coma_web.wasm");
        std::fs::write(&wasm, b"<!doctype html> not a wasm module").unwrap();
        let err = bind_page(&wasm, &out.path().join("pkg")).unwrap_err();
        let message = format!("{err:#}");
        assert!(
            message.contains("writing the page's JavaScript glue"),
            "{message}"
        );
        assert!(!out.path().join("pkg/coma_web.js").exists());
    }

    /// The glue writer, `Cargo.lock`'s wasm-bindgen and the test runner that
    /// `scripts/tools.sh` installs must be one version, or the page or its wasm tests break.
    #[test]
    fn the_lock_file_and_the_tools_name_the_glue_writers_version() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let lock = std::fs::read_to_string(root.join("Cargo.lock")).unwrap();
        let locked = lock
            .split("[[package]]")
            .find(|p| p.contains("\nname = \"wasm-bindgen\"\n"))
            .and_then(|p| p.lines().find_map(|l| l.strip_prefix("version = ")))
            .expect("wasm-bindgen in Cargo.lock");
        assert_eq!(locked.trim_matches('"'), WASM_BINDGEN_VERSION);
        let tools = std::fs::read_to_string(root.join("scripts/tools.sh")).unwrap();
        assert!(
            tools.contains(&format!("\nWASM_BINDGEN_VERSION={WASM_BINDGEN_VERSION}\n")),
            "scripts/tools.sh installs another wasm-bindgen-cli"
        );
        let manifest = std::fs::read_to_string(root.join("serve/Cargo.toml")).unwrap();
        assert!(manifest.contains(&format!(
            "wasm-bindgen-cli-support = {{ version = \"={WASM_BINDGEN_VERSION}\""
        )));
    }
}
