//! The 3D viewer: the canvas with whichever renderer the browser allows (WebGPU, WebGL2 or
//! Canvas 2D, see [`crate::viewer::choice`]; one that fails, at start or later, gives way to
//! the next), the view's settings (skeleton or shaded body, a camera that follows the
//! character, reset), orbit (drag) and zoom (wheel), the playback controls (play/pause, scrub,
//! speed) and drawing a path on the ground (see [`super::path_draw`]: in draw mode a drag draws
//! instead of orbiting). The canvas follows its box's size.
//!
//! For tests and for people measuring, the canvas carries `data-frame-ms` (a running mean of
//! the milliseconds one frame takes: building its triangles and drawing them), `data-root-px`
//! (where the root shows, CSS pixels from the canvas's top left) and `data-drawn`; the viewer
//! carries `data-renderer`.

use super::path_draw::{PathDraw, Pen};
use crate::app::AppState;
use crate::take::joints_hash;
use crate::viewer::choice::{renderer_order, RendererKind};
use crate::viewer::renderer::Renderer;
use crate::viewer::scene::{
    body_triangles, contact_shadows, grid_lines, path_lines, screen_point, stroke_lines, Frame,
    OrbitCamera,
};
use leptos::html::Div;
use leptos::prelude::*;
use std::cell::RefCell;
use std::rc::Rc;
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;

use coma::timing::FPS;

/// The view's settings, read by every frame.
#[derive(Clone, Copy)]
struct ViewSettings {
    /// The skeleton instead of the shaded body.
    skeleton: RwSignal<bool>,
    /// The camera's target follows the root over the ground.
    follow: RwSignal<bool>,
    camera: StoredValue<OrbitCamera>,
    stroke: RwSignal<Vec<[f64; 2]>>,
}

/// Weight of the newest frame in `data-frame-ms`'s running mean (about the last 20 frames).
const FRAME_MS_WEIGHT: f64 = 0.05;

fn now_ms() -> f64 {
    web_sys::window()
        .and_then(|w| w.performance())
        .map_or(0.0, |p| p.now())
}

/// The pose shown at frame `frame` of the current take, if there is one.
fn current_pose(state: AppState, frame: f64) -> Option<[[f32; 3]; 22]> {
    state.history.with_untracked(|h| {
        let joints = &h.current().as_ref()?.motion.joints;
        joints
            .get((frame.max(0.0) as usize).min(joints.len().checked_sub(1)?))
            .copied()
    })
}

/// Draws the current frame and advances the playhead by `dt` seconds; an error when the
/// renderer can draw no more.
fn tick(
    state: AppState,
    canvas: &web_sys::HtmlCanvasElement,
    renderer: &mut Renderer,
    settings: ViewSettings,
    dt: f64,
) -> Result<(), String> {
    let started = now_ms();
    let ratio = crate::browser::device_pixel_ratio();
    let (css_w, css_h) = (
        canvas.client_width().max(1) as f64,
        canvas.client_height().max(1) as f64,
    );
    let (w, h) = ((css_w * ratio) as u32, (css_h * ratio) as u32);
    if canvas.width() != w || canvas.height() != h {
        canvas.set_width(w);
        canvas.set_height(h);
    }
    renderer.resize(w, h);
    let playing = state.playing.get_untracked();
    let speed = state.speed.get_untracked();
    let frame = state.frame.get_untracked();
    let frames = state
        .history
        .with_untracked(|h| h.current().as_ref().map_or(0, |t| t.motion.joints.len()));
    let mut next = frame;
    if playing && frames > 0 {
        next = (frame + dt * FPS * speed).rem_euclid(frames as f64);
        state.frame.set(next);
    }
    let mut camera = settings.camera.get_value();
    let pose = current_pose(state, next);
    if let (Some(pose), true) = (pose, settings.follow.get_untracked()) {
        camera.follow([pose[0][0], pose[0][2]], (dt * 3.0).min(1.0) as f32);
    }
    let mut lines = grid_lines([camera.target[0], camera.target[2]], 3.0, 0.5);
    let (mut body, mut parts, mut shadows) = (Vec::new(), Vec::new(), Vec::new());
    if let Some(pose) = &pose {
        (body, parts) = body_triangles(pose, settings.skeleton.get_untracked(), &camera);
        shadows = contact_shadows(pose);
        state.history.with_untracked(|h| {
            if let Some(take) = h.current() {
                lines.extend(path_lines(&take.motion.joints));
            }
        });
    }
    settings
        .stroke
        .with_untracked(|s| lines.extend(stroke_lines(s)));
    let view_projection = camera.view_projection((css_w / css_h) as f32);
    settings.camera.set_value(camera);
    let drawn = renderer.draw(&Frame {
        view_projection,
        eye: camera.eye(),
        lines: &lines,
        shadows: &shadows,
        body: &body,
        body_parts: &parts,
    })?;
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
    let root =
        pose.and_then(|p| screen_point(&view_projection, p[0], [css_w as f32, css_h as f32]));
    let _ = match root {
        Some([x, y]) => canvas.set_attribute("data-root-px", &format!("{x:.1},{y:.1}")),
        None => canvas.remove_attribute("data-root-px"),
    };
    let spent = now_ms() - started;
    let mean = match canvas
        .get_attribute("data-frame-ms")
        .and_then(|m| m.parse::<f64>().ok())
    {
        Some(m) => m + (spent - m) * FRAME_MS_WEIGHT,
        None => spent,
    };
    let _ = canvas.set_attribute("data-frame-ms", &format!("{mean:.3}"));
    Ok(())
}

/// Runs `tick` on every animation frame for as long as the renderer can draw; then calls
/// `on_failure` with why it stopped.
fn animate(
    state: AppState,
    canvas: web_sys::HtmlCanvasElement,
    mut renderer: Renderer,
    settings: ViewSettings,
    on_failure: impl FnOnce(String) + 'static,
) {
    type Step = Closure<dyn FnMut(f64)>;
    let step: Rc<RefCell<Option<Step>>> = Rc::new(RefCell::new(None));
    let again = step.clone();
    let mut last: Option<f64> = None;
    let mut on_failure = Some(on_failure);
    *step.borrow_mut() = Some(Closure::new(move |now: f64| {
        let dt = last.map_or(0.0, |l| ((now - l) / 1000.0).clamp(0.0, 0.25));
        last = Some(now);
        if let Err(e) = tick(state, &canvas, &mut renderer, settings, dt) {
            if let Some(f) = on_failure.take() {
                f(e);
            }
            // No next frame: the closure stays in `step` (a cycle), small and never run.
            return;
        }
        if let (Some(w), Some(f)) = (web_sys::window(), again.borrow().as_ref()) {
            let _ = w.request_animation_frame(f.as_ref().unchecked_ref());
        }
    }));
    let first = step.borrow();
    if let (Some(w), Some(f)) = (web_sys::window(), first.as_ref()) {
        let _ = w.request_animation_frame(f.as_ref().unchecked_ref());
    }
}

/// A new canvas in `holder`, in place of the one before (a canvas keeps the first kind of
/// context it gave out, so every renderer tried gets its own), sized to the holder.
fn fresh_canvas(holder: &web_sys::HtmlDivElement) -> Result<web_sys::HtmlCanvasElement, String> {
    let canvas: web_sys::HtmlCanvasElement = holder
        .owner_document()
        .ok_or("no document")?
        .create_element("canvas")
        .map_err(|e| format!("cannot make a canvas: {e:?}"))?
        .dyn_into()
        .map_err(|_| "not a canvas")?;
    canvas.set_id("view");
    holder.replace_children_with_node_1(&canvas);
    let ratio = crate::browser::device_pixel_ratio();
    canvas.set_width(((canvas.client_width().max(1) as f64) * ratio) as u32);
    canvas.set_height(((canvas.client_height().max(1) as f64) * ratio) as u32);
    Ok(canvas)
}

/// Starts the first renderer of `kinds` that works in `holder` and animates it; when it
/// later fails, starts the next ones the same way. `shown` names the renderer that draws.
fn run_renderers(
    state: AppState,
    holder: web_sys::HtmlDivElement,
    kinds: Vec<RendererKind>,
    settings: ViewSettings,
    shown: RwSignal<Option<RendererKind>>,
    problem: RwSignal<Option<String>>,
    before: Vec<String>,
) {
    leptos::task::spawn_local(async move {
        let (started, failures) = Renderer::start(&kinds, || fresh_canvas(&holder)).await;
        let reasons: Vec<String> = before.into_iter().chain(failures).collect();
        let Some((renderer, canvas)) = started else {
            shown.set(None);
            state.view_renderer.set(None);
            problem.set(Some(format!(
                "The 3D view is off: no renderer could draw here ({}). Generating, editing and exporting still work.",
                reasons.join("; ")
            )));
            return;
        };
        let kind = renderer.kind();
        shown.set(Some(kind));
        state
            .view_renderer
            .set(Some((kind.name().to_string(), reasons.join("; "))));
        let rest: Vec<RendererKind> = kinds
            .iter()
            .skip_while(|k| **k != kind)
            .skip(1)
            .copied()
            .collect();
        animate(state, canvas, renderer, settings, move |e| {
            let why = format!("{}: {e}", kind.name());
            state.say(format!(
                "The 3D view's {} renderer stopped ({e}); trying the next one.",
                kind.name()
            ));
            run_renderers(state, holder, rest, settings, shown, problem, vec![why]);
        });
    });
}

/// The view's options under the canvas: the skeleton instead of the body, the camera
/// following the character, and back to the starting view.
#[component]
fn ViewOptions(settings: ViewSettings) -> impl IntoView {
    let state = expect_context::<AppState>();
    let reset = move |_| {
        let root = current_pose(state, state.frame.get_untracked()).map(|p| [p[0][0], p[0][2]]);
        settings.camera.update_value(|c| {
            let at = root.unwrap_or([c.target[0], c.target[2]]);
            c.reset(at);
        });
    };
    view! {
        <div class="row view-options">
            <label title="Bones and joints instead of the shaded body">
                <input
                    id="skeleton"
                    type="checkbox"
                    prop:checked=move || settings.skeleton.get()
                    on:change=move |ev| settings.skeleton.set(event_target_checked(&ev))
                />
                " Skeleton"
            </label>
            <label title="The camera follows the character over the ground">
                <input
                    id="follow"
                    type="checkbox"
                    prop:checked=move || settings.follow.get()
                    on:change=move |ev| settings.follow.set(event_target_checked(&ev))
                />
                " Follow"
            </label>
            <button id="reset-view" class="small" on:click=reset>"Reset view"</button>
        </div>
    }
}

#[component]
pub fn Viewer() -> impl IntoView {
    let state = expect_context::<AppState>();
    let holder = NodeRef::<Div>::new();
    let pen = Pen::default();
    let settings = ViewSettings {
        skeleton: RwSignal::new(false),
        follow: RwSignal::new(true),
        camera: StoredValue::new(OrbitCamera::default()),
        stroke: pen.stroke,
    };
    let camera = settings.camera;
    let drag = StoredValue::new(None::<(i32, i32)>);
    let problem = RwSignal::new(None::<String>);
    let shown = RwSignal::new(None::<RendererKind>);
    // The canvas in the holder now (renderers that fail leave a new one behind).
    let canvas = move || {
        holder
            .get_untracked()?
            .first_element_child()?
            .dyn_into::<web_sys::HtmlCanvasElement>()
            .ok()
    };
    // The ground point under the pointer, through the camera as the last frame drew it.
    let ground = move |ev: &web_sys::PointerEvent| {
        let c = canvas()?;
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
    holder.on_load(move |element| {
        let choice = renderer_order(
            crate::browser::query("renderer").as_deref(),
            crate::browser::has_webgpu(),
        );
        if let Some(note) = &choice.note {
            state.fail(format!("The 3D view: {note}."));
        }
        run_renderers(
            state,
            element,
            choice.order,
            settings,
            shown,
            problem,
            Vec::new(),
        );
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
        <div
            class="viewer"
            data-joints-hash=hash
            data-frames=frames
            data-renderer=move || shown.get().map(|k| k.key())
        >
            <div
                class="view-box"
                node_ref=holder
                class:drawing=move || pen.on.get()
                on:pointerdown=move |ev: web_sys::PointerEvent| {
                    if let Some(c) = canvas() {
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
            >
                <canvas id="view"></canvas>
            </div>
            {move || problem.get().map(|p| view! { <p class="viewer-problem">{p}</p> })}
            <ViewOptions settings/>
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
