//! The steps of a run as they come (plan, generation, edits, reviews, blend), then those of
//! the take shown, its edit history, and what its planner and run noted: an LLM that failed
//! and the built-in planner that took over, words the model does not know, a review that was
//! skipped. A take's link carries all of it.

use crate::app::{AppState, Pending};
use crate::take::edit_line;
use coma::plan::PlannerKind;
use leptos::prelude::*;

#[component]
pub fn Steps() -> impl IntoView {
    let state = expect_context::<AppState>();
    let planner = move || {
        state.history.with(|h| {
            let plan = h.current().as_ref()?.plan.as_ref()?;
            Some(format!(
                "Planned by {}: \"{}\"",
                match &plan.planner {
                    PlannerKind::Offline => "the built-in planner".to_string(),
                    PlannerKind::Llm { model } => format!("the LLM {model}"),
                },
                plan.rewritten
            ))
        })
    };
    let notes = move || {
        state
            .history
            .with(|h| h.current().as_ref().map(|t| t.notes.clone()))
            .unwrap_or_default()
    };
    // What the take records (a link carries it), beside the live lines of the last run.
    let history = move || {
        state
            .history
            .with(|h| h.current().as_ref().map(|t| t.edits.clone()))
            .unwrap_or_default()
    };
    // The live lines while a run is in flight, else those of the take shown (its link keeps
    // them, and undo brings back each take's own).
    let lines = move || {
        if state
            .pending
            .with(|p| matches!(p, Some(Pending::Run { .. })))
        {
            state.steps.get()
        } else {
            state
                .history
                .with(|h| h.current().as_ref().map(|t| t.steps.clone()))
                .unwrap_or_default()
        }
    };
    let visible = move || !lines().is_empty() || planner().is_some();
    view! {
        <Show when=visible>
            <details class="panel steps" open>
                <summary>"Steps"</summary>
                {move || planner().map(|p| view! { <p class="planner">{p}</p> })}
                <ol id="steps">
                    {move || {
                        lines()
                            .into_iter()
                            .map(|line| view! { <li>{line}</li> })
                            .collect_view()
                    }}
                </ol>
                <details class="history">
                    <summary>{move || format!("Edit history ({})", history().len())}</summary>
                    <ol id="history">
                        {move || {
                            history()
                                .iter()
                                .map(|e| view! { <li>{edit_line(e)}</li> })
                                .collect_view()
                        }}
                    </ol>
                </details>
                <ul id="notes" class="notes">
                    {move || {
                        notes()
                            .into_iter()
                            .map(|note| view! { <li>{note}</li> })
                            .collect_view()
                    }}
                </ul>
            </details>
        </Show>
    }
}
