//! Settings: an OpenAI-compatible endpoint for the planner and the reviewer (base URL, model,
//! API key, optional vision model). They live in this browser's local storage under one key
//! and go only to that endpoint, from the worker; without them nothing is sent anywhere.

use crate::app::AppState;
use crate::messages::LlmSettings;
use leptos::prelude::*;

/// The local-storage key of the settings.
const STORAGE_KEY: &str = "coma.llm";

/// The stored settings, or none (the default: no LLM). Unreadable settings count as none.
pub fn stored() -> LlmSettings {
    crate::browser::stored(STORAGE_KEY)
        .and_then(|json| serde_json::from_str(&json).ok())
        .unwrap_or_default()
}

/// Why the settings cannot be used, if they cannot.
fn check(settings: &LlmSettings) -> Result<(), String> {
    let base = settings.base_url.trim();
    if base.is_empty() && settings.model.trim().is_empty() {
        return Ok(());
    }
    if !(base.starts_with("http://") || base.starts_with("https://")) {
        return Err("The base URL starts with http:// or https://.".into());
    }
    if settings.model.trim().is_empty() {
        return Err("Name the model the server should use.".into());
    }
    Ok(())
}

/// One labelled text field bound to `value`.
#[component]
fn Field(
    id: &'static str,
    label: &'static str,
    value: RwSignal<String>,
    #[prop(default = "text")] kind: &'static str,
    #[prop(default = "")] placeholder: &'static str,
) -> impl IntoView {
    view! {
        <label for=id>{label}</label>
        <input
            id=id
            type=kind
            placeholder=placeholder
            autocomplete="off"
            spellcheck="false"
            prop:value=move || value.get()
            on:input=move |ev| value.set(event_target_value(&ev))
        />
    }
}

#[component]
pub fn Settings() -> impl IntoView {
    let state = expect_context::<AppState>();
    let current = state.settings.get_untracked();
    let base_url = RwSignal::new(current.base_url);
    let model = RwSignal::new(current.model);
    let api_key = RwSignal::new(current.api_key);
    let vision_model = RwSignal::new(current.vision_model);
    let save = move |ev: leptos::ev::SubmitEvent| {
        // The form is only for the browser (a password field belongs in one); nothing is
        // submitted anywhere.
        ev.prevent_default();
        let settings = LlmSettings {
            base_url: base_url.get_untracked().trim().to_string(),
            model: model.get_untracked().trim().to_string(),
            api_key: api_key.get_untracked().trim().to_string(),
            vision_model: vision_model.get_untracked().trim().to_string(),
        };
        if let Err(e) = check(&settings) {
            return state.fail(e);
        }
        let json = serde_json::to_string(&settings).unwrap_or_default();
        let empty = settings.active().is_none();
        match crate::browser::store(STORAGE_KEY, (!empty).then_some(json.as_str())) {
            Ok(()) => state.say(if empty {
                "No LLM: the built-in planner plans and nothing is sent anywhere.".to_string()
            } else {
                format!(
                    "Saved: Generate plans with {} at {}.",
                    settings.model, settings.base_url
                )
            }),
            Err(e) => state.fail(e),
        }
        state.settings.set(settings);
    };
    let clear = move |_| {
        for field in [base_url, model, api_key, vision_model] {
            field.set(String::new());
        }
        state.settings.set(LlmSettings::default());
        match crate::browser::store(STORAGE_KEY, None) {
            Ok(()) => state.say("The LLM settings are removed from this browser."),
            Err(e) => state.fail(e),
        }
    };
    let summary = move || {
        state.settings.with(|s| match s.active() {
            Some(s) => format!("LLM: {}", s.model),
            None => "LLM: off".to_string(),
        })
    };
    let origin = crate::browser::origin();
    view! {
        <details class="settings">
            <summary id="settings-summary">{summary}</summary>
            <form class="settings-body panel" on:submit=save>
                <p>
                    "An OpenAI-compatible endpoint plans and reviews the motion; without one the built-in "
                    "planner does, and nothing leaves this page. The key stays in this browser's storage "
                    "and is sent only to this endpoint."
                </p>
                <Field
                    id="llm-base"
                    label="Base URL"
                    value=base_url
                    placeholder="http://127.0.0.1:11434/v1"
                />
                <Field id="llm-model" label="Model" value=model placeholder="qwen2.5:7b"/>
                <Field id="llm-key" label="API key" value=api_key kind="password"/>
                <Field
                    id="llm-vision"
                    label="Vision model (optional)"
                    value=vision_model
                    placeholder="describes the motion's pictures for the review"
                />
                <p class="hint">
                    "Local servers (Ollama, llama.cpp, LM Studio, vLLM) need CORS enabled for this "
                    "page's origin, " <code>{origin.clone()}</code> ": e.g. "
                    <code>{format!("OLLAMA_ORIGINS={origin}")}</code>
                    " for Ollama, \"Enable CORS\" in LM Studio's server settings, "
                    <code>{format!("--allowed-origins '[\"{origin}\"]'")}</code> " for vLLM."
                </p>
                <div class="row">
                    <button id="settings-save" class="primary" type="submit">
                        "Save"
                    </button>
                    <button id="settings-clear" type="button" on:click=clear>
                        "Remove"
                    </button>
                </div>
            </form>
        </details>
    }
}
