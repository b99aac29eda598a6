//! Drawing primitives on a tiny-skia [`Pixmap`], shared by the filmstrips and the plots.
//!
//! Coordinates are pixels with y pointing down; colours are sRGB `[r, g, b]` with a separate
//! alpha where it varies. Lines and circles are anti-aliased; text and the rectangles of grids
//! and frames are snapped to whole pixels and not anti-aliased, so that they stay crisp. Paths
//! tiny-skia refuses (non-finite or empty) are skipped rather than reported: the callers
//! validate their data first, and a missing line beats a failed picture.

use tiny_skia::{
    Color, FillRule, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform,
};

use super::font;

pub(super) fn color(c: [u8; 3], alpha: u8) -> Color {
    Color::from_rgba8(c[0], c[1], c[2], alpha)
}

/// An anti-aliased solid paint.
pub(super) fn paint(c: [u8; 3], alpha: u8) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(c[0], c[1], c[2], alpha);
    p.anti_alias = true;
    p
}

/// An opaque paint without anti-aliasing, for shapes snapped to whole pixels.
fn crisp_paint(c: [u8; 3]) -> Paint<'static> {
    let mut p = paint(c, 255);
    p.anti_alias = false;
    p
}

/// A stroke of `width` pixels with round caps and joins.
pub(super) fn round_stroke(width: f32) -> Stroke {
    Stroke {
        width,
        line_cap: LineCap::Round,
        line_join: LineJoin::Round,
        ..Stroke::default()
    }
}

pub(super) fn stroke_line(
    pm: &mut Pixmap,
    a: (f32, f32),
    b: (f32, f32),
    width: f32,
    c: [u8; 3],
    alpha: u8,
) {
    stroke_polyline(pm, [a, b].into_iter(), width, c, alpha);
}

/// Strokes a polyline `width` pixels wide with round caps and joins, as one path so that
/// overlapping segments do not darken each other.
pub(super) fn stroke_polyline(
    pm: &mut Pixmap,
    points: impl Iterator<Item = (f32, f32)>,
    width: f32,
    c: [u8; 3],
    alpha: u8,
) {
    stroke_polyline_with(pm, points, &round_stroke(width), c, alpha);
}

/// Strokes a polyline as one path with any `stroke` (e.g. a dashed one). A single point makes
/// no path, and nothing is drawn.
pub(super) fn stroke_polyline_with(
    pm: &mut Pixmap,
    points: impl Iterator<Item = (f32, f32)>,
    stroke: &Stroke,
    c: [u8; 3],
    alpha: u8,
) {
    if let Some(path) = polyline(points).finish() {
        pm.stroke_path(&path, &paint(c, alpha), stroke, Transform::identity(), None);
    }
}

/// A path through `points` in order, not closed.
fn polyline(points: impl Iterator<Item = (f32, f32)>) -> PathBuilder {
    let mut pb = PathBuilder::new();
    for (i, (x, y)) in points.enumerate() {
        if i == 0 {
            pb.move_to(x, y);
        } else {
            pb.line_to(x, y);
        }
    }
    pb
}

/// Fills the closed polygon through `points`.
pub(super) fn fill_polygon(pm: &mut Pixmap, points: &[(f32, f32)], c: [u8; 3], alpha: u8) {
    let mut pb = polyline(points.iter().copied());
    pb.close();
    if let Some(path) = pb.finish() {
        fill(pm, &path, c, alpha);
    }
}

pub(super) fn fill_circle(pm: &mut Pixmap, (x, y): (f32, f32), radius: f32, c: [u8; 3], alpha: u8) {
    if let Some(path) = PathBuilder::from_circle(x, y, radius) {
        fill(pm, &path, c, alpha);
    }
}

fn fill(pm: &mut Pixmap, path: &tiny_skia::Path, c: [u8; 3], alpha: u8) {
    pm.fill_path(
        path,
        &paint(c, alpha),
        FillRule::Winding,
        Transform::identity(),
        None,
    );
}

pub(super) fn stroke_circle(
    pm: &mut Pixmap,
    (x, y): (f32, f32),
    radius: f32,
    width: f32,
    c: [u8; 3],
) {
    if let Some(path) = PathBuilder::from_circle(x, y, radius) {
        pm.stroke_path(
            &path,
            &paint(c, 255),
            &round_stroke(width),
            Transform::identity(),
            None,
        );
    }
}

/// A filled rectangle snapped to whole pixels (at least one pixel each way) and not
/// anti-aliased, so that grid lines and frames stay sharp.
pub(super) fn fill_rect(pm: &mut Pixmap, x: f32, y: f32, w: f32, h: f32, c: [u8; 3]) {
    let (x, y) = (x.round(), y.round());
    if let Some(rect) = Rect::from_xywh(x, y, w.round().max(1.0), h.round().max(1.0)) {
        pm.fill_rect(rect, &crisp_paint(c), Transform::identity(), None);
    }
}

/// Draws `text` with the bitmap font, each font pixel an `s`×`s` square, top-left at `(x, y)`.
/// Squares are snapped to whole pixels and not anti-aliased so that small text stays crisp.
pub(super) fn draw_text(pm: &mut Pixmap, text: &str, x: f32, y: f32, s: u32, c: [u8; 3]) {
    let (x, y, s) = (x.round(), y.round(), s as f32);
    fill_font_squares(pm, text, s, c, |col, row| (x + col * s, y + row * s));
}

/// Draws `text` turned a quarter turn anticlockwise (read bottom to top), as a y axis label:
/// the glyph tops face left towards `x` and the text starts at `bottom`.
pub(super) fn draw_text_up(pm: &mut Pixmap, text: &str, x: f32, bottom: f32, s: u32, c: [u8; 3]) {
    let (x, bottom, s) = (x.round(), bottom.round(), s as f32);
    fill_font_squares(pm, text, s, c, |col, row| {
        (x + row * s, bottom - (col + 1.0) * s)
    });
}

/// Fills an `s`×`s` square for every inked font pixel of `text`, the square of font column
/// `col` and row `row` with its top-left corner at `place(col, row)`.
fn fill_font_squares(
    pm: &mut Pixmap,
    text: &str,
    s: f32,
    c: [u8; 3],
    place: impl Fn(f32, f32) -> (f32, f32),
) {
    let p = crisp_paint(c);
    for (col, row) in font::ink(text) {
        let (x, y) = place(col as f32, row as f32);
        if let Some(rect) = Rect::from_xywh(x, y, s, s) {
            pm.fill_rect(rect, &p, Transform::identity(), None);
        }
    }
}
