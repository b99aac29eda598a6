//! The prompt box: what the person should do, how long, which seed, how many review rounds,
//! and Generate (also Ctrl+Enter), which runs the whole pipeline: plan, generate, edit,
//! review, blend.

use crate::app::{AppState, Pending};
use coma::agents::pipeline::DEFAULT_ROUNDS;
use coma::session::Command;
use leptos::prelude::*;

/// Most review rounds offered: each round may regenerate every body part of every segment.
const MAX_ROUNDS: usize = 4;

/// Prompts the default model knows (its training vocabulary, see MODEL_CARD.md).
pub const EXAMPLES: [&str; 10] = [
    "a person walks forward",
    "a person waves the left hand",
    "a person raises the right hand",
    "a person bows",
    "a person runs forward",
    "a person walks forward in a tired way",
    "a person does a squat",
    "a person jumps with both feet",
    "a person kicks with the right foot",
    "a person walks backward",
];

/// What the prompt box holds, in the page's state so a share link that opens can fill it.
#[derive(Clone, Copy)]
pub struct PromptFields {
    pub text: RwSignal<String>,
    /// None: the planner estimates each segment's length.
    pub seconds: RwSignal<Option<f64>>,
    pub seed: RwSignal<u64>,
}

impl Default for PromptFields {
    /// The first example, the planner's length, seed 0.
    fn default() -> PromptFields {
        PromptFields {
            text: RwSignal::new(EXAMPLES[0].to_string()),
            seconds: RwSignal::new(None),
            seed: RwSignal::new(0),
        }
    }
}

impl PromptFields {
    /// Shows a link's prompt, its motion's length (seconds, rounded to the field's 0.2 s
    /// steps) and its seed.
    pub fn fill(&self, text: &str, seconds: f64, seed: u64) {
        self.text.set(text.to_string());
        self.seconds
            .set((seconds.is_finite() && seconds > 0.0).then(|| (seconds * 5.0).round() / 5.0));
        self.seed.set(seed);
    }
}

#[component]
pub fn PromptBox() -> impl IntoView {
    let state = expect_context::<AppState>();
    let PromptFields {
        text: prompt,
        seconds,
        seed,
    } = state.prompt;
    let rounds = RwSignal::new(DEFAULT_ROUNDS);
    let generate = move || {
        let text = prompt.get_untracked().trim().to_string();
        if text.is_empty() {
            state.fail("Type what the person should do first.");
            return;
        }
        let s = seed.get_untracked();
        let llm = state.settings.get_untracked().active();
        state.say(match &llm {
            Some(l) => format!("planning with {}…", l.model),
            None => "planning…".to_string(),
        });
        state.request(
            Command::Run {
                prompt: text.clone(),
                seed: s,
                rounds: rounds.get_untracked(),
                seconds: seconds.get_untracked(),
                plan: None,
            },
            llm,
            Pending::Run {
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
                <label title="The whole motion's length; empty lets the planner choose">
                    "Seconds "
                    <input
                        id="seconds"
                        type="number"
                        min="2"
                        max=coma::plan::MAX_PLAN_SECONDS.to_string()
                        step="0.2"
                        placeholder="auto"
                        prop:value=move || seconds.get().map_or(String::new(), |s| s.to_string())
                        on:change=move |ev| {
                            let text = event_target_value(&ev);
                            match text.trim() {
                                "" => seconds.set(None),
                                t => match t.parse::<f64>() {
                                    Ok(v) if v.is_finite() && v > 0.0 => seconds.set(Some(v)),
                                    _ => state.fail("Seconds is a number, or empty to let the planner choose."),
                                },
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
                <label title="Review rounds per segment (0: no review)">
                    "Review "
                    <select
                        id="rounds"
                        on:change=move |ev| {
                            if let Ok(r) = event_target_value(&ev).parse::<usize>() {
                                rounds.set(r.min(MAX_ROUNDS));
                            }
                        }
                    >
                        {(0..=MAX_ROUNDS)
                            .map(|r| {
                                view! {
                                    <option value=r.to_string() selected=r == DEFAULT_ROUNDS>
                                        {r.to_string()}
                                    </option>
                                }
                            })
                            .collect_view()}
                    </select>
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
