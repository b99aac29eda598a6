//! The status bar: the running step with its progress, the last message (errors stand out
//! and say what to do) and which renderer draws the 3D view.

use crate::app::{AppState, Pending};
use coma::agents::pipeline::DEFAULT_ROUNDS;
use coma::session::Command;
use leptos::prelude::*;

#[component]
pub fn StatusBar() -> impl IntoView {
    let state = expect_context::<AppState>();
    // Runs the link's own plan with its seed on this page's model: the same steps, though
    // not the same motion.
    let regenerate = move |_| {
        if let Some(link) = state.foreign_link.get_untracked() {
            state.foreign_link.set(None);
            state.request(
                Command::Run {
                    prompt: link.prompt.clone(),
                    seed: link.seed,
                    rounds: DEFAULT_ROUNDS,
                    seconds: None,
                    plan: link.plan.plan().cloned(),
                },
                None,
                Pending::Run {
                    prompt: link.prompt,
                    seed: link.seed,
                },
            );
        }
    };
    view! {
        <footer class="status">
            {move || {
                state
                    .progress
                    .get()
                    .map(|(stage, done, total)| {
                        view! {
                            <span class="progress">
                                <progress max=total.max(1) value=done></progress>
                                " "
                                {stage}
                            </span>
                        }
                    })
            }}
            <span id="status" role="status" class:error=move || state.status.with(|s| s.error)>
                {move || state.status.with(|s| s.text.clone())}
            </span>
            {move || {
                state
                    .view_renderer
                    .get()
                    .map(|(name, reasons)| {
                        view! {
                            <span id="view-renderer" class="view-renderer" title=reasons>
                                "View: "
                                {name}
                            </span>
                        }
                    })
            }}
            <Show when=move || state.foreign_link.with(Option::is_some)>
                <button on:click=regenerate>"Regenerate from its prompt"</button>
            </Show>
        </footer>
    }
}
