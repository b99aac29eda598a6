//! The page: a Leptos app (the UI, on the main thread) and an inference worker (the models,
//! in a Web Worker), built from this one wasm module. [`start`] mounts the app in a window;
//! [`worker_main`] is called by `static/worker.js` inside the worker, [`partner_main`] inside
//! the worker's guidance partner.
//!
//! The modules without a browser in them (messages, the worker's dispatch, history, takes,
//! exports, the viewer's scene) build and test natively; the rest only for wasm32.

pub mod dispatch;
pub mod exports;
pub mod history;
pub mod messages;
pub mod take;
pub mod viewer;

#[cfg(target_arch = "wasm32")]
mod app;
#[cfg(target_arch = "wasm32")]
mod browser;
#[cfg(target_arch = "wasm32")]
mod client;
#[cfg(target_arch = "wasm32")]
mod deadline;
#[cfg(target_arch = "wasm32")]
mod llm_fetch;
#[cfg(target_arch = "wasm32")]
mod partner;
#[cfg(target_arch = "wasm32")]
mod ui;
#[cfg(target_arch = "wasm32")]
mod worker;

#[cfg(target_arch = "wasm32")]
use wasm_bindgen::prelude::*;

#[cfg(target_arch = "wasm32")]
unsafe extern "C" {
    /// Runs the module's static constructors (the registries of burn's GPU compiler, filled
    /// by `inventory`); synthesised by the wasm linker.
    fn __wasm_call_ctors();
}

/// Runs when the module is instantiated, in the page and in the worker alike: only a page
/// (which has a window) mounts the app.
#[cfg(target_arch = "wasm32")]
#[wasm_bindgen(start)]
pub fn start() {
    // Without this call the linker treats the module as a command and runs all its
    // constructors again at the top of every export (the allocator, the JS-value table:
    // thousands of calls a generation), which a Chrome profile of the page showed as a large
    // share of a warm generation. Called here, from the start function every instance runs
    // once before anything else, they run once.
    // SAFETY: the linker's own function, called once per instance before any other export
    // of ours runs; the constructors it calls only fill registries.
    unsafe { __wasm_call_ctors() };
    console_error_panic_hook::set_once();
    if web_sys::window().is_some() {
        leptos::mount::mount_to_body(app::App);
    }
}

/// The worker's entry point (see `static/worker.js`).
#[cfg(target_arch = "wasm32")]
#[wasm_bindgen]
pub fn worker_main() {
    worker::start();
}

/// The guidance partner's entry point: `static/worker.js` started by the inference worker in
/// its partner role (see `partner.rs`).
#[cfg(target_arch = "wasm32")]
#[wasm_bindgen]
pub fn partner_main() {
    partner::serve();
}
