//! The viewer's Canvas 2D renderer, for browsers where neither WebGPU nor WebGL2 draws: it
//! fills what [`super::flat`] computes (the same triangles, camera and light as the GPU
//! renderers, sorted back to front and flat-shaded per triangle) and strokes the lines.

use super::flat::{flat_lines, flat_parts, shadow_rings};
use super::scene::{Frame, BACKGROUND};
use wasm_bindgen::JsCast;

/// The Canvas 2D renderer of one canvas.
pub struct Canvas2dRenderer {
    canvas: web_sys::HtmlCanvasElement,
    context: web_sys::CanvasRenderingContext2d,
}

fn css_rgb(rgb: [u8; 3]) -> String {
    format!("rgb({},{},{})", rgb[0], rgb[1], rgb[2])
}

impl Canvas2dRenderer {
    /// A renderer on `canvas`; fails when the canvas already holds another kind of context.
    pub fn new(canvas: web_sys::HtmlCanvasElement) -> Result<Canvas2dRenderer, String> {
        let context = canvas
            .get_context("2d")
            .map_err(|e| format!("the canvas refused a 2D context: {e:?}"))?
            .ok_or("the canvas has no 2D context")?
            .dyn_into::<web_sys::CanvasRenderingContext2d>()
            .map_err(|_| "the canvas's 2D context is not one")?;
        Ok(Canvas2dRenderer { canvas, context })
    }

    /// Draws one frame (the canvas is sized by the caller). Always reaches the canvas.
    pub fn draw(&mut self, frame: &Frame) -> Result<bool, String> {
        let size = [self.canvas.width() as f32, self.canvas.height() as f32];
        let m = &frame.view_projection;
        let ctx = &self.context;
        ctx.set_global_alpha(1.0);
        ctx.set_fill_style_str(&css_rgb(BACKGROUND.map(|c| (c * 255.0).round() as u8)));
        ctx.fill_rect(0.0, 0.0, size[0] as f64, size[1] as f64);

        // Lines, a path per colour: the grid is hundreds of segments of one colour.
        let mut lines = flat_lines(frame.lines, m, size);
        lines.sort_by_key(|l| l.rgb);
        ctx.set_line_width(1.0);
        for group in lines.chunk_by(|a, b| a.rgb == b.rgb) {
            ctx.begin_path();
            for l in group {
                ctx.move_to(l.from[0] as f64, l.from[1] as f64);
                ctx.line_to(l.to[0] as f64, l.to[1] as f64);
            }
            ctx.set_stroke_style_str(&css_rgb(group[0].rgb));
            ctx.stroke();
        }

        // Shadows on the ground, under everything standing on it.
        ctx.set_fill_style_str("rgb(0,0,0)");
        for shadow in frame.shadows {
            for (outline, alpha) in shadow_rings(shadow, m, size) {
                ctx.set_global_alpha(alpha as f64);
                ctx.begin_path();
                for (i, p) in outline.iter().enumerate() {
                    if i == 0 {
                        ctx.move_to(p[0] as f64, p[1] as f64);
                    } else {
                        ctx.line_to(p[0] as f64, p[1] as f64);
                    }
                }
                ctx.close_path();
                ctx.fill();
            }
        }

        // The figure, back to front, part by part. Each triangle is also outlined in its own colour: the
        // canvas smooths every edge, which otherwise leaves light seams between neighbours.
        ctx.set_line_width(0.8);
        ctx.set_line_join("round");
        for t in flat_parts(frame.body, frame.body_parts, m, frame.eye, size) {
            let color = css_rgb(t.rgb);
            ctx.set_global_alpha(t.alpha as f64);
            ctx.begin_path();
            ctx.move_to(t.points[0][0] as f64, t.points[0][1] as f64);
            ctx.line_to(t.points[1][0] as f64, t.points[1][1] as f64);
            ctx.line_to(t.points[2][0] as f64, t.points[2][1] as f64);
            ctx.close_path();
            ctx.set_fill_style_str(&color);
            ctx.fill();
            ctx.set_stroke_style_str(&color);
            ctx.stroke();
        }
        ctx.set_global_alpha(1.0);
        Ok(true)
    }
}
