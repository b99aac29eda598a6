//! Top-down pictures of ground paths, as PNG bytes: the path a motion walks (as planned by
//! [`trajectory`](crate::trajectory)), optionally over the curve that was asked for.
//!
//! The view is from above (looking down −Y) with world +Z pointing up the image. Seen from
//! above, +X is then on the image's *left* (as on a map read from behind the walker, whose
//! left hand is +X), so a clockwise circle is drawn clockwise. The grid is in metres at a
//! "nice" spacing (1, 2 or 5 × 10^k), with the coordinates written along the left and bottom
//! edges. The start is a green dot, the end an arrowhead in the walking direction, the
//! requested curve (if any) a dashed grey line.
//!
//! Text uses the filmstrips' bitmap font ([`render`](crate::render)).

use tiny_skia::{Color, Pixmap, StrokeDash};

use super::super::draw::{
    draw_text, fill_circle, fill_polygon, round_stroke, stroke_polyline, stroke_polyline_with,
};
use super::{
    decimal_label, draw_label_centred, draw_label_ending_at, line_height, nice_step, Area, BLUE,
    GREEN, GRID_COLOR, RED,
};

/// Largest coordinate accepted, metres: a walking path is never this far from its start.
pub const MAX_COORD_M: f64 = 1.0e4;

/// Colours (sRGB) of the walked path, its start dot and its end arrowhead.
const PATH_COLOR: [u8; 3] = BLUE;
const START_COLOR: [u8; 3] = GREEN;
const END_COLOR: [u8; 3] = RED;
/// Colour of the requested curve, drawn dashed under the path.
const REFERENCE_COLOR: [u8; 3] = [150, 150, 150];
/// Colour of the grid lines through the origin (x = 0 and z = 0); the others are lighter.
const AXIS_COLOR: [u8; 3] = [170, 170, 170];
/// Colours of the title, and of the coordinates and the legend line.
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
    let line_h = line_height(s);
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
        let points = r.iter().map(|p| view.pixel(*p));
        stroke_polyline_with(&mut pm, points, &stroke, REFERENCE_COLOR, 255);
    }
    let points = path.iter().map(|p| view.pixel(*p));
    stroke_polyline(&mut pm, points, 2.5 * sf, PATH_COLOR, 255);
    fill_circle(&mut pm, view.pixel(path[0]), 5.0 * sf, START_COLOR, 255);
    draw_arrowhead(&mut pm, path, &view, 9.0 * sf);

    if !options.title.is_empty() {
        let max_chars = ((size as f32 - 2.0 * pad) / (6.0 * sf * 1.5)) as usize;
        let title: String = options.title.chars().take(max_chars).collect();
        draw_text(&mut pm, &title, pad, pad, s + s / 2, TEXT_COLOR);
    }
    let legend = format!(
        "VIEW FROM ABOVE, +Z UP, +X LEFT. GRID {} M",
        decimal_label(view.step, view.step)
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

/// Grid lines every `view.step` metres across `area`, the lines through the origin darker,
/// with their coordinates under the area (x) and left of it (z).
fn draw_grid(pm: &mut Pixmap, view: &View, area: &Area, s: u32) {
    let sf = s as f32;
    let [x0, x1, z0, z1] = view.bounds;
    let step = view.step;
    // Bounded by the view: the extent is about six steps, so at most a dozen lines each way.
    let ticks = |lo: f64, hi: f64| {
        ((lo / step).ceil() as i64..=(hi / step).floor() as i64).map(move |i| {
            let color = if i == 0 { AXIS_COLOR } else { GRID_COLOR };
            (i as f64 * step, color)
        })
    };
    // The lines are one pixel wide, centred on the coordinate's pixel.
    for (x, color) in ticks(x0, x1) {
        let (px, _) = view.pixel([x, 0.0]);
        area.vertical_rule(pm, px - 0.5, 1.0, color);
        let label = decimal_label(x, step);
        draw_label_centred(pm, &label, px, area.bottom + 3.0 * sf, s, LABEL_COLOR);
    }
    for (z, color) in ticks(z0, z1) {
        let (_, py) = view.pixel([0.0, z]);
        area.horizontal_rule(pm, py - 0.5, 1.0, color);
        let label = decimal_label(z, step);
        draw_label_ending_at(pm, &label, area.left - 3.0 * sf, py, s, LABEL_COLOR);
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
        fill_circle(pm, view.pixel(end), length / 2.0, END_COLOR, 255);
        return;
    };
    let (ex, ey) = view.pixel(end);
    let (fx, fy) = view.pixel(*from);
    let (dx, dy) = (ex - fx, ey - fy);
    let n = dx.hypot(dy);
    if n <= 0.0 {
        fill_circle(pm, (ex, ey), length / 2.0, END_COLOR, 255);
        return;
    }
    let (ux, uy) = (dx / n, dy / n);
    let (bx, by) = (ex - ux * length, ey - uy * length);
    let half = length * 0.5;
    let tip = (ex + ux * half * 0.3, ey + uy * half * 0.3);
    let corners = [
        (bx - uy * half, by + ux * half),
        (bx + uy * half, by - ux * half),
    ];
    fill_polygon(pm, &[tip, corners[0], corners[1]], END_COLOR, 255);
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
}
