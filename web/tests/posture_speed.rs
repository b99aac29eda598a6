//! The posture solver's speed, in milliseconds per pose, in the browser's wasm engine (headless
//! Chromium through wasm-bindgen-test-runner) and natively, on the same scripts: every named
//! posture of the library, every key pose of its movements, and the 300 random valid scripts of
//! `coma posture check` (seed 17). It asserts what the native check does (the library read back
//! in full, random scripts at 98 % or more, no joint-limit break, nothing under the floor, every
//! pose finite) and prints the times; it asserts no time. `scripts/posture_speed.sh` runs both
//! and prints them side by side. Natively the tests are ignored unless asked for
//! (`-- --ignored`), so `cargo test --workspace` does not time the solver twice.

use coma::posture::check::{random_scripts, round_trip_timed, PoseTimes, RoundTrip};
use coma::posture::library::Library;

/// Seed and number of random scripts, as `coma posture check` draws them by default.
const RANDOM_SEED: u64 = 17;
const RANDOM_SCRIPTS: usize = 300;

#[cfg(target_arch = "wasm32")]
mod engine {
    use wasm_bindgen::prelude::*;

    pub const NAME: &str = "wasm (Chromium)";

    #[wasm_bindgen]
    extern "C" {
        // `performance.now()`, in a page or a worker (std's Instant panics on this target).
        #[wasm_bindgen(js_namespace = performance, js_name = now)]
        fn performance_now() -> f64;
    }

    pub fn now_ms() -> f64 {
        performance_now()
    }

    pub fn say(line: &str) {
        wasm_bindgen_test::console_log!("{line}");
    }
}

#[cfg(not(target_arch = "wasm32"))]
mod engine {
    use std::sync::OnceLock;
    use std::time::Instant;

    pub const NAME: &str = "native";

    pub fn now_ms() -> f64 {
        static START: OnceLock<Instant> = OnceLock::new();
        START.get_or_init(Instant::now).elapsed().as_secs_f64() * 1e3
    }

    pub fn say(line: &str) {
        println!("{line}");
    }
}

#[cfg(target_arch = "wasm32")]
wasm_bindgen_test::wasm_bindgen_test_configure!(run_in_browser);

/// Prints one line: `posture speed, <engine>, <what>: …` (the script greps for the prefix).
fn print(what: &str, r: &RoundTrip, t: &PoseTimes) {
    engine::say(&format!(
        "posture speed, {}, {what}: {} poses, {:.1} ms per pose mean, {:.1} median, {:.1} max; \
         {} of {} constraints read back ({:.1} %)",
        engine::NAME,
        t.ms.len(),
        t.mean(),
        t.median(),
        t.max(),
        r.read_back,
        r.constraints,
        100.0 * r.rate(),
    ));
}

fn assert_sound(what: &str, r: &RoundTrip, t: &PoseTimes) {
    assert_eq!(
        t.non_finite, 0,
        "{what}: poses with a non-finite coordinate"
    );
    assert_eq!(r.limit_breaks, 0, "{what}: joint-limit breaks");
    assert_eq!(r.below_floor, 0, "{what}: poses below the floor");
}

#[cfg_attr(target_arch = "wasm32", wasm_bindgen_test::wasm_bindgen_test)]
#[cfg_attr(
    not(target_arch = "wasm32"),
    test,
    ignore = "a timing run: scripts/posture_speed.sh"
)]
fn every_named_posture_and_movement_key_solves_and_reads_back() {
    let library = Library::builtin();
    let (named, times) = round_trip_timed(
        library.postures.iter().map(|p| (p.name.clone(), &p.script)),
        &engine::now_ms,
    );
    print("named library", &named, &times);
    assert!(named.scripts >= 40, "{} named postures", named.scripts);
    assert_eq!(named.read_back, named.constraints, "{:#?}", named.misses);
    assert_sound("named library", &named, &times);

    let (keys, times) = round_trip_timed(
        library.actions.iter().flat_map(|a| {
            a.keys.iter().map(move |k| {
                let key = k.script.name.as_deref().unwrap_or("key");
                (format!("{}: {key}", a.name), &k.script)
            })
        }),
        &engine::now_ms,
    );
    print("key poses of the movements", &keys, &times);
    assert_eq!(keys.read_back, keys.constraints, "{:#?}", keys.misses);
    assert_sound("key poses of the movements", &keys, &times);
}

#[cfg_attr(target_arch = "wasm32", wasm_bindgen_test::wasm_bindgen_test)]
#[cfg_attr(
    not(target_arch = "wasm32"),
    test,
    ignore = "a timing run: scripts/posture_speed.sh"
)]
fn random_valid_scripts_solve_and_read_back() {
    let scripts = random_scripts(RANDOM_SCRIPTS, RANDOM_SEED);
    let (random, times) = round_trip_timed(
        scripts
            .iter()
            .enumerate()
            .map(|(i, s)| (format!("random script {}", i + 1), s)),
        &engine::now_ms,
    );
    print(
        &format!("random valid scripts (seed {RANDOM_SEED})"),
        &random,
        &times,
    );
    assert!(random.rate() >= 0.98, "round trip {:.3}", random.rate());
    assert_sound("random valid scripts", &random, &times);
}
