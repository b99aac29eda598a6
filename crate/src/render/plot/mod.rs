//! Plots as PNG images: data drawn in a plot area over a grid at "nice" values.
//!
//! - [`line`](mod@line): line plots of training curves, such as loss against step.
//! - [`ground_path`]: a path on the ground (x, z in metres) seen from above, such as the path
//!   a motion walks, over the curve that was asked for.
//!
//! Both draw on white, write text with the bitmap font of [`render`](crate::render), space
//! their grid lines 1, 2 or 5 × 10^k apart and label the ticks with just enough decimals to
//! tell neighbours apart; this module holds what they share. The main items of both plots
//! are re-exported here.

pub mod ground_path;
pub mod line;

use tiny_skia::Pixmap;

use super::draw::{draw_text, fill_rect};
use super::font;

pub use ground_path::{path_png, PathPlotOptions, PlotError};
pub use line::{line_plot_png, write_line_plot, PlotOptions, Series, SERIES_COLORS};

// The first six colours of Tableau 10 (sRGB), chosen to be told apart on white.
const BLUE: [u8; 3] = [31, 119, 180];
const ORANGE: [u8; 3] = [255, 127, 14];
const GREEN: [u8; 3] = [44, 160, 44];
const RED: [u8; 3] = [214, 39, 40];
const PURPLE: [u8; 3] = [148, 103, 189];
const BROWN: [u8; 3] = [140, 86, 75];

/// Colour of the grid lines at the ticks.
const GRID_COLOR: [u8; 3] = [226, 226, 226];

/// A rectangle by its edges, in pixels (y down).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Area {
    left: f32,
    top: f32,
    right: f32,
    bottom: f32,
}

impl Area {
    /// The area with each edge moved `by` pixels inwards.
    fn shrunk(self, by: f32) -> Area {
        Area {
            left: self.left + by,
            top: self.top + by,
            right: self.right - by,
            bottom: self.bottom - by,
        }
    }

    /// A crisp vertical grid line from the top of the area to its bottom, `width` pixels wide
    /// with its left edge at column `x`.
    fn vertical_rule(&self, pm: &mut Pixmap, x: f32, width: f32, c: [u8; 3]) {
        fill_rect(pm, x, self.top, width, self.bottom - self.top, c);
    }

    /// A crisp horizontal grid line across the area, `width` pixels high with its top edge at
    /// row `y`.
    fn horizontal_rule(&self, pm: &mut Pixmap, y: f32, width: f32, c: [u8; 3]) {
        fill_rect(pm, self.left, y, self.right - self.left, width, c);
    }
}

/// The smallest 1, 2 or 5 × 10^k at least `raw` (which must be positive and finite).
fn nice_step(raw: f64) -> f64 {
    let magnitude = 10f64.powf(raw.log10().floor());
    let normalised = raw / magnitude;
    // The tolerance keeps e.g. 0.2, whose quotient comes out as 2.0000000000000004, at 2.
    let factor = [1.0, 2.0, 5.0]
        .into_iter()
        .find(|&f| normalised <= f * (1.0 + 1e-9))
        .unwrap_or(10.0);
    factor * magnitude
}

/// The power of ten of a tick spacing: k for steps of 1, 2 or 5 × 10^k.
fn step_exponent(step: f64) -> i32 {
    (step.log10() + 1e-9).floor() as i32
}

/// Tick `v` of an axis with ticks `step` apart, with the tiny or negative-zero value that
/// rounding error can leave where the tick is 0 replaced by 0.
fn snap_zero(v: f64, step: f64) -> f64 {
    if v.abs() < 0.5 * step {
        0.0
    } else {
        v
    }
}

/// Label of tick `v` on an axis with ticks `step` apart, in plain decimals: just enough digits
/// to tell neighbouring ticks apart ("-2" for a step of 1, "0.5" for a step of 0.5).
fn decimal_label(v: f64, step: f64) -> String {
    let decimals = (-step_exponent(step)).max(0) as usize;
    format!("{:.decimals$}", snap_zero(v, step))
}

/// Width in pixels of `text` drawn at font pixel size `scale`.
fn text_width(text: &str, scale: u32) -> f32 {
    (font::text_width(text) * scale) as f32
}

/// Height in pixels of capital letters at font pixel size `scale`.
fn cap_height(scale: u32) -> f32 {
    (font::CAP_ROWS * scale) as f32
}

/// Pixels from one line of text to the next at font pixel size `scale`.
fn line_height(scale: u32) -> f32 {
    (font::LINE_ROWS * scale) as f32
}

/// Draws `text` centred on column `centre_x` with its top at row `top`, as an x tick label.
fn draw_label_centred(
    pm: &mut Pixmap,
    text: &str,
    centre_x: f32,
    top: f32,
    scale: u32,
    c: [u8; 3],
) {
    let x = centre_x - 0.5 * text_width(text, scale);
    draw_text(pm, text, x, top, scale, c);
}

/// Draws `text` ending at column `right`, its capitals centred on row `middle_y`, as a y tick
/// label.
fn draw_label_ending_at(
    pm: &mut Pixmap,
    text: &str,
    right: f32,
    middle_y: f32,
    scale: u32,
    c: [u8; 3],
) {
    let x = right - text_width(text, scale);
    let y = middle_y - 0.5 * cap_height(scale);
    draw_text(pm, text, x, y, scale, c);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_are_one_two_or_five_times_a_power_of_ten() {
        assert_eq!(nice_step(0.3), 0.5);
        assert_eq!(nice_step(0.2), 0.2);
        assert_eq!(nice_step(1.0), 1.0);
        assert_eq!(nice_step(1.1), 2.0);
        assert_eq!(nice_step(7.0), 10.0);
        assert_eq!(nice_step(2500.0), 5000.0);
    }

    #[test]
    fn decimal_labels_are_short() {
        assert_eq!(decimal_label(0.5, 0.5), "0.5");
        assert_eq!(decimal_label(-2.0, 1.0), "-2");
        assert_eq!(decimal_label(-0.04, 0.02), "-0.04");
        assert_eq!(decimal_label(1e-17, 0.1), "0.0");
        assert_eq!(decimal_label(-1e-17, 0.1), "0.0");
        assert_eq!(decimal_label(400.0, 200.0), "400");
    }
}
