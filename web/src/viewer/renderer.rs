//! One renderer over the three ways of drawing the view, so the viewer does not care which
//! one draws: [`Renderer::start`] tries them in the order [`super::choice`] gives, each on a
//! fresh canvas (a canvas keeps the first kind of context it gives out), and says why the
//! ones before failed.

use super::canvas2d::Canvas2dRenderer;
use super::choice::RendererKind;
use super::gpu::{GpuApi, GpuRenderer};
use super::scene::Frame;

/// The renderer that draws the view.
pub enum Renderer {
    /// Boxed: the wgpu renderer is large, and the enum is moved around while it starts.
    Gpu(Box<GpuRenderer>, RendererKind),
    Canvas2d(Canvas2dRenderer),
}

impl Renderer {
    /// A renderer of `kind` on `canvas`.
    pub async fn new(
        kind: RendererKind,
        canvas: web_sys::HtmlCanvasElement,
    ) -> Result<Renderer, String> {
        match kind {
            RendererKind::WebGpu => GpuRenderer::new(canvas, GpuApi::WebGpu)
                .await
                .map(|r| Renderer::Gpu(Box::new(r), kind)),
            RendererKind::WebGl2 => GpuRenderer::new(canvas, GpuApi::WebGl2)
                .await
                .map(|r| Renderer::Gpu(Box::new(r), kind)),
            RendererKind::Canvas2d => Canvas2dRenderer::new(canvas).map(Renderer::Canvas2d),
        }
    }

    /// The first of `kinds` that starts, each tried on a canvas from `fresh_canvas`, with
    /// the canvas it draws on; the reasons of those that did not, in order ("WebGPU: no
    /// adapter"). None when none starts.
    pub async fn start(
        kinds: &[RendererKind],
        mut fresh_canvas: impl FnMut() -> Result<web_sys::HtmlCanvasElement, String>,
    ) -> (Option<(Renderer, web_sys::HtmlCanvasElement)>, Vec<String>) {
        let mut failures = Vec::new();
        for kind in kinds {
            let canvas = match fresh_canvas() {
                Ok(c) => c,
                Err(e) => {
                    failures.push(format!("{}: {e}", kind.name()));
                    continue;
                }
            };
            match Renderer::new(*kind, canvas.clone()).await {
                Ok(r) => return (Some((r, canvas)), failures),
                Err(e) => failures.push(format!("{}: {e}", kind.name())),
            }
        }
        (None, failures)
    }

    /// Which renderer this is.
    pub fn kind(&self) -> RendererKind {
        match self {
            Renderer::Gpu(_, kind) => *kind,
            Renderer::Canvas2d(_) => RendererKind::Canvas2d,
        }
    }

    /// Follows a new canvas size in device pixels (the 2D renderer reads the canvas's own).
    pub fn resize(&mut self, width: u32, height: u32) {
        if let Renderer::Gpu(r, _) = self {
            r.resize(width, height);
        }
    }

    /// Draws one frame: Ok(false) when it did not reach the canvas this time, an error when
    /// the renderer cannot draw any more (its device is lost).
    pub fn draw(&mut self, frame: &Frame) -> Result<bool, String> {
        match self {
            Renderer::Gpu(r, _) => r.draw(frame),
            Renderer::Canvas2d(r) => r.draw(frame),
        }
    }
}
