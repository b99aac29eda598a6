//! The timeline: the plan's segments (see [`super::segments`]) with the playhead and the key
//! poses; a time range and body parts to edit with an instruction (in-between or body-part
//! edit) or to hold a named posture on (see [`super::postures`]); undo and redo.

use super::clips::{add_clip, ClipTracks};
use super::postures::PosturePicker;
use super::segments::{next_seed, shown_segments, PlanList, SegmentBar};
use crate::app::{AppState, Pending};
use coma::session::Command;
use coma::share::{Edit, EditKind};
use coma::skeleton::BodyPart;
use leptos::prelude::*;

use coma::timing::FPS;

#[component]
pub fn Timeline() -> impl IntoView {
    let state = expect_context::<AppState>();
    let from = RwSignal::new(0.0f64);
    let to = RwSignal::new(1.0f64);
    let parts = RwSignal::new([false; 4]);
    let instruction = RwSignal::new(String::new());
    let frames = move || {
        state
            .history
            .with(|h| h.current().as_ref().map_or(0, |t| t.frames()))
    };
    let has_take = move || frames() > 0;

    let edit_range = move |_| {
        let Some(take) = state.take() else { return };
        let text = instruction.get_untracked().trim().to_string();
        if text.is_empty() {
            return state.fail("Type an instruction for the edit first.");
        }
        let (a, b) = (from.get_untracked(), to.get_untracked());
        // NaN or a backward range: nothing to edit.
        if a.partial_cmp(&b) != Some(std::cmp::Ordering::Less) {
            return state.fail("The range must start before it ends.");
        }
        let (a, b) = ((a * FPS) as usize, (b * FPS).ceil() as usize);
        let seed = next_seed(&state);
        state.say("editing the range…");
        state.request(
            Command::InBetween {
                tokens: take.motion.tokens.clone(),
                text: text.clone(),
                from: a,
                to: b,
                seed,
                plan: take.plan.clone(),
            },
            None,
            Pending::Edit(Edit {
                kind: EditKind::InBetween,
                text,
                from_frame: a as u32,
                to_frame: b as u32,
                parts: 0,
                seed,
            }),
        );
    };
    let edit_parts = move |_| {
        let Some(take) = state.take() else { return };
        let text = instruction.get_untracked().trim().to_string();
        if text.is_empty() {
            return state.fail("Type an instruction for the edit first.");
        }
        let chosen = parts.get_untracked();
        if !chosen.contains(&true) {
            return state.fail("Tick the body parts to edit first.");
        }
        let names: Vec<BodyPart> = BodyPart::ALL
            .iter()
            .zip(chosen)
            .filter(|(_, c)| *c)
            .map(|(p, _)| *p)
            .collect();
        let mask = chosen
            .iter()
            .enumerate()
            .fold(0u8, |m, (i, c)| if *c { m | 1 << i } else { m });
        let seed = next_seed(&state);
        state.say("editing the body parts…");
        state.request(
            Command::EditParts {
                tokens: take.motion.tokens.clone(),
                text: text.clone(),
                parts: names,
                seed,
                plan: take.plan.clone(),
            },
            None,
            Pending::Edit(Edit {
                kind: EditKind::BodyParts,
                text,
                from_frame: 0,
                to_frame: take.frames() as u32,
                parts: mask,
                seed,
            }),
        );
    };
    let add = move |_| {
        let text = instruction.get_untracked().trim().to_string();
        if text.is_empty() {
            return state.fail("Type what the parts should do first.");
        }
        let chosen: Vec<BodyPart> = BodyPart::ALL
            .iter()
            .zip(parts.get_untracked())
            .filter(|(_, c)| *c)
            .map(|(p, _)| *p)
            .collect();
        if chosen.is_empty() {
            return state.fail("Tick the body parts the clip moves first.");
        }
        add_clip(
            state,
            chosen,
            text,
            from.get_untracked(),
            to.get_untracked(),
        );
    };
    let step = move |undo: bool| {
        state.history.update(|h| {
            if undo {
                h.undo();
            } else {
                h.redo();
            }
        });
        state.frame.set(0.0);
        state.publish();
    };
    let shown = shown_segments(state);
    view! {
        <div class="panel timeline">
            <SegmentBar shown/>
            <ClipTracks from to/>
            <PlanList shown/>
            <div class="row">
                <label>
                    "From "
                    <input
                        id="range-from"
                        type="number"
                        min="0"
                        step="0.2"
                        prop:value=move || from.get().to_string()
                        on:change=move |ev| {
                            if let Ok(v) = event_target_value(&ev).parse::<f64>() {
                                from.set(v.max(0.0));
                            }
                        }
                    />
                </label>
                <label>
                    "to "
                    <input
                        id="range-to"
                        type="number"
                        min="0"
                        step="0.2"
                        prop:value=move || to.get().to_string()
                        on:change=move |ev| {
                            if let Ok(v) = event_target_value(&ev).parse::<f64>() {
                                to.set(v.max(0.0));
                            }
                        }
                    />
                    " s"
                </label>
                {BodyPart::ALL
                    .iter()
                    .enumerate()
                    .map(|(i, p)| {
                        view! {
                            <label class="part">
                                <input
                                    type="checkbox"
                                    data-part=p.name()
                                    prop:checked=move || parts.get()[i]
                                    on:change=move |ev| {
                                        let on = event_target_checked(&ev);
                                        parts.update(|ps| ps[i] = on);
                                    }
                                />
                                {p.name()}
                            </label>
                        }
                    })
                    .collect_view()}
            </div>
            <div class="row">
                <input
                    id="instruction"
                    type="text"
                    placeholder="Instruction, e.g. raise the right arm higher"
                    prop:value=move || instruction.get()
                    on:input=move |ev| instruction.set(event_target_value(&ev))
                />
                <button on:click=edit_range disabled=move || state.busy() || !has_take()>
                    "Edit range"
                </button>
                <button on:click=edit_parts disabled=move || state.busy() || !has_take()>
                    "Edit parts"
                </button>
                <button
                    id="add-clip"
                    title="A clip on the ticked parts' tracks over the range"
                    on:click=add
                    disabled=move || state.busy() || !has_take()
                >
                    "Add clip"
                </button>
                <button
                    id="undo"
                    on:click=move |_| step(true)
                    disabled=move || state.busy() || !state.history.with(|h| h.can_undo())
                >
                    "Undo"
                </button>
                <button
                    id="redo"
                    on:click=move |_| step(false)
                    disabled=move || state.busy() || !state.history.with(|h| h.can_redo())
                >
                    "Redo"
                </button>
            </div>
            <PosturePicker from to parts/>
        </div>
    }
}
