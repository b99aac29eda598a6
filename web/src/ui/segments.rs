//! The plan on the timeline: a bar of the segments in time (each with its text, length and a
//! Regenerate button, and a mark where each key pose is reached) and, under it, what each asks
//! for (base motion, body-part edits, path, each key pose's script in words) with its review
//! scores, and the plan's clips that span segments. While a run is in flight they show its plan, before the motion exists.

use crate::app::{AppState, Pending};
use crate::take::{plan_segments, Segment};
use coma::session::Command;
use coma::share::SegmentScores;
use coma::share::{Edit, EditKind};
use coma::skeleton::BodyPart;
use coma::timing::FPS;
use leptos::prelude::*;

/// What the timeline shows.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Shown {
    pub segments: Vec<Segment>,
    pub frames: usize,
    pub scores: Vec<SegmentScores>,
    /// The plan of a run still in flight: nothing to regenerate yet.
    pub preview: bool,
    /// The plan's clips over spans of their own, one line each ("left arm and right arm,
    /// 0.0–12.4 s: T-pose").
    pub clips: Vec<String>,
}

/// The plan's own clips (not the segments' part instructions, listed under their segment), one
/// line each.
fn clip_lines(plan: Option<&coma::plan::Plan>) -> Vec<String> {
    plan.map(|p| {
        p.clips
            .iter()
            .map(|c| {
                let parts: Vec<&str> = c.parts.iter().map(|p| p.name()).collect();
                let held = if c.postures.is_some() { "held: " } else { "" };
                format!(
                    "{}, {:.1}–{:.1} s: {held}{}",
                    parts.join(" and "),
                    c.start,
                    c.end,
                    c.text
                )
            })
            .collect()
    })
    .unwrap_or_default()
}

/// The plan of the run in flight, else the current take's segments.
pub fn shown_segments(state: AppState) -> Memo<Shown> {
    Memo::new(move |_| {
        if let Some(plan) = state.preview.get() {
            let segments = plan_segments(&plan, 0);
            return Shown {
                frames: segments.last().map_or(0, |s| s.to),
                segments,
                scores: Vec::new(),
                preview: true,
                clips: clip_lines(Some(&plan)),
            };
        }
        state.history.with(|h| {
            h.current().as_ref().map_or_else(Shown::default, |t| Shown {
                segments: t.segments.clone(),
                frames: t.frames(),
                scores: t.scores.clone(),
                preview: false,
                clips: clip_lines(t.plan.as_ref()),
            })
        })
    })
}

/// A fresh seed for an edit: different from the take's, reproducible from it.
pub fn next_seed(state: &AppState) -> u64 {
    state
        .take()
        .map_or(1, |t| t.seed.wrapping_add(1 + t.edits.len() as u64))
}

/// Regenerates segment `index` of the current take from its text.
fn regenerate(state: AppState, index: usize) {
    let Some(take) = state.take() else { return };
    let Some(segment) = take.segments.get(index).cloned() else {
        return;
    };
    let seed = next_seed(&state);
    state.say("regenerating the segment…");
    state.request(
        Command::InBetween {
            tokens: take.motion.tokens.clone(),
            text: segment.text.clone(),
            from: segment.from,
            to: segment.to,
            seed,
            plan: take.plan.clone(),
        },
        None,
        Pending::Edit(Edit {
            kind: EditKind::Regenerate,
            text: segment.text,
            from_frame: segment.from as u32,
            to_frame: segment.to as u32,
            parts: 0,
            seed,
        }),
    );
}

/// The segments in time, with the playhead.
#[component]
pub fn SegmentBar(shown: Memo<Shown>) -> impl IntoView {
    let state = expect_context::<AppState>();
    view! {
        <div class="segments" aria-label="Segments" class:preview=move || shown.with(|s| s.preview)>
            {move || {
                let Shown { segments, frames, preview, .. } = shown.get();
                let total = frames.max(1) as f64;
                segments
                    .into_iter()
                    .enumerate()
                    .map(|(i, s)| {
                        let width = (s.to - s.from) as f64 / total * 100.0;
                        view! {
                            <div
                                class="segment"
                                style=format!("width: {width:.2}%")
                                data-from=s.from
                                data-to=s.to
                                title=s.text.clone()
                            >
                                <span class="segment-text">{s.text.clone()}</span>
                                <span class="segment-foot">
                                    <span class="seconds">{format!("{:.1} s", s.seconds())}</span>
                                    <button
                                        class="small"
                                        on:click=move |_| regenerate(state, i)
                                        disabled=move || preview || state.busy()
                                    >
                                        "Regenerate"
                                    </button>
                                </span>
                            </div>
                        }
                    })
                    .collect_view()
            }}
            {move || {
                let Shown { segments, frames, .. } = shown.get();
                let total = frames.max(1) as f64;
                segments
                    .into_iter()
                    .flat_map(|s| s.keys)
                    .map(|k| {
                        let title = format!(
                            "{} (reached at {:.1} s, held {:.1} s)",
                            k.name,
                            k.frame / FPS,
                            k.hold,
                        );
                        view! {
                            <div
                                class="key-pose"
                                style=format!("left: {:.2}%", (k.frame / total * 100.0).min(100.0))
                                title=title
                                data-name=k.name
                            ></div>
                        }
                    })
                    .collect_view()
            }}
            <div
                class="playhead"
                style=move || {
                    format!(
                        "left: {:.2}%",
                        state.frame.get() / shown.with(|s| s.frames).max(1) as f64 * 100.0,
                    )
                }
            ></div>
        </div>
    }
}

/// What a segment's key poses drive, as a heading for their lines ("key poses of the whole
/// body", "key poses held on the left arm, right arm"); `None` without key poses.
fn posture_heading(parts: &[String]) -> Option<String> {
    match parts.len() {
        0 => None,
        n if n == BodyPart::ALL.len() => Some("key poses of the whole body:".into()),
        _ => Some(format!("key poses held on the {}:", parts.join(", "))),
    }
}

fn score_line(scores: &SegmentScores) -> Option<String> {
    let before = scores.before?;
    Some(match scores.after {
        Some(after) if scores.rounds > 0 => format!(
            "review: {before:.0} → {after:.0} ({} round(s), {} kept)",
            scores.rounds, scores.kept
        ),
        _ => format!("review: {before:.0}"),
    })
}

/// What each segment asks for.
#[component]
pub fn PlanList(shown: Memo<Shown>) -> impl IntoView {
    view! {
        <ol class="plan" aria-label="Plan">
            {move || {
                let Shown { segments, scores, .. } = shown.get();
                segments
                    .into_iter()
                    .enumerate()
                    .map(|(i, s)| {
                        // A take without a plan (an older link) knows only its texts.
                        let base = (!s.base.is_empty() && s.base != s.text).then(|| s.base.clone());
                        let score = scores.get(i).and_then(score_line);
                        view! {
                            <li class="plan-segment">
                                <span>{format!("{} ({:.1} s)", s.text, s.seconds())}</span>
                                <ul>
                                    {base.map(|b| view! { <li class="base">{format!("base: {b}")}</li> })}
                                    {s
                                        .parts
                                        .into_iter()
                                        .map(|(part, text)| {
                                            view! {
                                                <li class="part-edit" data-part=part.clone()>
                                                    {format!("{part}: {text}")}
                                                </li>
                                            }
                                        })
                                        .collect_view()}
                                    {s.path.map(|p| view! { <li class="path">{format!("path: {p}")}</li> })}
                                    {posture_heading(&s.posture_parts)
                                        .map(|h| view! { <li class="postures">{h}</li> })}
                                    {s
                                        .postures
                                        .into_iter()
                                        .map(|line| {
                                            // The name and hold, the constraints folded under
                                            // it; the text reads as the whole line.
                                            let (head, words) = match line.split_once("): ") {
                                                Some((h, w)) => (format!("{h}):"), format!(" {w}")),
                                                None => (line, String::new()),
                                            };
                                            view! {
                                                <li class="posture-key">
                                                    <details>
                                                        <summary>{head}</summary>
                                                        {words}
                                                    </details>
                                                </li>
                                            }
                                        })
                                        .collect_view()}
                                    {score.map(|l| view! { <li class="score">{l}</li> })}
                                </ul>
                            </li>
                        }
                    })
                    .collect_view()
            }}
            {move || {
                shown
                    .get()
                    .clips
                    .into_iter()
                    .map(|line| view! { <li class="plan-clip">{format!("clip: {line}")}</li> })
                    .collect_view()
            }}
        </ol>
    }
}
