//! The prompt box: what the person should do, how long, which seed, and Generate
//! (also Ctrl+Enter).

use crate::app::{AppState, Pending};
use crate::messages::Request;
use leptos::prelude::*;

/// Prompts the default model knows (its training vocabulary, see MODEL_CARD.md).
pub const EXAMPLES: [&str; 8] = [
    "a person walks forward",
    "a person waves the left hand",
    "a person raises the right hand",
    "a person bows",
    "a person runs forward",
    "a person walks forward in a tired way",
    "a person kicks",
    "a person walks backward",
];

#[component]
pub fn PromptBox() -> impl IntoView {
    let state = expect_context::<AppState>();
    let prompt = RwSignal::new(EXAMPLES[0].to_string());
    let seconds = RwSignal::new(4.0f64);
    let seed = RwSignal::new(0u64);
    let generate = move || {
        let text = prompt.get_untracked().trim().to_string();
        if text.is_empty() {
            state.fail("Type what the person should do first.");
            return;
        }
        let s = seed.get_untracked();
        state.say("generating…");
        state.request(
            Request::Generate {
                prompt: text.clone(),
                seconds: seconds.get_untracked(),
                seed: s,
                parts: vec![],
            },
            Pending::Generate {
                prompt: text,
                seed: s,
            },
        );
    };
    view! {
        <div class="panel prompt">
            <label for="prompt">"Prompt"</label>
            <textarea
                id="prompt"
                rows="3"
                prop:value=move || prompt.get()
                on:input=move |ev| prompt.set(event_target_value(&ev))
                on:keydown=move |ev: web_sys::KeyboardEvent| {
                    if ev.key() == "Enter" && (ev.ctrl_key() || ev.meta_key()) {
                        ev.prevent_default();
                        generate();
                    }
                }
            ></textarea>
            <div class="row">
                <select
                    aria-label="Example prompts"
                    on:change=move |ev| {
                        let v = event_target_value(&ev);
                        if !v.is_empty() {
                            prompt.set(v);
                        }
                    }
                >
                    <option value="">"Examples…"</option>
                    {EXAMPLES.iter().map(|e| view! { <option value=*e>{*e}</option> }).collect_view()}
                </select>
                <label>
                    "Seconds "
                    <input
                        id="seconds"
                        type="number"
                        min="1"
                        max="9.8"
                        step="0.2"
                        prop:value=move || seconds.get().to_string()
                        on:change=move |ev| {
                            match event_target_value(&ev).parse::<f64>() {
                                Ok(v) if v.is_finite() => seconds.set(v.clamp(1.0, 9.8)),
                                _ => state.fail("Seconds must be a number from 1 to 9.8."),
                            }
                        }
                    />
                </label>
                <label>
                    "Seed "
                    <input
                        id="seed"
                        type="number"
                        min="0"
                        step="1"
                        prop:value=move || seed.get().to_string()
                        on:change=move |ev| {
                            match event_target_value(&ev).parse::<u64>() {
                                Ok(v) => seed.set(v),
                                Err(_) => state.fail("The seed is a whole number from 0."),
                            }
                        }
                    />
                </label>
                <button
                    id="generate"
                    class="primary"
                    on:click=move |_| generate()
                    disabled=move || state.busy() || state.model.with(Option::is_none)
                >
                    "Generate"
                </button>
            </div>
        </div>
    }
}
