//! Top-down pictures of ground paths, as PNG bytes: the path a motion walks, optionally over
//! the curve that was asked for.
//!
//! The view is from above (looking down −Y) with world +Z pointing up the image. Seen from
//! above, +X is then on the image's *left* (as on a map read from behind the walker, whose
//! left hand is +X), so a clockwise circle is drawn clockwise. The grid is in metres at a
//! "nice" spacing (1, 2 or 5 × 10^k), with the coordinates written along the left and bottom
//! edges. The start is a green dot, the end an arrowhead in the walking direction, the
//! requested curve (if any) a dashed grey line.
//!
//! Text uses the filmstrips' bitmap font ([`render`](crate::render)).

use crate::render::{draw_text, font, font::text_width};
use tiny_skia::{
    Color, FillRule, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Stroke, StrokeDash, Transform,
};

/// Largest coordinate accepted, metres: a walking path is never this far from its start.
pub const MAX_COORD_M: f64 = 1.0e4;

const PATH_COLOR: [u8; 3] = [31, 119, 180];
const REFERENCE_COLOR: [u8; 3] = [150, 150, 150];
const START_COLOR: [u8; 3] = [44, 160, 44];
const END_COLOR: [u8; 3] = [214, 39, 40];
const GRID_COLOR: [u8; 3] = [225, 225, 225];
const AXIS_COLOR: [u8; 3] = [170, 170, 170];
const TEXT_COLOR: [u8; 3] = [40, 40, 40];
const LABEL_COLOR: [u8; 3] = [110, 110, 110];

/// How to draw a path picture.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PathPlotOptions {
    /// Text above the picture (cut to fit one line); empty for none.
    pub title: String,
    /// Width and height of the square image in pixels, 200 to 4096.
    pub size_px: u32,
}

impl Default for PathPlotOptions {
    fn default() -> Self {
        PathPlotOptions {
            title: String::new(),
            size_px: 640,
        }
    }
}

/// Why a path could not be drawn.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlotError {
    /// The path has no points.
    #[error("cannot draw an empty path")]
    Empty,
    /// A point is NaN, infinite or implausibly far away.
    #[error("point {index} of the {which} is not a finite coordinate within ±{MAX_COORD_M} m")]
    BadPoint {
        /// `"path"` or `"reference"`.
        which: &'static str,
        /// Index of the point.
        index: usize,
    },
    /// The image size is out of range.
    #[error("a path picture must be 200 to 4096 pixels wide, not {0}")]
    BadSize(u32),
    /// The PNG encoder failed.
    #[error("PNG encoding failed: {0}")]
    Png(String),
}

/// Draws `path` (x, z in metres, in walking order) seen from above, over `reference` if given,
/// and returns the PNG bytes.
pub fn path_png(
    path: &[[f64; 2]],
    reference: Option<&[[f64; 2]]>,
    options: &PathPlotOptions,
) -> Result<Vec<u8>, PlotError> {
    if path.is_empty() {
        return Err(PlotError::Empty);
    }
    check_points(path, "path")?;
    if let Some(r) = reference {
        check_points(r, "reference")?;
    }
    let size = options.size_px;
    if !(200..=4096).contains(&size) {
        return Err(PlotError::BadSize(size));
    }
    let mut pm = Pixmap::new(size, size).ok_or(PlotError::BadSize(size))?;
    pm.fill(Color::WHITE);

    let s = (size / 320).clamp(1, 4);
    let sf = s as f32;
    let line_h = font::LINE_ROWS as f32 * sf;
    let pad = 10.0 * sf;
    let top = pad
        + if options.title.is_empty() {
            0.0
        } else {
            2.0 * line_h
        };
    let area = Area {
        left: pad + 5.0 * line_h,
        top,
        right: size as f32 - pad,
        bottom: size as f32 - pad - 3.0 * line_h,
    };
    let view = View::fit(path, reference.unwrap_or(&[]), &area);

    draw_grid(&mut pm, &view, &area, s);
    if let Some(r) = reference {
        let mut stroke = round_stroke(1.5 * sf);
        stroke.dash = StrokeDash::new(vec![6.0 * sf, 4.0 * sf], 0.0);
        stroke_polyline(
            &mut pm,
            r.iter().map(|p| view.pixel(*p)),
            &stroke,
            REFERENCE_COLOR,
        );
    }
    stroke_polyline(
        &mut pm,
        path.iter().map(|p| view.pixel(*p)),
        &round_stroke(2.5 * sf),
        PATH_COLOR,
    );
    fill_circle(&mut pm, view.pixel(path[0]), 5.0 * sf, START_COLOR);
    draw_arrowhead(&mut pm, path, &view, 9.0 * sf);

    if !options.title.is_empty() {
        let max_chars = ((size as f32 - 2.0 * pad) / (6.0 * sf * 1.5)) as usize;
        let title: String = options.title.chars().take(max_chars).collect();
        draw_text(&mut pm, &title, pad, pad, s + s / 2, TEXT_COLOR);
    }
    let legend = format!(
        "VIEW FROM ABOVE, +Z UP, +X LEFT. GRID {} M",
        format_tick(view.step, view.step)
    );
    draw_text(
        &mut pm,
        &legend,
        area.left,
        size as f32 - pad - line_h,
        s,
        LABEL_COLOR,
    );
    pm.encode_png().map_err(|e| PlotError::Png(e.to_string()))
}

fn check_points(points: &[[f64; 2]], which: &'static str) -> Result<(), PlotError> {
    match points
        .iter()
        .position(|p| p.iter().any(|v| !v.is_finite() || v.abs() > MAX_COORD_M))
    {
        Some(index) => Err(PlotError::BadPoint { which, index }),
        None => Ok(()),
    }
}

#[derive(Clone, Copy, Debug)]
struct Area {
    left: f32,
    top: f32,
    right: f32,
    bottom: f32,
}

/// The mapping from metres to pixels: one scale for both axes, so shapes keep their
/// proportions.
#[derive(Clone, Copy, Debug)]
struct View {
    /// World point at the centre of the area.
    centre: [f64; 2],
    /// Pixel of that centre.
    pixel_centre: (f64, f64),
    /// Pixels per metre.
    scale: f64,
    /// Grid spacing, metres.
    step: f64,
    /// World bounds shown: x from, x to, z from, z to.
    bounds: [f64; 4],
}

impl View {
    fn fit(path: &[[f64; 2]], reference: &[[f64; 2]], area: &Area) -> View {
        let mut lo = [0.0f64; 2];
        let mut hi = [0.0f64; 2];
        for p in path.iter().chain(reference) {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1.0) * 1.1;
        let centre = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
        let width = f64::from(area.right - area.left);
        let height = f64::from(area.bottom - area.top);
        let scale = width.min(height) / extent;
        let half = [width / scale / 2.0, height / scale / 2.0];
        View {
            centre,
            pixel_centre: (
                f64::from(area.left) + width / 2.0,
                f64::from(area.top) + height / 2.0,
            ),
            scale,
            step: nice_step(extent / 6.0),
            bounds: [
                centre[0] - half[0],
                centre[0] + half[0],
                centre[1] - half[1],
                centre[1] + half[1],
            ],
        }
    }

    /// Pixel of a world point: +Z up, +X to the left (seen from above).
    fn pixel(&self, p: [f64; 2]) -> (f32, f32) {
        (
            (self.pixel_centre.0 - (p[0] - self.centre[0]) * self.scale) as f32,
            (self.pixel_centre.1 - (p[1] - self.centre[1]) * self.scale) as f32,
        )
    }
}

/// The smallest 1, 2 or 5 × 10^k at least `raw` (positive).
fn nice_step(raw: f64) -> f64 {
    let magnitude = 10f64.powf(raw.log10().floor());
    let normalised = raw / magnitude;
    let factor = [1.0, 2.0, 5.0]
        .into_iter()
        .find(|&f| normalised <= f * (1.0 + 1e-9))
        .unwrap_or(10.0);
    factor * magnitude
}

fn format_tick(v: f64, step: f64) -> String {
    let v = if v.abs() < 0.5 * step { 0.0 } else { v };
    let decimals = (-(step.log10() + 1e-9).floor()).max(0.0) as usize;
    format!("{v:.decimals$}")
}

fn draw_grid(pm: &mut Pixmap, view: &View, area: &Area, s: u32) {
    let sf = s as f32;
    let [x0, x1, z0, z1] = view.bounds;
    let step = view.step;
    let thin = round_stroke(1.0);
    // Bounded by the view: the extent is about six steps, so at most a dozen lines each way.
    let first = |lo: f64| (lo / step).ceil() as i64;
    let last = |hi: f64| (hi / step).floor() as i64;
    for i in first(x0)..=last(x1) {
        let x = i as f64 * step;
        let (px, _) = view.pixel([x, 0.0]);
        let color = if i == 0 { AXIS_COLOR } else { GRID_COLOR };
        stroke_polyline(
            pm,
            [(px, area.top), (px, area.bottom)].into_iter(),
            &thin,
            color,
        );
        let label = format_tick(x, step);
        let w = text_width(&label) as f32 * sf;
        draw_text(
            pm,
            &label,
            px - w / 2.0,
            area.bottom + 3.0 * sf,
            s,
            LABEL_COLOR,
        );
    }
    for i in first(z0)..=last(z1) {
        let z = i as f64 * step;
        let (_, py) = view.pixel([0.0, z]);
        let color = if i == 0 { AXIS_COLOR } else { GRID_COLOR };
        stroke_polyline(
            pm,
            [(area.left, py), (area.right, py)].into_iter(),
            &thin,
            color,
        );
        let label = format_tick(z, step);
        let w = text_width(&label) as f32 * sf;
        draw_text(
            pm,
            &label,
            area.left - w - 3.0 * sf,
            py - font::CAP_ROWS as f32 / 2.0 * sf,
            s,
            LABEL_COLOR,
        );
    }
}

/// An arrowhead at the last point, along the last step longer than a millimetre.
fn draw_arrowhead(pm: &mut Pixmap, path: &[[f64; 2]], view: &View, length: f32) {
    let end = path[path.len() - 1];
    let Some(from) = path
        .iter()
        .rev()
        .find(|p| (p[0] - end[0]).hypot(p[1] - end[1]) > 1e-3)
    else {
        fill_circle(pm, view.pixel(end), length / 2.0, END_COLOR);
        return;
    };
    let (ex, ey) = view.pixel(end);
    let (fx, fy) = view.pixel(*from);
    let (dx, dy) = (ex - fx, ey - fy);
    let n = dx.hypot(dy);
    if n <= 0.0 {
        fill_circle(pm, (ex, ey), length / 2.0, END_COLOR);
        return;
    }
    let (ux, uy) = (dx / n, dy / n);
    let (bx, by) = (ex - ux * length, ey - uy * length);
    let half = length * 0.5;
    let mut pb = PathBuilder::new();
    pb.move_to(ex + ux * half * 0.3, ey + uy * half * 0.3);
    pb.line_to(bx - uy * half, by + ux * half);
    pb.line_to(bx + uy * half, by - ux * half);
    pb.close();
    if let Some(p) = pb.finish() {
        pm.fill_path(
            &p,
            &paint(END_COLOR),
            FillRule::Winding,
            Transform::identity(),
            None,
        );
    }
}

fn paint(c: [u8; 3]) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(c[0], c[1], c[2], 255);
    p.anti_alias = true;
    p
}

fn round_stroke(width: f32) -> Stroke {
    Stroke {
        width,
        line_cap: LineCap::Round,
        line_join: LineJoin::Round,
        ..Stroke::default()
    }
}

fn stroke_polyline(
    pm: &mut Pixmap,
    points: impl Iterator<Item = (f32, f32)>,
    stroke: &Stroke,
    c: [u8; 3],
) {
    let mut pb = PathBuilder::new();
    for (i, (x, y)) in points.enumerate() {
        if i == 0 {
            pb.move_to(x, y);
        } else {
            pb.line_to(x, y);
        }
    }
    // A single point makes no path; tiny-skia returns None and nothing is drawn.
    if let Some(path) = pb.finish() {
        pm.stroke_path(&path, &paint(c), stroke, Transform::identity(), None);
    }
}

fn fill_circle(pm: &mut Pixmap, (x, y): (f32, f32), r: f32, c: [u8; 3]) {
    if let Some(path) = PathBuilder::from_circle(x, y, r) {
        pm.fill_path(
            &path,
            &paint(c),
            FillRule::Winding,
            Transform::identity(),
            None,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trajectory::path::resample_curve;
    use crate::trajectory::shapes::{Shape, Side};

    fn decode(png: &[u8]) -> Pixmap {
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
        Pixmap::decode_png(png).unwrap()
    }

    fn has_color(pm: &Pixmap, c: [u8; 3]) -> bool {
        pm.pixels().iter().any(|p| {
            let p = p.demultiply();
            [p.red(), p.green(), p.blue()] == c
        })
    }

    #[test]
    fn draws_a_path_with_reference_start_and_end() {
        let path = resample_curve(&Shape::Circle(Side::Right).curve(), 120, 8.0)
            .unwrap()
            .points;
        let reference = resample_curve(&Shape::Circle(Side::Right).curve(), 60, 8.5)
            .unwrap()
            .points;
        let options = PathPlotOptions {
            title: "walks in a circle clockwise".into(),
            size_px: 400,
        };
        let pm = decode(&path_png(&path, Some(&reference), &options).unwrap());
        assert_eq!((pm.width(), pm.height()), (400, 400));
        for c in [
            PATH_COLOR,
            START_COLOR,
            END_COLOR,
            TEXT_COLOR,
            REFERENCE_COLOR,
        ] {
            assert!(has_color(&pm, c), "{c:?} missing");
        }
    }

    #[test]
    fn clockwise_is_drawn_clockwise() {
        // A clockwise circle starts at the origin heading +Z (up) and bends to −X, which is
        // drawn to the right: the path's leftmost ink is near the start marker's column.
        let path = resample_curve(&Shape::Circle(Side::Right).curve(), 120, 6.0)
            .unwrap()
            .points;
        let area = Area {
            left: 0.0,
            top: 0.0,
            right: 100.0,
            bottom: 100.0,
        };
        let view = View::fit(&path, &[], &area);
        let start = view.pixel(path[0]);
        let quarter = view.pixel(path[30]);
        assert!(
            quarter.0 > start.0 && quarter.1 < start.1,
            "{start:?} {quarter:?}"
        );
    }

    #[test]
    fn single_points_and_bad_input() {
        assert!(path_png(&[[0.0, 0.0]], None, &PathPlotOptions::default()).is_ok());
        assert_eq!(
            path_png(&[], None, &PathPlotOptions::default()),
            Err(PlotError::Empty)
        );
        assert_eq!(
            path_png(&[[0.0, f64::NAN]], None, &PathPlotOptions::default()),
            Err(PlotError::BadPoint {
                which: "path",
                index: 0
            })
        );
        assert!(matches!(
            path_png(
                &[[0.0, 0.0]],
                Some(&[[1e9, 0.0]]),
                &PathPlotOptions::default()
            ),
            Err(PlotError::BadPoint {
                which: "reference",
                ..
            })
        ));
        let tiny = PathPlotOptions {
            size_px: 10,
            ..PathPlotOptions::default()
        };
        assert_eq!(
            path_png(&[[0.0, 0.0]], None, &tiny),
            Err(PlotError::BadSize(10))
        );
    }

    #[test]
    fn ticks_are_short_and_steps_nice() {
        assert_eq!(format_tick(0.5, 0.5), "0.5");
        assert_eq!(format_tick(-2.0, 1.0), "-2");
        assert_eq!(nice_step(0.3), 0.5);
    }
}

#[cfg(test)]
mod tmp_compare {
    use super::*;
    use crate::trajectory::path::resample_curve;
    use crate::trajectory::shapes::{Shape, Side};
    #[test]
    fn tmp_write_compare_pngs() {
        let tag = std::env::var("PLOTCMP_TAG").unwrap_or_else(|_| "x".into());
        let path = resample_curve(&Shape::Circle(Side::Right).curve(), 120, 8.0)
            .unwrap()
            .points;
        let reference = resample_curve(&Shape::Circle(Side::Right).curve(), 60, 8.5)
            .unwrap()
            .points;
        for (i, size) in [200u32, 400, 640, 1000, 1500].into_iter().enumerate() {
            let options = PathPlotOptions {
                title: if i % 2 == 0 {
                    "walks in a circle clockwise".into()
                } else {
                    String::new()
                },
                size_px: size,
            };
            let png = path_png(&path, Some(&reference), &options).unwrap();
            std::fs::write(format!("/tmp/plotcmp/{tag}_ref_{size}.png"), png).unwrap();
        }
        let png = path_png(&[[0.3, 0.2]], None, &PathPlotOptions::default()).unwrap();
        std::fs::write(format!("/tmp/plotcmp/{tag}_point.png"), png).unwrap();
        let png = path_png(
            &[[0.0, 0.0], [0.0, 0.0]],
            Some(&[[-3.0, 120.0], [2.0, -7.5]]),
            &PathPlotOptions::default(),
        )
        .unwrap();
        std::fs::write(format!("/tmp/plotcmp/{tag}_far.png"), png).unwrap();
    }
}
