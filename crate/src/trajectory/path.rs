//! From a curve to a walkable ground-plane path: sampled, smoothed, parametrised by arc length,
//! placed at the origin heading +Z and scaled to a length in metres.
//!
//! The curve is evaluated at [`CURVE_SAMPLES`] evenly spaced parameter values. Those samples
//! become the control points of a uniform cubic B-spline whose end points are tripled, so the
//! spline starts exactly at the first sample and ends exactly at the last. A B-spline
//! (rather than an interpolating Catmull-Rom spline) approximates: it never overshoots, is C²
//! everywhere and rounds sharp corners (a square's, a zigzag's) over a couple of samples,
//! while a smooth curve moves by only about h²·κ/6 (h the sample spacing, κ the curvature;
//! under 0.02 % of the radius for a circle). The spline is tabulated at [`SPAN_STEPS`] points
//! per span and arc length is the length of that polyline, so any arc position maps to a
//! point by a binary search and a linear interpolation: the reparametrisation to constant
//! speed.
//!
//! Headings are angles about +Y in radians with 0 = +Z and positive towards +X, the same sense
//! as [`Quat::from_yaw`](crate::geom::Quat::from_yaw): a positive change is a left turn,
//! counter-clockwise seen from above. Along a path the heading is unwrapped (continuous), so a
//! full clockwise circle ends at −2π.

use super::shapes::{Curve, CurveError};

/// Curve samples taken before fitting the spline.
pub const CURVE_SAMPLES: usize = 200;
/// Tabulated points per spline span, for arc length and lookup.
pub const SPAN_STEPS: usize = 8;
/// Largest coordinate magnitude accepted from a curve (arbitrary units): beyond this, lengths
/// would lose precision and the formula is surely broken.
pub const MAX_COORD: f64 = 1.0e6;

/// Why a curve or point list cannot become a path.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PathError {
    /// A formula failed at a sample.
    #[error(transparent)]
    Curve(#[from] CurveError),
    /// A point is NaN or infinite.
    #[error("point {index} of the path is not finite")]
    NonFinite {
        /// Index of the point.
        index: usize,
    },
    /// A coordinate beyond [`MAX_COORD`].
    #[error("point {index} of the path has a coordinate of {value}, beyond ±{MAX_COORD}")]
    TooLarge {
        /// Index of the point.
        index: usize,
        /// The coordinate.
        value: f64,
    },
    /// Fewer than two points.
    #[error("a path needs at least 2 points, got {0}")]
    TooFewPoints(usize),
    /// All points coincide.
    #[error("the path is a single point: it has no length to walk")]
    ZeroLength,
    /// Fewer than two output frames.
    #[error("a resampled path needs at least 2 frames, got {0}")]
    TooFewFrames(usize),
    /// The requested length is not a positive finite number of metres.
    #[error("invalid path length {0} m: need a finite length above zero")]
    BadLength(f64),
}

/// Heading of the ground-plane direction `[dx, dz]` (see the module documentation).
pub fn heading_of(d: [f64; 2]) -> f64 {
    d[0].atan2(d[1])
}

/// Unit ground-plane direction `[dx, dz]` of a heading.
pub fn direction(heading: f64) -> [f64; 2] {
    let (s, c) = heading.sin_cos();
    [s, c]
}

/// `p` turned by `angle` radians about +Y (positive from +Z towards +X), as
/// [`Quat::from_yaw`](crate::geom::Quat::from_yaw) turns `[p[0], 0, p[1]]`.
pub fn rotate(p: [f64; 2], angle: f64) -> [f64; 2] {
    let (s, c) = angle.sin_cos();
    [p[0] * c + p[1] * s, p[1] * c - p[0] * s]
}

/// Evaluates `curve` at `samples` evenly spaced parameter values, first and last included.
pub fn sample_curve(curve: &Curve, samples: usize) -> Result<Vec<[f64; 2]>, PathError> {
    let samples = samples.max(2);
    (0..samples)
        .map(|i| {
            let t = curve.t0 + (curve.t1 - curve.t0) * i as f64 / (samples - 1) as f64;
            Ok(curve.point(t)?)
        })
        .collect()
}

/// A smooth path parametrised by arc length, starting at the origin heading +Z. Lengths are
/// in the units of the points it was built from until [`ArcPath::scaled_to`] makes them
/// metres.
#[derive(Clone, Debug, PartialEq)]
pub struct ArcPath {
    /// Arc length at each tabulated point, from 0, non-decreasing.
    arc: Vec<f64>,
    /// Tabulated spline points (x, z).
    points: Vec<[f64; 2]>,
    /// Arc length at the middle of each tabulated segment of non-zero length.
    mid_arc: Vec<f64>,
    /// Unwrapped heading of those segments.
    mid_heading: Vec<f64>,
}

impl ArcPath {
    /// The path of a curve: [`CURVE_SAMPLES`] samples through [`ArcPath::from_points`].
    pub fn from_curve(curve: &Curve) -> Result<ArcPath, PathError> {
        ArcPath::from_points(&sample_curve(curve, CURVE_SAMPLES)?)
    }

    /// Fits the B-spline through ordered points (x, z), e.g. curve samples or a path drawn
    /// with the pointer, then moves it to start at the origin and turns it so its initial
    /// heading is +Z.
    pub fn from_points(points: &[[f64; 2]]) -> Result<ArcPath, PathError> {
        if points.len() < 2 {
            return Err(PathError::TooFewPoints(points.len()));
        }
        for (index, p) in points.iter().enumerate() {
            if !p.iter().all(|v| v.is_finite()) {
                return Err(PathError::NonFinite { index });
            }
            if let Some(&value) = p.iter().find(|v| v.abs() > MAX_COORD) {
                return Err(PathError::TooLarge { index, value });
            }
        }
        let extent = bounding_extent(points);
        if extent == 0.0 {
            return Err(PathError::ZeroLength);
        }
        // Repeated points (a formula that pauses) would only stall the spline.
        let eps = 1e-9 * extent;
        let mut control: Vec<[f64; 2]> = vec![points[0]];
        for p in &points[1..] {
            let last = control[control.len() - 1];
            if dist(*p, last) > eps {
                control.push(*p);
            }
        }
        if control.len() < 2 {
            return Err(PathError::ZeroLength);
        }
        let start = control[0];
        let turn = -heading_of(initial_direction(&control));
        for p in &mut control {
            *p = rotate([p[0] - start[0], p[1] - start[1]], turn);
        }
        let points = tabulate_bspline(&control);
        let mut arc = Vec::with_capacity(points.len());
        let mut total = 0.0;
        arc.push(0.0);
        for w in points.windows(2) {
            total += dist(w[0], w[1]);
            arc.push(total);
        }
        if total <= eps {
            return Err(PathError::ZeroLength);
        }
        let mut mid_arc = Vec::new();
        let mut mid_heading: Vec<f64> = Vec::new();
        for (i, w) in points.windows(2).enumerate() {
            let d = [w[1][0] - w[0][0], w[1][1] - w[0][1]];
            if arc[i + 1] - arc[i] <= 1e-12 * total {
                continue;
            }
            let mut h = heading_of(d);
            if let Some(&prev) = mid_heading.last() {
                h = unwrap_near(h, prev);
            }
            mid_arc.push(0.5 * (arc[i] + arc[i + 1]));
            mid_heading.push(h);
        }
        Ok(ArcPath {
            arc,
            points,
            mid_arc,
            mid_heading,
        })
    }

    /// Total length (units of the points; metres after [`ArcPath::scaled_to`]).
    pub fn length(&self) -> f64 {
        self.arc[self.arc.len() - 1]
    }

    /// The same path scaled about the origin so that its length is `length_m` metres.
    pub fn scaled_to(&self, length_m: f64) -> Result<ArcPath, PathError> {
        if !(length_m.is_finite() && length_m > 0.0) {
            return Err(PathError::BadLength(length_m));
        }
        let k = length_m / self.length();
        Ok(ArcPath {
            arc: self.arc.iter().map(|s| s * k).collect(),
            points: self.points.iter().map(|p| [p[0] * k, p[1] * k]).collect(),
            mid_arc: self.mid_arc.iter().map(|s| s * k).collect(),
            mid_heading: self.mid_heading.clone(),
        })
    }

    /// The point `arc` along the path (clamped to the path's ends).
    pub fn point_at(&self, arc: f64) -> [f64; 2] {
        let s = arc.clamp(0.0, self.length());
        let i = self.arc.partition_point(|&a| a <= s);
        if i == 0 {
            return self.points[0];
        }
        if i >= self.arc.len() {
            return self.points[self.points.len() - 1];
        }
        let (a0, a1) = (self.arc[i - 1], self.arc[i]);
        let f = if a1 > a0 { (s - a0) / (a1 - a0) } else { 0.0 };
        let (p, q) = (self.points[i - 1], self.points[i]);
        [p[0] + (q[0] - p[0]) * f, p[1] + (q[1] - p[1]) * f]
    }

    /// The tangent's (unwrapped) heading `arc` along the path, clamped to the ends.
    pub fn heading_at(&self, arc: f64) -> f64 {
        let n = self.mid_arc.len();
        if n == 0 || arc <= self.mid_arc[0] {
            return self.mid_heading.first().copied().unwrap_or(0.0);
        }
        if arc >= self.mid_arc[n - 1] {
            return self.mid_heading[n - 1];
        }
        let i = self.mid_arc.partition_point(|&a| a <= arc);
        let (a0, a1) = (self.mid_arc[i - 1], self.mid_arc[i]);
        let f = (arc - a0) / (a1 - a0);
        self.mid_heading[i - 1] + (self.mid_heading[i] - self.mid_heading[i - 1]) * f
    }

    /// The path at the given arc positions, in order.
    pub fn sample_at(&self, arcs: &[f64]) -> Path {
        Path {
            points: arcs.iter().map(|&s| self.point_at(s)).collect(),
            heading: arcs.iter().map(|&s| self.heading_at(s)).collect(),
        }
    }

    /// `frames` points at constant speed from start to end, first and last included.
    pub fn resample(&self, frames: usize) -> Result<Path, PathError> {
        if frames < 2 {
            return Err(PathError::TooFewFrames(frames));
        }
        let l = self.length();
        let arcs: Vec<f64> = (0..frames)
            .map(|k| l * k as f64 / (frames - 1) as f64)
            .collect();
        Ok(self.sample_at(&arcs))
    }

    /// The tabulated spline points (x, z), for drawing.
    pub fn polyline(&self) -> &[[f64; 2]] {
        &self.points
    }
}

/// A path sampled once per frame: where the root is on the ground and which way the path
/// runs there.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Path {
    /// Ground position (x, z) per frame; metres when built from a scaled [`ArcPath`].
    pub points: Vec<[f64; 2]>,
    /// Unwrapped tangent heading per frame, radians (see the module documentation).
    pub heading: Vec<f64>,
}

impl Path {
    /// Length of the polyline through the points.
    pub fn length(&self) -> f64 {
        self.points.windows(2).map(|w| dist(w[0], w[1])).sum()
    }
}

/// `frames` points of `curve` at constant speed, `length_m` metres long, starting at the
/// origin heading +Z: the whole pipeline of this module.
pub fn resample_curve(curve: &Curve, frames: usize, length_m: f64) -> Result<Path, PathError> {
    ArcPath::from_curve(curve)?
        .scaled_to(length_m)?
        .resample(frames)
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

fn bounding_extent(points: &[[f64; 2]]) -> f64 {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (hi[0] - lo[0]).max(hi[1] - lo[1])
}

/// The curve's direction at its first point. The one-sided second-order difference
/// `(−3p₀ + 4p₁ − p₂)/2` is exact for a parabola, so a circle that starts heading +Z is not
/// tilted by half a sample's turn; where it disagrees wildly with the first chord (a corner or
/// a cusp right at the start) the chord is used.
fn initial_direction(p: &[[f64; 2]]) -> [f64; 2] {
    let chord = [p[1][0] - p[0][0], p[1][1] - p[0][1]];
    if p.len() < 3 {
        return chord;
    }
    let d = [
        (-3.0 * p[0][0] + 4.0 * p[1][0] - p[2][0]) / 2.0,
        (-3.0 * p[0][1] + 4.0 * p[1][1] - p[2][1]) / 2.0,
    ];
    let (nd, nc) = (d[0].hypot(d[1]), chord[0].hypot(chord[1]));
    let cos = (d[0] * chord[0] + d[1] * chord[1]) / (nd * nc);
    if nd > 0.0 && cos > std::f64::consts::FRAC_1_SQRT_2 {
        d
    } else {
        chord
    }
}

/// `h` plus the multiple of 2π that brings it closest to `near`.
fn unwrap_near(h: f64, near: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    h + ((near - h) / tau).round() * tau
}

/// Points along the uniform cubic B-spline with control points `control`, end points tripled
/// so that it runs from the first control point to the last.
fn tabulate_bspline(control: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let n = control.len();
    let padded: Vec<[f64; 2]> = [control[0]; 2]
        .into_iter()
        .chain(control.iter().copied())
        .chain([control[n - 1]; 2])
        .collect();
    let spans = padded.len() - 3;
    let mut out = Vec::with_capacity(spans * SPAN_STEPS + 1);
    for i in 0..spans {
        let c = &padded[i..i + 4];
        for k in 0..SPAN_STEPS {
            out.push(bspline_point(c, k as f64 / SPAN_STEPS as f64));
        }
    }
    out.push(bspline_point(&padded[spans - 1..spans + 3], 1.0));
    out
}

fn bspline_point(c: &[[f64; 2]], u: f64) -> [f64; 2] {
    let u2 = u * u;
    let u3 = u2 * u;
    let w = [
        (1.0 - u).powi(3) / 6.0,
        (3.0 * u3 - 6.0 * u2 + 4.0) / 6.0,
        (-3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0) / 6.0,
        u3 / 6.0,
    ];
    let mut p = [0.0; 2];
    for (ci, wi) in c.iter().zip(w) {
        p[0] += ci[0] * wi;
        p[1] += ci[1] * wi;
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Quat;
    use crate::trajectory::shapes::{CurveSpec, Shape, Side};
    use std::f64::consts::{PI, TAU};

    fn spec(x: &str, z: &str, t1: f64) -> Curve {
        CurveSpec {
            x: x.into(),
            z: z.into(),
            t0: 0.0,
            t1,
        }
        .compile()
        .unwrap()
    }

    #[test]
    fn heading_and_rotation_agree_with_quat_from_yaw() {
        for angle in [0.3, -1.2, 2.9] {
            let q = Quat::from_yaw(angle).rotate([0.0, 0.0, 1.0]);
            let d = direction(angle);
            assert!((q[0] - d[0]).abs() < 1e-12 && (q[2] - d[1]).abs() < 1e-12);
            assert!((heading_of(d) - angle).abs() < 1e-12);
            let p = [0.7, -0.4];
            let r = rotate(p, angle);
            let q = Quat::from_yaw(angle).rotate([p[0], 0.0, p[1]]);
            assert!((q[0] - r[0]).abs() < 1e-12 && (q[2] - r[1]).abs() < 1e-12);
        }
        // Facing +Z, a left turn (towards +X) raises the heading.
        assert!(heading_of([0.1, 1.0]) > 0.0);
    }

    #[test]
    fn constant_speed_line_has_exact_length_and_spacing() {
        let path = resample_curve(&Shape::Line.curve(), 11, 5.0).unwrap();
        for (k, p) in path.points.iter().enumerate() {
            assert!(
                p[0].abs() < 1e-9 && (p[1] - 0.5 * k as f64).abs() < 1e-9,
                "{k} {p:?}"
            );
        }
        assert!(path.heading.iter().all(|h| h.abs() < 1e-9));
    }

    #[test]
    fn circle_is_resampled_at_constant_speed_and_scaled() {
        let length = 2.0 * PI * 1.5;
        let frames = 121;
        let path = resample_curve(&Shape::Circle(Side::Right).curve(), frames, length).unwrap();
        assert!((path.length() - length).abs() < 1e-3 * length);
        let step = length / (frames - 1) as f64;
        for w in path.points.windows(2) {
            assert!((dist(w[0], w[1]) - step).abs() < 2e-3 * step);
        }
        // Clockwise: centre on the right (−X), radius 1.5, heading falls to −2π.
        let centre = [-1.5, 0.0];
        for p in &path.points {
            assert!((dist(*p, centre) - 1.5).abs() < 2e-3, "{p:?}");
        }
        assert!(path.heading[0].abs() < 0.02);
        assert!((path.heading[frames - 1] + TAU).abs() < 0.02);
        let end = path.points[frames - 1];
        assert!(end[0].abs() < 1e-9 && end[1].abs() < 1e-9);
    }

    #[test]
    fn any_start_is_moved_to_the_origin_heading_forward() {
        // Starts at (3, 2) heading +X; after normalising it must head +Z.
        let curve = spec("3 + t", "2 + 0.1*t^2", 4.0);
        let arc = ArcPath::from_curve(&curve).unwrap();
        assert_eq!(arc.point_at(0.0), [0.0, 0.0]);
        // The first spline span runs along the first chord, half a sample's turn off.
        assert!(arc.heading_at(0.0).abs() < 5e-3, "{}", arc.heading_at(0.0));
        // Heading +X, the walker's left is −Z: bending towards +Z is a right turn.
        assert!(arc.heading_at(arc.length()) < -0.1);
    }

    #[test]
    fn degenerate_curves_are_errors() {
        assert_eq!(
            ArcPath::from_curve(&spec("1", "2", 1.0)),
            Err(PathError::ZeroLength)
        );
        assert!(matches!(
            ArcPath::from_curve(&spec("log(t - 0.5)", "t", 1.0)),
            Err(PathError::Curve(CurveError::NonFinite { axis: "x", .. }))
        ));
        assert!(matches!(
            ArcPath::from_curve(&spec("exp(t)", "t", 100.0)),
            Err(PathError::TooLarge { .. })
        ));
        assert_eq!(
            ArcPath::from_points(&[[0.0, 0.0]]),
            Err(PathError::TooFewPoints(1))
        );
        assert_eq!(
            ArcPath::from_points(&[[0.0, 0.0], [f64::NAN, 1.0]]),
            Err(PathError::NonFinite { index: 1 })
        );
        assert_eq!(
            ArcPath::from_points(&[[1.0, 1.0]; 5]),
            Err(PathError::ZeroLength)
        );
        let line = ArcPath::from_curve(&Shape::Line.curve()).unwrap();
        assert_eq!(line.scaled_to(0.0), Err(PathError::BadLength(0.0)));
        assert!(line.scaled_to(f64::NAN).is_err());
        assert_eq!(line.resample(1), Err(PathError::TooFewFrames(1)));
    }

    #[test]
    fn pauses_and_two_point_paths_work() {
        // The curve stands still for half its range.
        let curve = spec("0", "min(t, 1)", 2.0);
        let path = resample_curve(&curve, 5, 2.0).unwrap();
        assert!((path.points[4][1] - 2.0).abs() < 1e-9);
        let arc = ArcPath::from_points(&[[0.0, 0.0], [1.0, 0.0]]).unwrap();
        assert!((arc.length() - 1.0).abs() < 1e-12);
        assert!(arc.heading_at(0.5).abs() < 1e-12);
    }

    #[test]
    fn every_shape_becomes_a_path() {
        for shape in Shape::ALL {
            let path = resample_curve(&shape.curve(), 100, 10.0).unwrap();
            // Chords between the samples cut the corners (the heart's tip and dip most).
            assert!(
                (path.length() - 10.0).abs() < 0.2,
                "{shape:?} {}",
                path.length()
            );
            assert!(
                path.heading[0].abs() < 0.05,
                "{shape:?} {}",
                path.heading[0]
            );
        }
    }
}
