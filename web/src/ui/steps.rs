//! The steps of the last run as they came (plan, generation, edits, reviews, blend), the
//! current take's edit history (what its link carries), and what its planner and run noted: an LLM that failed and the built-in planner that
//! took over, words the model does not know, a review that was skipped.

use crate::app::AppState;
use crate::take::edit_line;
use coma::agents::plan::PlannerKind;
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
    let visible = move || state.steps.with(|s| !s.is_empty()) || planner().is_some();
    view! {
        <Show when=visible>
            <details class="panel steps" open>
                <summary>"Steps"</summary>
                {move || planner().map(|p| view! { <p class="planner">{p}</p> })}
                <ol id="steps">
                    {move || {
                        state
                            .steps
                            .get()
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
