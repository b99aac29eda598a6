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
use crate::limb::two_bone;
use crate::posecodes::{FOOT_CONTACT_M, HAND_CONTACT_M, KNEE_CONTACT_M, PELVIS_CONTACT_M};
use crate::skeleton::{
    forward_kinematics, inverse_kinematics, joint, Offsets, Pose, Rotations, NUM_JOINTS,
    REFERENCE_BONE_LENGTHS,
};
use crate::timing::FPS;

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

/// A limb that can be held to a target: root joint (kept), middle joint (bent by IK), end
/// joint (the target) and, for legs, the toe carried by the end.
struct Limb {
    root: usize,
    mid: usize,
    end: usize,
    tip: Option<usize>,
    leg: bool,
}

impl Limb {
    fn effectors(&self) -> impl Iterator<Item = usize> {
        std::iter::once(self.end).chain(self.tip)
    }
}

const LEFT_LEG: usize = 0;
const RIGHT_LEG: usize = 1;
const LEFT_ARM: usize = 2;
const RIGHT_ARM: usize = 3;

const LIMBS: [Limb; 4] = [
    Limb {
        root: joint::L_HIP,
        mid: joint::L_KNEE,
        end: joint::L_ANKLE,
        tip: Some(joint::L_FOOT),
        leg: true,
    },
    Limb {
        root: joint::R_HIP,
        mid: joint::R_KNEE,
        end: joint::R_ANKLE,
        tip: Some(joint::R_FOOT),
        leg: true,
    },
    Limb {
        root: joint::L_SHOULDER,
        mid: joint::L_ELBOW,
        end: joint::L_WRIST,
        tip: None,
        leg: false,
    },
    Limb {
        root: joint::R_SHOULDER,
        mid: joint::R_ELBOW,
        end: joint::R_WRIST,
        tip: None,
        leg: false,
    },
];

/// Where a limb's end (and toe) must be in one frame.
#[derive(Clone, Copy)]
struct Target {
    end: Vec3,
    tip: Option<Vec3>,
    /// 0–1: how much the limb may fall short of a target near its full reach (see
    /// [`crate::limb::SOFT_REACH`]); 0 for a limb that carries weight.
    soft: f64,
}

#[derive(Clone, Copy)]
struct Flight {
    /// Take-off (and landing) vertical speed, m/s.
    v0: f64,
    /// Seconds airborne.
    time: f64,
}

struct Landing {
    time: f64,
    v0: f64,
    /// Time constant of the dip, seconds.
    tau: f64,
}

/// One key, placed in the world and in time.
struct Key {
    /// Local bone rotations; the root's is the identity (facing is `yaw`).
    rots: Rotations,
    /// Pelvis in the key's own frame: ground offset x, height, ground offset z.
    pelvis: Vec3,
    /// The key's pose in the world.
    world: Pose,
    contact: [bool; NUM_JOINTS],
    /// Facing (radians about +Y from +Z) and ground origin of the key's frame.
    yaw: f64,
    ground: Vec3,
    /// Ground origin at take-off, for a key reached by a flight.
    takeoff: Vec3,
    /// Facing change from the previous key (radians).
    turn: f64,
    /// Eased transition, or push-off for a flight (seconds).
    trans: f64,
    hold: f64,
    flight: Option<Flight>,
    /// Time the key is reached (seconds from the start).
    reached: f64,
}

/// What a limb does during a transition.
#[derive(Clone, Copy, PartialEq)]
enum LimbMode {
    /// Follows the body.
    Free,
    /// Stays where it is on the ground.
    Planted,
    /// Moves from its place in one key to its place in the next inside windows of the
    /// transition: `steps` windows of its own, interleaved with `of` limbs at position `slot`.
    /// `stepping` when it is on the ground at both ends (so it must lift to move). Its windows
    /// fill the transition after the share `wait` (0–1), where it stays at its first place.
    Moving {
        slot: usize,
        of: usize,
        steps: usize,
        stepping: bool,
        wait: f64,
    },
    /// On the ground when a jump starts: stays until take-off.
    PushOff,
}

/// How a transition keeps its contacts.
struct Plan {
    /// Effectors on the ground in both keys: the pelvis height keeps them on the floor.
    supports: Vec<usize>,
    /// Pelvis height above the lowest support in each key.
    support_a: f64,
    support_b: f64,
    limbs: [LimbMode; 4],
}

struct Timeline {
    offsets: Offsets,
    keys: Vec<Key>,
    /// `plans[b]` for the transition into key `b` (`plans[0]` unused).
    plans: Vec<Plan>,
    landings: Vec<Landing>,
    total: f64,
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

fn seconds(s: f64) -> f64 {
    if s.is_nan() {
        0.0
    } else {
        s.clamp(0.0, MAX_KEY_SECONDS)
    }
}

fn finite_or_zero(v: f64) -> f64 {
    if v.is_finite() {
        v
    } else {
        0.0
    }
}

fn flight_of(motion: Transition) -> Option<Flight> {
    match motion {
        Transition::Flight { apex_m } if apex_m >= MIN_APEX => {
            let apex = apex_m.min(MAX_APEX);
            let time = 2.0 * (2.0 * apex / GRAVITY).sqrt();
            Some(Flight {
                v0: GRAVITY * time / 2.0,
                time,
            })
        }
        _ => None,
    }
}

/// World position of the pelvis for a key frame at `ground` facing `yaw`.
fn root_position(ground: Vec3, yaw: f64, pelvis: Vec3, height: f64) -> Vec3 {
    let offset = yawed(yaw, [pelvis[0], 0.0, pelvis[2]]);
    [ground[0] + offset[0], height, ground[2] + offset[2]]
}

fn pose_of(rots: &Rotations, yaw: f64, root: Vec3, offsets: &Offsets) -> Pose {
    let mut rots = *rots;
    rots[0] = Quat::from_yaw(yaw);
    forward_kinematics(&[rots], offsets, &[root])[0]
}

/// A key pose's bone rotations, pelvis (ground offset x, height over the floor, ground offset
/// z) and joints in its own frame (facing +Z, lowest joint on the floor).
fn shape(pose: &Pose, offsets: &Offsets) -> (Rotations, Vec3, Pose) {
    let usable = pose
        .iter()
        .flatten()
        .all(|c| c.is_finite() && c.abs() <= MAX_COORDINATE);
    let pelvis_xz = if usable {
        [pose[0][0], pose[0][2]]
    } else {
        [0.0, 0.0]
    };
    let mut rots = if usable {
        inverse_kinematics(&[*pose], false)[0]
    } else {
        [Quat::IDENTITY; NUM_JOINTS]
    };
    rots[0] = Quat::IDENTITY;
    let body = pose_of(&rots, 0.0, [0.0; 3], offsets);
    let pelvis = [pelvis_xz[0], -lowest(&body), pelvis_xz[1]];
    (rots, pelvis, body.map(|p| geom::add(p, pelvis)))
}

/// Where the body must stand so that its supports do not move needlessly: the ground offset
/// (metres, x and z) to add to `prev.ground + travel` for a key of shape `local` facing `yaw`.
///
/// Key poses are solved independently, each with its pelvis above the origin, so a squat's
/// feet sit ahead of a stand's. The supports of the new key (joints on the ground in both keys)
/// are expected where the old ones were, turned about the old pelvis and moved by `travel`; the
/// offset is the one that meets that expectation for the most limbs (all supports together
/// first, then each limb's own), ties going to the smaller total miss.
fn align(prev: &Key, local: &Pose, contact: &[bool; NUM_JOINTS], yaw: f64, travel: Vec3) -> Vec3 {
    let pelvis = prev.world[joint::PELVIS];
    let turn = yaw - prev.yaw;
    let flat = |v: Vec3| [v[0], 0.0, v[2]];
    let misses: Vec<Vec<Vec3>> = LIMBS
        .iter()
        .map(|limb| {
            limb.effectors()
                .filter(|&e| prev.contact[e] && contact[e])
                .map(|e| {
                    let expected = geom::add(
                        geom::add(pelvis, yawed(turn, geom::sub(prev.world[e], pelvis))),
                        travel,
                    );
                    let placed =
                        geom::add(geom::add(prev.ground, travel), yawed(yaw, flat(local[e])));
                    flat(geom::sub(expected, placed))
                })
                .collect()
        })
        .collect();
    let mean = |v: &[Vec3]| {
        let sum = v.iter().fold([0.0; 3], |a, b| geom::add(a, *b));
        geom::scale(sum, 1.0 / v.len().max(1) as f64)
    };
    let all: Vec<Vec3> = misses.iter().flatten().copied().collect();
    if all.is_empty() {
        return [0.0; 3];
    }
    let score = |offset: Vec3| {
        let kept = misses
            .iter()
            .filter(|m| {
                !m.is_empty() && m.iter().all(|d| geom::dist(*d, offset) <= PLANT_TOLERANCE)
            })
            .count();
        let miss: f64 = all.iter().map(|d| geom::dist(*d, offset)).sum();
        (kept, miss)
    };
    let mut best = mean(&all);
    let mut best_score = score(best);
    for m in misses.iter().filter(|m| !m.is_empty()) {
        let offset = mean(m);
        let s = score(offset);
        if s.0 > best_score.0 || (s.0 == best_score.0 && s.1 < best_score.1 - 1e-9) {
            (best, best_score) = (offset, s);
        }
    }
    best
}

/// A target from pins on some of a limb's effectors; an unpinned end or toe keeps its place
/// relative to the pinned one in `pose`.
fn pinned(limb: &Limb, end: Option<Vec3>, tip: Option<Vec3>, pose: &Pose) -> Option<Target> {
    match (end, limb.tip, tip) {
        (Some(end), _, Some(tip)) => Some(Target {
            end,
            tip: Some(tip),
            soft: 0.0,
        }),
        (Some(end), Some(t), None) => Some(Target {
            end,
            tip: Some(geom::add(end, geom::sub(pose[t], pose[limb.end]))),
            soft: 0.0,
        }),
        (Some(end), None, None) => Some(Target {
            end,
            tip: None,
            soft: 0.0,
        }),
        (None, Some(t), Some(tip)) => Some(Target {
            end: geom::add(tip, geom::sub(pose[limb.end], pose[t])),
            tip: Some(tip),
            soft: 0.0,
        }),
        _ => None,
    }
}

/// Holds the limbs on their targets: sinks the pelvis as far as needed (and allowed) for the
/// targets to be in reach, bends the limbs by two-bone IK, then lifts the body if any joint is
/// under the floor.
fn solve(pose: &mut Pose, targets: &[Option<Target>; 4], yaw: f64) {
    let bone = |j: usize| REFERENCE_BONE_LENGTHS[j];
    let mut drop = 0.0f64;
    for (limb, target) in LIMBS.iter().zip(targets) {
        let Some(target) = target else { continue };
        let reach = bone(limb.mid) + bone(limb.end);
        let root = pose[limb.root];
        let across = dist_xz(root, target.end);
        let allowed = (reach * reach - across * across).max(0.0).sqrt();
        drop = drop.max(root[1] - target.end[1] - allowed);
    }
    shift_y(pose, -drop.clamp(0.0, MAX_REACH_DROP));
    let forward = yawed(yaw, [0.0, 0.0, 1.0]);
    for (limb, target) in LIMBS.iter().zip(targets) {
        let Some(target) = target else { continue };
        // Knees bend over the toes (and forward when the foot gives no direction), elbows
        // backward.
        let hint = match (limb.tip, target.tip) {
            (Some(tip), Some(toe)) => {
                let foot = geom::sub(toe, target.end);
                let foot = geom::scale([foot[0], 0.0, foot[2]], 1.0 / bone(tip));
                geom::normalize(geom::add(foot, geom::scale(forward, 0.2)))
            }
            _ if limb.leg => forward,
            _ => geom::scale(forward, -1.0),
        };
        let (mid, end) = two_bone(
            [pose[limb.root], pose[limb.mid], pose[limb.end]],
            target.end,
            [bone(limb.mid), bone(limb.end)],
            hint,
            target.soft,
        );
        if let Some(tip) = limb.tip {
            let natural = geom::sub(pose[tip], pose[limb.end]);
            let aim = target
                .tip
                .map(|p| geom::sub(p, end))
                .filter(|d| geom::norm(*d) > 1e-9)
                .unwrap_or(natural);
            pose[tip] = geom::add(end, geom::scale(geom::normalize(aim), bone(tip)));
        }
        pose[limb.mid] = mid;
        pose[limb.end] = end;
    }
    let low = lowest(pose);
    if low < 0.0 {
        shift_y(pose, -low);
    }
}

impl Timeline {
    fn new(input: &[KeyPose]) -> Timeline {
        let mut timeline = Timeline {
            offsets: Offsets::reference(),
            keys: Vec::new(),
            plans: Vec::new(),
            landings: Vec::new(),
            total: 0.0,
        };
        let mut clock = 0.0;
        for (i, key) in input.iter().enumerate() {
            if i > 0 && clock >= MAX_SECONDS {
                break;
            }
            let (rots, pelvis, local) = shape(&key.pose, &timeline.offsets);
            let contact: [bool; NUM_JOINTS] =
                std::array::from_fn(|j| local[j][1] < contact_height(j));
            let (yaw, ground, takeoff, turn, flight) = match timeline.keys.last() {
                None => (0.0, [0.0; 3], [0.0; 3], 0.0, None),
                Some(prev) => {
                    let turn = finite_or_zero(key.turn_deg)
                        .clamp(-MAX_TURN_DEG, MAX_TURN_DEG)
                        .to_radians();
                    let [left, forward] = key
                        .travel
                        .map(|v| finite_or_zero(v).clamp(-MAX_TRAVEL, MAX_TRAVEL));
                    let travel = yawed(prev.yaw, [left, 0.0, forward]);
                    let yaw = prev.yaw + turn;
                    let ground = geom::add(
                        geom::add(prev.ground, travel),
                        align(prev, &local, &contact, yaw, travel),
                    );
                    // A jump takes off in its new shape from where it stands, still facing the
                    // old way; turn and travel happen in the air.
                    let takeoff = geom::add(
                        prev.ground,
                        align(prev, &local, &contact, prev.yaw, [0.0; 3]),
                    );
                    (yaw, ground, takeoff, turn, flight_of(key.motion))
                }
            };
            let root = root_position(ground, yaw, pelvis, pelvis[1]);
            timeline.keys.push(Key {
                world: pose_of(&rots, yaw, root, &timeline.offsets),
                rots,
                pelvis,
                contact,
                yaw,
                ground,
                takeoff,
                turn,
                trans: 0.0,
                hold: seconds(key.hold),
                flight,
                reached: 0.0,
            });
            if i == 0 {
                timeline.plans.push(Plan {
                    supports: Vec::new(),
                    support_a: 0.0,
                    support_b: 0.0,
                    limbs: [LimbMode::Free; 4],
                });
            } else {
                let plan = timeline.plan(i);
                timeline.plans.push(plan);
                let least = if flight.is_some() {
                    MIN_PUSH_OFF
                } else {
                    MIN_TRANSITION
                };
                let asked = seconds(key.transition).max(least);
                timeline.keys[i].trans =
                    asked.max(timeline.shortest_duration(i).min(MAX_KEY_SECONDS));
            }
            let key = &mut timeline.keys[i];
            key.reached = clock + key.trans + key.flight.map_or(0.0, |f| f.time);
            clock = key.reached + key.hold;
            if let Some(f) = key.flight {
                timeline.landings.push(Landing {
                    time: key.reached,
                    v0: f.v0,
                    tau: (LANDING_DIP * std::f64::consts::E / f.v0).min(LANDING_TIME),
                });
            }
        }
        timeline.total = clock.min(MAX_SECONDS);
        timeline
    }

    /// Decides, for the transition into key `b`, which limbs stay, step or follow the body.
    fn plan(&self, b: usize) -> Plan {
        let (ka, kb) = (&self.keys[b - 1], &self.keys[b]);
        // Knees and the pelvis carry weight too (kneeling, sitting, lying): the body's height
        // keeps them on the floor, though only hands and feet are pinned in place.
        let supports: Vec<usize> = LIMBS
            .iter()
            .flat_map(Limb::effectors)
            .chain([joint::L_KNEE, joint::R_KNEE, joint::PELVIS])
            .filter(|&e| ka.contact[e] && kb.contact[e])
            .collect();
        let support = |k: &Key| {
            supports
                .iter()
                .map(|&e| k.pelvis[1] - k.world[e][1])
                .fold(f64::NEG_INFINITY, f64::max)
        };
        let (support_a, support_b) = if supports.is_empty() {
            (0.0, 0.0)
        } else {
            (support(ka), support(kb))
        };
        let mut limbs = [LimbMode::Free; 4];
        if kb.flight.is_some() {
            for (mode, limb) in limbs.iter_mut().zip(&LIMBS) {
                if limb.effectors().any(|e| ka.contact[e]) {
                    *mode = LimbMode::PushOff;
                }
            }
        } else {
            let mut stepping = Vec::new();
            let mut stride = 0.0f64;
            for (li, limb) in LIMBS.iter().enumerate() {
                let on_a = limb.effectors().any(|e| ka.contact[e]);
                let on_b = limb.effectors().any(|e| kb.contact[e]);
                if !on_a && !on_b {
                    continue;
                }
                let shared: Vec<usize> = limb
                    .effectors()
                    .filter(|&e| ka.contact[e] && kb.contact[e])
                    .collect();
                let still = shared
                    .iter()
                    .all(|&e| dist_xz(ka.world[e], kb.world[e]) <= PLANT_TOLERANCE);
                if !shared.is_empty() && still && kb.turn.abs() <= PIVOT_DEG.to_radians() {
                    limbs[li] = LimbMode::Planted;
                } else if on_a && on_b {
                    stepping.push(li);
                    for e in limb.effectors() {
                        stride = stride.max(dist_xz(ka.world[e], kb.world[e]));
                    }
                } else {
                    // A hand or foot leaving the ground carries weight until the body has come
                    // down onto its next supports (standing to sitting or lying), rather than
                    // sliding out from under it.
                    limbs[li] = LimbMode::Moving {
                        slot: 0,
                        of: 1,
                        steps: 1,
                        stepping: false,
                        wait: if on_a { LEAVE_LATE } else { 0.0 },
                    };
                }
            }
            // Limbs step one at a time, the leading side first (a crawl's lateral sequence: leg,
            // then the arm on the same side).
            let order = if kb.turn >= 0.0 {
                [LEFT_LEG, LEFT_ARM, RIGHT_LEG, RIGHT_ARM]
            } else {
                [RIGHT_LEG, RIGHT_ARM, LEFT_LEG, LEFT_ARM]
            };
            let steps = (kb.turn.abs() / STEP_TURN_DEG.to_radians())
                .ceil()
                .max((stride / STEP_LENGTH).ceil())
                .clamp(1.0, MAX_STEPS as f64) as usize;
            let of = stepping.len();
            for (slot, &li) in order.iter().filter(|li| stepping.contains(li)).enumerate() {
                limbs[li] = LimbMode::Moving {
                    slot,
                    of,
                    steps,
                    stepping: true,
                    wait: 0.0,
                };
            }
        }
        Plan {
            supports,
            support_a,
            support_b,
            limbs,
        }
    }

    /// The shape between keys `b − 1` and `b` at `sigma` (0–1) placed at `ground` facing `yaw`,
    /// pelvis `extra` metres above where it keeps the supports on the floor.
    fn body(&self, b: usize, sigma: f64, yaw: f64, ground: Vec3, extra: f64) -> Pose {
        let (ka, kb, plan) = (&self.keys[b - 1], &self.keys[b], &self.plans[b]);
        let rots: Rotations = std::array::from_fn(|j| ka.rots[j].slerp(kb.rots[j], sigma));
        let mut pose = pose_of(&rots, yaw, [0.0; 3], &self.offsets);
        let pelvis = geom::lerp(ka.pelvis, kb.pelvis, sigma);
        // Interpolated shapes put the feet at heights neither key has; measuring the support
        // height of the shape itself keeps them on the floor, and subtracting its interpolation
        // leaves both ends exactly at the keys' heights.
        let correction = if plan.supports.is_empty() {
            0.0
        } else {
            let support = plan
                .supports
                .iter()
                .map(|&e| -pose[e][1])
                .fold(f64::NEG_INFINITY, f64::max);
            support - (plan.support_a + (plan.support_b - plan.support_a) * sigma)
        };
        let root = root_position(ground, yaw, pelvis, pelvis[1] + correction + extra);
        for p in pose.iter_mut() {
            *p = geom::add(*p, root);
        }
        if plan.supports.is_empty() {
            // Nothing carries the body from one key to the next (standing to lying): it rests
            // on whatever is lowest rather than floating between the keys' heights.
            let low = lowest(&pose) - extra;
            if low > 0.0 {
                shift_y(&mut pose, -low);
            }
        }
        pose
    }

    /// Where the body is at `sigma` of an eased transition into `b`, before contacts.
    fn natural(&self, b: usize, sigma: f64) -> Pose {
        let (ka, kb) = (&self.keys[b - 1], &self.keys[b]);
        let yaw = ka.yaw + sigma * kb.turn;
        self.body(b, sigma, yaw, geom::lerp(ka.ground, kb.ground, sigma), 0.0)
    }

    /// Target of a hand or foot that leaves the ground in the transition into `b`, at `u`: it
    /// stays where it was until `wait`, then lifts and joins the body's interpolated shape
    /// (whose limbs are always within reach of the body, unlike a place taken from another
    /// moment of the transition).
    fn leaving_target(&self, b: usize, limb: &Limb, u: f64, wait: f64) -> Target {
        let start = self.natural(b, 0.0);
        let now = self.natural(b, geom::ease(u));
        let r = ((u - wait) / (1.0 - wait)).clamp(0.0, 1.0);
        let join = geom::ease(r / 0.75);
        // Lifted while it moves, and kept up at the end only if the body holds it up there.
        let lift = MAX_LIFT * geom::ease(r / 0.25);
        let at = |j: usize| {
            let p = geom::lerp(start[j], now[j], join);
            [p[0], p[1].max(now[j][1] + lift * (1.0 - join)), p[2]]
        };
        Target {
            end: at(limb.end),
            tip: limb.tip.map(at),
            soft: geom::ease(r / 0.25),
        }
    }

    /// Target of a moving limb at `u` of the transition into `b`: pinned between its windows;
    /// inside one, lifted first, moved across while high, set down last.
    fn moving_target(
        &self,
        b: usize,
        limb: &Limb,
        u: f64,
        [slot, of, steps]: [usize; 3],
        stepping: bool,
    ) -> Target {
        let windows = (of * steps) as f64;
        let mut from = 0.0;
        let mut active = None;
        for k in 0..steps {
            // Each step lands where the limb will be when the body has done this step's share.
            let to = geom::ease((k + 1) as f64 / steps as f64);
            let start = (k * of + slot) as f64 / windows;
            if u < start {
                break;
            }
            if u < start + 1.0 / windows {
                active = Some(((u - start) * windows, to));
                break;
            }
            from = to;
        }
        match active {
            None => {
                let p = self.natural(b, from);
                Target {
                    end: p[limb.end],
                    tip: limb.tip.map(|t| p[t]),
                    soft: 0.0,
                }
            }
            Some((r, to)) => {
                let across = self.natural(b, from + (to - from) * geom::ease((r - 0.2) / 0.6));
                let up = self.natural(b, from + (to - from) * geom::ease(r));
                let stride = dist_xz(
                    self.natural(b, from)[limb.end],
                    self.natural(b, to)[limb.end],
                );
                let lift = if stepping || stride > PLANT_TOLERANCE {
                    (0.5 * stride).clamp(MIN_LIFT, MAX_LIFT)
                } else {
                    0.0
                };
                let raise = lift * bump(r);
                let at = |j: usize| [across[j][0], up[j][1] + raise, across[j][2]];
                Target {
                    end: at(limb.end),
                    tip: limb.tip.map(at),
                    soft: bump(r),
                }
            }
        }
    }

    /// A frame of the eased transition into `b` (or of the push-off before its flight) at `u`
    /// (0–1), with the pelvis `dip` metres lower; `launch` adds the push-off's countermovement.
    fn ease_pose(&self, b: usize, u: f64, dip: f64, launch: bool) -> Pose {
        let (ka, kb, plan) = (&self.keys[b - 1], &self.keys[b], &self.plans[b]);
        let s = geom::ease(u);
        let mut targets = [None; 4];
        let (yaw, mut pose) = match kb.flight {
            Some(f) => {
                let ground = geom::lerp(ka.ground, kb.takeoff, s);
                let natural = self.body(b, s, ka.yaw, ground, 0.0);
                // u³ − u² is 0 at both ends and climbs at 1/push-off at take-off: the pelvis
                // leaves at the flight's speed after dipping below the shape's path.
                let spring = if launch {
                    f.v0 * kb.trans * (u * u * u - u * u)
                } else {
                    0.0
                };
                let mut pose = natural;
                shift_y(&mut pose, dip + spring);
                for (li, limb) in LIMBS.iter().enumerate() {
                    if plan.limbs[li] == LimbMode::PushOff {
                        let pin = |e: usize| ka.contact[e].then_some(ka.world[e]);
                        targets[li] = pinned(limb, pin(limb.end), limb.tip.and_then(pin), &pose);
                    }
                }
                (ka.yaw, pose)
            }
            None => {
                let yaw = ka.yaw + s * kb.turn;
                let mut pose = self.body(b, s, yaw, geom::lerp(ka.ground, kb.ground, s), 0.0);
                shift_y(&mut pose, dip);
                for (li, limb) in LIMBS.iter().enumerate() {
                    targets[li] = match plan.limbs[li] {
                        LimbMode::Planted => {
                            let pin = |e: usize| {
                                (ka.contact[e] && kb.contact[e])
                                    .then(|| geom::lerp(ka.world[e], kb.world[e], s))
                            };
                            pinned(limb, pin(limb.end), limb.tip.and_then(pin), &pose)
                        }
                        LimbMode::Moving { wait, .. } if wait > 0.0 => {
                            Some(self.leaving_target(b, limb, u, wait))
                        }
                        LimbMode::Moving {
                            slot,
                            of,
                            steps,
                            stepping,
                            ..
                        } => Some(self.moving_target(b, limb, u, [slot, of, steps], stepping)),
                        _ => None,
                    };
                }
                (yaw, pose)
            }
        };
        solve(&mut pose, &targets, yaw);
        if plan.supports.is_empty() && kb.flight.is_none() {
            // A lifted hand or foot may have been what the body rested on.
            let low = lowest(&pose) - dip.max(0.0);
            if low > 0.0 {
                shift_y(&mut pose, -low);
            }
        }
        pose
    }

    /// A frame `t` seconds into the flight into `b`.
    fn flight_pose(&self, b: usize, t: f64, dip: f64, flight: Flight) -> Pose {
        let (ka, kb) = (&self.keys[b - 1], &self.keys[b]);
        let q = (t / flight.time).clamp(0.0, 1.0);
        let yaw = ka.yaw + q * kb.turn;
        let ground = geom::lerp(kb.takeoff, kb.ground, q);
        let height = kb.pelvis[1] + dip + flight.v0 * t - 0.5 * GRAVITY * t * t;
        // The feet leave the ground where they pushed off and take the landing shape in the
        // air (a jumping jack's legs open while airborne, not by sliding apart on the floor).
        let mut takeoff = inverse_kinematics(&[self.ease_pose(b, 1.0, 0.0, true)], false)[0];
        takeoff[0] = Quat::IDENTITY;
        let mix = geom::ease(q / FLIGHT_SHAPING);
        let rots: Rotations = std::array::from_fn(|j| takeoff[j].slerp(kb.rots[j], mix));
        let mut pose = pose_of(
            &rots,
            yaw,
            root_position(ground, yaw, kb.pelvis, height),
            &self.offsets,
        );
        solve(&mut pose, &[None; 4], yaw);
        pose
    }

    /// A frame of key `k` held, with the pelvis `dip` metres lower.
    fn hold_pose(&self, k: usize, dip: f64) -> Pose {
        let key = &self.keys[k];
        let mut pose = key.world;
        shift_y(&mut pose, dip);
        let pin = |e: usize| key.contact[e].then_some(key.world[e]);
        let targets = std::array::from_fn(|li| {
            let limb = &LIMBS[li];
            pinned(limb, pin(limb.end), limb.tip.and_then(pin), &pose)
        });
        solve(&mut pose, &targets, key.yaw);
        pose
    }

    /// The shortest duration of the transition into `b` (its push-off for a flight) that keeps
    /// every joint under [`MAX_JOINT_SPEED`]: the peak of |d position / d u| over the
    /// transition's own frames (no landing dip, no launch), divided by the speed.
    fn shortest_duration(&self, b: usize) -> f64 {
        let windows = self.plans[b]
            .limbs
            .iter()
            .map(|m| match m {
                LimbMode::Moving { of, steps, .. } => of * steps,
                _ => 1,
            })
            .max()
            .unwrap_or(1);
        let samples = 32 * windows.max(2);
        let mut prev = self.ease_pose(b, 0.0, 0.0, false);
        let mut peak = 0.0f64;
        for i in 1..=samples {
            let pose = self.ease_pose(b, i as f64 / samples as f64, 0.0, false);
            let moved = prev
                .iter()
                .zip(&pose)
                .map(|(p, q)| geom::dist(*p, *q))
                .fold(0.0, f64::max);
            peak = peak.max(moved * samples as f64);
            prev = pose;
        }
        if peak.is_finite() {
            peak * SPEED_MARGIN / MAX_JOINT_SPEED
        } else {
            0.0
        }
    }

    /// The landing dips active at `t`: the pelvis keeps its landing speed into a dip that
    /// recovers with time constant `tau` (−v₀·τ·e^(−τ/tau), deepest at v₀·tau/e).
    fn dip(&self, t: f64) -> f64 {
        let landed = self.landings.partition_point(|l| l.time <= t);
        self.landings[..landed]
            .iter()
            .rev()
            .take_while(|l| t - l.time < DIP_WINDOW)
            .map(|l| {
                let since = t - l.time;
                -l.v0 * since * (-since / l.tau).exp()
            })
            .sum()
    }

    fn frame_at(&self, t: f64) -> Pose {
        let k = self
            .keys
            .partition_point(|k| k.reached + k.hold < t)
            .min(self.keys.len() - 1);
        let key = &self.keys[k];
        let dip = self.dip(t);
        if k > 0 && t < key.reached {
            let airborne = key.flight.map_or(0.0, |f| f.time);
            let local = (t - (key.reached - airborne - key.trans)).max(0.0);
            match key.flight {
                Some(f) if local > key.trans => {
                    self.flight_pose(k, (local - key.trans).min(f.time), dip, f)
                }
                _ => self.ease_pose(k, (local / key.trans).min(1.0), dip, true),
            }
        } else {
            self.hold_pose(k, dip)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::probes::foot_skating;
    use crate::skeleton::PARENTS;

    fn rot_x(deg: f64) -> Quat {
        Quat::from_axis_angle([1.0, 0.0, 0.0], deg.to_radians())
    }

    fn rot_z(deg: f64) -> Quat {
        Quat::from_axis_angle([0.0, 0.0, 1.0], deg.to_radians())
    }

    /// The reference skeleton posed by `rots`, lowest joint on the floor.
    fn pose_from(rots: Rotations) -> Pose {
        let mut pose = forward_kinematics(&[rots], &Offsets::reference(), &[[0.0; 3]])[0];
        let low = lowest(&pose);
        shift_y(&mut pose, -low);
        pose
    }

    fn standing() -> Pose {
        pose_from([Quat::IDENTITY; NUM_JOINTS])
    }

    fn arms_out() -> Pose {
        let mut rots = [Quat::IDENTITY; NUM_JOINTS];
        rots[joint::L_ELBOW] = rot_z(90.0);
        rots[joint::R_ELBOW] = rot_z(-90.0);
        pose_from(rots)
    }

    /// Thighs raised `hip` degrees forward, knees bent `knee` degrees, feet flat, torso leaning
    /// forward; pelvis above the origin as the posture solver leaves it, so the feet are ahead
    /// of where they are standing.
    fn bent(hip: f64, knee: f64, lean: f64) -> Pose {
        let mut rots = [Quat::IDENTITY; NUM_JOINTS];
        for (thigh, shin, foot) in [
            (joint::L_KNEE, joint::L_ANKLE, joint::L_FOOT),
            (joint::R_KNEE, joint::R_ANKLE, joint::R_FOOT),
        ] {
            rots[thigh] = rot_x(-hip);
            rots[shin] = rot_x(knee);
            rots[foot] = rot_x(hip - knee);
        }
        rots[joint::SPINE1] = rot_x(lean);
        pose_from(rots)
    }

    fn squat() -> Pose {
        bent(80.0, 110.0, 30.0)
    }

    fn crouch() -> Pose {
        bent(50.0, 90.0, 20.0)
    }

    /// On hands and knees: trunk pitched forward, thighs and arms vertical, shins and feet
    /// flat behind; the pitch is chosen so hands and knees touch the floor together.
    fn hands_and_knees() -> Pose {
        let build = |pitch: f64| {
            let mut rots = [Quat::IDENTITY; NUM_JOINTS];
            rots[0] = rot_x(pitch);
            for (thigh, shin, foot) in [
                (joint::L_KNEE, joint::L_ANKLE, joint::L_FOOT),
                (joint::R_KNEE, joint::R_ANKLE, joint::R_FOOT),
            ] {
                rots[thigh] = rot_x(-pitch);
                rots[shin] = rot_x(90.0);
                rots[foot] = rot_x(90.0);
            }
            rots[joint::L_ELBOW] = rot_x(-pitch);
            rots[joint::R_ELBOW] = rot_x(-pitch);
            pose_from(rots)
        };
        let gap = |p: &Pose| (p[joint::L_WRIST][1] - p[joint::L_KNEE][1]).abs();
        (0..=100)
            .map(|i| build(40.0 + 0.5 * i as f64))
            .min_by(|a, b| gap(a).total_cmp(&gap(b)))
            .unwrap()
    }

    /// Facing angle (radians from +Z towards +X) from the hips.
    fn facing(pose: &Pose) -> f64 {
        let across = geom::sub(pose[joint::L_HIP], pose[joint::R_HIP]);
        let forward = geom::cross(across, [0.0, 1.0, 0.0]);
        forward[0].atan2(forward[2])
    }

    const FEET: [usize; 4] = [joint::L_ANKLE, joint::R_ANKLE, joint::L_FOOT, joint::R_FOOT];

    /// How far any foot joint gets from where it started on the ground plane, and how far it
    /// leaves the range of heights it has in the frames `keys` (where the keys are held).
    fn foot_drift(motion: &[Pose], keys: &[usize]) -> (f64, f64) {
        let mut drift = (0.0f64, 0.0f64);
        for f in FEET {
            let heights = keys.iter().map(|&k| motion[k][f][1]);
            let low = heights.clone().fold(f64::INFINITY, f64::min);
            let high = heights.fold(f64::NEG_INFINITY, f64::max);
            for pose in motion {
                drift.0 = drift.0.max(dist_xz(pose[f], motion[0][f]));
                drift.1 = drift.1.max(low - pose[f][1]).max(pose[f][1] - high);
            }
        }
        drift
    }

    fn arms_motion() -> Vec<Pose> {
        go(&[
            KeyPose::new(standing(), 0.0, 0.5),
            KeyPose::new(arms_out(), 1.0, 0.5),
            KeyPose::new(standing(), 1.0, 0.3),
        ])
    }

    fn squats() -> Vec<Pose> {
        go(&repeat(
            &[
                KeyPose::new(standing(), 1.0, 0.3),
                KeyPose::new(squat(), 1.0, 0.3),
            ],
            3,
        ))
    }

    fn spin() -> Vec<Pose> {
        go(&[
            KeyPose::new(standing(), 0.0, 0.2),
            KeyPose {
                turn_deg: 360.0,
                ..KeyPose::new(standing(), 2.0, 0.2)
            },
        ])
    }

    fn jump() -> Vec<Pose> {
        go(&[
            KeyPose::new(standing(), 0.0, 0.3),
            KeyPose::new(crouch(), 0.6, 0.2),
            KeyPose {
                motion: Transition::Flight { apex_m: 0.4 },
                ..KeyPose::new(standing(), 0.3, 0.8)
            },
        ])
    }

    fn crawl_keys() -> Vec<KeyPose> {
        let stride = KeyPose {
            travel: [0.0, 0.2],
            ..KeyPose::new(hands_and_knees(), 0.8, 0.0)
        };
        repeat(&[stride, stride], 3)
    }

    fn eased_motions() -> Vec<(&'static str, Vec<Pose>)> {
        vec![
            ("arms", arms_motion()),
            ("squats", squats()),
            ("spin", spin()),
            ("crawl", go(&crawl_keys())),
        ]
    }

    #[test]
    fn bones_keep_the_reference_lengths() {
        let mut all = eased_motions();
        all.push(("jump", jump()));
        for (name, motion) in all {
            assert!(!motion.is_empty(), "{name}");
            for (f, pose) in motion.iter().enumerate() {
                for j in 1..NUM_JOINTS {
                    let parent = PARENTS[j].unwrap();
                    let length = geom::dist(pose[j], pose[parent]);
                    let error = (length - REFERENCE_BONE_LENGTHS[j]).abs();
                    assert!(error < 1e-3, "{name} frame {f} bone {j}: off by {error}");
                }
            }
        }
    }

    #[test]
    fn nothing_goes_under_the_floor() {
        let mut all = eased_motions();
        all.push(("jump", jump()));
        for (name, motion) in all {
            let low = motion.iter().map(lowest).fold(f64::INFINITY, f64::min);
            assert!(low > -0.02, "{name}: lowest joint at {low}");
        }
    }

    #[test]
    fn a_hold_keeps_the_pose_still() {
        let motion = go(&[
            KeyPose::new(standing(), 0.0, 1.0),
            KeyPose::new(arms_out(), 0.8, 1.0),
        ]);
        // 1 s hold, 0.8 s transition, 1 s hold: 57 frames.
        assert_eq!(motion.len(), 57);
        let first_hold = &motion[..=20];
        let last_hold = &motion[36..];
        for hold in [first_hold, last_hold] {
            for pose in hold {
                let moved = pose
                    .iter()
                    .zip(&hold[0])
                    .map(|(a, b)| geom::dist(*a, *b))
                    .fold(0.0, f64::max);
                assert!(moved < 1e-9, "moved {moved} during a hold");
            }
        }
        // The first frame is the key itself: at the origin, facing +Z, on the floor.
        let start = standing();
        for (a, b) in motion[0].iter().zip(&start) {
            assert!(geom::dist(*a, *b) < 1e-6);
        }
        // The held end is the second key (arms out sideways at shoulder height).
        let end = motion.last().unwrap();
        assert!((end[joint::L_WRIST][1] - end[joint::L_SHOULDER][1]).abs() < 1e-6);
    }

    #[test]
    fn transitions_ease_in_and_out() {
        let motion = arms_motion();
        // The transition runs from frame 10 to frame 30: the wrist starts and stops gently.
        let speed = |f: usize| geom::dist(motion[f][joint::L_WRIST], motion[f + 1][joint::L_WRIST]);
        assert!(speed(9) < 1e-9 && speed(30) < 1e-9);
        assert!(speed(10) < 0.15 * speed(19) && speed(29) < 0.15 * speed(19));
    }

    #[test]
    fn a_full_spin_passes_through_half_and_ends_where_it_began() {
        let motion = spin();
        let yaws: Vec<f64> = motion.iter().map(facing).collect();
        assert!(yaws[0].abs() < 1e-6);
        assert!(
            yaws.last().unwrap().cos() > 0.9999,
            "ends at {}",
            yaws.last().unwrap()
        );
        assert!(
            yaws.iter().any(|y| y.cos() < -0.99),
            "never faced backwards"
        );
        let mut turned = 0.0;
        for w in yaws.windows(2) {
            let mut d = w[1] - w[0];
            while d > std::f64::consts::PI {
                d -= std::f64::consts::TAU;
            }
            while d < -std::f64::consts::PI {
                d += std::f64::consts::TAU;
            }
            turned += d;
        }
        assert!(
            (turned - std::f64::consts::TAU).abs() < 0.01,
            "turned {turned}"
        );
        // The body spins in place.
        let start = motion[0][joint::PELVIS];
        for pose in &motion {
            assert!(dist_xz(pose[joint::PELVIS], start) < 0.01);
        }
    }

    #[test]
    fn a_left_turn_with_travel_faces_and_moves_as_asked() {
        let motion = go(&[
            KeyPose::new(standing(), 0.0, 0.0),
            KeyPose {
                turn_deg: 90.0,
                travel: [0.0, 0.5],
                ..KeyPose::new(standing(), 1.5, 0.2)
            },
            KeyPose {
                travel: [0.0, 0.4],
                ..KeyPose::new(standing(), 1.0, 0.2)
            },
        ]);
        let end = motion.last().unwrap();
        // Turning left from +Z faces +X; the second stride goes along +X.
        assert!((facing(end) - std::f64::consts::FRAC_PI_2).abs() < 1e-6);
        let pelvis = end[joint::PELVIS];
        assert!((pelvis[0] - 0.4).abs() < 1e-6 && (pelvis[2] - 0.5).abs() < 1e-6);
        assert!(foot_skating(&motion) == 0.0);
    }

    #[test]
    fn a_jump_flies_to_its_apex_and_lands() {
        let motion = jump();
        let stand = standing()[joint::PELVIS][1];
        let (top, peak) = motion
            .iter()
            .enumerate()
            .max_by(|a, b| a.1[joint::PELVIS][1].total_cmp(&b.1[joint::PELVIS][1]))
            .unwrap();
        let rise = peak[joint::PELVIS][1] - stand;
        assert!((rise - 0.4).abs() < 0.02, "pelvis rose {rise}");
        assert!(
            lowest(peak) > 0.05,
            "lowest joint at {} at the apex",
            lowest(peak)
        );
        // Airborne about as long as the apex demands: 2·√(2·0.4/9.81) s ≈ 11.4 frames.
        let airborne = motion.iter().filter(|p| lowest(p) > 0.01).count();
        assert!((9..=13).contains(&airborne), "{airborne} frames airborne");
        assert!(top > 20 && top < motion.len() - 10);
        // It lands and settles back in the key, on the floor where it took off.
        let end = motion.last().unwrap();
        assert!((end[joint::PELVIS][1] - stand).abs() < 1e-3);
        assert!(lowest(end).abs() < 1e-9);
        assert!(dist_xz(end[joint::L_ANKLE], motion[0][joint::L_ANKLE]) < 1e-6);

        // A half-turn jump forward turns and travels in the air and lands facing back.
        let motion = go(&[
            KeyPose::new(standing(), 0.0, 0.2),
            KeyPose::new(crouch(), 0.6, 0.1),
            KeyPose {
                motion: Transition::Flight { apex_m: 0.3 },
                turn_deg: 180.0,
                travel: [0.0, 0.5],
                ..KeyPose::new(standing(), 0.3, 0.5)
            },
        ]);
        let end = motion.last().unwrap();
        assert!(facing(end).cos() < -0.9999, "faces {}", facing(end));
        let moved = end[joint::PELVIS][2] - motion[0][joint::PELVIS][2];
        assert!((moved - 0.5).abs() < 0.15, "moved {moved}");
        let airborne: Vec<&Pose> = motion.iter().filter(|p| lowest(p) > 0.01).collect();
        let turned = |p: &Pose| facing(p).cos();
        assert!(turned(airborne[0]) > 0.9 && turned(airborne[airborne.len() - 1]) < -0.9);
    }

    #[test]
    fn planted_feet_do_not_skate() {
        // Standing and squatting, the reference skeleton's right foot hangs 1 cm and 0.65 cm
        // above the floor (its right leg is shorter): a planted foot may only move between
        // the heights the keys give it (frame 28 is in the first squat's hold).
        for (name, motion, keys) in [
            ("arms", arms_motion(), vec![0]),
            ("squats", squats(), vec![0, 28]),
        ] {
            assert_eq!(foot_skating(&motion), 0.0, "{name}");
            let (across, up) = foot_drift(&motion, &keys);
            assert!(across < 1e-3, "{name}: feet slid {across} m");
            assert!(up < 1e-3, "{name}: feet rose or sank {up} m");
        }
        // The squats really squat.
        let motion = squats();
        let low = motion
            .iter()
            .map(|p| p[joint::PELVIS][1])
            .fold(f64::INFINITY, f64::min);
        assert!(low < standing()[joint::PELVIS][1] - 0.3);
    }

    #[test]
    fn a_crawl_cycle_travels_the_sum_of_its_strides() {
        let keys = crawl_keys();
        assert_eq!(keys.len(), 7);
        let motion = go(&keys);
        let travel: f64 = keys[1..].iter().map(|k| k.travel[1]).sum();
        let start = motion[0][joint::PELVIS];
        let end = motion.last().unwrap()[joint::PELVIS];
        assert!(
            (end[2] - start[2] - travel).abs() < 1e-3,
            "moved {}",
            end[2] - start[2]
        );
        assert!((end[0] - start[0]).abs() < 1e-3);
        // Hands and feet step one at a time: they do not drag along the floor.
        assert_eq!(foot_skating(&motion), 0.0);
        let crawl = hands_and_knees();
        assert!(crawl[joint::L_WRIST][1] < contact_height(joint::L_WRIST));
        assert!(crawl[joint::L_ANKLE][1] < contact_height(joint::L_ANKLE));
    }

    #[test]
    fn joints_never_move_too_fast_outside_flight() {
        for (name, motion) in eased_motions() {
            let fastest = max_joint_speed(&motion);
            assert!(fastest <= MAX_JOINT_SPEED + 1e-9, "{name}: {fastest} m/s");
        }
        // A transition asked to take no time is lengthened, not a teleport.
        let motion = go(&[
            KeyPose::new(standing(), 0.0, 0.0),
            KeyPose::new(squat(), 0.0, 0.0),
        ]);
        assert!(motion.len() > 4, "{} frames", motion.len());
        assert!(max_joint_speed(&motion) <= MAX_JOINT_SPEED + 1e-9);
        assert_eq!(foot_skating(&motion), 0.0);
    }

    #[test]
    fn odd_input_gives_a_finite_motion() {
        assert!(go(&[]).is_empty());
        assert!(repeat(&[], 3).is_empty());
        assert!(repeat(&[KeyPose::new(standing(), 1.0, 0.0)], 0).is_empty());
        assert_eq!(go(&[KeyPose::new(standing(), 0.0, 0.0)]).len(), 1);
        let mut broken = standing();
        broken[3][1] = f64::NAN;
        let weird = [
            KeyPose::new(standing(), f64::NAN, -1.0),
            KeyPose {
                turn_deg: f64::INFINITY,
                travel: [f64::NAN, 1e300],
                ..KeyPose::new(broken, -5.0, f64::INFINITY)
            },
            KeyPose {
                motion: Transition::Flight { apex_m: f64::NAN },
                ..KeyPose::new([[0.0; 3]; NUM_JOINTS], 0.0, 0.0)
            },
            KeyPose {
                motion: Transition::Flight { apex_m: 1e9 },
                turn_deg: -720.0,
                ..KeyPose::new([[1e200; 3]; NUM_JOINTS], 0.0, 0.1)
            },
            KeyPose {
                motion: Transition::Flight { apex_m: -1.0 },
                ..KeyPose::new(hands_and_knees(), 0.0, 0.0)
            },
        ];
        let motion = go(&weird);
        assert!(!motion.is_empty());
        assert!(motion.len() as f64 <= MAX_SECONDS * FPS + 1.0);
        assert!(motion.iter().flatten().flatten().all(|c| c.is_finite()));
        assert!(motion.iter().map(lowest).fold(f64::INFINITY, f64::min) > -0.02);
        assert_eq!(go(&weird), motion, "not deterministic");
        assert_eq!(repeat(&weird, usize::MAX).len(), MAX_REPEAT_KEYS);
    }

    #[test]
    fn a_solved_squat_keeps_its_toes_planted() {
        // Keys as the posture solver makes them: each with its pelvis above the origin, so the
        // squat's feet are not where the standing feet are until `go` sets them there.
        use crate::posture::{script::PostureScript, solver};
        let stand = solver::pose_of(&solver::rest_angles());
        let script = PostureScript::parse(
            r#"{"name":"squat","constraints":[
            {"kind":"level","is":"crouching"},
            {"kind":"bend","joint":"left_knee","is":"completely_bent"},
            {"kind":"bend","joint":"right_knee","is":"completely_bent"},
            {"kind":"orientation","limb":"left_thigh","is":"horizontal"},
            {"kind":"orientation","limb":"right_thigh","is":"horizontal"},
            {"kind":"contact","point":"left_foot","on_ground":true},
            {"kind":"contact","point":"right_foot","on_ground":true},
            {"kind":"lean","is":"forward"}]}"#,
        )
        .expect("a valid squat script");
        let squat = solver::solve(&script, None).pose;
        let motion = go(&repeat(
            &[KeyPose::new(stand, 1.0, 0.3), KeyPose::new(squat, 1.0, 0.3)],
            2,
        ));
        assert_eq!(foot_skating(&motion), 0.0);
        for toe in [joint::L_FOOT, joint::R_FOOT] {
            for pose in &motion {
                assert!(dist_xz(pose[toe], motion[0][toe]) <= PLANT_TOLERANCE);
            }
        }
        assert!(max_joint_speed(&motion) <= MAX_JOINT_SPEED + 1e-9);
        assert!(motion.iter().map(lowest).fold(f64::INFINITY, f64::min) > -0.02);
    }
}
