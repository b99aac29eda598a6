//! Root trajectories from text: make a motion walk a path such as "in a circle clockwise".
//!
//! The pipeline (design §5): a path is a curve `x(t)`, `z(t)` on the ground plane, either a
//! built-in [`Shape`] recognised in the prompt or formulas written by the LLM, both evaluated
//! by the sandboxed [`expr`] language, or points drawn with the pointer on the page's ground
//! plane ([`drawn`]). [`path`] samples a curve, fits a B-spline, reparametrises it
//! by arc length and scales it to the motion's own travelled distance; [`root`] rewrites the
//! root features (angular and linear velocity) so that the rebuilt joints walk it, keeping the
//! local pose; [`check`] measures the result, and
//! [`render::plot::ground_path`](crate::render::plot::ground_path) draws it.
//!
//! Conventions: 20 fps, Y up, metres; a motion starts at the origin facing +Z, its left is +X.
//! "Clockwise" is seen from above (looking down −Y): turning to the walker's right, from +Z
//! towards −X.

pub mod check;
pub mod drawn;
pub mod expr;
pub mod path;
pub mod root;
pub mod shapes;

use serde::{Deserialize, Serialize};

use crate::features::{FeatureFrame, Features};

pub use check::{circle_report, CircleReport};
pub use drawn::{check_drawn, DrawnError, MAX_DRAWN_COORD_M, MAX_DRAWN_POINTS, MIN_DRAWN_LENGTH_M};
pub use path::{ArcPath, Path, PathError};
pub use root::{
    map_curve, map_path, path_length, root_path, MapOptions, MapReport, PathLength, RootError,
};
pub use shapes::{Curve, CurveError, CurveSpec, Shape, Side};

/// A path request as a plan stores it: a named built-in shape, a curve the LLM wrote, or
/// points the user drew. Serialised with a `type` tag:
/// `{"type": "shape", "shape": "circle_right"}`,
/// `{"type": "curve", "x": "sin(t)", "z": "t", "t0": 0, "t1": 6.28}` (`y` is accepted for
/// `z`; both are ground-plane axes) or `{"type": "points", "points": [[0, 0], [0.5, 1.2]]}`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Trajectory {
    /// A shape from the built-in library.
    Shape {
        /// Which shape, by its stable name.
        shape: Shape,
    },
    /// Formulas in `t` (arbitrary units; rescaled to the motion).
    Curve(CurveSpec),
    /// A path drawn with the pointer: `[x, z]` ground-plane points in metres in drawing
    /// order (Y up; the motion starts at the origin facing +Z, +X is the walker's left), 2 to
    /// [`MAX_DRAWN_POINTS`] of them, each coordinate within ±[`MAX_DRAWN_COORD_M`] m, at
    /// least [`MIN_DRAWN_LENGTH_M`] long (see [`drawn`]). Like every path it is walked from
    /// where its segment starts, turned to the heading the walker has there, and scaled to
    /// the distance the motion travels (see [`root`]): what is kept is its shape.
    Points {
        /// The drawn points, metres.
        points: Vec<[f64; 2]>,
    },
}

/// Why a trajectory request cannot be used.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TrajectoryError {
    /// The formulas or range are invalid.
    #[error(transparent)]
    Curve(#[from] CurveError),
    /// The curve is not a walkable path (not finite, or a single point).
    #[error(transparent)]
    Path(#[from] PathError),
    /// The path could not be mapped onto the motion.
    #[error(transparent)]
    Root(#[from] RootError),
    /// Drawn points that are not a path (too few, too many, too short, out of range).
    #[error(transparent)]
    Drawn(#[from] DrawnError),
    /// [`Trajectory::curve`] of a drawn path, which has points, not formulas.
    #[error("a drawn path is points, not a curve")]
    NotACurve,
}

impl Trajectory {
    /// The built-in shape named in a prompt, if any (see [`Shape::parse`]).
    pub fn from_text(text: &str) -> Option<Trajectory> {
        Shape::parse(text).map(|shape| Trajectory::Shape { shape })
    }

    /// The compiled curve of a shape or formulas, without checking that it is walkable; a
    /// drawn path has none ([`TrajectoryError::NotACurve`]).
    pub fn curve(&self) -> Result<Curve, TrajectoryError> {
        match self {
            Trajectory::Shape { shape } => Ok(shape.curve()),
            Trajectory::Curve(spec) => Ok(spec.compile()?),
            Trajectory::Points { .. } => Err(TrajectoryError::NotACurve),
        }
    }

    /// Checks everything that can be checked without a motion: the formulas parse within the
    /// sandbox's limits, the range is sane, every sample is finite and within range, and the
    /// path has a length; drawn points pass [`check_drawn`]. Returns the walkable path (in
    /// the curve's own units; metres for drawn points).
    pub fn validate(&self) -> Result<ArcPath, TrajectoryError> {
        match self {
            Trajectory::Points { points } => {
                check_drawn(points)?;
                Ok(ArcPath::from_points(points)?)
            }
            _ => Ok(ArcPath::from_curve(&self.curve()?)?),
        }
    }

    /// A short description for messages, e.g. "a circle, clockwise", "the curve x = …" or
    /// "a drawn path (4.2 m, 40 points)".
    pub fn describe(&self) -> String {
        match self {
            Trajectory::Shape { shape } => shape.describe(),
            Trajectory::Curve(c) => format!(
                "the curve x = {}, z = {} for t from {} to {}",
                c.x, c.z, c.t0, c.t1
            ),
            Trajectory::Points { points } => format!(
                "a drawn path ({:.1} m, {} points)",
                drawn::polyline_length(points),
                points.len()
            ),
        }
    }
}

/// Offline path from a prompt: the curve of the built-in shape it names ("walks in a zigzag",
/// "figure 8", "turns left"), or `None` if it names none.
pub fn path_for_text(text: &str) -> Option<Curve> {
    Shape::parse(text).map(Shape::curve)
}

/// Makes `features` (raw, denormalised rows at 20 fps) walk `trajectory`; see [`root`].
pub fn apply(
    features: &[FeatureFrame],
    trajectory: &Trajectory,
    options: &MapOptions,
) -> Result<(Features, MapReport), TrajectoryError> {
    let path = trajectory.validate()?;
    Ok(map_path(features, &path, options)?)
}

/// Synthetic motions shared by the tests of the submodules.
#[cfg(test)]
pub(crate) mod test_motion {
    use crate::features::{Features, FEATURE_DIM, POSITIONS};
    use crate::geom::{self, Quat, Vec3};
    use crate::skeleton::{self, joint, Offsets, Pose, Rotations, NUM_JOINTS};
    use crate::timing::FPS;

    /// A walk-like motion as joints: the root moves `step_m` per frame along its facing,
    /// which turns `yaw_per_frame` radians per frame (positive to the left), while legs and
    /// arms swing. Bones are 0.15 m along the rest directions, except that the shoulders are
    /// wider than the hips as in people: HumanML3D's facing subtracts the hip line from the
    /// shoulder line, so equal widths would leave no facing at all.
    pub fn walking_poses(frames: usize, step_m: f64, yaw_per_frame: f64) -> Vec<Pose> {
        let mut offsets = Offsets(skeleton::RAW_OFFSETS.map(|d| geom::scale(d, 0.15)));
        for (j, len) in [
            (joint::L_HIP, 0.1),
            (joint::R_HIP, 0.1),
            (joint::L_COLLAR, 0.2),
            (joint::R_COLLAR, 0.2),
        ] {
            offsets.0[j] = geom::scale(skeleton::RAW_OFFSETS[j], len);
        }
        let mut root: Vec<Vec3> = Vec::with_capacity(frames);
        let mut p = [0.0, 0.9, 0.0];
        let rots: Vec<Rotations> = (0..frames)
            .map(|t| {
                let yaw = yaw_per_frame * t as f64;
                root.push(p);
                let (s, c) = yaw.sin_cos();
                p = [p[0] + step_m * s, p[1], p[2] + step_m * c];
                let swing = (t as f64 * 0.3).sin();
                let mut r = [Quat::IDENTITY; NUM_JOINTS];
                r[0] = Quat::from_yaw(yaw);
                r[joint::L_ELBOW] = Quat::from_axis_angle([1.0, 0.0, 0.0], 0.6 * swing);
                r[joint::R_ELBOW] = Quat::from_axis_angle([1.0, 0.0, 0.0], -0.6 * swing);
                r[joint::L_HIP] = Quat::from_axis_angle([1.0, 0.0, 0.0], -0.4 * swing);
                r[joint::R_HIP] = Quat::from_axis_angle([1.0, 0.0, 0.0], 0.4 * swing);
                r
            })
            .collect();
        skeleton::forward_kinematics(&rots, &offsets, &root)
    }

    /// Feature rows written directly: a fixed standing pose moving forward at `speed_m_s`
    /// and turning `turn_rad_s` (positive to the left), `rows` rows.
    pub fn walk(rows: usize, speed_m_s: f64, turn_rad_s: f64) -> Features {
        let pose = walking_poses(1, 0.0, 0.0)[0];
        let mut row = [0f32; FEATURE_DIM];
        row[3] = pose[0][1] as f32;
        for (j, p) in pose.iter().enumerate().skip(1) {
            let c = POSITIONS.start + (j - 1) * 3;
            row[c..c + 3].copy_from_slice(&p.map(|v| v as f32));
        }
        // Heading turns by +turn/FPS per frame; column 0 holds minus half of that.
        row[0] = (-turn_rad_s / FPS / 2.0) as f32;
        row[2] = (speed_m_s / FPS) as f32;
        let mut rows_out = vec![row; rows];
        crate::trajectory::root::tests_support::refresh_velocities(&mut rows_out);
        rows_out
    }

    /// `still` rows standing, then `walking` rows walking at `speed_m_s`.
    pub fn standing_then_walking(still: usize, walking: usize, speed_m_s: f64) -> Features {
        let mut f = walk(still + walking, speed_m_s, 0.0);
        for row in &mut f[..still] {
            row[2] = 0.0;
        }
        crate::trajectory::root::tests_support::refresh_velocities(&mut f);
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn path_for_text_finds_offline_shapes() {
        let curve = path_for_text("a person walks in a circle clockwise").unwrap();
        assert_eq!(curve.spec(), Shape::Circle(Side::Right).spec());
        assert!(path_for_text("a person waves").is_none());
        assert_eq!(
            Trajectory::from_text("walks in a figure 8"),
            Some(Trajectory::Shape {
                shape: Shape::FigureEight(Side::Left)
            })
        );
    }

    #[test]
    fn trajectories_serialise_with_a_type_tag() {
        let t = Trajectory::Shape {
            shape: Shape::Circle(Side::Right),
        };
        let json = serde_json::to_string(&t).unwrap();
        assert_eq!(json, r#"{"type":"shape","shape":"circle_right"}"#);
        assert_eq!(serde_json::from_str::<Trajectory>(&json).unwrap(), t);

        let llm = r#"{"type": "curve", "x": "2*sin(t)", "y": "t", "t0": 0, "t1": 6.28}"#;
        let t: Trajectory = serde_json::from_str(llm).unwrap();
        assert!(t.validate().is_ok());
        let back: Trajectory = serde_json::from_str(&serde_json::to_string(&t).unwrap()).unwrap();
        assert_eq!(back, t);
        assert!(serde_json::from_str::<Trajectory>(r#"{"type":"shape","shape":"blob"}"#).is_err());
    }

    #[test]
    fn validate_rejects_unusable_curves() {
        let curve = |x: &str, z: &str| {
            Trajectory::Curve(CurveSpec {
                x: x.into(),
                z: z.into(),
                t0: 0.0,
                t1: 1.0,
            })
        };
        assert!(matches!(
            curve("import(os)", "t").validate(),
            Err(TrajectoryError::Curve(CurveError::Expr { .. }))
        ));
        assert!(matches!(
            curve("0", "0").validate(),
            Err(TrajectoryError::Path(PathError::ZeroLength))
        ));
        assert!(matches!(
            curve("log(t - 0.5)", "t").validate(),
            Err(TrajectoryError::Path(PathError::Curve(
                CurveError::NonFinite { .. }
            )))
        ));
        assert!(matches!(
            curve("exp(50*t)", "t").validate(),
            Err(TrajectoryError::Path(PathError::TooLarge { .. }))
        ));
        for shape in Shape::ALL {
            assert!(Trajectory::Shape { shape }.validate().is_ok(), "{shape:?}");
        }
    }

    #[test]
    fn drawn_paths_serialise_and_are_checked_as_data() {
        let t = Trajectory::Points {
            points: vec![[0.0, 0.0], [0.0, 1.5], [1.25, 1.5]],
        };
        let json = serde_json::to_string(&t).unwrap();
        assert_eq!(
            json,
            r#"{"type":"points","points":[[0.0,0.0],[0.0,1.5],[1.25,1.5]]}"#
        );
        assert_eq!(serde_json::from_str::<Trajectory>(&json).unwrap(), t);
        assert_eq!(t.describe(), "a drawn path (2.8 m, 3 points)");
        // Three points are three spline control points: the corner is cut, never lengthened.
        let length = t.validate().unwrap().length();
        assert!((1.95..=2.75).contains(&length), "{length}");
        assert_eq!(t.curve(), Err(TrajectoryError::NotACurve));

        let points = |points: Vec<[f64; 2]>| Trajectory::Points { points };
        let err = |t: Trajectory| t.validate().unwrap_err();
        assert_eq!(
            err(points(vec![[0.0, 0.0]])),
            TrajectoryError::Drawn(DrawnError::TooFewPoints(1))
        );
        assert_eq!(
            err(points(vec![[0.0, 0.0]; MAX_DRAWN_POINTS + 1])),
            TrajectoryError::Drawn(DrawnError::TooManyPoints(MAX_DRAWN_POINTS + 1))
        );
        assert_eq!(
            err(points(vec![[0.0, 0.0], [0.0, 1.0], [1e9, 1.0]])),
            TrajectoryError::Drawn(DrawnError::OutOfRange {
                index: 2,
                value: 1e9
            })
        );
        let short = err(points(vec![[0.0, 0.0], [0.1, 0.1]]));
        assert!(matches!(
            short,
            TrajectoryError::Drawn(DrawnError::TooShort { .. })
        ));
        assert!(short.to_string().contains("too short"), "{short}");
        // A doctored link's JSON: NaN does not parse as a number, so it is refused there.
        assert!(
            serde_json::from_str::<Trajectory>(r#"{"type":"points","points":[[0,0],[1]]}"#)
                .is_err()
        );
    }

    #[test]
    fn a_drawn_line_and_an_l_shape_are_walked() {
        // Drawn anywhere, in any direction: the walk starts where it is, heading along the
        // first stroke, and walks the stroke's shape scaled to its own distance.
        let f = test_motion::walk(81, 1.2, 0.0);
        let line = Trajectory::Points {
            points: (0..20).map(|i| [2.0 + 0.1 * i as f64, -1.0]).collect(),
        };
        let (mapped, report) = apply(&f, &line, &MapOptions::default()).unwrap();
        let root = root_path(&mapped);
        assert!((report.path_length_m - 4.8).abs() < 0.05, "{report:?}");
        assert!(report.net_turn_deg.abs() < 2.0, "{report:?}");
        for p in &root {
            assert!(p[0].abs() < 0.06, "{p:?}");
        }
        assert!((root[80][1] - 4.8).abs() < 0.1, "{:?}", root[80]);

        // An L: 2 m forward, then 2 m to the walker's right (−X), drawn from the origin.
        let mut points: Vec<[f64; 2]> = (0..=20).map(|i| [0.0, 0.1 * i as f64]).collect();
        points.extend((1..=20).map(|i| [-0.1 * i as f64, 2.0]));
        let l_shape = Trajectory::Points { points };
        let (mapped, report) = apply(&f, &l_shape, &MapOptions::default()).unwrap();
        let root = root_path(&mapped);
        // 4.8 m walked over 4 m drawn: every distance grows by 1.2.
        let corner = root[40];
        assert!(
            corner[0].abs() < 0.25 && (corner[1] - 2.4).abs() < 0.25,
            "{corner:?}"
        );
        let end = root[80];
        assert!(
            (end[0] + 2.4).abs() < 0.15 && (end[1] - 2.4).abs() < 0.15,
            "{end:?}"
        );
        assert!((report.net_turn_deg + 90.0).abs() < 10.0, "{report:?}");
    }

    #[test]
    fn apply_maps_a_trajectory_onto_features() {
        let f = test_motion::walk(81, 1.2, 0.0);
        let t = Trajectory::from_text("turns right").unwrap();
        let (mapped, report) = apply(&f, &t, &MapOptions::default()).unwrap();
        assert_eq!(mapped.len(), f.len());
        assert!((report.net_turn_deg + 90.0).abs() < 10.0, "{report:?}");
        let end = root_path(&mapped)[80];
        // Turned right: ends on the −X side.
        assert!(end[0] < -1.0, "{end:?}");
        assert!(t.describe().contains("right"));
    }
}
