//! Go (PRO-Motion's plan–posture–go, design §4.5): key poses placed in time become a motion.
//!
//! A timeline is a list of [`KeyPose`]s. Each holds a body shape (solved at the origin, facing
//! +Z, lowest joint on the floor), the time to reach it from the previous key, the time it is
//! held, and how the whole body turns and travels on the way. [`go`] turns the timeline into
//! frames at 20 fps; [`repeat`] makes cycles (squats, jumping jacks, crawling) of a short one.
//!
//! How a frame is made:
//! - Shapes: the local bone rotations of the two keys (inverse kinematics, no twist) are
//!   slerped with a smoothstep ease and rebuilt by forward kinematics on the reference skeleton,
//!   so every frame has its bone lengths, whatever skeleton the keys were solved on.
//! - Placement: each key is set where the joints it shares on the ground with the previous key
//!   (its supports) stay where they were, moved by the key's travel and turned about the old
//!   pelvis by its turn; a squat solved with its pelvis above the origin thus sits back over
//!   the standing feet instead of stepping forward. The facing angle is interpolated as an
//!   angle (a 360° turn is a full spin), the ground position along a straight line, the pelvis
//!   height so that the supports stay on the floor.
//! - Contacts: a foot (ankle, toe) or hand (wrist) within [`contact_height`] of the floor in a
//!   key is on the ground there; knees and the pelvis on the ground hold the body's height. A
//!   limb on the ground in both keys at the same place stays planted; one that must move (the
//!   body travels or turns under it) steps: it stays put, lifts, moves and sets down inside its
//!   own window of the transition, limbs one after another. A limb that leaves the ground
//!   carries weight through the first part of the transition, then lifts into the body's
//!   shape. Two-bone IK (hip–knee–ankle, shoulder–elbow–wrist) holds the targets; the pelvis
//!   sinks when a planted foot would be out of reach, and the body rises when any joint would
//!   go under the floor. With nothing on the ground in both keys, the body rests on its lowest
//!   joint instead of floating between the keys' heights.
//! - Jumps: a [`Transition::Flight`] key is reached by a push-off from the previous key (feet
//!   planted, a countermovement that ends at take-off speed), a ballistic flight under
//!   [`GRAVITY`] whose duration follows from the apex, and a landing absorbed by a short dip.
//! - Speed: a transition too short for its movement is lengthened until no joint moves faster
//!   than [`MAX_JOINT_SPEED`]; flights (take-off, airborne, landing dip) are exempt.

use crate::geom::{self, Quat, Vec3};
use crate::posecodes::{FOOT_CONTACT_M, HAND_CONTACT_M, KNEE_CONTACT_M, PELVIS_CONTACT_M};
use crate::skeleton::{joint, Pose};
use crate::timing::FPS;

mod limbs;
#[cfg(test)]
mod tests;
mod timeline;

use timeline::Timeline;

/// The fastest a joint may move outside flight (m/s, frame to frame). Transitions that would
/// move a joint faster are lengthened. A chosen bound, not a measurement: the training data's
/// 99th-percentile joint speed is measured by the evaluation, and this should follow it.
pub const MAX_JOINT_SPEED: f64 = 3.5;

/// Gravitational acceleration for flights (m/s²).
pub const GRAVITY: f64 = 9.81;

/// How close to the floor (metres) a joint must be in a key pose to be on the ground there: the
/// describer's own thresholds ([`crate::posecodes::Support`]), so a hand the script puts
/// on the ground (a wrist 8 cm up, the joint sits above the palm) carries weight here too.
/// Feet (ankle, toe) and the joints not listed take [`FOOT_CONTACT_M`].
pub fn contact_height(j: usize) -> f64 {
    match j {
        joint::L_WRIST | joint::R_WRIST => HAND_CONTACT_M,
        joint::L_KNEE | joint::R_KNEE => KNEE_CONTACT_M,
        joint::PELVIS => PELVIS_CONTACT_M,
        _ => FOOT_CONTACT_M,
    }
}

/// Shortest eased transition (seconds); shorter or missing times are raised to it.
pub const MIN_TRANSITION: f64 = 0.1;

/// Shortest push-off before a flight (seconds).
pub const MIN_PUSH_OFF: f64 = 0.15;

/// Longest time one key may ask for (seconds), for its transition and for its hold each.
pub const MAX_KEY_SECONDS: f64 = 30.0;

/// Longest motion [`go`] makes (seconds); keys past it are dropped.
pub const MAX_SECONDS: f64 = 600.0;

/// Highest flight apex (metres); higher ones are lowered to it.
pub const MAX_APEX: f64 = 1.5;

/// Lowest flight apex (metres); a flight below it is an eased transition.
pub const MIN_APEX: f64 = 0.02;

/// Most keys [`repeat`] returns.
pub const MAX_REPEAT_KEYS: usize = 4096;

/// A contact that moves less than this between keys (metres, on the ground plane) slides
/// slowly instead of stepping: key poses solved independently rarely agree to the millimetre.
const PLANT_TOLERANCE: f64 = 0.05;
/// Turns larger than this (degrees) cannot be made on planted feet: the legs would twist.
const PIVOT_DEG: f64 = 30.0;
/// A turn takes one step per limb for every this many degrees.
const STEP_TURN_DEG: f64 = 90.0;
/// Travel takes one step per limb for every this many metres.
const STEP_LENGTH: f64 = 0.5;
/// Most steps one limb takes in one transition.
const MAX_STEPS: usize = 16;
/// Height a stepping hand or foot is lifted to (metres), by stride.
const MIN_LIFT: f64 = 0.06;
const MAX_LIFT: f64 = 0.12;
/// Deepest landing dip of the pelvis (metres) and its time constant bound (seconds).
const LANDING_DIP: f64 = 0.15;
const LANDING_TIME: f64 = 0.1;
/// After this long (seconds) a landing dip is over.
const DIP_WINDOW: f64 = 2.0;
/// Lowest the pelvis sinks (metres) to let a planted foot or hand be reached.
const MAX_REACH_DROP: f64 = 0.25;
/// Largest turn (degrees) and travel (metres) one key may ask for.
const MAX_TURN_DEG: f64 = 3600.0;
const MAX_TRAVEL: f64 = 50.0;
/// Largest coordinate (metres) of a usable key pose.
const MAX_COORDINATE: f64 = 100.0;
/// Share of a flight (0–1) in which the body turns from its take-off shape into the landing
/// key's.
const FLIGHT_SHAPING: f64 = 0.6;
/// Share of a transition (0–1) for which a hand or foot that leaves the ground stays on it.
const LEAVE_LATE: f64 = 0.6;
/// Headroom on the measured peak speed: samples can straddle the true peak.
const SPEED_MARGIN: f64 = 1.05;

/// How the body gets from the previous key into a key.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Transition {
    /// Shapes, facing and ground position ease in and out; planted limbs stay, others step.
    #[default]
    Ease,
    /// A ballistic jump: the transition time is the push-off from the previous key (feet
    /// planted, the shape turns into this key's), then the pelvis flies a parabola under
    /// [`GRAVITY`] for the time its apex takes (`2·√(2·apex/g)`), turning and travelling at a
    /// constant rate, and lands in this key. Apexes are clamped to [`MAX_APEX`]; one below
    /// [`MIN_APEX`] (or not a number) makes an eased transition.
    Flight {
        /// Height (metres) the pelvis rises above its landing height at the top of the flight.
        apex_m: f64,
    },
}

/// One key pose in a timeline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KeyPose {
    /// The body shape: world joint positions (metres, Y up) solved at the origin facing +Z,
    /// lowest joint on the floor. Bone directions, contacts (joints within [`contact_height`]
    /// of the floor) and, for a key with no support in common with the previous one, the
    /// pelvis's ground offset are read from it; bone lengths come from the reference skeleton,
    /// and the body is set on the floor again. A pose with a coordinate that is not finite or
    /// beyond 100 m is replaced by the rest pose (standing, arms down).
    pub pose: Pose,
    /// Seconds to move from the previous key into this one (ignored for the first key). Not a
    /// number or negative counts as 0; raised to [`MIN_TRANSITION`] ([`MIN_PUSH_OFF`] before
    /// a flight), capped at [`MAX_KEY_SECONDS`], and lengthened when the movement would
    /// otherwise be faster than [`MAX_JOINT_SPEED`] (to at most [`MAX_KEY_SECONDS`]). For a
    /// flight it is the push-off time only.
    pub transition: f64,
    /// Seconds the pose is held once reached (0 to [`MAX_KEY_SECONDS`]; not a number is 0).
    pub hold: f64,
    /// Change of facing (degrees, + = counter-clockwise seen from above = turning left)
    /// reached at this key, relative to the previous key's facing; interpolated as an angle, so
    /// 360 or 720 make full spins. Ignored for the first key; capped at ±3600°.
    pub turn_deg: f64,
    /// Ground displacement of the body `[left, forward]` (metres) in the previous key's facing
    /// frame, covered during the transition: the supports of this key are expected that far
    /// from the previous key's (limbs on the ground step there), and with the same shape the
    /// pelvis moves exactly that far. Ignored for the first key; capped at ±50 m.
    pub travel: [f64; 2],
    /// How this key is reached.
    pub motion: Transition,
}

impl KeyPose {
    /// A key reached in `transition` seconds and held for `hold` seconds, eased, without turn or
    /// travel.
    pub fn new(pose: Pose, transition: f64, hold: f64) -> KeyPose {
        KeyPose {
            pose,
            transition,
            hold,
            turn_deg: 0.0,
            travel: [0.0, 0.0],
            motion: Transition::Ease,
        }
    }
}

/// Turns key poses into a motion: world joint positions at 20 fps, starting at the first key
/// (at the origin, facing +Z) and ending at the end of the last key's hold, at most
/// [`MAX_SECONDS`] long. A transition too short for its movement is lengthened (never skipped
/// or jumped), so the motion may be longer than the keys' times add up to. An empty list
/// gives an empty motion; the same keys always give the same frames.
pub fn go(keys: &[KeyPose]) -> Vec<Pose> {
    go_timed(keys).0
}

/// [`go`], with the time (seconds from the start) at which each key is reached and its hold
/// begins: transitions the go stage lengthened show here, so a key's frames can be found.
pub fn go_timed(keys: &[KeyPose]) -> (Vec<Pose>, Vec<f64>) {
    if keys.is_empty() {
        return (Vec::new(), Vec::new());
    }
    let timeline = Timeline::new(keys);
    let frames = (timeline.total * FPS - 1e-9).ceil().max(0.0) as usize + 1;
    let poses = (0..frames)
        .map(|f| timeline.frame_at((f as f64 / FPS).min(timeline.total)))
        .collect();
    (poses, timeline.keys.iter().map(|k| k.reached).collect())
}

/// A cycle played `times` times and closed on its first key: `keys` repeated, then
/// `keys[0]` once more, so that squats or jumping jacks end standing. Between cycles the first
/// key is reached from the last one with the first key's own `transition`, `turn_deg`,
/// `travel` and `motion` (which [`go`] ignores for the very first key), so a cycle that travels
/// puts its last stride there. At most [`MAX_REPEAT_KEYS`] keys, unless one cycle alone has
/// more (it is then returned once, closed).
pub fn repeat(keys: &[KeyPose], times: usize) -> Vec<KeyPose> {
    if keys.is_empty() || times == 0 {
        return Vec::new();
    }
    let cycles = times.min((MAX_REPEAT_KEYS.saturating_sub(1) / keys.len()).max(1));
    let mut out = Vec::with_capacity(cycles * keys.len() + 1);
    for _ in 0..cycles {
        out.extend_from_slice(keys);
    }
    if keys.len() > 1 {
        out.push(keys[0]);
    }
    out
}

/// The fastest frame-to-frame speed of any joint (m/s at 20 fps); 0 for fewer than two frames.
pub fn max_joint_speed(poses: &[Pose]) -> f64 {
    poses
        .windows(2)
        .flat_map(|w| w[0].iter().zip(&w[1]).map(|(a, b)| geom::dist(*a, *b)))
        .fold(0.0, f64::max)
        * FPS
}

/// 0 → 1 over the first quarter, 1 → 0 over the last: the lift of a step.
fn bump(r: f64) -> f64 {
    geom::ease(r / 0.25).min(geom::ease((1.0 - r) / 0.25))
}

fn yawed(yaw: f64, v: Vec3) -> Vec3 {
    Quat::from_yaw(yaw).rotate(v)
}

fn dist_xz(a: Vec3, b: Vec3) -> f64 {
    (a[0] - b[0]).hypot(a[2] - b[2])
}

fn shift_y(pose: &mut Pose, dy: f64) {
    for p in pose.iter_mut() {
        p[1] += dy;
    }
}

fn lowest(pose: &Pose) -> f64 {
    pose.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min)
}
