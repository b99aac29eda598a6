//! The page's wasm entry point. For now it only proves that the Rust → wasm → page path works:
//! it replaces the loading message with a status line. The Leptos app replaces this.

use wasm_bindgen::prelude::*;

/// Called by the browser once the module is instantiated.
#[wasm_bindgen(start)]
pub fn start() -> Result<(), JsValue> {
    let document = web_sys::window()
        .and_then(|w| w.document())
        .ok_or_else(|| JsValue::from_str("no document"))?;
    if let Some(status) = document.get_element_by_id("status") {
        status.set_text_content(Some(&status_text()));
    }
    Ok(())
}

/// The status line the page shows once the wasm module runs.
pub fn status_text() -> String {
    format!(
        "CoMA {} loaded. The motion model and editor are not in the page yet.",
        env!("CARGO_PKG_VERSION")
    )
}
