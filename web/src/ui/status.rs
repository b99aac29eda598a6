//! The status bar: the running step with its progress, and the last message (errors stand
//! out and say what to do).

use crate::app::{AppState, Pending};
use crate::messages::Request;
use coma::model::motion_model::frames_for_seconds;
use leptos::prelude::*;

#[component]
pub fn StatusBar() -> impl IntoView {
    let state = expect_context::<AppState>();
    let regenerate = move |_| {
        if let Some(link) = state.foreign_link.get_untracked() {
            state.foreign_link.set(None);
            let frames = link
                .tokens
                .first()
                .and_then(|p| p.first())
                .map_or(80, |l| l.len() * 4);
            state.request(
                Request::Generate {
                    prompt: link.prompt.clone(),
                    seconds: frames_for_seconds(frames as f64 / 20.0) as f64 / 20.0,
                    seed: link.seed,
                    parts: vec![],
                },
                Pending::Generate {
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
            <Show when=move || state.foreign_link.with(Option::is_some)>
                <button on:click=regenerate>"Regenerate from its prompt"</button>
            </Show>
        </footer>
    }
}
