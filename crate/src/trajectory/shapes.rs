//! The offline shape library and LLM-written curves: ground-plane paths as formulas in `t`.
//!
//! A curve is `x(t)`, `z(t)` on the ground plane (world X and Z, Y is up), for `t` from `t0`
//! to `t1`, written in the [`expr`](super::expr) language, so curves written by a language
//! model and the built-in shapes go through the same sandboxed evaluator. Units are
//! arbitrary: [`path`](super::path) rescales the curve to the distance the motion walks.
//!
//! Every built-in shape starts at the origin heading +Z (the way a motion starts), and turns
//! "left" or "right" as the walker sees it. Facing +Z, the walker's left is +X, so a left turn
//! swings the heading from +Z towards +X: counter-clockwise seen from above. A right turn
//! (from +Z towards −X) is clockwise seen from above.

use serde::{Deserialize, Serialize};

use super::expr::{Expr, ExprError, NonFinite};

/// Which way a shape turns, as the walker sees it (see the module documentation): left is
/// towards the walker's left (+X at the start), counter-clockwise seen from above; right is
/// clockwise.
pub use crate::skeleton::Side;

/// A built-in path shape. Shapes that can turn either way carry a [`Side`]; for closed shapes
/// (circle, square, heart, figure eight, spiral) it is the direction they are walked round, for
/// the others the direction of the first bend.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(into = "String", try_from = "String")]
pub enum Shape {
    /// Straight ahead.
    Line,
    /// One full circle, back to the start.
    Circle(Side),
    /// A quarter circle.
    Arc(Side),
    /// A short straight lead-in, then four straight legs at 45° to the walking direction.
    Zigzag(Side),
    /// The letter S: a half circle one way, then a half circle the other way, ending with the
    /// start heading. The first half turns to the given side.
    SCurve(Side),
    /// Two circles touching at the start, the first turning to the given side, the second the
    /// other way; both are walked in full.
    FigureEight(Side),
    /// Four equal sides with 90° corners, back to the start.
    Square(Side),
    /// The classic heart curve, starting on the side of one lobe heading along the heart's
    /// axis, back to the start.
    Heart(Side),
    /// Two turns outwards, the radius growing from 1 to 3 (a slow start, so the first steps
    /// are not a spin on the spot).
    Spiral(Side),
    /// Forward, a 90° turn on a small rounded corner, then forward again.
    Turn(Side),
}

/// Shape names without a side, in [`Shape::ALL`] order after `line`.
const SIDED_KINDS: [&str; 9] = [
    "circle",
    "arc",
    "zigzag",
    "s_curve",
    "figure_eight",
    "square",
    "heart",
    "spiral",
    "turn",
];

impl Shape {
    /// Every shape, each side of each.
    pub const ALL: [Shape; 19] = [
        Shape::Line,
        Shape::Circle(Side::Left),
        Shape::Circle(Side::Right),
        Shape::Arc(Side::Left),
        Shape::Arc(Side::Right),
        Shape::Zigzag(Side::Left),
        Shape::Zigzag(Side::Right),
        Shape::SCurve(Side::Left),
        Shape::SCurve(Side::Right),
        Shape::FigureEight(Side::Left),
        Shape::FigureEight(Side::Right),
        Shape::Square(Side::Left),
        Shape::Square(Side::Right),
        Shape::Heart(Side::Left),
        Shape::Heart(Side::Right),
        Shape::Spiral(Side::Left),
        Shape::Spiral(Side::Right),
        Shape::Turn(Side::Left),
        Shape::Turn(Side::Right),
    ];

    /// The kind without its side, e.g. `"figure_eight"`.
    pub fn kind(self) -> &'static str {
        match self {
            Shape::Line => "line",
            Shape::Circle(_) => "circle",
            Shape::Arc(_) => "arc",
            Shape::Zigzag(_) => "zigzag",
            Shape::SCurve(_) => "s_curve",
            Shape::FigureEight(_) => "figure_eight",
            Shape::Square(_) => "square",
            Shape::Heart(_) => "heart",
            Shape::Spiral(_) => "spiral",
            Shape::Turn(_) => "turn",
        }
    }

    /// The side it turns to; `None` for a line.
    pub fn side(self) -> Option<Side> {
        match self {
            Shape::Line => None,
            Shape::Circle(s)
            | Shape::Arc(s)
            | Shape::Zigzag(s)
            | Shape::SCurve(s)
            | Shape::FigureEight(s)
            | Shape::Square(s)
            | Shape::Heart(s)
            | Shape::Spiral(s)
            | Shape::Turn(s) => Some(s),
        }
    }

    fn with_side(kind: &str, side: Side) -> Option<Shape> {
        Some(match kind {
            "line" => Shape::Line,
            "circle" => Shape::Circle(side),
            "arc" => Shape::Arc(side),
            "zigzag" => Shape::Zigzag(side),
            "s_curve" => Shape::SCurve(side),
            "figure_eight" => Shape::FigureEight(side),
            "square" => Shape::Square(side),
            "heart" => Shape::Heart(side),
            "spiral" => Shape::Spiral(side),
            "turn" => Shape::Turn(side),
            _ => return None,
        })
    }

    /// The stable name stored in plans: `"line"` or `"{kind}_{left|right}"`, e.g.
    /// `"circle_right"` (clockwise).
    pub fn name(self) -> String {
        match self.side() {
            None => self.kind().to_string(),
            Some(side) => format!("{}_{}", self.kind(), side.name()),
        }
    }

    /// The shape of a stored name. Besides [`Shape::name`]'s `_left`/`_right`, accepts
    /// `_ccw`/`_counterclockwise`/`_anticlockwise` (left) and `_cw`/`_clockwise` (right),
    /// and a bare kind, which turns left. Case and `-`/space for `_` do not matter.
    pub fn from_name(name: &str) -> Option<Shape> {
        let name = name.trim().to_ascii_lowercase().replace(['-', ' '], "_");
        if name == "line" {
            return Some(Shape::Line);
        }
        for kind in SIDED_KINDS {
            let Some(rest) = name.strip_prefix(kind) else {
                continue;
            };
            let side = match rest {
                "" | "_left" | "_ccw" | "_counterclockwise" | "_counter_clockwise"
                | "_anticlockwise" | "_anti_clockwise" => Side::Left,
                "_right" | "_cw" | "_clockwise" => Side::Right,
                _ => continue,
            };
            return Shape::with_side(kind, side);
        }
        None
    }

    /// A short human description, e.g. "a circle, clockwise".
    pub fn describe(self) -> String {
        let turning = |s: Side| {
            if s.is_clockwise() {
                "clockwise"
            } else {
                "counter-clockwise"
            }
        };
        match self {
            Shape::Line => "a straight line".into(),
            Shape::Circle(s) => format!("a circle, {}", turning(s)),
            Shape::Arc(s) => format!("an arc to the {}", s.name()),
            Shape::Zigzag(s) => format!("a zigzag, first to the {}", s.name()),
            Shape::SCurve(s) => format!("an S curve, first to the {}", s.name()),
            Shape::FigureEight(s) => format!("a figure eight, first loop to the {}", s.name()),
            Shape::Square(s) => format!("a square, {}", turning(s)),
            Shape::Heart(s) => format!("a heart, {}", turning(s)),
            Shape::Spiral(s) => format!("a spiral, {}", turning(s)),
            Shape::Turn(s) => format!("a turn to the {}", s.name()),
        }
    }

    /// The shape's curve as formulas. Right-turning shapes are the left ones mirrored
    /// (`x → −x`).
    pub fn spec(self) -> CurveSpec {
        use std::f64::consts::{FRAC_PI_2, TAU};
        let (x, z, t1) = match self {
            Shape::Line => ("0", "t", 1.0),
            // Centre (1, 0): starts heading +Z, bending towards +X.
            Shape::Circle(_) => ("1 - cos(t)", "sin(t)", TAU),
            Shape::Arc(_) => ("1 - cos(t)", "sin(t)", FRAC_PI_2),
            Shape::Zigzag(_) => (
                "if(t < 0.5, 0, if(t < 1.5, t - 0.5, if(t < 3.5, 2.5 - t, if(t < 5.5, t - 4.5, 6.5 - t))))",
                "t",
                6.5,
            ),
            // Half circle round (1, 0) to (2, 0) heading −Z, then round (3, 0) to (4, 0)
            // heading +Z again.
            Shape::SCurve(_) => ("if(t < pi, 1 - cos(t), 3 + cos(t))", "sin(t)", TAU),
            Shape::FigureEight(_) => ("if(t < 2*pi, 1 - cos(t), cos(t) - 1)", "sin(t)", 2.0 * TAU),
            Shape::Square(_) => (
                "if(t < 1, 0, if(t < 2, t - 1, if(t < 3, 1, 4 - t)))",
                "if(t < 1, t, if(t < 2, 1, if(t < 3, 3 - t, 0)))",
                4.0,
            ),
            // x = 16 sin³θ, y = 13 cos θ − 5 cos 2θ − 2 cos 3θ − cos 4θ with θ = π/2 − t,
            // turned so the lobe's outer side runs along +Z from the origin.
            Shape::Heart(_) => (
                "16 - 16*cos(t)^3",
                "13*sin(t) + 5*cos(2*t) + 2*sin(3*t) - cos(4*t) - 4",
                TAU,
            ),
            // r = 1 + (t − sin t)/(2π): dr/dt is 0 at the start, so it starts heading +Z.
            Shape::Spiral(_) => (
                "1 - (1 + (t - sin(t))/(2*pi))*cos(t)",
                "(1 + (t - sin(t))/(2*pi))*sin(t)",
                2.0 * TAU,
            ),
            // 1 forward, a quarter circle of radius 0.3, then 1 along +X.
            Shape::Turn(_) => (
                "if(t < 1, 0, if(t < 1 + pi/2, 0.3 - 0.3*cos(t - 1), t - 0.7 - pi/2))",
                "if(t < 1, t, if(t < 1 + pi/2, 1 + 0.3*sin(t - 1), 1.3))",
                2.0 + FRAC_PI_2,
            ),
        };
        let x = match self.side() {
            Some(Side::Right) => format!("-({x})"),
            _ => x.to_string(),
        };
        CurveSpec {
            x,
            z: z.to_string(),
            t0: 0.0,
            t1,
        }
    }

    /// The compiled curve of the shape.
    pub fn curve(self) -> Curve {
        // The built-in formulas are tested to compile; a failure here is a bug in this file.
        self.spec()
            .compile()
            .expect("built-in shape formulas are valid")
    }

    /// Recognises a path shape in a prompt such as "a man walks in a circle clockwise",
    /// "walks in a zigzag", "counterclockwise circle", "figure 8", "turns left", "in a
    /// square", "spiral". Without a stated direction, shapes turn left (counter-clockwise).
    /// Returns `None` when no shape is named ("walks forward" is not a path request).
    pub fn parse(text: &str) -> Option<Shape> {
        let lower = text.to_lowercase();
        let words: Vec<&str> = lower
            .split(|c: char| !c.is_alphanumeric())
            .filter(|w| !w.is_empty())
            .collect();
        let (kind, at) = find_kind(&words)?;
        let side = find_side(&words, at);
        if kind == "turn" {
            // "turns around" or "turns his head" are not paths; a turn needs its side.
            return side.map(Shape::Turn);
        }
        Shape::with_side(kind, side.unwrap_or(Side::Left))
    }
}

impl From<Shape> for String {
    fn from(shape: Shape) -> String {
        shape.name()
    }
}

impl TryFrom<String> for Shape {
    type Error = String;

    fn try_from(name: String) -> Result<Shape, String> {
        Shape::from_name(&name).ok_or_else(|| {
            format!(
                "unknown shape '{}': expected line or one of {} with _left or _right",
                name.chars().take(40).collect::<String>(),
                SIDED_KINDS.join(", ")
            )
        })
    }
}

/// Words that make a nearby shape or side word about a body part ("circles his arms",
/// "right hand", "turns his head") rather than about the path.
const BODY: [&str; 26] = [
    "hand",
    "hands",
    "arm",
    "arms",
    "leg",
    "legs",
    "foot",
    "feet",
    "knee",
    "knees",
    "shoulder",
    "shoulders",
    "elbow",
    "elbows",
    "wrist",
    "wrists",
    "hip",
    "hips",
    "ankle",
    "ankles",
    "head",
    "neck",
    "torso",
    "waist",
    "body",
    "upper",
];

/// Verbs after which "straight" means a straight path.
const TRAVEL: [&str; 14] = [
    "walk", "walks", "walking", "walked", "run", "runs", "running", "jog", "jogs", "jogging", "go",
    "goes", "moves", "marches",
];

/// The first shape word in `words` (by priority, so "s curve" is not an arc and "turns in
/// a circle" is not a turn) and its index.
fn find_kind(words: &[&str]) -> Option<(&'static str, usize)> {
    let is = |i: usize, options: &[&str]| words.get(i).is_some_and(|w| options.contains(w));
    let about_body = |i: usize| {
        (i.saturating_sub(3)..i).any(|j| is(j, &BODY))
            || is(i + 1, &BODY)
            || (is(i + 1, &["his", "her", "their", "the", "both", "its"]) && is(i + 2, &BODY))
    };
    let at = |pred: &dyn Fn(usize) -> bool| (0..words.len()).find(|&i| pred(i) && !about_body(i));
    let rules: [(&'static str, &dyn Fn(usize) -> bool); 10] = [
        ("figure_eight", &|i| {
            is(i, &["figure8", "figureeight", "infinity", "lemniscate"])
                || (is(i, &["figure"])
                    && (is(i + 1, &["8", "eight"])
                        || (is(i + 1, &["of"]) && is(i + 2, &["8", "eight"]))))
        }),
        ("zigzag", &|i| {
            is(
                i,
                &["zigzag", "zigzags", "zigzagging", "zigzaging", "zigzagged"],
            ) || (is(i, &["zig"]) && is(i + 1, &["zag", "zags"]))
        }),
        ("s_curve", &|i| {
            is(i, &["scurve", "serpentine"])
                || (is(i, &["s"])
                    && (is(
                        i + 1,
                        &[
                            "curve", "curves", "shape", "shaped", "path", "bend", "pattern",
                        ],
                    ) || (i > 0 && is(i - 1, &["an"]))))
        }),
        ("heart", &|i| is(i, &["heart", "hearts"])),
        ("spiral", &|i| {
            is(
                i,
                &[
                    "spiral",
                    "spirals",
                    "spiraling",
                    "spiralling",
                    "spiraled",
                    "spiralled",
                ],
            )
        }),
        ("square", &|i| {
            is(i, &["square", "squares", "rectangle", "rectangular"])
        }),
        ("circle", &|i| {
            is(
                i,
                &[
                    "circle", "circles", "circular", "circling", "circled", "loop", "loops",
                ],
            )
        }),
        ("arc", &|i| {
            is(
                i,
                &[
                    "arc", "arcs", "arcing", "curve", "curves", "curving", "curved",
                ],
            )
        }),
        ("turn", &|i| {
            is(
                i,
                &[
                    "turn", "turns", "turning", "turned", "veer", "veers", "veering",
                ],
            )
        }),
        ("line", &|i| {
            (is(i, &["straight"])
                && (is(i + 1, &["line", "ahead", "forward", "forwards"])
                    || (i > 0 && is(i - 1, &TRAVEL))))
                || (is(i, &["line"]) && i >= 2 && is(i - 1, &["a"]) && is(i - 2, &["in", "along"]))
        }),
    ];
    rules
        .iter()
        .find_map(|(kind, rule)| at(*rule).map(|i| (*kind, i)))
}

/// The direction in `words`: a clockwise word anywhere, else "left"/"right" near the shape
/// word at `at` and not about a body part ("right hand").
fn find_side(words: &[&str], at: usize) -> Option<Side> {
    for (i, w) in words.iter().enumerate() {
        let prefixed = i > 0 && matches!(words[i - 1], "counter" | "anti");
        match *w {
            "counterclockwise" | "anticlockwise" | "ccw" => return Some(Side::Left),
            "clockwise" if prefixed => return Some(Side::Left),
            "clockwise" | "cw" => return Some(Side::Right),
            _ => {}
        }
    }
    let lo = at.saturating_sub(3);
    let hi = (at + 5).min(words.len().saturating_sub(1));
    (lo..=hi).find_map(|i| {
        let about_body = words.get(i + 1).is_some_and(|n| BODY.contains(n));
        match words[i] {
            "left" if !about_body => Some(Side::Left),
            "right" if !about_body => Some(Side::Right),
            _ => None,
        }
    })
}

/// Largest accepted `|t0|`, `|t1|`: parameters beyond this are surely a mistake.
pub const MAX_T: f64 = 1.0e6;

/// A curve as the planner stores it and an LLM writes it: formulas for the ground-plane
/// coordinates and the parameter range. `z` is the forward axis at the start (world +Z);
/// because models think of 2D curves as x/y, the field also accepts the name `y` when read
/// from JSON (it is still the ground plane's second axis, never height).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CurveSpec {
    /// World X (the walker's left at the start) as a formula in `t`.
    pub x: String,
    /// World Z (forward at the start) as a formula in `t`.
    #[serde(alias = "y")]
    pub z: String,
    /// First parameter value.
    pub t0: f64,
    /// Last parameter value, greater than `t0`.
    pub t1: f64,
}

/// Why a curve is not usable.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CurveError {
    /// A formula does not parse.
    #[error("the {axis} formula is invalid: {source}")]
    Expr {
        /// `"x"` or `"z"`.
        axis: &'static str,
        /// The parse error.
        source: ExprError,
    },
    /// The parameter range is empty, reversed, not finite or absurdly large.
    #[error("invalid parameter range t0 = {t0}, t1 = {t1}: need finite t0 < t1 within ±{MAX_T}")]
    Range {
        /// Start of the range.
        t0: f64,
        /// End of the range.
        t1: f64,
    },
    /// A formula is NaN or infinite at some sample.
    #[error("the {axis} formula {source}")]
    NonFinite {
        /// `"x"` or `"z"`.
        axis: &'static str,
        /// Where and what.
        source: NonFinite,
    },
}

impl CurveSpec {
    /// Parses both formulas and checks the range. Whether the curve is a usable path (finite
    /// everywhere, not a single point) is checked when it is sampled, in
    /// [`path`](super::path).
    pub fn compile(&self) -> Result<Curve, CurveError> {
        let range_ok = self.t0.is_finite()
            && self.t1.is_finite()
            && self.t0 < self.t1
            && self.t0.abs() <= MAX_T
            && self.t1.abs() <= MAX_T;
        if !range_ok {
            return Err(CurveError::Range {
                t0: self.t0,
                t1: self.t1,
            });
        }
        let x = Expr::parse(&self.x).map_err(|source| CurveError::Expr { axis: "x", source })?;
        let z = Expr::parse(&self.z).map_err(|source| CurveError::Expr { axis: "z", source })?;
        Ok(Curve {
            x,
            z,
            t0: self.t0,
            t1: self.t1,
        })
    }
}

/// A compiled ground-plane curve: `(x(t), z(t))` in arbitrary units for `t` in `t0..=t1`.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// World X formula.
    pub x: Expr,
    /// World Z formula.
    pub z: Expr,
    /// First parameter value.
    pub t0: f64,
    /// Last parameter value.
    pub t1: f64,
}

impl Curve {
    /// The point `(x, z)` at `t`.
    pub fn point(&self, t: f64) -> Result<[f64; 2], CurveError> {
        let x = self
            .x
            .eval(t)
            .map_err(|source| CurveError::NonFinite { axis: "x", source })?;
        let z = self
            .z
            .eval(t)
            .map_err(|source| CurveError::NonFinite { axis: "z", source })?;
        Ok([x, z])
    }

    /// The formulas back as a [`CurveSpec`].
    pub fn spec(&self) -> CurveSpec {
        CurveSpec {
            x: self.x.source().to_string(),
            z: self.z.source().to_string(),
            t0: self.t0,
            t1: self.t1,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shape_compiles_starts_at_the_origin_heading_forward() {
        for shape in Shape::ALL {
            let curve = shape.curve();
            let p0 = curve.point(curve.t0).unwrap();
            assert!(
                p0[0].abs() < 1e-12 && p0[1].abs() < 1e-12,
                "{shape:?} {p0:?}"
            );
            let h = 1e-6 * (curve.t1 - curve.t0);
            let p1 = curve.point(curve.t0 + h).unwrap();
            let (dx, dz) = (p1[0] - p0[0], p1[1] - p0[1]);
            assert!(
                dz > 0.0 && dx.abs() < 1e-3 * dz,
                "{shape:?} starts {dx}, {dz}"
            );
            for i in 0..=400 {
                let t = curve.t0 + (curve.t1 - curve.t0) * i as f64 / 400.0;
                assert!(curve.point(t).is_ok(), "{shape:?} at {t}");
            }
        }
    }

    #[test]
    fn sides_turn_the_way_the_walker_sees_them() {
        // A little way along, a left turn has moved towards +X, a right turn towards −X.
        for shape in Shape::ALL {
            let Some(side) = shape.side() else { continue };
            let curve = shape.curve();
            let mut first_off_axis = None;
            for i in 1..=1000 {
                let t = curve.t0 + (curve.t1 - curve.t0) * i as f64 / 1000.0;
                let x = curve.point(t).unwrap()[0];
                if x.abs() > 1e-9 {
                    first_off_axis = Some(x);
                    break;
                }
            }
            let x = first_off_axis.unwrap();
            assert_eq!(x > 0.0, side == Side::Left, "{shape:?}");
        }
    }

    #[test]
    fn closed_shapes_end_where_they_start() {
        for shape in Shape::ALL {
            if matches!(
                shape,
                Shape::Circle(_) | Shape::Square(_) | Shape::Heart(_) | Shape::FigureEight(_)
            ) {
                let curve = shape.curve();
                let end = curve.point(curve.t1).unwrap();
                assert!(
                    end[0].abs() < 1e-9 && end[1].abs() < 1e-9,
                    "{shape:?} {end:?}"
                );
            }
        }
    }

    #[test]
    fn names_round_trip_and_accept_aliases() {
        for shape in Shape::ALL {
            assert_eq!(Shape::from_name(&shape.name()), Some(shape));
            let json = serde_json::to_string(&shape).unwrap();
            assert_eq!(serde_json::from_str::<Shape>(&json).unwrap(), shape);
        }
        assert_eq!(
            Shape::from_name("circle_cw"),
            Some(Shape::Circle(Side::Right))
        );
        assert_eq!(
            Shape::from_name("Circle-Counterclockwise"),
            Some(Shape::Circle(Side::Left))
        );
        assert_eq!(Shape::from_name("spiral"), Some(Shape::Spiral(Side::Left)));
        assert_eq!(Shape::from_name("circles"), None);
        assert_eq!(Shape::from_name("octagon"), None);
        assert!(serde_json::from_str::<Shape>("\"octagon\"").is_err());
    }

    #[test]
    fn recognises_shape_phrases() {
        use Side::{Left, Right};
        let cases: &[(&str, Option<Shape>)] = &[
            (
                "a person walks in a circle clockwise",
                Some(Shape::Circle(Right)),
            ),
            ("walks clockwise in a circle", Some(Shape::Circle(Right))),
            ("a counterclockwise circle", Some(Shape::Circle(Left))),
            (
                "walks in a counter-clockwise circle",
                Some(Shape::Circle(Left)),
            ),
            ("runs anti-clockwise in circles", Some(Shape::Circle(Left))),
            ("walks in a circle", Some(Shape::Circle(Left))),
            ("jogs in a circle to the right", Some(Shape::Circle(Right))),
            ("someone walks in a zigzag", Some(Shape::Zigzag(Left))),
            ("zig-zags forward", Some(Shape::Zigzag(Left))),
            ("walks in a figure 8", Some(Shape::FigureEight(Left))),
            (
                "a figure-eight to the right",
                Some(Shape::FigureEight(Right)),
            ),
            ("figure of eight", Some(Shape::FigureEight(Left))),
            ("a man turns left", Some(Shape::Turn(Left))),
            (
                "walks forward and then turns right",
                Some(Shape::Turn(Right)),
            ),
            ("makes a right turn", Some(Shape::Turn(Right))),
            ("turns to his left", Some(Shape::Turn(Left))),
            ("walks in a square", Some(Shape::Square(Left))),
            ("walks in a square clockwise", Some(Shape::Square(Right))),
            ("walks in a spiral", Some(Shape::Spiral(Left))),
            ("spirals clockwise", Some(Shape::Spiral(Right))),
            ("walks in an S curve", Some(Shape::SCurve(Left))),
            ("walks in an s-shaped path", Some(Shape::SCurve(Left))),
            ("walks in a heart shape", Some(Shape::Heart(Left))),
            ("walks in an arc to the right", Some(Shape::Arc(Right))),
            ("curves to the left", Some(Shape::Arc(Left))),
            ("walks in a straight line", Some(Shape::Line)),
            (
                "raises his right hand while walking in a circle",
                Some(Shape::Circle(Left)),
            ),
            ("waves his right hand", None),
            ("a person circles his arms", None),
            ("moves both arms in a circle", None),
            ("turns his head to the left", None),
            ("stands up straight", None),
            ("walks straight ahead", Some(Shape::Line)),
            (
                "walks in a circle with hands on hips",
                Some(Shape::Circle(Left)),
            ),
            ("walks forward", None),
            ("turns around", None),
            ("jumps up and down", None),
            ("", None),
        ];
        for (text, want) in cases {
            assert_eq!(Shape::parse(text), *want, "{text:?}");
        }
    }

    #[test]
    fn curve_spec_validates_and_reads_y_as_z() {
        let spec: CurveSpec =
            serde_json::from_str(r#"{"x": "sin(t)", "y": "t", "t0": 0, "t1": 3}"#).unwrap();
        assert_eq!(spec.z, "t");
        let curve = spec.compile().unwrap();
        assert_eq!(curve.point(0.0).unwrap(), [0.0, 0.0]);
        assert_eq!(curve.spec(), spec);

        let bad = |x: &str, t0: f64, t1: f64| CurveSpec {
            x: x.into(),
            z: "t".into(),
            t0,
            t1,
        };
        assert!(matches!(
            bad("eval(t)", 0.0, 1.0).compile(),
            Err(CurveError::Expr { axis: "x", .. })
        ));
        for (t0, t1) in [(1.0, 1.0), (2.0, 1.0), (0.0, f64::NAN), (0.0, 1e9)] {
            assert!(matches!(
                bad("t", t0, t1).compile(),
                Err(CurveError::Range { .. })
            ));
        }
        let err = bad("log(t)", 0.0, 1.0).compile().unwrap().point(0.0);
        assert!(matches!(err, Err(CurveError::NonFinite { axis: "x", .. })));
    }
}
