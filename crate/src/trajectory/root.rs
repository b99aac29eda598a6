//! Makes a motion walk a path: rewrites the root features so that
//! [`features_to_joints`](crate::features::features_to_joints) follows the path, keeping the
//! body's own movement.
//!
//! Input and output are raw (denormalised) feature rows at 20 fps. What is rewritten:
//!
//! - column 0, the root's angular velocity: from the change of facing along the path. The
//!   features store half the per-frame yaw change with the opposite sign of
//!   [`heading`](super::path): `recover_root` adds `row[0]` to an angle `a` and faces
//!   `Quat([cos a, 0, sin a, 0])` (world to facing, a turn of `2a` about +Y), so the body's
//!   forward direction is `from_yaw(−2a)·(+Z)`. A positive `row[0]` therefore turns the body
//!   from +Z towards −X: to its right, clockwise seen from above.
//! - columns 1–2, the root's step on the ground in the facing frame of the next frame (x =
//!   the body's left, z = forward): the path's step, so the root lands exactly on the path.
//! - columns 193–259, joint velocities in the facing frame: recomputed from the new root
//!   motion and the unchanged local pose, so the rows stay self-consistent (the last row's
//!   next pose is recovered from its old velocities).
//!
//! Everything else, the local pose (root height, joint positions and rotations relative to the
//! root) and the foot contacts, is kept. The motion's own turning is replaced by the path's: a
//! walk that curved now walks the path instead.
//!
//! Speed: the path's length defaults to the distance the motion itself travels, and that
//! length is spread over the frames in proportion to the motion's own per-frame root speed, so
//! a person who stands still at first still stands still, and one who speeds up still speeds
//! up. A motion that barely moves (mean speed under [`MapOptions::min_mean_speed_m_s`]) has no
//! usable speed profile: it walks the path at constant [`MapOptions::default_speed_m_s`]
//! instead, and the [`MapReport`] says so (its feet will slide: the pose does not walk).
//!
//! Facing follows the path's tangent, smoothed over time with a Gaussian of
//! [`MapOptions::turn_smoothing_s`], so that a square's corner becomes a quick turn of the body
//! over a few frames rather than a snap in one (the root itself still follows the path exactly;
//! near a sharp corner the body briefly sidesteps).
//!
//! Lateral sway: the pelvis of a walker swings sideways over the stance foot. Dropping that
//! would make the feet slide sideways instead, so the motion's own sideways displacement is
//! kept as a small offset across the path: high-passed (minus its 1 s moving average, which
//! removes drift and sidestepping), faded in and out over the first and last half second so the
//! path's ends are met exactly, and clamped to [`MapOptions::max_sway_m`].

use crate::features::{FeatureFrame, Features, POSITIONS, VELOCITIES};
use crate::geom::{self, Quat, Vec3};
use crate::skeleton::NUM_JOINTS;
use crate::timing::FPS;

use super::path::{self, ArcPath, PathError};
use super::shapes::Curve;

/// Walking speed used for motions that barely move, m/s (a typical adult walk).
pub const DEFAULT_WALK_SPEED_M_S: f64 = 1.2;
/// Mean root speed under which a motion counts as not travelling, m/s.
pub const MIN_MEAN_SPEED_M_S: f64 = 0.25;

/// Frames either side in the moving average that separates sway from travel (1 s window).
const SWAY_HALF_WINDOW: usize = 10;

/// How a path is mapped onto a motion.
#[derive(Clone, Debug, PartialEq)]
pub struct MapOptions {
    /// Path length in metres; `None` for the distance the motion's root travels (or, for a
    /// motion that barely moves, the default speed times its duration).
    pub length_m: Option<f64>,
    /// Speed for motions that barely move, m/s.
    pub default_speed_m_s: f64,
    /// Mean root speed (m/s) under which the motion's own speed profile is not used.
    pub min_mean_speed_m_s: f64,
    /// Keep the motion's own sideways sway around the path.
    pub keep_sway: bool,
    /// Largest sideways offset from the path, metres.
    pub max_sway_m: f64,
    /// Standard deviation of the Gaussian that smooths the facing over time, seconds; 0
    /// faces exactly along the tangent.
    pub turn_smoothing_s: f64,
}

impl Default for MapOptions {
    fn default() -> Self {
        MapOptions {
            length_m: None,
            default_speed_m_s: DEFAULT_WALK_SPEED_M_S,
            min_mean_speed_m_s: MIN_MEAN_SPEED_M_S,
            keep_sway: true,
            max_sway_m: 0.05,
            turn_smoothing_s: 0.15,
        }
    }
}

/// What the mapping did, for the user and the planner.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct MapReport {
    /// Feature rows mapped.
    pub rows: usize,
    /// Duration from the first to the last displayed frame, seconds.
    pub duration_s: f64,
    /// Distance the root travelled before, metres (sum of per-frame steps).
    pub source_distance_m: f64,
    /// Mean root speed before, m/s.
    pub source_mean_speed_m_s: f64,
    /// Length of the path walked, metres.
    pub path_length_m: f64,
    /// Mean speed along the path, m/s.
    pub mean_speed_m_s: f64,
    /// Whether the motion barely moved and was given the default walking speed.
    pub used_default_speed: bool,
    /// Net change of facing, degrees; positive is counter-clockwise seen from above (to the
    /// left), so a clockwise circle gives about −360.
    pub net_turn_deg: f64,
    /// Largest sideways offset from the path that was kept, metres.
    pub max_sway_m: f64,
    /// Plain-language remarks, e.g. that the default speed was used.
    pub notes: Vec<String>,
}

/// Why a path could not be mapped.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RootError {
    /// Fewer than two rows: there is no step to place.
    #[error("a motion needs at least 2 feature rows to walk a path, got {0}")]
    TooShort(usize),
    /// A feature value is NaN or infinite.
    #[error("feature row {0} contains a non-finite value")]
    NonFinite(usize),
    /// An option is out of range.
    #[error("invalid trajectory option: {0}")]
    BadOption(String),
    /// The path could not be built or scaled.
    #[error(transparent)]
    Path(#[from] PathError),
}

/// The length a path is given on a motion, as [`map_path`] chooses it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathLength {
    /// The path's length once laid, metres.
    pub length_m: f64,
    /// Distance the motion's root travels over its displayed frames, metres.
    pub source_distance_m: f64,
    /// Duration from the first to the last displayed frame, seconds.
    pub duration_s: f64,
    /// Whether the motion barely moves, so the path is walked at
    /// [`MapOptions::default_speed_m_s`] (unless [`MapOptions::length_m`] sets the length).
    pub slow: bool,
}

/// The root's step on the ground per row, metres (the last row's leads past the end).
fn root_steps(features: &[FeatureFrame]) -> Vec<f64> {
    features
        .iter()
        .map(|r| (r[1] as f64).hypot(r[2] as f64))
        .collect()
}

/// How long a path laid on `features` (raw rows at 20 fps) by [`map_path`] with `options`
/// is: [`MapOptions::length_m`] if set, else the distance the motion travels, else (for a
/// motion that barely moves) the default speed times its duration. The page says this to
/// the user before the engine lays a drawn path. Fewer than two rows travel nothing in no
/// time.
pub fn path_length(features: &[FeatureFrame], options: &MapOptions) -> PathLength {
    // Steps between the displayed frames (features_to_joints gives one pose per row); the
    // last row's step leads past the end, to the pose `features_to_joints_with_final` adds.
    let step = root_steps(features);
    let shown = &step[..step.len().saturating_sub(1)];
    let source_distance: f64 = shown.iter().sum();
    let duration = features.len().saturating_sub(1) as f64 / FPS;
    let source_speed = if duration > 0.0 {
        source_distance / duration
    } else {
        0.0
    };
    // A motion with no travel at all has no profile to follow even if the threshold is 0.
    let slow = source_speed < options.min_mean_speed_m_s || source_distance <= 1e-9;
    let length = match options.length_m {
        Some(l) => l,
        None if slow => options.default_speed_m_s * duration,
        None => source_distance,
    };
    PathLength {
        length_m: length,
        source_distance_m: source_distance,
        duration_s: duration,
        slow,
    }
}

/// Rewrites the root of `features` so the motion walks `curve` (see the module
/// documentation).
pub fn map_curve(
    features: &[FeatureFrame],
    curve: &Curve,
    options: &MapOptions,
) -> Result<(Features, MapReport), RootError> {
    map_path(features, &ArcPath::from_curve(curve)?, options)
}

/// Rewrites the root of `features` so the motion walks `path`, whatever its units: it is
/// scaled to the length chosen by `options`.
pub fn map_path(
    features: &[FeatureFrame],
    path: &ArcPath,
    options: &MapOptions,
) -> Result<(Features, MapReport), RootError> {
    check_options(options)?;
    let rows = features.len();
    if rows < 2 {
        return Err(RootError::TooShort(rows));
    }
    if let Some(r) = features
        .iter()
        .position(|row| row.iter().any(|v| !v.is_finite()))
    {
        return Err(RootError::NonFinite(r));
    }

    let step = root_steps(features);
    let PathLength {
        length_m: length,
        source_distance_m: source_distance,
        duration_s: duration,
        slow,
    } = path_length(features, options);
    let source_speed = source_distance / duration;
    let scaled = path.scaled_to(length)?;
    let weight = |k: usize| if slow { 1.0 } else { step[k] };
    let total_weight: f64 = (0..rows - 1).map(weight).sum();

    // Arc position of every frame 0..=rows, the last one extrapolated past the end.
    let mut arc = Vec::with_capacity(rows + 1);
    let mut s = 0.0;
    arc.push(0.0);
    for k in 0..rows - 1 {
        s += length * weight(k) / total_weight;
        arc.push(s);
    }
    arc[rows - 1] = length;
    let beyond = length * weight(rows - 1) / total_weight;

    let mut centre: Vec<[f64; 2]> = arc.iter().map(|&s| scaled.point_at(s)).collect();
    let mut tangent: Vec<f64> = arc.iter().map(|&s| scaled.heading_at(s)).collect();
    let end_heading = tangent[rows - 1];
    let d = path::direction(end_heading);
    let end = centre[rows - 1];
    centre.push([end[0] + beyond * d[0], end[1] + beyond * d[1]]);
    tangent.push(end_heading);

    let sway = if options.keep_sway {
        sway_offsets(features, options.max_sway_m)
    } else {
        vec![0.0; rows + 1]
    };
    let positions: Vec<[f64; 2]> = (0..=rows)
        .map(|k| {
            let left = left_of(tangent[k]);
            [
                centre[k][0] + sway[k] * left[0],
                centre[k][1] + sway[k] * left[1],
            ]
        })
        .collect();

    let facing_target = smooth_headings(&tangent, options.turn_smoothing_s * FPS);

    let mut out: Features = features.to_vec();
    // recover_root starts facing +Z whatever the path says; the first row absorbs any
    // difference.
    let mut previous = 0.0;
    for k in 0..rows {
        out[k][0] = (-(facing_target[k + 1] - previous) / 2.0) as f32;
        previous = facing_target[k + 1];
    }
    // Facings as recover_root will integrate them from the stored f32 values, so the steps
    // below are expressed in exactly the frames that will undo them.
    let mut facing = Vec::with_capacity(rows + 1);
    let mut angle = 0.0f64;
    facing.push(0.0);
    for row in &out {
        angle += row[0] as f64;
        facing.push(-2.0 * angle);
    }
    for k in 0..rows {
        let d = [
            positions[k + 1][0] - positions[k][0],
            positions[k + 1][1] - positions[k][1],
        ];
        let local = path::rotate(d, -facing[k + 1]);
        out[k][1] = local[0] as f32;
        out[k][2] = local[1] as f32;
    }
    rewrite_joint_velocities(&mut out, features);

    let max_sway = sway.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut notes = Vec::new();
    if slow {
        notes.push(format!(
            "the motion barely moves (mean speed {source_speed:.2} m/s, under {:.2} m/s), so it \
             walks the path at {:.1} m/s; its feet will slide",
            options.min_mean_speed_m_s, options.default_speed_m_s
        ));
    }
    let report = MapReport {
        rows,
        duration_s: duration,
        source_distance_m: source_distance,
        source_mean_speed_m_s: source_speed,
        path_length_m: length,
        mean_speed_m_s: length / duration,
        used_default_speed: slow,
        net_turn_deg: facing[rows - 1].to_degrees(),
        max_sway_m: max_sway,
        notes,
    };
    Ok((out, report))
}

/// The root's ground path (x, z) of features, one point per displayed frame: the pelvis of
/// [`features_to_joints`](crate::features::features_to_joints).
pub fn root_path(features: &[FeatureFrame]) -> Vec<[f64; 2]> {
    crate::features::features_to_joints(features)
        .iter()
        .map(|pose| [pose[0][0], pose[0][2]])
        .collect()
}

fn check_options(o: &MapOptions) -> Result<(), RootError> {
    let bad = |what: &str, v: f64| Err(RootError::BadOption(format!("{what} = {v}")));
    if let Some(l) = o.length_m {
        if !(l.is_finite() && l > 0.0) {
            return bad("length_m", l);
        }
    }
    if !(o.default_speed_m_s.is_finite() && o.default_speed_m_s > 0.0) {
        return bad("default_speed_m_s", o.default_speed_m_s);
    }
    if !(o.min_mean_speed_m_s.is_finite() && o.min_mean_speed_m_s >= 0.0) {
        return bad("min_mean_speed_m_s", o.min_mean_speed_m_s);
    }
    if !(o.max_sway_m.is_finite() && o.max_sway_m >= 0.0) {
        return bad("max_sway_m", o.max_sway_m);
    }
    // Beyond a few seconds the facing would no longer follow the path at all.
    if !(o.turn_smoothing_s.is_finite() && (0.0..=5.0).contains(&o.turn_smoothing_s)) {
        return bad("turn_smoothing_s", o.turn_smoothing_s);
    }
    Ok(())
}

/// Unit vector to the left of a heading (+X when facing +Z).
fn left_of(heading: f64) -> [f64; 2] {
    let (s, c) = heading.sin_cos();
    [c, -s]
}

/// Headings smoothed by a Gaussian of `sigma` frames (edges repeated); unchanged for σ ≈ 0.
fn smooth_headings(h: &[f64], sigma: f64) -> Vec<f64> {
    if sigma < 1e-3 {
        return h.to_vec();
    }
    let as_vec: Vec<Vec3> = h.iter().map(|&v| [v, 0.0, 0.0]).collect();
    geom::gaussian_smooth(&as_vec, sigma)
        .iter()
        .map(|v| v[0])
        .collect()
}

/// The motion's own sideways displacement per frame 0..=rows, high-passed, faded at the ends
/// (zero at frame 0 and at the last displayed frame) and clamped.
fn sway_offsets(features: &[FeatureFrame], max: f64) -> Vec<f64> {
    let rows = features.len();
    let mut lateral = Vec::with_capacity(rows + 1);
    let mut acc = 0.0;
    lateral.push(0.0);
    for row in features {
        acc += row[1] as f64;
        lateral.push(acc);
    }
    let w = SWAY_HALF_WINDOW as i64;
    let last = rows as i64;
    let fade = SWAY_HALF_WINDOW as f64;
    (0..=rows)
        .map(|k| {
            let ki = k as i64;
            let mean = (-w..=w)
                .map(|j| lateral[(ki + j).clamp(0, last) as usize])
                .sum::<f64>()
                / (2 * w + 1) as f64;
            let to_end = (rows as f64 - 1.0 - k as f64).max(0.0);
            let taper = (k as f64 / fade).min(to_end / fade).min(1.0);
            ((lateral[k] - mean) * taper).clamp(-max, max)
        })
        .collect()
}

/// Recomputes the joint velocities (columns 193–259, facing frame of each row) after the root
/// motion of `rows` changed, from the unchanged local pose. With `Δ` the facing change from
/// frame t to t+1, `s` the root step in the facing frame of t+1 and `l` the root-relative
/// positions (the pelvis's being its height), a joint moves `Δ(s + l[t+1]) − l[t]` in the
/// facing frame of t. The last row has no next row; its next local pose is recovered from its
/// old velocities with the same formula.
fn rewrite_joint_velocities(rows: &mut [FeatureFrame], original: &[FeatureFrame]) {
    let n = rows.len();
    let local = |row: &FeatureFrame, j: usize| -> Vec3 {
        if j == 0 {
            [0.0, row[3] as f64, 0.0]
        } else {
            let c = POSITIONS.start + (j - 1) * 3;
            [row[c] as f64, row[c + 1] as f64, row[c + 2] as f64]
        }
    };
    let root_step = |row: &FeatureFrame| -> Vec3 { [row[1] as f64, 0.0, row[2] as f64] };
    // Facing change from frame t to t+1 as a rotation about +Y (heading sense).
    let turn = |row: &FeatureFrame| Quat::from_yaw(-2.0 * row[0] as f64);
    let velocity = |row: &FeatureFrame, j: usize| -> Vec3 {
        let c = VELOCITIES.start + j * 3;
        [row[c] as f64, row[c + 1] as f64, row[c + 2] as f64]
    };
    for t in 0..n {
        let delta = turn(&rows[t]);
        let step = root_step(&rows[t]);
        let mut new_v = [[0.0f64; 3]; NUM_JOINTS];
        for (j, v) in new_v.iter_mut().enumerate() {
            let here = local(&rows[t], j);
            let next = if t + 1 < n {
                local(&rows[t + 1], j)
            } else {
                let old = &original[t];
                let moved = geom::add(velocity(old, j), here);
                geom::sub(turn(old).inv().rotate(moved), root_step(old))
            };
            *v = geom::sub(delta.rotate(geom::add(step, next)), here);
        }
        for (j, v) in new_v.iter().enumerate() {
            let c = VELOCITIES.start + j * 3;
            rows[t][c..c + 3].copy_from_slice(&v.map(|x| x as f32));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::{features_to_joints, joints_to_features, recover_root};
    use crate::skeleton::joint;
    use crate::trajectory::shapes::{Shape, Side};
    use crate::trajectory::test_motion::{standing_then_walking, walk};

    /// The body's forward heading in a pose, from the hips and shoulders.
    fn body_heading(pose: &crate::skeleton::Pose) -> f64 {
        let across = geom::add(
            geom::sub(pose[joint::L_HIP], pose[joint::R_HIP]),
            geom::sub(pose[joint::L_SHOULDER], pose[joint::R_SHOULDER]),
        );
        // `across` points to the body's left; left × up is forward (X × Y = Z).
        let fwd = geom::cross(across, [0.0, 1.0, 0.0]);
        path::heading_of([fwd[0], fwd[2]])
    }

    #[test]
    fn positive_row0_turns_the_body_to_its_right() {
        // The sign convention this module relies on, checked on rebuilt joints.
        let mut f = walk(40, 1.0, 0.0);
        for row in &mut f {
            row[0] = 0.02;
        }
        let joints = features_to_joints(&f);
        let h0 = body_heading(&joints[0]);
        let h1 = body_heading(&joints[30]);
        assert!(h0.abs() < 1e-3);
        // 30 frames × 2 × 0.02 rad, towards −X (right, clockwise from above).
        assert!((h1 - (-1.2)).abs() < 1e-3, "{h1}");
        // And the walker drifts to −X.
        assert!(joints[30][0][0] < -0.1);
    }

    #[test]
    fn clockwise_circle_turns_right_and_follows_the_circle() {
        let f = walk(161, 1.2, 0.0);
        let (mapped, report) = map_curve(
            &f,
            &Shape::Circle(Side::Right).curve(),
            &MapOptions::default(),
        )
        .unwrap();
        assert!(!report.used_default_speed);
        assert!(
            (report.path_length_m - 1.2 * 8.0).abs() < 0.05,
            "{report:?}"
        );
        assert!((report.net_turn_deg + 360.0).abs() < 15.0, "{report:?}");
        let joints = features_to_joints(&mapped);
        // The body faces along the path: a quarter of the way it heads −X.
        let quarter = body_heading(&joints[40]);
        assert!(
            (quarter + std::f64::consts::FRAC_PI_2).abs() < 0.1,
            "{quarter}"
        );
        let r = 1.2 * 8.0 / std::f64::consts::TAU;
        for pose in &joints {
            let d = (pose[0][0] + r).hypot(pose[0][2]);
            assert!((d - r).abs() < 0.02, "{d} vs {r}");
        }
        let end = joints[joints.len() - 1][0];
        assert!(end[0].hypot(end[2]) < 0.02, "{end:?}");
    }

    #[test]
    fn the_local_pose_is_kept_and_velocities_stay_consistent() {
        let f = walk(80, 1.0, 0.3);
        let (mapped, _) = map_curve(
            &f,
            &Shape::FigureEight(Side::Left).curve(),
            &MapOptions::default(),
        )
        .unwrap();
        for (a, b) in mapped.iter().zip(&f) {
            assert_eq!(a[3..VELOCITIES.start], b[3..VELOCITIES.start]);
            assert_eq!(a[VELOCITIES.end..], b[VELOCITIES.end..]);
        }
        // Velocities equal the finite differences of the rebuilt joints, in facing frames.
        let joints = features_to_joints(&mapped);
        let (rots, _) = recover_root(&mapped);
        for t in 0..mapped.len() - 1 {
            for (j, (next, now)) in joints[t + 1].iter().zip(&joints[t]).enumerate() {
                let d = rots[t].rotate(geom::sub(*next, *now));
                let c = VELOCITIES.start + j * 3;
                for k in 0..3 {
                    assert!(
                        (d[k] - mapped[t][c + k] as f64).abs() < 1e-4,
                        "row {t} joint {j}"
                    );
                }
            }
        }
    }

    #[test]
    fn velocity_rewrite_reproduces_velocities_of_real_features() {
        // On features computed from joints, recomputing velocities with the unchanged root
        // must give back what joints_to_features stored.
        let poses = crate::trajectory::test_motion::walking_poses(60, 0.05, 0.02);
        let target = crate::skeleton::Offsets::from_pose(&poses[0]);
        let (f, _) = joints_to_features(&poses, &target).unwrap();
        let mut again = f.clone();
        rewrite_joint_velocities(&mut again, &f);
        for (a, b) in again.iter().zip(&f) {
            for c in VELOCITIES {
                assert!(
                    (a[c] - b[c]).abs() < 1e-4,
                    "column {c}: {} vs {}",
                    a[c],
                    b[c]
                );
            }
        }
    }

    #[test]
    fn a_straight_line_leaves_a_straight_walk_alone() {
        let poses = crate::trajectory::test_motion::walking_poses(60, 0.06, 0.0);
        let target = crate::skeleton::Offsets::from_pose(&poses[0]);
        let (f, _) = joints_to_features(&poses, &target).unwrap();
        let (mapped, report) = map_curve(&f, &Shape::Line.curve(), &MapOptions::default()).unwrap();
        assert!(report.net_turn_deg.abs() < 1e-3);
        let before = features_to_joints(&f);
        let after = features_to_joints(&mapped);
        assert!(crate::skeleton::max_joint_distance(&before, &after) < 0.01);
    }

    #[test]
    fn standing_still_at_first_still_stands_still() {
        let f = standing_then_walking(20, 60, 1.2);
        let (mapped, report) = map_curve(
            &f,
            &Shape::Circle(Side::Left).curve(),
            &MapOptions::default(),
        )
        .unwrap();
        assert!(!report.used_default_speed);
        let path = root_path(&mapped);
        for p in &path[..20] {
            assert!(p[0].hypot(p[1]) < 1e-6, "{p:?}");
        }
        assert!(path[30][0].hypot(path[30][1]) > 0.3);
        // Turning left: the walker moves towards +X.
        assert!(path[30][0] > 0.0);
    }

    #[test]
    fn a_motion_that_barely_moves_gets_the_default_speed() {
        let f = walk(101, 0.05, 0.0);
        let (mapped, report) = map_curve(&f, &Shape::Line.curve(), &MapOptions::default()).unwrap();
        assert!(report.used_default_speed);
        assert!(!report.notes.is_empty() && report.notes[0].contains("barely moves"));
        assert!((report.path_length_m - 1.2 * 5.0).abs() < 1e-9);
        let path = root_path(&mapped);
        let end = path[path.len() - 1];
        assert!(
            (end[1] - 6.0).abs() < 1e-3 && end[0].abs() < 1e-3,
            "{end:?}"
        );
        // Constant speed.
        for w in path.windows(2) {
            assert!(((w[1][1] - w[0][1]) - 0.06).abs() < 1e-4);
        }
    }

    #[test]
    fn explicit_length_and_bad_input() {
        let f = walk(41, 1.0, 0.0);
        let options = MapOptions {
            length_m: Some(3.0),
            ..MapOptions::default()
        };
        let (mapped, report) = map_curve(&f, &Shape::Line.curve(), &options).unwrap();
        assert_eq!(report.path_length_m, 3.0);
        let end = root_path(&mapped)[40];
        assert!((end[1] - 3.0).abs() < 1e-3);

        let line = Shape::Line.curve();
        let still = walk(41, 0.0, 0.0);
        let no_threshold = MapOptions {
            min_mean_speed_m_s: 0.0,
            ..MapOptions::default()
        };
        let (mapped, report) = map_curve(&still, &line, &no_threshold).unwrap();
        assert!(report.used_default_speed);
        assert!(mapped.iter().flatten().all(|v| v.is_finite()));
        assert_eq!(
            map_curve(&f[..1], &line, &MapOptions::default()),
            Err(RootError::TooShort(1))
        );
        let mut nan = f.clone();
        nan[7][100] = f32::NAN;
        assert_eq!(
            map_curve(&nan, &line, &MapOptions::default()),
            Err(RootError::NonFinite(7))
        );
        for bad in [
            MapOptions {
                length_m: Some(-1.0),
                ..MapOptions::default()
            },
            MapOptions {
                default_speed_m_s: 0.0,
                ..MapOptions::default()
            },
            MapOptions {
                turn_smoothing_s: f64::NAN,
                ..MapOptions::default()
            },
        ] {
            assert!(matches!(
                map_curve(&f, &line, &bad),
                Err(RootError::BadOption(_))
            ));
        }
    }

    #[test]
    fn sway_is_kept_small_and_ends_are_exact() {
        // A walk whose pelvis swings ±3 cm sideways every second.
        let mut f = walk(121, 1.2, 0.0);
        for (t, row) in f.iter_mut().enumerate() {
            let phase = std::f64::consts::TAU * t as f64 / 20.0;
            row[1] = (0.03 * (phase + 0.314).sin() - 0.03 * phase.sin()) as f32;
        }
        let (mapped, report) = map_curve(
            &f,
            &Shape::Square(Side::Right).curve(),
            &MapOptions::default(),
        )
        .unwrap();
        assert!(
            report.max_sway_m > 0.01 && report.max_sway_m <= 0.05,
            "{report:?}"
        );
        let path = root_path(&mapped);
        let end = path[path.len() - 1];
        assert!(end[0].hypot(end[1]) < 1e-3, "{end:?}");
        let no_sway = MapOptions {
            keep_sway: false,
            ..MapOptions::default()
        };
        let (_, report) = map_curve(&f, &Shape::Square(Side::Right).curve(), &no_sway).unwrap();
        assert_eq!(report.max_sway_m, 0.0);
    }
}

/// Helpers for building synthetic feature rows in tests.
#[cfg(test)]
pub(crate) mod tests_support {
    use super::*;

    /// Fills in the joint velocities of hand-written rows from their root motion and local
    /// pose; the last row assumes the pose holds still after it.
    pub fn refresh_velocities(rows: &mut [FeatureFrame]) {
        let Some(&last) = rows.last() else { return };
        let mut extended = rows.to_vec();
        extended.push(last);
        let original = extended.clone();
        rewrite_joint_velocities(&mut extended, &original);
        let n = rows.len();
        rows.copy_from_slice(&extended[..n]);
    }
}
