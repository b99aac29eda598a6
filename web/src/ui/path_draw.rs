//! Drawing a segment's path on the ground with the pointer. With "Draw path" on, a drag on
//! the 3D view draws instead of orbiting the camera: each pointer position is picked on the
//! ground plane ([`OrbitCamera::ground_point`](crate::viewer::scene::OrbitCamera::ground_point)),
//! the stroke shows as it grows, and on release the trajectory editor lays the chosen
//! segment's root along it, as it lays a typed path: the take's tokens are decoded again with
//! a plan whose segment walks the drawn points (nothing is regenerated), the result is a new
//! take (undo goes back), the edit history records it and the share link rebuilds it. Esc or
//! Cancel stops without changing anything; a stroke too short to walk says so and keeps the
//! take.

use crate::app::AppState;
use crate::take::with_drawn_path;
use crate::ui::segments::next_seed;
use leptos::prelude::*;

/// The drawing in progress, shared by the viewer's canvas (which picks the points) and the
/// controls under it.
#[derive(Clone, Copy)]
pub struct Pen {
    /// Draw mode: drags on the canvas draw instead of orbiting.
    pub on: RwSignal<bool>,
    /// The stroke so far, `[x, z]` ground-plane metres (Y up; the motion starts at the
    /// origin facing +Z, +X is its left); shown until the path it made is laid.
    pub stroke: RwSignal<Vec<[f64; 2]>>,
    /// Whether a press on the canvas started the stroke and has not been released.
    pub down: RwSignal<bool>,
    /// The plan segment the path is for (index from 0).
    pub segment: RwSignal<usize>,
}

/// A new point closer than this to the last one (metres) adds nothing a walker would follow;
/// [`with_drawn_path`] thins the stroke again before it is laid.
const PICK_STEP_M: f64 = 0.01;

impl Default for Pen {
    fn default() -> Pen {
        Pen {
            on: RwSignal::new(false),
            stroke: RwSignal::new(Vec::new()),
            down: RwSignal::new(false),
            segment: RwSignal::new(0),
        }
    }
}

impl Pen {
    /// The pointer went down at ground point `at` (`None`: it missed the ground).
    pub fn press(&self, at: Option<[f32; 2]>) {
        self.down.set(true);
        self.stroke.set(
            at.map(|p| vec![[p[0] as f64, p[1] as f64]])
                .unwrap_or_default(),
        );
    }

    /// The pointer moved to `at` while down; points off the ground are skipped.
    pub fn drag(&self, at: Option<[f32; 2]>) {
        let Some(p) = at.filter(|_| self.down.get_untracked()) else {
            return;
        };
        let p = [p[0] as f64, p[1] as f64];
        let far_enough = self.stroke.with_untracked(|s| {
            s.last()
                .is_none_or(|q| (p[0] - q[0]).hypot(p[1] - q[1]) >= PICK_STEP_M)
        });
        if far_enough {
            self.stroke.update(|s| s.push(p));
        }
    }

    /// The pointer was released: the stroke becomes the segment's path, or a message says
    /// why not and the take stays.
    pub fn release(&self, state: AppState) {
        if !self.down.get_untracked() {
            return;
        }
        self.down.set(false);
        let stroke = self.stroke.get_untracked();
        let Some(take) = state.take() else {
            self.stroke.set(Vec::new());
            return state.fail("Generate a motion first, then draw its path.");
        };
        match with_drawn_path(&take, self.segment.get_untracked(), &stroke) {
            Err(e) => {
                // Draw mode stays on: the user can simply draw again.
                self.stroke.set(Vec::new());
                state.fail(e);
            }
            Ok(edit) => {
                let line = edit.line();
                let record = edit.edit(next_seed(&state));
                // The stroke stays on screen until the laid path replaces it (see PathDraw).
                self.on.set(false);
                state.say(format!("laying the drawn path: {line}…"));
                state.decode_with_plan(&take, edit.plan, line, Some(record));
            }
        }
    }

    /// Leaves draw mode without changing anything.
    pub fn cancel(&self, state: AppState) {
        if self.on.get_untracked() {
            self.on.set(false);
            self.down.set(false);
            self.stroke.set(Vec::new());
            state.say("Drawing cancelled: the motion is unchanged.");
        }
    }
}

/// The segment the playhead is in, as an index into the take's segments.
fn segment_at_playhead(state: AppState) -> usize {
    let frame = state.frame.get_untracked() as usize;
    state.history.with_untracked(|h| {
        h.current().as_ref().map_or(0, |t| {
            t.segments
                .iter()
                .position(|s| s.from <= frame && frame < s.to)
                .unwrap_or(0)
        })
    })
}

/// The controls: "Draw path" (on and off), which segment (when there are several), Cancel,
/// and a hint while drawing.
#[component]
pub fn PathDraw(pen: Pen) -> impl IntoView {
    let state = expect_context::<AppState>();
    let segments = move || {
        state.history.with(|h| {
            h.current().as_ref().map_or_else(Vec::new, |t| {
                t.segments
                    .iter()
                    .map(|s| (s.text.clone(), s.from))
                    .collect::<Vec<_>>()
            })
        })
    };
    let can_draw = move || {
        !state.busy()
            && state
                .history
                .with(|h| h.current().as_ref().is_some_and(|t| t.plan.is_some()))
    };
    // The playhead goes to where the segment starts and stops there: the camera follows the
    // character, so the view centres on where the drawn path will begin.
    let go_to_segment = move |index: usize| {
        pen.segment.set(index);
        if let Some(from) = segments().get(index).map(|s| s.1) {
            state.playing.set(false);
            state.frame.set(from as f64);
        }
    };
    let toggle = move |_| {
        if pen.on.get_untracked() {
            pen.cancel(state);
        } else {
            pen.on.set(true);
            pen.stroke.set(Vec::new());
            go_to_segment(segment_at_playhead(state));
            state.say(
                "Draw the path on the ground: press, drag and release on the view (Esc cancels).",
            );
        }
    };
    // Esc cancels, wherever the focus is.
    let keys = window_event_listener(leptos::ev::keydown, move |ev| {
        if ev.key() == "Escape" {
            pen.cancel(state);
        }
    });
    on_cleanup(move || keys.remove());
    // The stroke goes once the path it made is laid (or refused), and a take that changes
    // under draw mode (undo, a new run) ends it: its segments may not be the ones chosen.
    Effect::new(move |_| {
        if !state.busy() && !pen.on.get() {
            pen.stroke.set(Vec::new());
        }
    });
    Effect::new(move |_| {
        state.history.track();
        untrack(|| {
            if pen.on.get() && !pen.down.get() {
                pen.on.set(false);
                pen.stroke.set(Vec::new());
            }
        });
    });
    view! {
        <div class="row path-draw">
            <button
                id="draw-path"
                aria-pressed=move || pen.on.get().to_string()
                title="Draw the root's path on the ground with the pointer"
                on:click=toggle
                disabled=move || !can_draw() && !pen.on.get()
            >
                "Draw path"
            </button>
            {move || {
                let all = segments();
                (all.len() > 1)
                    .then(|| {
                        view! {
                            <label>
                                "for segment "
                                <select
                                    id="path-segment"
                                    aria-label="Segment to draw the path for"
                                    on:change=move |ev| {
                                        if let Ok(i) = event_target_value(&ev).parse::<usize>() {
                                            go_to_segment(i);
                                        }
                                    }
                                >
                                    {all
                                        .into_iter()
                                        .enumerate()
                                        .map(|(i, (text, _))| {
                                            view! {
                                                <option
                                                    value=i.to_string()
                                                    selected=move || pen.segment.get() == i
                                                >
                                                    {format!("{}: {text}", i + 1)}
                                                </option>
                                            }
                                        })
                                        .collect_view()}
                                </select>
                            </label>
                        }
                    })
            }}
            <Show when=move || pen.on.get()>
                <button id="cancel-path" on:click=move |_| pen.cancel(state)>
                    "Cancel"
                </button>
                <span class="hint">
                    {move || {
                        let n = pen.stroke.with(Vec::len);
                        if n > 1 {
                            format!(
                                "{:.1} m drawn",
                                coma::trajectory::drawn::polyline_length(&pen.stroke.get()),
                            )
                        } else {
                            // The root mapping keeps the segment's start and facing, so
                            // what is walked is the drawn shape, not the drawn place.
                            "Drag on the ground to draw: the segment walks this shape from where \
                             it starts, turned to the way it faces, at its own length."
                                .to_string()
                        }
                    }}
                </span>
            </Show>
        </div>
    }
}
