//! The body-part tracks of the timeline: one row per part, each clip a bar from its start to
//! its end (the segments' own part instructions included, see [`Plan::part_clips`]). A click
//! selects a clip and puts its times in the range fields; its ends drag to retime it. Moving,
//! adding and deleting a clip regenerate only the spans that changed
//! ([`Command::EditClips`]); each is an edit of the take's history, so it undoes, and the
//! new plan goes into the share link.

use crate::app::{AppState, Pending};
use crate::take::Take;
use coma::agents::pipeline::clip_frames;
use coma::plan::{Clip, Plan};
use coma::session::Command;
use coma::share::{Edit, EditKind};
use coma::skeleton::BodyPart;
use coma::timing::FPS;
use leptos::prelude::*;

use super::segments::next_seed;

/// A clip as the tracks draw it: where it sits in the motion, in frames (20 fps).
#[derive(Clone, Debug, PartialEq)]
struct Bar {
    clip: Clip,
    from: usize,
    to: usize,
}

/// The clips of the current take, with their frames, and the motion's length in frames.
fn bars(take: &Take) -> (Vec<Bar>, usize) {
    let frames = take.frames();
    let Some(plan) = &take.plan else {
        return (Vec::new(), frames);
    };
    let bars = plan
        .part_clips()
        .into_iter()
        .map(|clip| {
            let span = clip_frames(plan, &clip, &take.motion.tokens);
            Bar {
                clip,
                from: span.start,
                to: span.end,
            }
        })
        .collect();
    (bars, frames)
}

/// Sends the take's motion to follow `after` (its clips changed), recording `what`.
fn change_clips(state: AppState, take: &Take, before: Plan, after: Plan, what: &Clip, line: &str) {
    let after = match after.checked() {
        Ok(plan) => plan,
        Err(e) => return state.fail(format!("The clip cannot go there: {e}.")),
    };
    let seed = next_seed(&state);
    let parts = what
        .parts
        .iter()
        .map(|p| 1u8 << BodyPart::ALL.iter().position(|q| q == p).unwrap_or(0))
        .fold(0, |a, b| a | b);
    state.say(format!("{line}…"));
    state.request(
        Command::EditClips {
            tokens: take.motion.tokens.clone(),
            before,
            plan: after.clone(),
            seed,
        },
        None,
        Pending::Plan {
            plan: after,
            line: line.to_string(),
            edit: Some(Edit {
                kind: EditKind::BodyParts,
                text: what.text.clone(),
                from_frame: (what.start * FPS) as u32,
                to_frame: (what.end * FPS).ceil() as u32,
                parts,
                seed,
            }),
        },
    );
}

/// Clip `index` of the take's timeline (as [`Plan::part_clips`] lists them) moved to
/// `start..end` seconds, or deleted with `None`.
fn edit_clip(state: AppState, index: usize, span: Option<(f64, f64)>) {
    let Some(take) = state.take() else { return };
    let Some(plan) = &take.plan else {
        return state.fail("This motion has no plan to edit (an older link).");
    };
    let before = plan.lifted();
    let Some(clip) = before.clips.get(index).cloned() else {
        return state.fail("Select a clip on the body-part tracks first.");
    };
    let mut after = before.clone();
    after.clips.remove(index);
    match span {
        Some((start, end)) => {
            let moved = Clip {
                start,
                end,
                ..clip.clone()
            };
            after.clips.push(moved.clone());
            let line = format!("clip \"{}\" moved to {start:.1}–{end:.1} s", clip.text);
            change_clips(state, &take, before, after, &moved, &line);
        }
        None => {
            let line = format!("clip \"{}\" deleted", clip.text);
            change_clips(state, &take, before, after, &clip, &line);
        }
    }
}

/// A clip of `text` on `parts` from `start` to `end` seconds added to the take's timeline.
pub fn add_clip(state: AppState, parts: Vec<BodyPart>, text: String, start: f64, end: f64) {
    let Some(take) = state.take() else { return };
    let Some(plan) = &take.plan else {
        return state.fail("This motion has no plan to add a clip to (an older link).");
    };
    let before = plan.lifted();
    let clip = Clip {
        parts,
        text,
        start,
        end,
        postures: None,
    };
    let mut after = before.clone();
    after.clips.push(clip.clone());
    let names: Vec<&str> = clip.parts.iter().map(|p| p.name()).collect();
    let line = format!(
        "{}: \"{}\" added from {start:.1} to {end:.1} s",
        names.join(" and "),
        clip.text
    );
    change_clips(state, &take, before, after, &clip, &line);
}

/// Which end of a clip a drag holds.
#[derive(Clone, Copy, Debug, PartialEq)]
enum End {
    Start,
    End,
}

/// The body-part tracks, with Move and Delete for the selected clip.
#[component]
pub fn ClipTracks(from: RwSignal<f64>, to: RwSignal<f64>) -> impl IntoView {
    let state = expect_context::<AppState>();
    let selected = RwSignal::new(None::<usize>);
    // A drag in progress: the clip, the end held, and the time it is at now (seconds).
    let drag = RwSignal::new(None::<(usize, End, f64)>);
    let shown = Memo::new(move |_| {
        state
            .history
            .with(|h| h.current().as_ref().map(bars).unwrap_or_default())
    });
    // A new take (an edit, undo, a new run) may not have the clip selected before.
    Effect::new(move |_| {
        shown.track();
        selected.set(None);
        drag.set(None);
    });
    let seconds_at = move |ev: &leptos::ev::PointerEvent| -> Option<f64> {
        use wasm_bindgen::JsCast;
        let row = ev.current_target()?.dyn_into::<web_sys::Element>().ok()?;
        let rect = row.get_bounding_client_rect();
        let share = ((ev.client_x() as f64 - rect.left()) / rect.width().max(1.0)).clamp(0.0, 1.0);
        let frames = shown.with(|(_, f)| *f).max(1) as f64;
        // Whole token steps (0.2 s), the finest the model edits.
        Some((share * frames / FPS * 5.0).round() / 5.0)
    };
    let release = move |ev: leptos::ev::PointerEvent| {
        let Some((index, end, _)) = drag.get_untracked() else {
            return;
        };
        drag.set(None);
        let Some(t) = seconds_at(&ev) else { return };
        let Some(clip) = shown.with(|(b, _)| b.get(index).map(|b| b.clip.clone())) else {
            return;
        };
        let (start, stop) = match end {
            End::Start => (t.min(clip.end - 0.4), clip.end),
            End::End => (clip.start, t.max(clip.start + 0.4)),
        };
        if (start, stop) != (clip.start, clip.end) {
            edit_clip(state, index, Some((start, stop)));
        }
    };
    let selected_clip = move || {
        selected
            .get()
            .and_then(|i| shown.with(|(b, _)| b.get(i).map(|b| b.clip.clone())))
    };
    view! {
        <div class="clip-tracks" aria-label="Body-part tracks">
            {BodyPart::ALL
                .iter()
                .map(|part| {
                    let part = *part;
                    view! {
                        <div
                            class="clip-track"
                            data-part=part.name()
                            on:pointermove=move |ev| {
                                if let (Some((i, end, _)), Some(t)) = (drag.get_untracked(), seconds_at(&ev)) {
                                    drag.set(Some((i, end, t)));
                                }
                            }
                            on:pointerup=release
                            on:pointerleave=move |_| drag.set(None)
                        >
                            <span class="track-name">{part.name()}</span>
                            {move || {
                                let (bars, frames) = shown.get();
                                let total = frames.max(1) as f64;
                                bars.into_iter()
                                    .enumerate()
                                    .filter(|(_, b)| b.clip.parts.contains(&part))
                                    .map(|(i, b)| {
                                        let (mut from_f, mut to_f) = (b.from as f64, b.to as f64);
                                        if let Some((j, end, t)) = drag.get() {
                                            if j == i {
                                                match end {
                                                    End::Start => from_f = (t * FPS).min(to_f - 8.0),
                                                    End::End => to_f = (t * FPS).max(from_f + 8.0),
                                                }
                                            }
                                        }
                                        let left = from_f / total * 100.0;
                                        let width = (to_f - from_f) / total * 100.0;
                                        let title = format!(
                                            "{} ({:.1}–{:.1} s)",
                                            b.clip.text,
                                            b.clip.start,
                                            b.clip.end
                                        );
                                        let clip = b.clip.clone();
                                        view! {
                                            <div
                                                class="clip"
                                                class:selected=move || selected.get() == Some(i)
                                                class:posture=clip.postures.is_some()
                                                style=format!("left: {left:.2}%; width: {width:.2}%")
                                                title=title
                                                data-start=format!("{:.1}", clip.start)
                                                data-end=format!("{:.1}", clip.end)
                                                on:click=move |_| {
                                                    selected.set(Some(i));
                                                    from.set(clip.start);
                                                    to.set(clip.end);
                                                }
                                            >
                                                <span
                                                    class="clip-end start"
                                                    title="drag to retime"
                                                    on:pointerdown=move |ev| {
                                                        ev.prevent_default();
                                                        if !state.busy() {
                                                            drag.set(Some((i, End::Start, b.clip.start)));
                                                        }
                                                    }
                                                ></span>
                                                <span class="clip-text">{b.clip.text.clone()}</span>
                                                <span
                                                    class="clip-end end"
                                                    title="drag to retime"
                                                    on:pointerdown=move |ev| {
                                                        ev.prevent_default();
                                                        if !state.busy() {
                                                            drag.set(Some((i, End::End, b.clip.end)));
                                                        }
                                                    }
                                                ></span>
                                            </div>
                                        }
                                    })
                                    .collect_view()
                            }}
                        </div>
                    }
                })
                .collect_view()}
            <div class="row">
                <span class="muted">
                    {move || match selected_clip() {
                        Some(c) => format!("clip \"{}\", {:.1}–{:.1} s", c.text, c.start, c.end),
                        None => "no clip selected".into(),
                    }}
                </span>
                <button
                    id="move-clip"
                    on:click=move |_| {
                        if let Some(i) = selected.get_untracked() {
                            edit_clip(state, i, Some((from.get_untracked(), to.get_untracked())));
                        }
                    }
                    disabled=move || state.busy() || selected.get().is_none()
                >
                    "Move clip to range"
                </button>
                <button
                    id="delete-clip"
                    on:click=move |_| {
                        if let Some(i) = selected.get_untracked() {
                            edit_clip(state, i, None);
                        }
                    }
                    disabled=move || state.busy() || selected.get().is_none()
                >
                    "Delete clip"
                </button>
            </div>
        </div>
    }
}
