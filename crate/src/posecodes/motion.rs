//! Motion descriptors of a window of frames.

use super::frame::{
    self, ArmCodes, ArmJoints, BodyFrame, FrameCodes, LegCodes, LegJoints, Vertical, LEFT_ARM,
    LEFT_LEG, RIGHT_ARM, RIGHT_LEG,
};
use crate::geom::{self, Vec3};
use crate::skeleton::{joint, Pose};
use crate::timing::FPS;
use serde::Serialize;

/// Below this root speed on the ground (m/s) the body is "still". Set above the drift of a
/// pelvis that sways or shifts its weight, and of a pelvis that moves back when sitting down.
pub const STILL_MAX_MPS: f64 = 0.25;
/// From this root speed (m/s) the body "walks"; between [`STILL_MAX_MPS`] and this it moves
/// "slowly".
pub const WALK_MIN_MPS: f64 = 0.7;
/// From this root speed (m/s) the body "runs".
pub const RUN_MIN_MPS: f64 = 2.0;

/// Both feet higher than this above the floor (metres) means the body may be airborne.
pub const JUMP_CLEARANCE_M: f64 = 0.08;
/// An airborne phase counts as a jump only if both feet get at least this high (metres) at its
/// peak.
pub const JUMP_PEAK_CLEARANCE_M: f64 = 0.12;
/// ... and the pelvis rises at least this much (metres) above its height while a foot is down.
pub const JUMP_RISE_M: f64 = 0.05;
/// Shortest airborne phase of a jump, in frames (0.15 s): the flight phase of running is
/// shorter and must not count.
pub const JUMP_MIN_FRAMES: usize = 3;
/// Longest airborne phase of a jump, in frames (1.5 s); longer means the floor estimate is
/// wrong (climbing) rather than a jump.
pub const JUMP_MAX_FRAMES: usize = 30;

/// Forward torso tilt (degrees between pelvis→neck and the vertical) that counts as bending
/// forward or bowing.
pub const BOW_MIN_DEG: f64 = 30.0;
/// How much the tilt must change (degrees) to count as going down into, or coming back from, a
/// bend.
pub const TILT_CHANGE_DEG: f64 = 20.0;
/// Backward torso tilt (degrees) that counts as leaning back.
pub const LEAN_BACK_DEG: f64 = 20.0;

/// The pelvis is "low" (crouching, sitting, kneeling) below this height above the floor, as a
/// fraction of the leg length (thigh + shin). Standing puts it at about 1.1.
pub const LOW_PELVIS_RATIO: f64 = 0.8;
/// Pelvis height change, as a fraction of the leg length, that counts as lowering or rising.
pub const LEVEL_CHANGE_RATIO: f64 = 0.25;

/// A raised hand waves when its horizontal motion reverses at least this many times.
pub const WAVE_MIN_REVERSALS: usize = 3;
/// Smallest back-and-forth movement (metres) of the wrist that counts as a reversal in a wave;
/// smaller wobbles are noise.
pub const WAVE_REVERSAL_M: f64 = 0.05;
/// A low arm swings when its forward-backward motion reverses at least this many times...
pub const SWING_MIN_REVERSALS: usize = 2;
/// ... by at least this much (metres) each time.
pub const SWING_REVERSAL_M: f64 = 0.08;
/// A limb whose end (wrist or ankle) travels faster than this (m/s) relative to its shoulder
/// or hip, in the body frame, is moving rather than held.
pub const ACTIVE_MIN_MPS: f64 = 0.3;
/// A wrist closer than this to the head joint (metres) is at the head (face, ear, hair).
pub const NEAR_HEAD_M: f64 = 0.22;
/// A raised wrist at least this far (metres) from its shoulder horizontally reaches forward or
/// out to the side.
pub const REACH_MIN_M: f64 = 0.3;
/// A wrist more than this far (metres) past the midline, on the other side, crosses the body.
pub const CROSS_MIN_M: f64 = 0.10;

/// A leg is lifted when its ankle is at least this high above the floor (metres)...
pub const LIFT_CLEARANCE_M: f64 = 0.25;
/// ... and at least this far (metres) in front of or behind the pelvis, or 5 cm further than
/// this out to the side.
pub const LIFT_REACH_M: f64 = 0.35;
/// A lifted leg kicks when its ankle moves faster than this (m/s) relative to the hip.
pub const KICK_MIN_MPS: f64 = 2.0;
/// A knee at most this far (metres) below its hip, with the foot off the ground, is lifted
/// high (thigh about horizontal).
pub const KNEE_LIFT_BELOW_HIP_M: f64 = 0.12;

/// A pose code must hold for this many frames (0.15 s) to count for a window, so a single
/// noisy frame does not.
const MIN_EVENT_FRAMES: usize = 3;
/// Smoothing (frames) of the facing direction before limbs are measured in the body frame, so
/// frame-to-frame wobble of the hips does not read as limb motion.
const FACING_SIGMA: f64 = 2.0;
/// Root positions are compared this many frames apart (0.25 s) for speed, so the side-to-side
/// sway of each step does not add to the distance travelled.
const SPEED_STRIDE: usize = 5;

/// How fast the body travels over the ground.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Pace {
    /// Root speed under [`STILL_MAX_MPS`] (0.25 m/s).
    #[default]
    Still,
    /// 0.25 to 0.7 m/s.
    Slow,
    /// 0.7 to 2.0 m/s.
    Walking,
    /// [`RUN_MIN_MPS`] (2.0 m/s) and faster.
    Running,
}

impl Pace {
    /// The category of a root speed on the ground in m/s.
    pub fn from_speed(mps: f64) -> Pace {
        if mps < STILL_MAX_MPS {
            Pace::Still
        } else if mps < WALK_MIN_MPS {
            Pace::Slow
        } else if mps < RUN_MIN_MPS {
            Pace::Walking
        } else {
            Pace::Running
        }
    }

    /// Words for the category ("walking").
    pub fn as_str(self) -> &'static str {
        match self {
            Pace::Still => "still",
            Pace::Slow => "slow",
            Pace::Walking => "walking",
            Pace::Running => "running",
        }
    }
}

/// Which way the body travels, relative to where it faces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Travel {
    /// The way the body faces.
    Forward,
    /// Away from where the body faces.
    Backward,
    /// Towards the character's left.
    Left,
    /// Towards the character's right.
    Right,
}

impl Travel {
    /// Words for the direction ("to the left").
    pub fn as_str(self) -> &'static str {
        match self {
            Travel::Forward => "forward",
            Travel::Backward => "backward",
            Travel::Left => "to the left",
            Travel::Right => "to the right",
        }
    }
}

/// What the torso does over the window, from its forward tilt (pelvis→neck against the
/// vertical).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Torso {
    /// Never tilts [`BOW_MIN_DEG`] forward or [`LEAN_BACK_DEG`] back.
    #[default]
    Upright,
    /// Tilts forward past 30° from a tilt at least 20° smaller, then comes back up by 20°,
    /// with the head lower at the deepest point: a bow.
    Bows,
    /// Tilts forward past 30° and does not come back within the window.
    BendsForward,
    /// Starts tilted forward past 30° and comes back up by at least 20°.
    StraightensUp,
    /// Stays tilted forward past 30° throughout.
    StaysBent,
    /// Tilts back by more than 20°.
    LeansBack,
}

impl Torso {
    /// Words for what the torso does ("bows").
    pub fn as_str(self) -> &'static str {
        match self {
            Torso::Upright => "stays upright",
            Torso::Bows => "bows",
            Torso::BendsForward => "bends forward",
            Torso::StraightensUp => "straightens up",
            Torso::StaysBent => "stays bent forward",
            Torso::LeansBack => "leans back",
        }
    }
}

/// What the pelvis height does over the window, measured against the leg length.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Level {
    /// No large change, never low.
    #[default]
    Steady,
    /// Ends low, having dropped by [`LEVEL_CHANGE_RATIO`] of the leg length (crouching,
    /// sitting down).
    Lowers,
    /// Starts low and rises by that much (standing up).
    Rises,
    /// Goes low and comes back up within the window (a squat).
    Dips,
    /// Low throughout ([`LOW_PELVIS_RATIO`]): crouching, sitting or lying.
    StaysLow,
}

impl Level {
    /// Words for the category ("lowers the body").
    pub fn as_str(self) -> &'static str {
        match self {
            Level::Steady => "stays at the same height",
            Level::Lowers => "lowers the body",
            Level::Rises => "rises",
            Level::Dips => "squats down and rises again",
            Level::StaysLow => "stays low",
        }
    }
}

/// The highest an arm gets over the window (for at least three frames).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ArmHeight {
    /// The wrist stays below the shoulder.
    #[default]
    Low,
    /// The wrist reaches the shoulder's height ([`crate::posecodes::HEIGHT_BAND_M`] band).
    ShoulderHeight,
    /// The wrist goes above the head.
    AboveHead,
}

impl ArmHeight {
    /// Words for the category ("above the head").
    pub fn as_str(self) -> &'static str {
        match self {
            ArmHeight::Low => "stays low",
            ArmHeight::ShoulderHeight => "to shoulder height",
            ArmHeight::AboveHead => "above the head",
        }
    }
}

/// Where a raised arm points, horizontally, at its highest.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Reach {
    /// The wrist is at least [`REACH_MIN_M`] in front of the shoulder, more than out to the side.
    Forward,
    /// The wrist is at least [`REACH_MIN_M`] out to the arm's own side of the shoulder.
    Sideways,
}

/// Direction of a lifted leg from the pelvis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LegDirection {
    /// In front of the body.
    Forward,
    /// Out to the leg's own side.
    Sideways,
    /// Behind the body.
    Backward,
}

impl LegDirection {
    /// Words for the direction ("out to the side").
    pub fn as_str(self) -> &'static str {
        match self {
            LegDirection::Forward => "forward",
            LegDirection::Sideways => "out to the side",
            LegDirection::Backward => "backward",
        }
    }
}

/// How one arm moves over a window.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ArmMotion {
    /// Path length of the wrist relative to the shoulder, in the body frame, per second (m/s):
    /// how much the arm moves by itself, not counting the torso or travel.
    pub activity_mps: f64,
    /// The highest the wrist gets.
    pub height: ArmHeight,
    /// Reversals of the wrist's horizontal motion (sideways or forward-backward, whichever has
    /// more) while the wrist is at or above shoulder height.
    pub raised_reversals: usize,
    /// The raised hand waves: at least [`WAVE_MIN_REVERSALS`] raised reversals.
    pub waves: bool,
    /// The arm swings forward and back while low, as when walking.
    pub swings: bool,
    /// The wrist comes within [`NEAR_HEAD_M`] of the head.
    pub near_head: bool,
    /// The wrist crosses the body midline by more than [`CROSS_MIN_M`].
    pub crosses_midline: bool,
    /// Where the arm points when the wrist is highest, if it is raised to at least shoulder
    /// height and reaches out.
    pub reach: Option<Reach>,
    /// Fraction of frames with the wrist in front of the pelvis.
    pub in_front_fraction: f64,
    /// Smallest inner elbow angle in degrees.
    pub min_elbow_deg: f64,
}

/// How one leg moves over a window.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct LegMotion {
    /// Path length of the ankle relative to the hip, in the body frame, per second (m/s).
    pub activity_mps: f64,
    /// Fraction of frames with this foot on the ground.
    pub ground_fraction: f64,
    /// The knee rests on the ground for at least three frames.
    pub kneels: bool,
    /// The leg is lifted in this direction ([`LIFT_CLEARANCE_M`], [`LIFT_REACH_M`]) while the
    /// other foot stands and the pelvis is not low. Not looked for while walking or running,
    /// whose strides reach as far.
    pub lift: Option<LegDirection>,
    /// The lift is fast enough to be a kick ([`KICK_MIN_MPS`]).
    pub kicks: bool,
    /// The knee comes up to about hip height with the foot off the ground (marching, a knee
    /// raise), while the other foot stands.
    pub knee_lift: bool,
    /// Smallest inner knee angle in degrees.
    pub min_knee_deg: f64,
}

/// Descriptors of a window of motion at 20 fps: global movement, torso and each limb.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct MotionDescriptor {
    /// Number of frames in the window.
    pub frames: usize,
    /// Duration in seconds (`frames − 1` steps at 20 fps).
    pub duration_s: f64,
    /// Floor height used for contacts, metres.
    pub floor_m: f64,
    /// Root (pelvis) speed on the ground in m/s, along its path sampled every 0.25 s.
    pub speed_mps: f64,
    /// Category of the speed.
    pub pace: Pace,
    /// Direction of travel relative to the facing, `None` when still. Each step is judged
    /// against the facing at that moment, so walking forward along a curve stays "forward";
    /// without turning this is the facing at the window start.
    pub travel: Option<Travel>,
    /// Total change of facing in degrees; positive is a turn to the character's left
    /// (counter-clockwise seen from above, positive yaw about +Y), negative to its right.
    pub turn_deg: f64,
    /// Number of jumps: phases with both feet off the floor and the pelvis raised (see
    /// [`JUMP_CLEARANCE_M`] and the following thresholds).
    pub jumps: usize,
    /// Largest forward tilt of the torso in degrees (pelvis→neck against the vertical,
    /// negative when leaning back).
    pub max_forward_tilt_deg: f64,
    /// What the torso does.
    pub torso: Torso,
    /// Lowest pelvis height above the floor as a fraction of the leg length.
    pub min_pelvis_ratio: f64,
    /// What the pelvis height does.
    pub level: Level,
    /// Left arm.
    pub left_arm: ArmMotion,
    /// Right arm.
    pub right_arm: ArmMotion,
    /// Left leg.
    pub left_leg: LegMotion,
    /// Right leg.
    pub right_leg: LegMotion,
}

/// Descriptors of a window of poses at 20 fps, with the floor taken as the lowest joint of the
/// window ([`crate::posecodes::floor_height`]). For a window cut from a longer motion, prefer
/// [`describe_window_with_floor`] with the whole motion's floor.
pub fn describe_window(poses: &[Pose]) -> MotionDescriptor {
    describe_window_with_floor(poses, frame::floor_height(poses))
}

/// Descriptors of a window of poses at 20 fps, on a floor at height `floor` (metres).
pub fn describe_window_with_floor(poses: &[Pose], floor: f64) -> MotionDescriptor {
    let n = poses.len();
    if n == 0 {
        return MotionDescriptor {
            floor_m: floor,
            ..MotionDescriptor::default()
        };
    }
    let duration = (n - 1) as f64 / FPS;
    let codes: Vec<FrameCodes> = poses.iter().map(|p| frame::frame_codes(p, floor)).collect();
    let raw_facing: Vec<Vec3> = poses.iter().map(frame::facing).collect();
    let bodies: Vec<BodyFrame> = geom::gaussian_smooth(&raw_facing, FACING_SIGMA)
        .into_iter()
        .zip(poses)
        .map(|(f, p)| BodyFrame::new(p[joint::PELVIS], frame::horizontal_unit(f)))
        .collect();

    let speed = root_speed(poses, duration);
    let pace = Pace::from_speed(speed);
    let travel = (pace != Pace::Still).then(|| travel_direction(poses, &bodies));
    let turn_deg = raw_facing
        .windows(2)
        .map(|w| wrap_deg(frame::heading_deg(w[1]) - frame::heading_deg(w[0])))
        .sum();

    let tilts: Vec<f64> = poses
        .iter()
        .zip(&bodies)
        .map(|(p, b)| {
            let v = b.dir(geom::sub(p[joint::NECK], p[joint::PELVIS]));
            v[2].atan2(v[1]).to_degrees()
        })
        .collect();
    let (torso, max_tilt) = torso_motion(poses, &tilts);

    let leg_length = 0.5
        * [LEFT_LEG, RIGHT_LEG]
            .iter()
            .map(|l| {
                geom::dist(poses[0][l.hip], poses[0][l.knee])
                    + geom::dist(poses[0][l.knee], poses[0][l.ankle])
            })
            .sum::<f64>();
    let ratios: Vec<f64> = poses
        .iter()
        .map(|p| {
            if leg_length > 1e-6 {
                (p[joint::PELVIS][1] - floor) / leg_length
            } else {
                LOW_PELVIS_RATIO + 1.0
            }
        })
        .collect();
    let level = level_change(&ratios);

    let ctx = Window {
        poses,
        bodies: &bodies,
        ratios: &ratios,
        floor,
        duration,
        pace,
    };
    let left_arm_codes: Vec<ArmCodes> = codes.iter().map(|c| c.left_arm).collect();
    let right_arm_codes: Vec<ArmCodes> = codes.iter().map(|c| c.right_arm).collect();
    let left_leg_codes: Vec<LegCodes> = codes.iter().map(|c| c.left_leg).collect();
    let right_leg_codes: Vec<LegCodes> = codes.iter().map(|c| c.right_leg).collect();

    MotionDescriptor {
        frames: n,
        duration_s: duration,
        floor_m: floor,
        speed_mps: speed,
        pace,
        travel,
        turn_deg,
        jumps: count_jumps(poses, &codes, floor),
        max_forward_tilt_deg: max_tilt,
        torso,
        min_pelvis_ratio: ratios.iter().copied().fold(f64::INFINITY, f64::min),
        level,
        left_arm: ctx.arm(&LEFT_ARM, &left_arm_codes),
        right_arm: ctx.arm(&RIGHT_ARM, &right_arm_codes),
        left_leg: ctx.leg(&LEFT_LEG, &left_leg_codes, &right_leg_codes),
        right_leg: ctx.leg(&RIGHT_LEG, &right_leg_codes, &left_leg_codes),
    }
}

/// An angle difference brought into (−180°, 180°].
fn wrap_deg(d: f64) -> f64 {
    let w = d.rem_euclid(360.0);
    if w > 180.0 {
        w - 360.0
    } else {
        w
    }
}

fn horizontal_dist(a: Vec3, b: Vec3) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn root_speed(poses: &[Pose], duration: f64) -> f64 {
    if duration <= 0.0 {
        return 0.0;
    }
    let last = poses.len() - 1;
    let mut samples: Vec<usize> = (0..poses.len()).step_by(SPEED_STRIDE).collect();
    if samples.last() != Some(&last) {
        samples.push(last);
    }
    let path: f64 = samples
        .windows(2)
        .map(|w| horizontal_dist(poses[w[0]][joint::PELVIS], poses[w[1]][joint::PELVIS]))
        .sum();
    path / duration
}

fn travel_direction(poses: &[Pose], bodies: &[BodyFrame]) -> Travel {
    let (mut forward, mut left) = (0.0, 0.0);
    for (w, body) in poses.windows(2).zip(bodies) {
        let step = geom::sub(w[1][joint::PELVIS], w[0][joint::PELVIS]);
        let local = body.dir(step);
        forward += local[2];
        left += local[0];
    }
    if forward.abs() >= left.abs() {
        if forward >= 0.0 {
            Travel::Forward
        } else {
            Travel::Backward
        }
    } else if left > 0.0 {
        Travel::Left
    } else {
        Travel::Right
    }
}

fn count_jumps(poses: &[Pose], codes: &[FrameCodes], floor: f64) -> usize {
    let clearance: Vec<f64> = poses
        .iter()
        .map(|p| {
            frame::foot_clearance(p, &LEFT_LEG, floor)
                .min(frame::foot_clearance(p, &RIGHT_LEG, floor))
        })
        .collect();
    let mut grounded_heights: Vec<f64> = poses
        .iter()
        .zip(codes)
        .filter(|(_, c)| c.left_leg.foot_on_ground || c.right_leg.foot_on_ground)
        .map(|(p, _)| p[joint::PELVIS][1])
        .collect();
    // Without a frame on the ground there is no take-off or landing to judge a jump against.
    let Some(baseline) = median(&mut grounded_heights) else {
        return 0;
    };
    runs(&clearance, |c| c > JUMP_CLEARANCE_M)
        .into_iter()
        .filter(|r| {
            let len = r.len();
            let peak_clearance = clearance[r.clone()].iter().copied().fold(0.0, f64::max);
            let peak_pelvis = poses[r.clone()]
                .iter()
                .map(|p| p[joint::PELVIS][1])
                .fold(f64::NEG_INFINITY, f64::max);
            (JUMP_MIN_FRAMES..=JUMP_MAX_FRAMES).contains(&len)
                && peak_clearance >= JUMP_PEAK_CLEARANCE_M
                && peak_pelvis >= baseline + JUMP_RISE_M
        })
        .count()
}

fn median(values: &mut [f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    Some(values[values.len() / 2])
}

/// Maximal index ranges where `pred` holds.
fn runs<T: Copy>(values: &[T], pred: impl Fn(T) -> bool) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, &v) in values.iter().enumerate() {
        match (pred(v), start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push(s..i);
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push(s..values.len());
    }
    out
}

fn torso_motion(poses: &[Pose], tilts: &[f64]) -> (Torso, f64) {
    let (peak, max) =
        tilts
            .iter()
            .copied()
            .enumerate()
            .fold(
                (0, f64::NEG_INFINITY),
                |acc, (i, t)| if t > acc.1 { (i, t) } else { acc },
            );
    let min = tilts.iter().copied().fold(f64::INFINITY, f64::min);
    let (start, end) = (tilts[0], tilts[tilts.len() - 1]);
    let torso = if max >= BOW_MIN_DEG {
        let went_down = start <= max - TILT_CHANGE_DEG;
        let came_back = end <= max - TILT_CHANGE_DEG;
        let head_lowered = poses[peak][joint::HEAD][1] < poses[0][joint::HEAD][1] - 0.05;
        match (went_down, came_back) {
            (true, true) if head_lowered => Torso::Bows,
            (true, _) => Torso::BendsForward,
            (false, _) if end <= start - TILT_CHANGE_DEG => Torso::StraightensUp,
            _ => Torso::StaysBent,
        }
    } else if min <= -LEAN_BACK_DEG {
        Torso::LeansBack
    } else {
        Torso::Upright
    };
    (torso, max)
}

fn level_change(ratios: &[f64]) -> Level {
    let (start, end) = (ratios[0], ratios[ratios.len() - 1]);
    let min = ratios.iter().copied().fold(f64::INFINITY, f64::min);
    if ratios.iter().all(|&r| r < LOW_PELVIS_RATIO) {
        Level::StaysLow
    } else if end < LOW_PELVIS_RATIO && end <= start - LEVEL_CHANGE_RATIO {
        Level::Lowers
    } else if start < LOW_PELVIS_RATIO && end >= start + LEVEL_CHANGE_RATIO {
        Level::Rises
    } else if min < LOW_PELVIS_RATIO && min <= start.min(end) - LEVEL_CHANGE_RATIO {
        Level::Dips
    } else {
        Level::Steady
    }
}

/// Number of times a coordinate changes direction by more than `hysteresis`: small wobbles
/// around an extreme are ignored, so noise does not count as oscillation.
fn reversals(xs: &[f64], hysteresis: f64) -> usize {
    let Some(&first) = xs.first() else {
        return 0;
    };
    let mut count = 0;
    let mut direction = 0i8;
    let mut extreme = first;
    for &x in &xs[1..] {
        match direction {
            0 => {
                if (x - extreme).abs() > hysteresis {
                    direction = if x > extreme { 1 } else { -1 };
                    extreme = x;
                }
            }
            1 => {
                if x > extreme {
                    extreme = x;
                } else if extreme - x > hysteresis {
                    direction = -1;
                    extreme = x;
                    count += 1;
                }
            }
            _ => {
                if x < extreme {
                    extreme = x;
                } else if x - extreme > hysteresis {
                    direction = 1;
                    extreme = x;
                    count += 1;
                }
            }
        }
    }
    count
}

fn path_length(points: &[Vec3]) -> f64 {
    points.windows(2).map(|w| geom::dist(w[0], w[1])).sum()
}

fn enough_frames(count: usize, n: usize) -> bool {
    count >= MIN_EVENT_FRAMES.min(n.max(1))
}

/// What the limb measurements of a window share.
struct Window<'a> {
    poses: &'a [Pose],
    bodies: &'a [BodyFrame],
    ratios: &'a [f64],
    floor: f64,
    duration: f64,
    pace: Pace,
}

impl Window<'_> {
    fn per_second(&self, path: f64) -> f64 {
        if self.duration > 0.0 {
            path / self.duration
        } else {
            0.0
        }
    }

    fn arm(&self, arm: &ArmJoints, codes: &[ArmCodes]) -> ArmMotion {
        let n = self.poses.len();
        let rel: Vec<Vec3> = self
            .poses
            .iter()
            .zip(self.bodies)
            .map(|(p, b)| b.dir(geom::sub(p[arm.wrist], p[arm.shoulder])))
            .collect();
        let raised: Vec<bool> = codes
            .iter()
            .map(|c| c.wrist_vs_shoulder != Vertical::Below)
            .collect();

        // A wave needs a few samples per raised stretch to show any back-and-forth.
        let raised_reversals: usize = runs(&raised, |r| r)
            .into_iter()
            .filter(|r| r.len() >= 4)
            .map(|r| {
                let sideways: Vec<f64> = rel[r.clone()].iter().map(|v| v[0]).collect();
                let forward: Vec<f64> = rel[r].iter().map(|v| v[2]).collect();
                reversals(&sideways, WAVE_REVERSAL_M).max(reversals(&forward, WAVE_REVERSAL_M))
            })
            .sum();
        let low_reversals: usize = runs(&raised, |r| !r)
            .into_iter()
            .map(|r| {
                let forward: Vec<f64> = rel[r].iter().map(|v| v[2]).collect();
                reversals(&forward, SWING_REVERSAL_M)
            })
            .sum();
        let activity = self.per_second(path_length(&rel));

        let above_head = codes
            .iter()
            .filter(|c| c.wrist_vs_head == Vertical::Above)
            .count();
        let at_shoulder = raised.iter().filter(|&&r| r).count();
        let height = if enough_frames(above_head, n) {
            ArmHeight::AboveHead
        } else if enough_frames(at_shoulder, n) {
            ArmHeight::ShoulderHeight
        } else {
            ArmHeight::Low
        };

        let reach = if height == ArmHeight::Low {
            None
        } else {
            let top = (0..n)
                .max_by(|&a, &b| rel[a][1].total_cmp(&rel[b][1]))
                .unwrap_or(0);
            let out = rel[top][0] * arm.outward;
            let forward = rel[top][2];
            if forward.max(out) < REACH_MIN_M {
                None
            } else if forward >= out {
                Some(Reach::Forward)
            } else {
                Some(Reach::Sideways)
            }
        };

        let near_head = self
            .poses
            .iter()
            .filter(|p| geom::dist(p[arm.wrist], p[joint::HEAD]) < NEAR_HEAD_M)
            .count();
        let crossing = self
            .poses
            .iter()
            .zip(self.bodies)
            .filter(|(p, b)| b.point(p[arm.wrist])[0] * arm.outward < -CROSS_MIN_M)
            .count();
        let in_front = codes
            .iter()
            .filter(|c| c.wrist_depth == frame::Depth::InFront)
            .count();

        ArmMotion {
            activity_mps: activity,
            height,
            raised_reversals,
            waves: raised_reversals >= WAVE_MIN_REVERSALS,
            swings: low_reversals >= SWING_MIN_REVERSALS && activity >= ACTIVE_MIN_MPS,
            near_head: enough_frames(near_head, n),
            crosses_midline: enough_frames(crossing, n),
            reach,
            in_front_fraction: in_front as f64 / n as f64,
            min_elbow_deg: codes
                .iter()
                .map(|c| c.elbow_angle_deg)
                .fold(180.0, f64::min),
        }
    }

    fn leg(&self, leg: &LegJoints, codes: &[LegCodes], other: &[LegCodes]) -> LegMotion {
        let n = self.poses.len();
        let rel: Vec<Vec3> = self
            .poses
            .iter()
            .zip(self.bodies)
            .map(|(p, b)| b.dir(geom::sub(p[leg.ankle], p[leg.hip])))
            .collect();
        let peak_speed = rel
            .windows(2)
            .map(|w| geom::dist(w[0], w[1]) * FPS)
            .fold(0.0, f64::max);
        // Standing on the other foot, body up: a sitting or lying body also has its feet high
        // in front, and is not lifting a leg.
        let standing_on_other =
            |t: usize| other[t].foot_on_ground && self.ratios[t] >= LOW_PELVIS_RATIO;

        let mut lift: Option<(LegDirection, f64)> = None;
        if self.pace < Pace::Walking {
            for t in 0..n {
                if !standing_on_other(t) {
                    continue;
                }
                let p = &self.poses[t];
                let height = p[leg.ankle][1] - self.floor;
                let local = self.bodies[t].point(p[leg.ankle]);
                let (out, forward) = (local[0] * leg.outward, local[2]);
                let dir = if height < LIFT_CLEARANCE_M {
                    None
                } else if forward > LIFT_REACH_M && forward >= out {
                    Some(LegDirection::Forward)
                } else if out > LIFT_REACH_M + 0.05 {
                    Some(LegDirection::Sideways)
                } else if forward < -LIFT_REACH_M {
                    Some(LegDirection::Backward)
                } else {
                    None
                };
                if let Some(dir) = dir {
                    if lift.is_none_or(|(_, h)| height > h) {
                        lift = Some((dir, height));
                    }
                }
            }
        }

        let knee_lift = (0..n)
            .filter(|&t| {
                let p = &self.poses[t];
                standing_on_other(t)
                    && !codes[t].foot_on_ground
                    && p[leg.knee][1] >= p[leg.hip][1] - KNEE_LIFT_BELOW_HIP_M
            })
            .count();
        let kneeling = codes.iter().filter(|c| c.knee_on_ground).count();
        let grounded = codes.iter().filter(|c| c.foot_on_ground).count();

        LegMotion {
            activity_mps: self.per_second(path_length(&rel)),
            ground_fraction: grounded as f64 / n as f64,
            kneels: enough_frames(kneeling, n),
            lift: lift.map(|(d, _)| d),
            kicks: lift.is_some() && peak_speed >= KICK_MIN_MPS,
            knee_lift: enough_frames(knee_lift, n),
            min_knee_deg: codes.iter().map(|c| c.knee_angle_deg).fold(180.0, f64::min),
        }
    }
}

#[cfg(test)]
mod unit {
    use super::*;

    #[test]
    fn reversals_ignore_small_wobble() {
        let xs: Vec<f64> = (0..40)
            .map(|i| 0.1 * (i as f64 * 0.5).sin() + 0.01 * (i as f64 * 3.0).sin())
            .collect();
        // sin(0.5 t) over 40 samples turns about 6 times; the 1 cm wobble adds none.
        assert_eq!(reversals(&xs, 0.05), 6);
        let noise: Vec<f64> = (0..40).map(|i| 0.02 * (i as f64 * 2.0).sin()).collect();
        assert_eq!(reversals(&noise, 0.05), 0);
    }

    #[test]
    fn wrap_keeps_turns_small() {
        assert!((wrap_deg(350.0) + 10.0).abs() < 1e-9);
        assert!((wrap_deg(-350.0) - 10.0).abs() < 1e-9);
        assert!((wrap_deg(90.0) - 90.0).abs() < 1e-9);
    }

    #[test]
    fn pace_thresholds() {
        assert_eq!(Pace::from_speed(0.1), Pace::Still);
        assert_eq!(Pace::from_speed(0.5), Pace::Slow);
        assert_eq!(Pace::from_speed(1.2), Pace::Walking);
        assert_eq!(Pace::from_speed(2.5), Pace::Running);
    }
}
