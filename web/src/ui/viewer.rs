//! The 3D viewer: the canvas with the WebGPU renderer, orbit (drag) and zoom (wheel), the
//! playback controls (play/pause, scrub, speed) and drawing a path on the ground (see
//! [`super::path_draw`]: in draw mode a drag draws instead of orbiting). The canvas follows
//! its box's size.

use super::path_draw::{PathDraw, Pen};
use crate::app::AppState;
use crate::take::joints_hash;
use crate::viewer::gpu::{Frame, Renderer};
use crate::viewer::scene::{grid_lines, path_lines, skeleton_triangles, stroke_lines, OrbitCamera};
use leptos::html::Canvas;
use leptos::prelude::*;
use std::cell::RefCell;
use std::rc::Rc;
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;

use coma::timing::FPS;

/// Draws the current frame and advances the playhead by `dt` seconds.
fn tick(
    state: AppState,
    canvas: &web_sys::HtmlCanvasElement,
    renderer: &mut Renderer,
    camera: &mut OrbitCamera,
    stroke: RwSignal<Vec<[f64; 2]>>,
    dt: f64,
) {
    let ratio = crate::browser::device_pixel_ratio();
    let (w, h) = (
        (canvas.client_width().max(1) as f64 * ratio) as u32,
        (canvas.client_height().max(1) as f64 * ratio) as u32,
    );
    if canvas.width() != w || canvas.height() != h {
        canvas.set_width(w);
        canvas.set_height(h);
    }
    renderer.resize(w, h);
    let playing = state.playing.get_untracked();
    let speed = state.speed.get_untracked();
    let frame = state.frame.get_untracked();
    state.history.with_untracked(|history| {
        let take = history.current().as_ref();
        let frames = take.map_or(0, |t| t.motion.joints.len());
        let mut next = frame;
        if playing && frames > 0 {
            next = (frame + dt * FPS * speed).rem_euclid(frames as f64);
            state.frame.set(next);
        }
        let mut triangles = Vec::new();
        let mut lines = grid_lines([camera.target[0], camera.target[2]], 3.0, 0.5);
        if let Some(take) = take.filter(|_| frames > 0) {
            let pose = &take.motion.joints[(next as usize).min(frames - 1)];
            // The camera follows the character over the ground.
            let root = pose[0];
            let follow = (dt * 3.0).min(1.0) as f32;
            camera.target[0] += (root[0] - camera.target[0]) * follow;
            camera.target[2] += (root[2] - camera.target[2]) * follow;
            triangles = skeleton_triangles(pose, camera);
            lines.extend(path_lines(&take.motion.joints));
        }
        stroke.with_untracked(|s| lines.extend(stroke_lines(s)));
        let drawn = renderer.draw(&Frame {
            view_projection: camera.view_projection(renderer.aspect()),
            triangles: &triangles,
            lines: &lines,
        });
        // How many frames reached the screen, for tests and for telling a stuck canvas.
        let count: u64 = canvas
            .get_attribute("data-drawn")
            .and_then(|c| c.parse().ok())
            .unwrap_or(0);
        if drawn {
            let _ = canvas.set_attribute("data-drawn", &(count + 1).to_string());
        } else {
            let _ = canvas.set_attribute("data-missed", "1");
        }
    });
}

/// Runs `tick` on every animation frame for as long as the page lives.
fn animate(
    state: AppState,
    canvas: web_sys::HtmlCanvasElement,
    mut renderer: Renderer,
    camera: StoredValue<OrbitCamera>,
    stroke: RwSignal<Vec<[f64; 2]>>,
) {
    type Step = Closure<dyn FnMut(f64)>;
    let step: Rc<RefCell<Option<Step>>> = Rc::new(RefCell::new(None));
    let again = step.clone();
    let mut last: Option<f64> = None;
    *step.borrow_mut() = Some(Closure::new(move |now: f64| {
        let dt = last.map_or(0.0, |l| ((now - l) / 1000.0).clamp(0.0, 0.25));
        last = Some(now);
        let mut cam = camera.get_value();
        tick(state, &canvas, &mut renderer, &mut cam, stroke, dt);
        camera.set_value(cam);
        if let (Some(w), Some(f)) = (web_sys::window(), again.borrow().as_ref()) {
            let _ = w.request_animation_frame(f.as_ref().unchecked_ref());
        }
    }));
    let first = step.borrow();
    if let (Some(w), Some(f)) = (web_sys::window(), first.as_ref()) {
        let _ = w.request_animation_frame(f.as_ref().unchecked_ref());
    }
}

#[component]
pub fn Viewer() -> impl IntoView {
    let state = expect_context::<AppState>();
    let canvas = NodeRef::<Canvas>::new();
    let camera = StoredValue::new(OrbitCamera::default());
    let drag = StoredValue::new(None::<(i32, i32)>);
    let problem = RwSignal::new(None::<String>);
    let pen = Pen::default();
    // The ground point under the pointer, through the camera as the last frame drew it.
    let ground = move |ev: &web_sys::PointerEvent| {
        let c = canvas.get_untracked()?;
        let (w, h) = (
            c.client_width().max(1) as f32,
            c.client_height().max(1) as f32,
        );
        let ndc = [
            2.0 * ev.offset_x() as f32 / w - 1.0,
            1.0 - 2.0 * ev.offset_y() as f32 / h,
        ];
        camera.get_value().ground_point(ndc, w / h)
    };
    canvas.on_load(move |element| {
        if !crate::browser::has_webgpu() {
            problem.set(Some(
                "This browser offers no WebGPU, so the 3D view is off; generating, editing and exporting still work.".into(),
            ));
            return;
        }
        leptos::task::spawn_local(async move {
            match Renderer::new(element.clone()).await {
                Ok(renderer) => animate(state, element, renderer, camera, pen.stroke),
                Err(e) => problem.set(Some(format!("The 3D view is off: {e}."))),
            }
        });
    });
    let frames = move || {
        state
            .history
            .with(|h| h.current().as_ref().map_or(0, |t| t.frames()))
    };
    let hash = move || {
        state
            .history
            .with(|h| h.current().as_ref().map(|t| joints_hash(&t.motion.joints)))
            .unwrap_or_default()
    };
    view! {
        <div class="viewer" data-joints-hash=hash data-frames=frames>
            <canvas
                id="view"
                node_ref=canvas
                class:drawing=move || pen.on.get()
                on:pointerdown=move |ev: web_sys::PointerEvent| {
                    if let Some(c) = canvas.get_untracked() {
                        let _ = c.set_pointer_capture(ev.pointer_id());
                    }
                    // In draw mode a drag draws; the camera holds still under the pen.
                    if pen.on.get_untracked() {
                        ev.prevent_default();
                        pen.press(ground(&ev));
                    } else {
                        drag.set_value(Some((ev.client_x(), ev.client_y())));
                    }
                }
                on:pointermove=move |ev: web_sys::PointerEvent| {
                    if pen.down.get_untracked() {
                        pen.drag(ground(&ev));
                    } else if let Some((x, y)) = drag.get_value() {
                        let (dx, dy) = (ev.client_x() - x, ev.client_y() - y);
                        camera.update_value(|c| c.orbit(-dx as f32 * 0.01, dy as f32 * 0.01));
                        drag.set_value(Some((ev.client_x(), ev.client_y())));
                    }
                }
                on:pointerup=move |_| {
                    drag.set_value(None);
                    pen.release(state);
                }
                on:pointercancel=move |_| {
                    drag.set_value(None);
                    // The browser took the pointer (a scroll, a lost touch): no path from that.
                    pen.down.set(false);
                    pen.stroke.set(Vec::new());
                }
                on:wheel=move |ev: web_sys::WheelEvent| {
                    ev.prevent_default();
                    camera.update_value(|c| c.zoom((ev.delta_y() * 0.001).exp() as f32));
                }
            ></canvas>
            {move || problem.get().map(|p| view! { <p class="viewer-problem">{p}</p> })}
            <div class="row playback">
                <button
                    id="play"
                    on:click=move |_| state.playing.update(|p| *p = !*p)
                    disabled=move || frames() == 0
                >
                    {move || if state.playing.get() { "Pause" } else { "Play" }}
                </button>
                <input
                    id="scrub"
                    type="range"
                    min="0"
                    aria-label="Frame"
                    prop:max=move || frames().saturating_sub(1).to_string()
                    prop:value=move || (state.frame.get() as usize).to_string()
                    on:input=move |ev| {
                        if let Ok(f) = event_target_value(&ev).parse::<f64>() {
                            state.playing.set(false);
                            state.frame.set(f);
                        }
                    }
                />
                <span class="time">
                    {move || format!("{:.1} / {:.1} s", state.frame.get() / FPS, frames() as f64 / FPS)}
                </span>
                <select
                    aria-label="Speed"
                    on:change=move |ev| {
                        if let Ok(s) = event_target_value(&ev).parse::<f64>() {
                            state.speed.set(s);
                        }
                    }
                >
                    <option value="0.25">"0.25×"</option>
                    <option value="0.5">"0.5×"</option>
                    <option value="1" selected>"1×"</option>
                    <option value="2">"2×"</option>
                </select>
            </div>
            <PathDraw pen/>
        </div>
    }
}
