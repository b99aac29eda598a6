//! How physically plausible a motion built from key poses is, by the figures issue 17 holds it
//! to: foot skating no worse than the real test motions', no joint more than
//! [`MAX_BELOW_FLOOR_M`] under the floor, and no frame-to-frame joint speed above the real
//! data's 99th percentile except in flight (see `coma posture motions`).
//!
//! The floor is y = 0, where the go stage and the dataset put it. A frame is *in flight* when
//! no joint is within [`FLIGHT_CLEARANCE_M`] of the floor; speeds are not held against the bar
//! in flight nor between the frames next to it (take-off and landing), where a body legitimately
//! moves as fast as a ballistic jump makes it.
//!
//! Foot skating, frame speeds and quantiles are the evaluation's own (`coma eval` reports the
//! real test motions' skating with [`foot_skating`]); they live here, below the evaluation,
//! and `eval::probes` uses them from here.

use crate::geom;
use crate::skeleton::{joint, Pose, JOINT_NAMES};
use crate::timing::FPS;
use serde::Serialize;

/// Per frame, the root speed and the fastest joint speed (m/s).
pub fn frame_speeds(poses: &[Pose]) -> Vec<(f64, f64)> {
    poses
        .windows(2)
        .map(|w| {
            let root = geom::dist(w[1][0], w[0][0]) * FPS;
            let joint = w[1]
                .iter()
                .zip(&w[0])
                .map(|(a, b)| geom::dist(*a, *b) * FPS)
                .fold(0.0, f64::max);
            (root, joint)
        })
        .collect()
}

/// Height above a motion's lowest foot position under which a foot counts as on the
/// ground, metres.
pub const CONTACT_HEIGHT: f64 = 0.05;
/// Horizontal foot speed above which a grounded foot is skating, m/s (2.5 cm a frame).
pub const SKATE_SPEED: f64 = 0.5;

/// Foot skating: the fraction of frame pairs in which a foot (ankle or toe joint) stays within
/// [`CONTACT_HEIGHT`] of the floor in both frames yet moves horizontally faster than
/// [`SKATE_SPEED`]. The floor is the motion's lowest foot position.
pub fn foot_skating(poses: &[Pose]) -> f64 {
    let feet = [joint::L_ANKLE, joint::R_ANKLE, joint::L_FOOT, joint::R_FOOT];
    let floor = poses
        .iter()
        .flat_map(|p| feet.iter().map(move |&f| p[f][1]))
        .fold(f64::INFINITY, f64::min);
    let mut skating = 0usize;
    for w in poses.windows(2) {
        let slides = feet.iter().any(|&f| {
            let grounded =
                w[0][f][1] - floor < CONTACT_HEIGHT && w[1][f][1] - floor < CONTACT_HEIGHT;
            let dx = w[1][f][0] - w[0][f][0];
            let dz = w[1][f][2] - w[0][f][2];
            grounded && (dx * dx + dz * dz).sqrt() * FPS > SKATE_SPEED
        });
        skating += slides as usize;
    }
    skating as f64 / poses.len().saturating_sub(1).max(1) as f64
}

/// The `q`-quantile (0–1) of values.
pub fn quantile(mut values: Vec<f64>, q: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    values.sort_by(f64::total_cmp);
    values[((values.len() - 1) as f64 * q).round() as usize]
}

/// A frame whose lowest joint is higher than this above the floor (metres) is in flight.
pub const FLIGHT_CLEARANCE_M: f64 = 0.05;
/// Deepest a joint may go under the floor (metres).
pub const MAX_BELOW_FLOOR_M: f64 = 0.02;

/// The lowest height any joint reaches over the motion (metres; negative is under the floor);
/// infinite for an empty motion.
pub fn lowest_joint(poses: &[Pose]) -> f64 {
    poses
        .iter()
        .flat_map(|p| p.iter().map(|j| j[1]))
        .fold(f64::INFINITY, f64::min)
}

/// Per frame, whether the body is in flight: no joint within [`FLIGHT_CLEARANCE_M`] of the
/// floor.
pub fn in_flight(poses: &[Pose]) -> Vec<bool> {
    poses
        .iter()
        .map(|p| p.iter().all(|j| j[1] > FLIGHT_CLEARANCE_M))
        .collect()
}

/// Longest airborne stretch (frames at 20 fps) that is a jump rather than a body floating:
/// 0.8 s in the air is a rise of the centre of mass of about 0.8 m, beyond any standing jump.
pub const MAX_FLIGHT_FRAMES: usize = 16;

/// Share of frames in which the body floats: no joint within [`FLIGHT_CLEARANCE_M`] of the
/// floor (y = 0) in a stretch longer than [`MAX_FLIGHT_FRAMES`], so not the flight of a jump.
pub fn floating_share(poses: &[Pose]) -> f64 {
    let airborne = in_flight(poses);
    let (mut floating, mut run) = (0, 0);
    for (t, &up) in airborne.iter().enumerate() {
        run = if up { run + 1 } else { 0 };
        // The last frame of an airborne stretch decides what the stretch was.
        if up && airborne.get(t + 1) != Some(&true) && run > MAX_FLIGHT_FRAMES {
            floating += run;
        }
    }
    floating as f64 / poses.len().max(1) as f64
}

/// How deep the lowest joint goes under the floor (y = 0) over the motion, metres; 0 when no
/// joint goes under it.
pub fn floor_penetration(poses: &[Pose]) -> f64 {
    (-lowest_joint(poses)).max(0.0)
}

/// Per frame pair `(i, i + 1)`, whether its speeds count against the bar: neither frame is in
/// flight or next to a frame in flight.
pub fn counted_pairs(poses: &[Pose]) -> Vec<bool> {
    let flight = in_flight(poses);
    let near = |f: usize| {
        flight[f.saturating_sub(1)..(f + 2).min(flight.len())]
            .iter()
            .any(|&b| b)
    };
    (0..poses.len().saturating_sub(1))
        .map(|i| !near(i) && !near(i + 1))
        .collect()
}

/// The speed of every joint between every two frames (m/s at 20 fps): the samples of the
/// per-joint 99th percentile.
pub fn joint_speeds(poses: &[Pose]) -> Vec<f64> {
    poses
        .windows(2)
        .flat_map(|w| {
            w[1].iter()
                .zip(&w[0])
                .map(|(a, b)| geom::dist(*a, *b) * FPS)
        })
        .collect()
}

/// The fastest joint between two frames: speed (m/s), the pair's first frame, the joint.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Fastest {
    pub speed: f64,
    pub frame: usize,
    pub joint: usize,
}

impl Fastest {
    /// The joint's name.
    pub fn joint_name(&self) -> &'static str {
        JOINT_NAMES[self.joint]
    }
}

/// The fastest frame-to-frame joint speed among the pairs that `counted` (from
/// [`counted_pairs`]) lets count; `None` when none does.
pub fn fastest_outside_flight(poses: &[Pose], counted: &[bool]) -> Option<Fastest> {
    let mut best: Option<Fastest> = None;
    for (i, w) in poses.windows(2).enumerate() {
        if !counted.get(i).copied().unwrap_or(false) {
            continue;
        }
        for (j, (a, b)) in w[1].iter().zip(&w[0]).enumerate() {
            let speed = geom::dist(*a, *b) * FPS;
            if best.is_none_or(|f| speed > f.speed) {
                best = Some(Fastest {
                    speed,
                    frame: i,
                    joint: j,
                });
            }
        }
    }
    best
}

/// The figures of one motion.
#[derive(Clone, Debug, Serialize)]
pub struct Measure {
    pub frames: usize,
    /// [`foot_skating`]: share of frame pairs with a grounded foot sliding.
    pub skating: f64,
    /// [`lowest_joint`], metres.
    pub lowest_m: f64,
    /// Frames in flight.
    pub flight_frames: usize,
    /// The fastest joint outside flight (and the frames next to it).
    pub fastest: Option<Fastest>,
    /// Frame pairs outside flight whose fastest joint is faster than the bar the measure was
    /// given.
    pub pairs_over: usize,
}

impl Measure {
    /// Whether the motion meets issue 17's line: skating at most `max_skating`, no joint more
    /// than [`MAX_BELOW_FLOOR_M`] under the floor, nothing faster than the bar outside flight.
    pub fn passes(&self, max_skating: f64) -> bool {
        self.skating <= max_skating && self.lowest_m >= -MAX_BELOW_FLOOR_M && self.pairs_over == 0
    }
}

/// Measures a motion (world joints, metres, 20 fps) against a joint-speed bar (m/s).
pub fn measure(poses: &[Pose], speed_bar: f64) -> Measure {
    let counted = counted_pairs(poses);
    let pairs_over = frame_speeds(poses)
        .iter()
        .zip(&counted)
        .filter(|((_, fastest), &c)| c && *fastest > speed_bar)
        .count();
    Measure {
        frames: poses.len(),
        skating: foot_skating(poses),
        lowest_m: lowest_joint(poses),
        flight_frames: in_flight(poses).iter().filter(|&&f| f).count(),
        fastest: fastest_outside_flight(poses, &counted),
        pairs_over,
    }
}

/// The real motions' figures the key-posture motions are held to.
#[derive(Clone, Debug, Serialize)]
pub struct RealReference {
    pub motions: usize,
    pub frames: usize,
    /// Mean over the motions of [`foot_skating`] (as `coma eval` averages it).
    pub skating: f64,
    /// Share (0–1) of the real motions whose own skating is above that mean: the bar for
    /// comparing motion by motion rather than on average.
    pub skating_share_above: f64,
    /// 99th percentile over all frame pairs of the fastest joint's speed (m/s): the bar
    /// `coma eval`'s continuity probe uses.
    pub p99_fastest: f64,
    /// The same over the pairs outside flight only (see [`counted_pairs`]).
    pub p99_fastest_outside_flight: f64,
    /// 99th percentile of every joint's speed over all frame pairs (m/s): a stricter bar.
    pub p99_joint: f64,
    /// Lowest joint over all motions, metres.
    pub lowest_m: f64,
}

/// The reference figures of real motions (world joints, 20 fps).
pub fn real_reference(motions: &[Vec<Pose>]) -> RealReference {
    let mut fastest = Vec::new();
    let mut outside = Vec::new();
    let mut joints = Vec::new();
    let mut per_motion = Vec::with_capacity(motions.len());
    for m in motions {
        let counted = counted_pairs(m);
        for ((_, f), c) in frame_speeds(m).into_iter().zip(counted) {
            fastest.push(f);
            if c {
                outside.push(f);
            }
        }
        joints.extend(joint_speeds(m));
        per_motion.push(foot_skating(m));
    }
    let skating = per_motion.iter().sum::<f64>() / motions.len().max(1) as f64;
    RealReference {
        motions: motions.len(),
        frames: motions.iter().map(Vec::len).sum(),
        skating,
        skating_share_above: per_motion.iter().filter(|&&s| s > skating).count() as f64
            / motions.len().max(1) as f64,
        p99_fastest: quantile(fastest, 0.99),
        p99_fastest_outside_flight: quantile(outside, 0.99),
        p99_joint: quantile(joints, 0.99),
        lowest_m: motions
            .iter()
            .map(|m| lowest_joint(m))
            .fold(f64::INFINITY, f64::min),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A body whose every joint is `height` above the floor, `x` to the side.
    fn pose(height: f64, x: f64) -> Pose {
        std::array::from_fn(|j| [x, height + 0.1 * j as f64, 0.0])
    }

    #[test]
    fn the_lowest_joint_is_the_minimum_height() {
        let mut a = pose(0.0, 0.0);
        a[7][1] = -0.015;
        assert!((lowest_joint(&[pose(0.2, 0.0), a]) + 0.015).abs() < 1e-12);
        assert_eq!(lowest_joint(&[]), f64::INFINITY);
    }

    #[test]
    fn flight_is_no_joint_near_the_floor_and_its_neighbours_do_not_count() {
        // Standing, standing, airborne, airborne, standing, standing, standing.
        let heights = [0.0, 0.0, 0.3, 0.3, 0.01, 0.0, 0.0];
        let poses: Vec<Pose> = heights.iter().map(|&h| pose(h, 0.0)).collect();
        assert_eq!(
            in_flight(&poses),
            [false, false, true, true, false, false, false]
        );
        // Pairs (0,1) … (5,6): frames 1 and 4 are next to flight, so only (5,6) counts.
        assert_eq!(
            counted_pairs(&poses),
            [false, false, false, false, false, true]
        );
        // Just over the clearance is flight, just under is not.
        assert_eq!(
            in_flight(&[pose(FLIGHT_CLEARANCE_M + 1e-6, 0.0), pose(0.049, 0.0)]),
            [true, false]
        );
        assert!(counted_pairs(&poses[..1]).is_empty());
    }

    #[test]
    fn the_fastest_joint_is_found_outside_flight_only() {
        // A hop: the fast frames are in flight; on the ground one wrist moves 10 cm a frame.
        let mut poses: Vec<Pose> = [0.0, 0.0, 0.4, 0.0, 0.0, 0.0]
            .iter()
            .map(|&h| pose(h, 0.0))
            .collect();
        poses[5][21][0] = 0.1;
        let counted = counted_pairs(&poses);
        let f = fastest_outside_flight(&poses, &counted).unwrap();
        assert_eq!((f.frame, f.joint, f.joint_name()), (4, 21, "r_wrist"));
        assert!((f.speed - 2.0).abs() < 1e-9);
        let m = measure(&poses, 1.5);
        assert_eq!((m.flight_frames, m.pairs_over), (1, 1));
        assert!(!m.passes(1.0));
        assert!(measure(&poses, 2.5).passes(1.0));
        assert!(fastest_outside_flight(&poses, &[false; 5]).is_none());
    }

    #[test]
    fn joint_speeds_are_every_joint_every_pair() {
        let (a, mut b) = (pose(0.0, 0.0), pose(0.0, 0.0));
        b[3][2] = 0.05;
        let s = joint_speeds(&[a, b]);
        assert_eq!(s.len(), 22);
        assert!((s[3] - 1.0).abs() < 1e-9 && s.iter().filter(|&&v| v > 0.0).count() == 1);
    }

    #[test]
    fn a_jump_flies_and_a_hovering_body_floats() {
        let standing = [[0.0, 0.0, 0.0]; crate::skeleton::NUM_JOINTS];
        let lifted = |h: f64| standing.map(|p| [p[0], p[1] + h, p[2]]);
        // 10 frames on the floor, a 10-frame jump, 10 on the floor, 20 frames hovering.
        let mut poses = vec![standing; 10];
        poses.extend(vec![lifted(0.3); 10]);
        poses.extend(vec![standing; 10]);
        poses.extend(vec![lifted(0.1); 20]);
        assert!((floating_share(&poses) - 20.0 / 50.0).abs() < 1e-12);
        assert_eq!(floating_share(&poses[..30]), 0.0);
        assert_eq!(floor_penetration(&poses), 0.0);
        poses[3][joint::L_FOOT][1] = -0.02;
        assert!((floor_penetration(&poses) - 0.02).abs() < 1e-12);
    }

    #[test]
    fn a_body_under_the_floor_or_skating_fails() {
        let still: Vec<Pose> = (0..10).map(|_| pose(0.0, 0.0)).collect();
        let m = measure(&still, 5.0);
        assert!(m.passes(0.0) && m.skating == 0.0 && m.fastest.unwrap().speed == 0.0);
        let sunk: Vec<Pose> = (0..10).map(|_| pose(-0.03, 0.0)).collect();
        assert!(!measure(&sunk, 5.0).passes(1.0));
        // The whole body slides sideways 5 cm a frame (1 m/s) with its feet on the floor.
        let sliding: Vec<Pose> = (0..10).map(|t| pose(0.0, 0.05 * t as f64)).collect();
        let m = measure(&sliding, 5.0);
        assert!((m.skating - 1.0).abs() < 1e-12 && !m.passes(0.5));
    }

    #[test]
    fn the_real_reference_pools_the_motions() {
        let still: Vec<Pose> = (0..11).map(|_| pose(0.0, 0.0)).collect();
        let sliding: Vec<Pose> = (0..11).map(|t| pose(0.0, 0.05 * t as f64)).collect();
        let r = real_reference(&[still, sliding]);
        assert_eq!((r.motions, r.frames), (2, 22));
        assert!((r.skating - 0.5).abs() < 1e-12);
        assert!((r.p99_fastest - 1.0).abs() < 1e-9 && (r.p99_joint - 1.0).abs() < 1e-9);
        assert!(r.lowest_m.abs() < 1e-12);
    }
}
