//! What the page asks of the browser: downloads, the clipboard, the URL fragment and the
//! device pixel ratio. Every call reports failure as a message instead of panicking.

use wasm_bindgen::JsCast;

fn window() -> Result<web_sys::Window, String> {
    web_sys::window().ok_or_else(|| "no browser window".to_string())
}

/// Offers `bytes` as a download named `name`.
pub fn download(bytes: &[u8], name: &str, mime: &str) -> Result<(), String> {
    let parts = js_sys::Array::new();
    parts.push(&js_sys::Uint8Array::from(bytes));
    let bag = web_sys::BlobPropertyBag::new();
    bag.set_type(mime);
    let blob = web_sys::Blob::new_with_u8_array_sequence_and_options(&parts, &bag)
        .map_err(|e| format!("cannot prepare the download: {e:?}"))?;
    let url = web_sys::Url::create_object_url_with_blob(&blob)
        .map_err(|e| format!("cannot prepare the download: {e:?}"))?;
    let document = window()?.document().ok_or("no document")?;
    let anchor: web_sys::HtmlAnchorElement = document
        .create_element("a")
        .map_err(|e| format!("{e:?}"))?
        .dyn_into()
        .map_err(|_| "not an anchor")?;
    anchor.set_href(&url);
    anchor.set_download(name);
    anchor.click();
    // The click has started the download; the object URL is not needed after it.
    let _ = web_sys::Url::revoke_object_url(&url);
    Ok(())
}

/// Copies text to the clipboard (needs a user gesture, which the button gives).
pub async fn copy_text(text: &str) -> Result<(), String> {
    let promise = window()?.navigator().clipboard().write_text(text);
    wasm_bindgen_futures::JsFuture::from(promise)
        .await
        .map(|_| ())
        .map_err(|e| format!("the browser refused the clipboard: {e:?}"))
}

/// The value of `name` in the page's query string (`?backend=cpu`), if it is there.
pub fn query(name: &str) -> Option<String> {
    let search = window().ok()?.location().search().ok()?;
    search
        .trim_start_matches('?')
        .split('&')
        .filter_map(|pair| pair.split_once('='))
        .find(|(key, _)| *key == name)
        .map(|(_, value)| value.to_string())
}

/// The URL fragment without its `#`.
pub fn fragment() -> String {
    window()
        .and_then(|w| w.location().hash().map_err(|e| format!("{e:?}")))
        .unwrap_or_default()
        .trim_start_matches('#')
        .to_string()
}

/// Replaces the URL fragment without a new history entry.
pub fn set_fragment(fragment: &str) {
    if let Ok(w) = window() {
        if let Ok(history) = w.history() {
            let _ = history.replace_state_with_url(
                &wasm_bindgen::JsValue::NULL,
                "",
                Some(&format!("#{fragment}")),
            );
        }
    }
}

/// Calls `on_change` whenever a navigation changes the URL fragment (a link pasted into the
/// address bar, back and forward), as long as the page lives. [`set_fragment`] does not call
/// it: replaceState fires no hashchange.
pub fn on_fragment_change(on_change: impl FnMut() + 'static) -> Result<(), String> {
    let listener = wasm_bindgen::closure::Closure::<dyn FnMut()>::new(on_change);
    window()?
        .add_event_listener_with_callback("hashchange", listener.as_ref().unchecked_ref())
        .map_err(|e| format!("cannot watch the address for share links: {e:?}"))?;
    // The page listens until it is closed.
    listener.forget();
    Ok(())
}

/// `relative` resolved against the page's address (the worker resolves relative URLs against
/// its own script, so it is given absolute ones).
pub fn absolute_url(relative: &str) -> String {
    web_sys::Url::new_with_base(relative, &href())
        .map(|u| u.href())
        .unwrap_or_else(|_| relative.to_string())
}

/// The whole page URL.
pub fn href() -> String {
    window()
        .and_then(|w| w.location().href().map_err(|e| format!("{e:?}")))
        .unwrap_or_default()
}

pub fn device_pixel_ratio() -> f64 {
    window()
        .map_or(1.0, |w| w.device_pixel_ratio())
        .clamp(0.5, 4.0)
}

/// True when the browser offers WebGPU to this page.
pub fn has_webgpu() -> bool {
    window()
        .ok()
        .and_then(|w| js_sys::Reflect::get(&w.navigator(), &"gpu".into()).ok())
        .is_some_and(|gpu| !gpu.is_undefined() && !gpu.is_null())
}

fn local_storage() -> Result<web_sys::Storage, String> {
    window()?
        .local_storage()
        .map_err(|e| format!("{e:?}"))?
        .ok_or_else(|| "this browser keeps no local storage for the page".to_string())
}

/// The value stored under `key` in the browser's local storage, if any.
pub fn stored(key: &str) -> Option<String> {
    local_storage().ok()?.get_item(key).ok()?
}

/// Stores `value` under `key` in the browser's local storage (`None` removes it).
pub fn store(key: &str, value: Option<&str>) -> Result<(), String> {
    let storage = local_storage()?;
    match value {
        Some(v) => storage.set_item(key, v),
        None => storage.remove_item(key),
    }
    // The error may hold the value (the API key): say only that it failed.
    .map_err(|_| "the browser refused to store the settings (private mode or full storage?)".into())
}

/// The page's origin (`https://host:port`), as a server's CORS setting names it.
pub fn origin() -> String {
    window()
        .and_then(|w| w.location().origin().map_err(|e| format!("{e:?}")))
        .unwrap_or_default()
}
