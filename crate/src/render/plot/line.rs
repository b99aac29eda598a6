//! Line plots of training curves, such as loss against step, as PNG images.
//!
//! A plot has a white background, a title, a legend row under it with one colour per series
//! ([`SERIES_COLORS`], cycling), and a framed plot area with light grid lines at "nice" tick
//! values: 1, 2 or 5 × 10^k apart, or powers of ten on a logarithmic y axis. Both axes are
//! labelled; curves are anti-aliased polylines.
//!
//! Training logs are messy, so the data never makes plotting fail: non-finite points (the NaN
//! loss of a diverged step) are skipped, as are non-positive values on a logarithmic axis and
//! values beyond ±1e300 (their range would overflow), and a plot with nothing to show says
//! "no data" instead of returning an error. Long runs are cheap to draw: each curve is reduced
//! to the lowest and highest point of every pixel column before it is stroked, which looks the
//! same as stroking every point.

use std::path::Path;

use tiny_skia::{Color, Pixmap};

use super::super::draw::{draw_text, draw_text_up, fill_circle, fill_rect, stroke_polyline};
use super::super::{wrap, RenderError, LABEL_COLOR, MAX_PIXELS, TITLE_COLOR};
use super::{
    cap_height, decimal_label, draw_label_centred, draw_label_ending_at, line_height, nice_step,
    snap_zero, step_exponent, text_width, Area, BLUE, BROWN, GREEN, GRID_COLOR, ORANGE, PURPLE,
    RED,
};

/// Colours of the series (sRGB) in order; the seventh series reuses the first colour. They are
/// the first six colours of Tableau 10, chosen to be told apart on white.
pub const SERIES_COLORS: [[u8; 3]; 6] = [BLUE, ORANGE, GREEN, RED, PURPLE, BROWN];

/// Smallest image that still has room for labels and a plot area.
const MIN_WIDTH: u32 = 200;
const MIN_HEIGHT: u32 = 150;

/// Longest side in pixels: tiny-skia cannot draw on much larger images.
const MAX_SIDE: u32 = 16_384;

/// Values beyond this magnitude are skipped: the axis arithmetic (ranges, padding) would
/// overflow to infinity.
const MAX_ABS: f64 = 1e300;

/// Intervals between ticks a linear axis aims for; nice steps give 4 to 7 ticks.
const TARGET_INTERVALS: f64 = 5.0;

/// Upper bound on ticks per axis, so that pathological ranges (subnormal numbers) cannot
/// produce absurd tick counts.
const MAX_TICKS: usize = 50;

/// Colour of the frame round the plot area and of its tick marks.
const FRAME_COLOR: [u8; 3] = [120, 120, 120];
/// Colour of the unlabelled lines between powers of ten on a logarithmic axis.
const MINOR_GRID_COLOR: [u8; 3] = [242, 242, 242];
/// Colour of the axis labels (`x_label`, `y_label`).
const AXIS_LABEL_COLOR: [u8; 3] = [60, 60, 60];

/// One named curve: (x, y) points, e.g. (training step, loss).
///
/// Points are joined in the order given. Non-finite points are skipped (the line joins their
/// neighbours), and so are points with y ≤ 0 on a logarithmic y axis.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Series {
    /// Legend text; series with an empty name get no legend entry but keep their colour.
    pub name: String,
    /// The points, usually (step, value) in increasing step order.
    pub points: Vec<(f64, f64)>,
}

/// How to draw a line plot.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlotOptions {
    /// Text above the plot, wrapped onto at most two lines; empty for none. Characters outside
    /// printable ASCII are drawn as `?`.
    pub title: String,
    /// Label under the x axis; empty for none.
    pub x_label: String,
    /// Label along the y axis (written bottom to top); empty for none.
    pub y_label: String,
    /// Logarithmic y axis with ticks at powers of ten, for losses spanning decades.
    pub log_y: bool,
    /// Image width in pixels, 200 to 16384. Default 900.
    pub width: u32,
    /// Image height in pixels, 150 to 16384. Default 500.
    pub height: u32,
}

impl Default for PlotOptions {
    fn default() -> Self {
        PlotOptions {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            log_y: false,
            width: 900,
            height: 500,
        }
    }
}

/// Draws `series` as a line plot and returns it as PNG bytes.
///
/// Fails only for an unusable image size or an encoder failure; data with nothing to plot
/// (no series, or no finite points) gives a plot that says "no data".
pub fn line_plot_png(series: &[Series], options: &PlotOptions) -> Result<Vec<u8>, RenderError> {
    render(series, options)?
        .encode_png()
        .map_err(|e| RenderError::Png(e.to_string()))
}

/// Draws `series` as a line plot and writes it to `path` as a PNG file.
pub fn write_line_plot(
    path: &Path,
    series: &[Series],
    options: &PlotOptions,
) -> Result<(), RenderError> {
    let png = line_plot_png(series, options)?;
    std::fs::write(path, png).map_err(|source| RenderError::Io {
        path: path.to_path_buf(),
        source,
    })
}

fn render(series: &[Series], options: &PlotOptions) -> Result<Pixmap, RenderError> {
    let (width, height) = (options.width, options.height);
    if width < MIN_WIDTH || height < MIN_HEIGHT {
        return Err(RenderError::InvalidOptions(format!(
            "a line plot must be at least {MIN_WIDTH}×{MIN_HEIGHT} pixels, not {width}×{height}"
        )));
    }
    let too_large = RenderError::TooLarge {
        width: width.into(),
        height: height.into(),
    };
    if width > MAX_SIDE || height > MAX_SIDE || u64::from(width) * u64::from(height) > MAX_PIXELS {
        return Err(too_large);
    }
    let mut pm = Pixmap::new(width, height).ok_or(too_large)?;
    pm.fill(Color::WHITE);
    match Plot::new(series, options) {
        Some(plot) => plot.draw(&mut pm),
        None => draw_no_data(&mut pm, options),
    }
    Ok(pm)
}

/// Sizes derived from the image size, so that large images get proportionally larger text.
#[derive(Clone, Copy, Debug)]
struct Style {
    /// Font pixel size of labels; titles use one more.
    text: u32,
    /// Outer margin.
    pad: f32,
    /// Space between neighbouring elements.
    gap: f32,
    /// Length of tick marks.
    tick: f32,
    /// Space between the frame and the extreme ticks, so curves never run along the frame.
    inset: f32,
    /// Width of the curves.
    line: f32,
}

impl Style {
    fn new(width: u32, height: u32) -> Style {
        let text = (width.min(height) / 250).clamp(1, 4);
        let s = text as f32;
        Style {
            text,
            pad: 8.0 * s,
            gap: 3.0 * s,
            tick: 3.0 * s,
            inset: 5.0 * s,
            line: 1.0 + 0.5 * s,
        }
    }
}

/// One axis: the range it shows and its ticks, in axis units (log10 of the value on a
/// logarithmic axis). `lo < hi` always.
#[derive(Clone, Debug, PartialEq)]
struct Axis {
    lo: f64,
    hi: f64,
    /// Tick positions and their labels.
    ticks: Vec<(f64, String)>,
    /// Unlabelled grid positions (2…9 × 10^k on a logarithmic axis).
    minor: Vec<f64>,
}

impl Axis {
    /// A linear axis covering `min..=max`, widened to whole nice steps.
    fn linear(min: f64, max: f64) -> Axis {
        let (mut lo, mut hi) = (min, max);
        let magnitude = lo.abs().max(hi.abs());
        if hi - lo <= magnitude * 1e-9 {
            // A flat curve still needs a range to map onto; ±10 % puts it in the middle.
            let pad = if magnitude > 0.0 {
                0.1 * magnitude
            } else {
                1.0
            };
            lo -= pad;
            hi += pad;
        }
        // The tolerance keeps a bound that is a multiple of the step up to rounding error from
        // gaining a whole extra interval.
        let snap = |step: f64| {
            let first = (lo / step + 1e-9).floor();
            (first, (hi / step - 1e-9).ceil().max(first + 1.0))
        };
        // Widening to whole steps can nearly double the number of intervals, so the step is
        // chosen by the count after widening, not by the span alone.
        let off_target = |step: f64| {
            let (first, last) = snap(step);
            (last - first - TARGET_INTERVALS).abs()
        };
        let step = (3..=8)
            .map(|n| nice_step((hi - lo) / f64::from(n)))
            .min_by(|&a, &b| {
                off_target(a)
                    .total_cmp(&off_target(b))
                    .then(b.total_cmp(&a))
            })
            .expect("the candidate range is not empty");
        let (first, last) = snap(step);
        let values: Vec<f64> = (0..=(last - first) as usize)
            .take(MAX_TICKS)
            .map(|i| (first + i as f64) * step)
            .collect();
        let largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        // Exponents only for large or tiny values: a small step around a value like 1 reads
        // better as plain decimals.
        let scientific = largest >= 1e6 || (step < 1e-4 && largest < 1e-2);
        Axis {
            lo: first * step,
            hi: last * step,
            ticks: values
                .iter()
                .map(|&v| (v, linear_label(v, step, scientific)))
                .collect(),
            minor: Vec::new(),
        }
    }

    /// A logarithmic axis covering `10^min..=10^max` (arguments are log10 of the data),
    /// widened to whole decades.
    fn log(min: f64, max: f64) -> Axis {
        let mut lo = (min + 1e-9).floor();
        let mut hi = (max - 1e-9).ceil();
        if hi <= lo {
            // All values are the same power of ten: show a decade either side.
            lo -= 1.0;
            hi += 1.0;
        }
        // Ticks every 1, 2, 5, 10… decades, so that wide ranges keep a handful of labels.
        let step = nice_step((hi - lo) / 8.0).max(1.0);
        lo = (lo / step).floor() * step;
        hi = (hi / step).ceil() * step;
        let ticks = (0..=((hi - lo) / step).round() as usize)
            .take(MAX_TICKS)
            .map(|i| {
                let k = lo + i as f64 * step;
                (k, power_label(k as i32))
            })
            .collect();
        // Minor lines help to read values between powers of ten, but would crowd a wide range.
        let minor = if step == 1.0 && hi - lo <= 8.0 {
            (lo as i32..hi as i32)
                .flat_map(|k| (2..10).map(move |m| f64::from(k) + f64::from(m).log10()))
                .collect()
        } else {
            Vec::new()
        };
        Axis {
            lo,
            hi,
            ticks,
            minor,
        }
    }

    /// Where `v` lies on the axis, 0 at `lo` and 1 at `hi`.
    fn fraction(&self, v: f64) -> f64 {
        (v - self.lo) / (self.hi - self.lo)
    }
}

/// Label of linear tick `v` on an axis with ticks `step` apart: just enough digits to tell
/// neighbouring ticks apart.
fn linear_label(v: f64, step: f64, scientific: bool) -> String {
    if !scientific {
        return decimal_label(v, step);
    }
    let v = snap_zero(v, step);
    if v == 0.0 {
        return "0".to_string();
    }
    let step_exponent = step_exponent(step);
    let exponent = (v.abs().log10() + 1e-9).floor() as i32;
    let digits = (exponent - step_exponent).max(0) as usize;
    let text = format!("{v:.digits$e}");
    match text.split_once('e') {
        Some((mantissa, exponent)) if mantissa.contains('.') => {
            let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
            format!("{mantissa}e{exponent}")
        }
        _ => text,
    }
}

/// Label of 10^k: plain decimals near 1, where they are easiest to read, else `1e{k}`.
fn power_label(k: i32) -> String {
    match k {
        0..=3 => 10u32.pow(k as u32).to_string(),
        -3..=-1 => format!("{:.*}", (-k) as usize, 10f64.powi(k)),
        _ => format!("1e{k}"),
    }
}

/// The points of `points` that can be drawn, as (x, axis y): finite, within ±[`MAX_ABS`], and
/// on a logarithmic axis positive, with y replaced by its log10.
fn plottable(points: &[(f64, f64)], log_y: bool) -> Vec<(f64, f64)> {
    let usable = |v: f64| v.is_finite() && v.abs() <= MAX_ABS;
    points
        .iter()
        .filter(|&&(x, y)| usable(x) && usable(y) && (!log_y || y > 0.0))
        .map(|&(x, y)| (x, if log_y { y.log10() } else { y }))
        .collect()
}

/// Reduces a polyline in pixel coordinates to at most two points per pixel column: of each run
/// of consecutive points in the same column, the lowest and highest in their original order.
/// Every vertical extent the full line would paint in a column is kept, so the stroke looks
/// the same while long runs stay fast to draw.
fn decimate(points: impl IntoIterator<Item = (f32, f32)>) -> Vec<(f32, f32)> {
    /// The extremes of the current run as (index, point).
    struct Run {
        column: f32,
        low: (usize, (f32, f32)),
        high: (usize, (f32, f32)),
    }
    fn flush(run: &Run, out: &mut Vec<(f32, f32)>) {
        let (a, b) = if run.low.0 <= run.high.0 {
            (run.low, run.high)
        } else {
            (run.high, run.low)
        };
        out.push(a.1);
        if a.0 != b.0 {
            out.push(b.1);
        }
    }
    let mut out = Vec::new();
    let mut run: Option<Run> = None;
    for (i, p) in points.into_iter().enumerate() {
        let column = p.0.floor();
        match &mut run {
            Some(r) if r.column == column => {
                // Pixel y grows downwards: "low" is the smallest y value here.
                if p.1 < r.low.1 .1 {
                    r.low = (i, p);
                }
                if p.1 > r.high.1 .1 {
                    r.high = (i, p);
                }
            }
            _ => {
                if let Some(r) = &run {
                    flush(r, &mut out);
                }
                run = Some(Run {
                    column,
                    low: (i, p),
                    high: (i, p),
                });
            }
        }
    }
    if let Some(r) = &run {
        flush(r, &mut out);
    }
    out
}

/// A legend entry: a colour swatch and the series name, top-left at `(x, y)`.
#[derive(Clone, Debug, PartialEq)]
struct LegendItem {
    x: f32,
    y: f32,
    color: [u8; 3],
    text: String,
}

/// A curve ready to stroke: its colour and decimated pixel coordinates.
struct Curve {
    color: [u8; 3],
    points: Vec<(f32, f32)>,
}

/// Everything to draw, laid out; computed before drawing so tests can find the plot area.
struct Plot {
    style: Style,
    title: Vec<(String, f32, f32)>,
    legend: Vec<LegendItem>,
    /// The drawn frame.
    frame: Area,
    /// Where the axis ranges map to: the frame shrunk by [`Style::inset`].
    inner: Area,
    x: Axis,
    y: Axis,
    /// Indices of the ticks that get a label (every tick, or every second… when crowded).
    x_labelled: Vec<usize>,
    y_labelled: Vec<usize>,
    x_label: String,
    y_label: String,
    curves: Vec<Curve>,
}

impl Plot {
    /// Lays out the plot, or `None` when no series has a point that can be drawn.
    fn new(series: &[Series], options: &PlotOptions) -> Option<Plot> {
        let data: Vec<Vec<(f64, f64)>> = series
            .iter()
            .map(|s| plottable(&s.points, options.log_y))
            .collect();
        let bounds = |pick: fn(&(f64, f64)) -> f64| {
            data.iter()
                .flatten()
                .map(pick)
                .fold(None, |acc, v| match acc {
                    None => Some((v, v)),
                    Some((lo, hi)) => Some((v.min(lo), v.max(hi))),
                })
        };
        let (x_min, x_max) = bounds(|p| p.0)?;
        let (y_min, y_max) = bounds(|p| p.1)?;
        let x = Axis::linear(x_min, x_max);
        let y = if options.log_y {
            Axis::log(y_min, y_max)
        } else {
            Axis::linear(y_min, y_max)
        };

        let (width, height) = (options.width as f32, options.height as f32);
        let style = Style::new(options.width, options.height);
        let ts = style.text;
        let title = title_lines(&options.title, options.width, style);

        let y_label = options.y_label.trim().to_string();
        let x_label = options.x_label.trim().to_string();
        let y_label_band = if y_label.is_empty() {
            0.0
        } else {
            line_height(ts) + style.gap
        };
        let y_tick_width = y
            .ticks
            .iter()
            .map(|(_, label)| text_width(label, ts))
            .fold(0.0, f32::max);
        let left = style.pad + y_label_band + y_tick_width + style.gap + style.tick;
        // The last x label is centred on the frame's right end and must not be cut off.
        let last_x_label = x.ticks.last().map_or(0.0, |(_, l)| text_width(l, ts));
        let right = width - style.pad.max(0.5 * last_x_label + style.gap);

        let title_bottom = if title.is_empty() {
            style.pad
        } else {
            style.pad + title.len() as f32 * line_height(ts + 1) + style.gap
        };
        let max_legend_rows = (options.height / 150).clamp(1, 4) as usize;
        let legend = legend_items(series, left, right, title_bottom, style, max_legend_rows);
        let legend_bottom = legend
            .iter()
            .map(|item| item.y + line_height(ts))
            .fold(title_bottom, f32::max);
        let top = legend_bottom + style.gap;

        let x_label_band = if x_label.is_empty() {
            0.0
        } else {
            line_height(ts) + style.gap
        };
        let bottom = height - style.pad - x_label_band - cap_height(ts) - style.gap - style.tick;
        let frame = Area {
            left,
            top,
            right,
            bottom,
        };
        let inner = frame.shrunk(style.inset);
        // Options too cramped for a plot area still give an image rather than an error.
        let inner = Area {
            right: inner.right.max(inner.left + 1.0),
            bottom: inner.bottom.max(inner.top + 1.0),
            ..inner
        };

        let x_positions: Vec<f32> = x.ticks.iter().map(|t| x_px(&x, inner, t.0)).collect();
        let x_extent = x
            .ticks
            .iter()
            .map(|(_, l)| text_width(l, ts))
            .fold(0.0, f32::max)
            + 3.0 * style.gap;
        let y_positions: Vec<f32> = y.ticks.iter().map(|t| y_px(&y, inner, t.0)).collect();
        let y_extent = cap_height(ts) + 2.0 * style.gap;

        let curves = data
            .iter()
            .enumerate()
            .map(|(i, points)| Curve {
                color: series_color(i),
                points: decimate(
                    points
                        .iter()
                        .map(|&(px, py)| (x_px(&x, inner, px), y_px(&y, inner, py))),
                ),
            })
            .collect();

        Some(Plot {
            style,
            title,
            legend,
            frame,
            inner,
            x_labelled: labelled(&x_positions, x_extent),
            y_labelled: labelled(&y_positions, y_extent),
            x,
            y,
            x_label,
            y_label,
            curves,
        })
    }

    fn draw(&self, pm: &mut Pixmap) {
        let style = self.style;
        let ts = style.text;
        let frame = self.frame;
        let inner = self.inner;
        let grid_width = (ts / 2).max(1) as f32;

        for &v in &self.y.minor {
            frame.horizontal_rule(pm, y_px(&self.y, inner, v), 1.0, MINOR_GRID_COLOR);
        }
        for &(v, _) in &self.x.ticks {
            frame.vertical_rule(pm, x_px(&self.x, inner, v), grid_width, GRID_COLOR);
        }
        for &(v, _) in &self.y.ticks {
            frame.horizontal_rule(pm, y_px(&self.y, inner, v), grid_width, GRID_COLOR);
        }

        for curve in &self.curves {
            match curve.points.as_slice() {
                [] => {}
                // A lone point has no segment to stroke, yet should be visible.
                [p] => fill_circle(pm, *p, style.line * 1.5, curve.color, 255),
                points => stroke_polyline(pm, points.iter().copied(), style.line, curve.color, 255),
            }
        }

        // The frame goes over the curves so that it stays crisp where they approach it.
        frame.horizontal_rule(pm, frame.top, grid_width, FRAME_COLOR);
        // The bottom edge reaches under the right edge to close the corner.
        let w = frame.right - frame.left;
        fill_rect(
            pm,
            frame.left,
            frame.bottom,
            w + grid_width,
            grid_width,
            FRAME_COLOR,
        );
        frame.vertical_rule(pm, frame.left, grid_width, FRAME_COLOR);
        frame.vertical_rule(pm, frame.right, grid_width, FRAME_COLOR);

        let cap = cap_height(ts);
        for (i, (v, label)) in self.x.ticks.iter().enumerate() {
            let px = x_px(&self.x, inner, *v);
            fill_rect(pm, px, frame.bottom, grid_width, style.tick, FRAME_COLOR);
            if self.x_labelled.contains(&i) {
                let ty = frame.bottom + style.tick + style.gap;
                draw_label_centred(pm, label, px + 0.5 * grid_width, ty, ts, LABEL_COLOR);
            }
        }
        for (i, (v, label)) in self.y.ticks.iter().enumerate() {
            let py = y_px(&self.y, inner, *v);
            fill_rect(
                pm,
                frame.left - style.tick,
                py,
                style.tick,
                grid_width,
                FRAME_COLOR,
            );
            if self.y_labelled.contains(&i) {
                let right = frame.left - style.tick - style.gap;
                let middle = py + 0.5 * grid_width;
                draw_label_ending_at(pm, label, right, middle, ts, LABEL_COLOR);
            }
        }

        let frame_centre_x = 0.5 * (frame.left + frame.right);
        if !self.x_label.is_empty() {
            let ty = frame.bottom + style.tick + style.gap + cap + style.gap + style.gap;
            draw_label_centred(pm, &self.x_label, frame_centre_x, ty, ts, AXIS_LABEL_COLOR);
        }
        if !self.y_label.is_empty() {
            let bottom = 0.5 * (frame.top + frame.bottom) + 0.5 * text_width(&self.y_label, ts);
            draw_text_up(pm, &self.y_label, style.pad, bottom, ts, AXIS_LABEL_COLOR);
        }

        draw_title(pm, &self.title, ts + 1);
        let s = ts as f32;
        for item in &self.legend {
            let mid = item.y + 0.5 * cap;
            let swatch = [(item.x + s, mid), (item.x + 11.0 * s, mid)];
            stroke_polyline(pm, swatch.into_iter(), 2.0 * s, item.color, 255);
            draw_text(pm, &item.text, item.x + 15.0 * s, item.y, ts, LABEL_COLOR);
        }
    }
}

fn series_color(i: usize) -> [u8; 3] {
    SERIES_COLORS[i % SERIES_COLORS.len()]
}

fn x_px(axis: &Axis, inner: Area, v: f64) -> f32 {
    inner.left + (axis.fraction(v) * f64::from(inner.right - inner.left)) as f32
}

fn y_px(axis: &Axis, inner: Area, v: f64) -> f32 {
    inner.bottom - (axis.fraction(v) * f64::from(inner.bottom - inner.top)) as f32
}

/// Indices of the ticks at `positions` (evenly spaced pixels) to label so that labels
/// `extent` pixels long do not overlap: all of them, or every second, third…
fn labelled(positions: &[f32], extent: f32) -> Vec<usize> {
    let spacing = match positions {
        [a, b, ..] => (b - a).abs(),
        _ => f32::INFINITY,
    };
    let stride = if spacing >= extent {
        1
    } else {
        (extent / spacing.max(1e-3)).ceil() as usize
    };
    (0..positions.len()).step_by(stride.max(1)).collect()
}

/// Title lines and their top-left corners, centred on the image.
fn title_lines(title: &str, width: u32, style: Style) -> Vec<(String, f32, f32)> {
    let scale = style.text + 1;
    let available = (width as f32 - 2.0 * style.pad).max(0.0) as u32 / scale;
    wrap(title, available, 2)
        .into_iter()
        .enumerate()
        .map(|(i, line)| {
            let x = 0.5 * (width as f32 - text_width(&line, scale));
            let y = style.pad + i as f32 * line_height(scale);
            (line, x, y)
        })
        .collect()
}

fn draw_title(pm: &mut Pixmap, lines: &[(String, f32, f32)], scale: u32) {
    for (line, x, y) in lines {
        draw_text(pm, line, *x, *y, scale, TITLE_COLOR);
    }
}

/// Legend entries for the named series, flowed into at most `max_rows` rows between `left` and
/// `right` starting at `top`, each row centred. Names too long for a row are shortened with
/// "..."; entries beyond the last row are left out.
fn legend_items(
    series: &[Series],
    left: f32,
    right: f32,
    top: f32,
    style: Style,
    max_rows: usize,
) -> Vec<LegendItem> {
    let ts = style.text;
    let s = ts as f32;
    let swatch = 15.0 * s;
    let between = 12.0 * s;
    let available = right - left;
    let mut rows: Vec<Vec<(f32, LegendItem)>> = Vec::new();
    let mut x = left;
    for (i, one) in series.iter().enumerate() {
        let name = one.name.trim();
        if name.is_empty() {
            continue;
        }
        let max_text = ((available - swatch).max(0.0) / s) as u32;
        let Some(text) = wrap(name, max_text, 1).into_iter().next() else {
            continue;
        };
        let item_width = swatch + text_width(&text, ts);
        if rows.is_empty() || (x > left && x + item_width > right) {
            if rows.len() == max_rows {
                break;
            }
            rows.push(Vec::new());
            x = left;
        }
        let y = top + (rows.len() - 1) as f32 * line_height(ts);
        let row = rows.last_mut().expect("a row was just ensured");
        row.push((
            item_width,
            LegendItem {
                x,
                y,
                color: series_color(i),
                text,
            },
        ));
        x += item_width + between;
    }
    rows.into_iter()
        .flat_map(|row| {
            let used = row.iter().map(|(w, _)| w).sum::<f32>() + between * (row.len() - 1) as f32;
            let shift = (0.5 * (available - used)).max(0.0);
            row.into_iter().map(move |(_, mut item)| {
                item.x += shift;
                item
            })
        })
        .collect()
}

/// The picture for data with nothing to plot: the title and "no data" in the middle.
fn draw_no_data(pm: &mut Pixmap, options: &PlotOptions) {
    let style = Style::new(options.width, options.height);
    let scale = style.text + 1;
    draw_title(
        pm,
        &title_lines(&options.title, options.width, style),
        scale,
    );
    let message = "no data";
    let x = 0.5 * (options.width as f32 - text_width(message, scale));
    let y = 0.5 * (options.height as f32 - cap_height(scale));
    draw_text(pm, message, x, y, scale, LABEL_COLOR);
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Instant;

    fn series(name: &str, points: Vec<(f64, f64)>) -> Series {
        Series {
            name: name.to_string(),
            points,
        }
    }

    /// A loss-like curve: exponential decay from 2 towards 0.1 over `n` steps.
    fn decay(n: usize) -> Vec<(f64, f64)> {
        (0..n)
            .map(|i| {
                let t = i as f64 / n as f64;
                (i as f64, 0.1 + 1.9 * (-5.0 * t).exp())
            })
            .collect()
    }

    fn decode(png: &[u8]) -> Pixmap {
        Pixmap::decode_png(png).expect("valid PNG")
    }

    fn near(pm: &Pixmap, x: u32, y: u32, c: [u8; 3]) -> bool {
        let px = pm.pixel(x, y).expect("in bounds");
        px.alpha() == 255
            && [px.red(), px.green(), px.blue()]
                .iter()
                .zip(c)
                .all(|(&a, b)| a.abs_diff(b) <= 24)
    }

    /// Whether colour `c` appears in the given fractions of `area` (0 = left/top, 1 =
    /// right/bottom).
    fn has_color(pm: &Pixmap, area: Area, xs: (f32, f32), ys: (f32, f32), c: [u8; 3]) -> bool {
        let at = |a: f32, b: f32, f: f32| (a + f * (b - a)).round() as u32;
        let (x0, x1) = (
            at(area.left, area.right, xs.0),
            at(area.left, area.right, xs.1),
        );
        let (y0, y1) = (
            at(area.top, area.bottom, ys.0),
            at(area.top, area.bottom, ys.1),
        );
        (y0..y1).any(|y| (x0..x1).any(|x| near(pm, x, y, c)))
    }

    /// Whether any pixel in the rectangle is clearly darker than the background.
    fn has_ink(pm: &Pixmap, x0: u32, x1: u32, y0: u32, y1: u32) -> bool {
        (y0..y1).any(|y| (x0..x1).any(|x| pm.pixel(x, y).unwrap().red() < 160))
    }

    fn tick_labels(axis: &Axis) -> Vec<&str> {
        axis.ticks.iter().map(|(_, l)| l.as_str()).collect()
    }

    #[test]
    fn png_decodes_with_the_requested_size() {
        let data = [series("train", decay(500))];
        for (width, height) in [(900, 500), (200, 150), (1234, 777), (640, 1600)] {
            let options = PlotOptions {
                title: "Training loss".into(),
                x_label: "step".into(),
                y_label: "loss".into(),
                width,
                height,
                ..PlotOptions::default()
            };
            let pm = decode(&line_plot_png(&data, &options).unwrap());
            assert_eq!((pm.width(), pm.height()), (width, height));
        }
        let defaults = PlotOptions::default();
        assert_eq!(
            (defaults.width, defaults.height, defaults.log_y),
            (900, 500, false)
        );
    }

    #[test]
    fn decreasing_curve_runs_from_upper_left_to_lower_right() {
        let data = [series("train", decay(1000))];
        let options = PlotOptions {
            title: "Loss".into(),
            ..PlotOptions::default()
        };
        let pm = decode(&line_plot_png(&data, &options).unwrap());
        let area = Plot::new(&data, &options).unwrap().frame;
        let c = SERIES_COLORS[0];
        assert!(
            has_color(&pm, area, (0.0, 0.4), (0.0, 0.4), c),
            "upper left"
        );
        assert!(
            has_color(&pm, area, (0.6, 1.0), (0.6, 1.0), c),
            "lower right"
        );
        assert!(
            !has_color(&pm, area, (0.6, 1.0), (0.0, 0.4), c),
            "upper right"
        );
    }

    #[test]
    fn non_finite_points_are_skipped() {
        let mut points = decay(200);
        points[10].1 = f64::NAN;
        points[50].1 = f64::INFINITY;
        points[70].0 = f64::NAN;
        points.push((f64::NEG_INFINITY, 1.0));
        let data = [series("train", points)];
        let options = PlotOptions::default();
        let plot = Plot::new(&data, &options).unwrap();
        assert_eq!(plot.x.lo, 0.0);
        assert!(plot.y.hi <= 2.5, "the range ignores infinity: {:?}", plot.y);
        let pm = decode(&line_plot_png(&data, &options).unwrap());
        assert!(has_color(
            &pm,
            plot.frame,
            (0.0, 1.0),
            (0.0, 1.0),
            SERIES_COLORS[0]
        ));
    }

    #[test]
    fn empty_inputs_say_no_data() {
        let options = PlotOptions {
            title: "Nothing yet".into(),
            ..PlotOptions::default()
        };
        let log = PlotOptions {
            log_y: true,
            ..options.clone()
        };
        let cases: [(Vec<Series>, &PlotOptions); 4] = [
            (vec![], &options),
            (vec![series("a", vec![]), series("b", vec![])], &options),
            (
                vec![series("a", vec![(f64::NAN, 1.0), (1.0, f64::NAN)])],
                &options,
            ),
            (vec![series("a", vec![(0.0, 0.0), (1.0, -2.0)])], &log),
        ];
        for (data, options) in cases {
            assert!(Plot::new(&data, options).is_none());
            let pm = decode(&line_plot_png(&data, options).unwrap());
            assert_eq!((pm.width(), pm.height()), (900, 500));
            assert!(has_ink(&pm, 400, 500, 230, 270), "message in the middle");
            assert!(!has_ink(&pm, 0, 900, 300, 500), "nothing else below it");
        }
    }

    #[test]
    fn log_scale_spans_decades() {
        let points = (0..=300)
            .map(|i| (i as f64, 10f64.powf(-3.0 * i as f64 / 300.0)))
            .collect();
        let data = [series("train", points)];
        let options = PlotOptions {
            log_y: true,
            ..PlotOptions::default()
        };
        let plot = Plot::new(&data, &options).unwrap();
        assert_eq!((plot.y.lo, plot.y.hi), (-3.0, 0.0));
        assert_eq!(tick_labels(&plot.y), ["0.001", "0.01", "0.1", "1"]);
        assert_eq!(plot.y.minor.len(), 3 * 8);
        let pm = decode(&line_plot_png(&data, &options).unwrap());
        let c = SERIES_COLORS[0];
        // Exponential decay is a straight line on a log axis: it touches both ends.
        assert!(has_color(&pm, plot.frame, (0.0, 0.2), (0.0, 0.2), c));
        assert!(has_color(&pm, plot.frame, (0.8, 1.0), (0.8, 1.0), c));
        assert!(!has_color(&pm, plot.frame, (0.6, 1.0), (0.0, 0.4), c));
    }

    #[test]
    fn log_scale_skips_non_positive_values() {
        let data = [series(
            "a",
            vec![(0.0, 0.0), (1.0, 0.5), (2.0, -1.0), (3.0, 0.05)],
        )];
        let options = PlotOptions {
            log_y: true,
            ..PlotOptions::default()
        };
        let plot = Plot::new(&data, &options).unwrap();
        assert_eq!(plot.curves[0].points.len(), 2);
        assert_eq!((plot.y.lo, plot.y.hi), (-2.0, 0.0));
        line_plot_png(&data, &options).unwrap();
        let wide = Axis::log(-12.0, 3.0);
        assert_eq!(
            tick_labels(&wide),
            ["1e-12", "1e-10", "1e-8", "1e-6", "1e-4", "0.01", "1", "100", "1e4"]
        );
        assert!(wide.minor.is_empty());
    }

    #[test]
    fn constant_values_get_a_padded_range() {
        for v in [0.0, 3.0, -1e-7, 1e12] {
            let axis = Axis::linear(v, v);
            assert!(axis.lo < v && v < axis.hi, "{v}: {axis:?}");
            assert!(axis.ticks.len() >= 3, "{v}: {axis:?}");
        }
        let log = Axis::log(0.0, 0.0);
        assert_eq!(tick_labels(&log), ["0.1", "1", "10"]);
        let data = [
            series("flat", vec![(0.0, 1.0), (10.0, 1.0)]),
            series("point", vec![(5.0, 1.0)]),
        ];
        for log_y in [false, true] {
            let options = PlotOptions {
                log_y,
                ..PlotOptions::default()
            };
            let plot = Plot::new(&data, &options).unwrap();
            let all = plot.curves.iter().flat_map(|c| &c.points);
            assert!(all.clone().all(|p| p.0.is_finite() && p.1.is_finite()));
            let pm = decode(&line_plot_png(&data, &options).unwrap());
            assert!(has_color(
                &pm,
                plot.frame,
                (0.3, 0.7),
                (0.3, 0.7),
                SERIES_COLORS[1]
            ));
        }
    }

    #[test]
    fn ticks_are_one_two_or_five_times_a_power_of_ten() {
        assert_eq!(
            tick_labels(&Axis::linear(0.0, 1000.0)),
            ["0", "200", "400", "600", "800", "1000"]
        );
        assert_eq!(
            tick_labels(&Axis::linear(0.23, 2.31)),
            ["0.0", "0.5", "1.0", "1.5", "2.0", "2.5"]
        );
        assert_eq!(tick_labels(&Axis::linear(-1.0, 1.0)).len(), 5);
        for (lo, hi) in [
            (0.0, 1.0),
            (0.0, 7.3),
            (-3.2, 17.0),
            (1e-6, 3e-6),
            (5.0, 99999.0),
        ] {
            let axis = Axis::linear(lo, hi);
            let n = axis.ticks.len();
            assert!((4..=8).contains(&n), "{lo}..{hi}: {n} ticks");
            assert!(axis.lo <= lo && hi <= axis.hi);
            let step = axis.ticks[1].0 - axis.ticks[0].0;
            let mantissa = step / 10f64.powf(step.log10().floor());
            assert!(
                [1.0, 2.0, 5.0].iter().any(|m| (mantissa - m).abs() < 1e-6),
                "{lo}..{hi}: step {step}"
            );
        }
    }

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(linear_label(0.5, 0.5, false), "0.5");
        assert_eq!(linear_label(-0.04, 0.02, false), "-0.04");
        assert_eq!(linear_label(1e-17, 0.1, false), "0.0");
        assert_eq!(linear_label(-1e-17, 0.1, false), "0.0");
        assert_eq!(linear_label(1e6, 5e5, true), "1e6");
        assert_eq!(linear_label(1.5e6, 5e5, true), "1.5e6");
        assert_eq!(linear_label(2e-6, 1e-6, true), "2e-6");
        assert_eq!(
            tick_labels(&Axis::linear(0.0, 2e6)),
            ["0", "5e5", "1e6", "1.5e6", "2e6"]
        );
        let near_one = tick_labels(&Axis::linear(0.999_999, 1.000_001)).join(" ");
        assert_eq!(
            near_one,
            "0.9999990 0.9999995 1.0000000 1.0000005 1.0000010"
        );
        assert_eq!(
            tick_labels(&Axis::linear(1e-5, 4e-5)),
            ["1e-5", "1.5e-5", "2e-5", "2.5e-5", "3e-5", "3.5e-5", "4e-5"]
        );
        assert_eq!(power_label(-5), "1e-5");
        assert_eq!(power_label(-2), "0.01");
        assert_eq!(power_label(3), "1000");
        assert_eq!(power_label(4), "1e4");
    }

    #[test]
    fn long_series_are_decimated_and_fast() {
        let points: Vec<(f64, f64)> = (0..100_000)
            .map(|i| {
                let noise = ((i as f64 * 12.9898).sin() * 43_758.547).fract() * 0.2;
                (i as f64, 1.0 / (1.0 + i as f64 / 5000.0) + noise)
            })
            .collect();
        let data = [series("train", points)];
        let options = PlotOptions::default();
        let start = Instant::now();
        let plot = Plot::new(&data, &options).unwrap();
        let png = line_plot_png(&data, &options).unwrap();
        let elapsed = start.elapsed();
        let columns = (plot.inner.right - plot.inner.left).ceil() as usize + 1;
        assert!(plot.curves[0].points.len() <= 2 * columns);
        assert!(plot.curves[0].points.len() >= columns);
        decode(&png);
        // Generous, so a loaded machine does not fail it; undecimated stroking takes far longer.
        assert!(elapsed.as_secs_f64() < 2.0, "took {elapsed:?}");
    }

    #[test]
    fn decimation_keeps_each_columns_extremes_in_order() {
        let points = [
            (0.1, 5.0),
            (0.5, 9.0),
            (0.9, 1.0),
            (1.2, 4.0),
            (2.0, 3.0),
            (2.5, 3.0),
        ];
        assert_eq!(
            decimate(points),
            [(0.5, 9.0), (0.9, 1.0), (1.2, 4.0), (2.0, 3.0)]
        );
        assert!(decimate([]).is_empty());
    }

    #[test]
    fn series_colours_cycle_and_appear_in_the_legend() {
        let data: Vec<Series> = (0..8)
            .map(|i| {
                let points = (0..50).map(|x| (x as f64, (i * 50 + x) as f64)).collect();
                series(&format!("run {i}"), points)
            })
            .collect();
        let options = PlotOptions::default();
        let plot = Plot::new(&data, &options).unwrap();
        assert_eq!(plot.legend.len(), 8);
        for (i, item) in plot.legend.iter().enumerate() {
            assert_eq!(item.color, SERIES_COLORS[i % 6]);
            assert_eq!(item.text, format!("run {i}"));
            assert!(
                item.y + 10.0 < plot.frame.top,
                "the legend is above the plot"
            );
        }
        let distinct: std::collections::HashSet<_> = SERIES_COLORS.iter().collect();
        assert_eq!(distinct.len(), SERIES_COLORS.len());
        decode(&line_plot_png(&data, &options).unwrap());
    }

    #[test]
    fn unusable_sizes_are_errors() {
        let data = [series("a", decay(10))];
        let small = PlotOptions {
            width: 100,
            height: 100,
            ..PlotOptions::default()
        };
        assert!(matches!(
            line_plot_png(&data, &small),
            Err(RenderError::InvalidOptions(_))
        ));
        let huge = PlotOptions {
            width: 16_000,
            height: 16_000,
            ..PlotOptions::default()
        };
        assert!(matches!(
            line_plot_png(&data, &huge),
            Err(RenderError::TooLarge { .. })
        ));
    }

    #[test]
    fn writes_png_files() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("loss.png");
        write_line_plot(&path, &[series("a", decay(10))], &PlotOptions::default()).unwrap();
        let pm = decode(&std::fs::read(&path).unwrap());
        assert_eq!((pm.width(), pm.height()), (900, 500));
        let missing = dir.path().join("no/such/dir/loss.png");
        let err = write_line_plot(&missing, &[], &PlotOptions::default());
        assert!(matches!(err, Err(RenderError::Io { .. })));
    }

    /// Writes `plot-example.png` and `plot-example-log.png` to the temporary directory, for
    /// looking at: a noisy training loss with a NaN step, a validation loss and a short run.
    #[test]
    fn writes_example_plots() {
        let train: Vec<(f64, f64)> = (0..20_000)
            .map(|i| {
                let noise = ((i as f64 * 12.9898).sin() * 43_758.547).fract().abs();
                let loss = (0.08 + 2.2 * (-(i as f64) / 3000.0).exp()) * (0.8 + 0.4 * noise);
                (i as f64, if i == 7000 { f64::NAN } else { loss })
            })
            .collect();
        let validation: Vec<(f64, f64)> = (0..=20)
            .map(|k| {
                let step = k as f64 * 1000.0;
                (step, 0.2 + 2.0 * (-step / 3500.0).exp())
            })
            .collect();
        let short: Vec<(f64, f64)> = (0..8000)
            .map(|i| (i as f64, 0.3 + 1.8 * (-(i as f64) / 1500.0).exp()))
            .collect();
        let data = [
            series("train", train),
            series("validation", validation),
            series("lr 3e-4 (stopped)", short),
        ];
        let dir = std::env::temp_dir();
        for (log_y, name) in [(false, "plot-example.png"), (true, "plot-example-log.png")] {
            let options = PlotOptions {
                title: "Motion VAE training loss".into(),
                x_label: "step".into(),
                y_label: "loss".into(),
                log_y,
                ..PlotOptions::default()
            };
            write_line_plot(&dir.join(name), &data, &options).unwrap();
        }
    }
}
