//! Whole-body pose codes: what a posture script (see `crate::posture`) can ask of a pose beyond
//! the per-limb codes of [`super::frame_codes`] — any pair of body points, the torso's lean and
//! twist, what touches the ground and how high the pelvis is. Each reading has a continuous
//! measure (metres or degrees) and the category the describer reports, with the same bands as
//! the per-limb codes.

use super::frame::{
    horizontal_unit, BodyFrame, FOOT_CONTACT_M, KNEE_CONTACT_M, LEFT_LEG, RIGHT_LEG,
};
use super::{Depth, Side, Vertical};
use crate::geom::{self, Vec3};
use crate::skeleton::{joint, Pose};
use serde::{Deserialize, Serialize};

const UP: Vec3 = [0.0, 1.0, 0.0];

/// A wrist within this many metres of the floor is a hand on the ground (the joint sits a few
/// centimetres above the palm).
pub const HAND_CONTACT_M: f64 = 0.10;
/// A pelvis joint within this many metres of the floor rests on the ground (sitting or lying):
/// the joint is about 10 cm inside the body above the buttocks.
pub const PELVIS_CONTACT_M: f64 = 0.25;
/// A torso (pelvis to neck) within this many degrees of the vertical is upright; beyond it, it
/// leans.
pub const UPRIGHT_MAX_DEG: f64 = 20.0;
/// A torso more than this many degrees from the vertical with a low pelvis is lying (or in a
/// plank).
pub const LYING_MIN_DEG: f64 = 60.0;
/// Shoulders turned more than this many degrees against the hips are a twisted torso.
pub const TWIST_MIN_DEG: f64 = 20.0;
/// Pelvis height (metres above the floor) under which a pose with a horizontal torso is lying
/// whatever else touches the ground.
pub const LYING_PELVIS_M: f64 = 0.30;
/// Pelvis height under which a pose with a horizontal torso and no knee down is lying on its
/// hands and feet (a plank).
pub const PLANK_PELVIS_M: f64 = 0.60;
/// Pelvis height under which a pose (not kneeling, not lying) is crouching; the reference
/// skeleton stands with its pelvis about 0.93 m above the floor.
pub const CROUCH_PELVIS_M: f64 = 0.75;

/// A named point of the body that a posture script can relate to another.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyPoint {
    Head,
    Neck,
    Chest,
    Pelvis,
    LeftShoulder,
    RightShoulder,
    LeftElbow,
    RightElbow,
    LeftHand,
    RightHand,
    LeftHip,
    RightHip,
    LeftKnee,
    RightKnee,
    LeftFoot,
    RightFoot,
}

impl BodyPoint {
    /// Every point, in the order of the schema.
    pub const ALL: [BodyPoint; 16] = [
        BodyPoint::Head,
        BodyPoint::Neck,
        BodyPoint::Chest,
        BodyPoint::Pelvis,
        BodyPoint::LeftShoulder,
        BodyPoint::RightShoulder,
        BodyPoint::LeftElbow,
        BodyPoint::RightElbow,
        BodyPoint::LeftHand,
        BodyPoint::RightHand,
        BodyPoint::LeftHip,
        BodyPoint::RightHip,
        BodyPoint::LeftKnee,
        BodyPoint::RightKnee,
        BodyPoint::LeftFoot,
        BodyPoint::RightFoot,
    ];

    /// The skeleton joint that stands for the point: a hand is its wrist, a foot its ankle,
    /// the chest the top of the spine.
    pub fn joint(self) -> usize {
        match self {
            BodyPoint::Head => joint::HEAD,
            BodyPoint::Neck => joint::NECK,
            BodyPoint::Chest => joint::SPINE3,
            BodyPoint::Pelvis => joint::PELVIS,
            BodyPoint::LeftShoulder => joint::L_SHOULDER,
            BodyPoint::RightShoulder => joint::R_SHOULDER,
            BodyPoint::LeftElbow => joint::L_ELBOW,
            BodyPoint::RightElbow => joint::R_ELBOW,
            BodyPoint::LeftHand => joint::L_WRIST,
            BodyPoint::RightHand => joint::R_WRIST,
            BodyPoint::LeftHip => joint::L_HIP,
            BodyPoint::RightHip => joint::R_HIP,
            BodyPoint::LeftKnee => joint::L_KNEE,
            BodyPoint::RightKnee => joint::R_KNEE,
            BodyPoint::LeftFoot => joint::L_ANKLE,
            BodyPoint::RightFoot => joint::R_ANKLE,
        }
    }

    /// Words for the point ("the left hand").
    pub fn as_str(self) -> &'static str {
        match self {
            BodyPoint::Head => "the head",
            BodyPoint::Neck => "the neck",
            BodyPoint::Chest => "the chest",
            BodyPoint::Pelvis => "the pelvis",
            BodyPoint::LeftShoulder => "the left shoulder",
            BodyPoint::RightShoulder => "the right shoulder",
            BodyPoint::LeftElbow => "the left elbow",
            BodyPoint::RightElbow => "the right elbow",
            BodyPoint::LeftHand => "the left hand",
            BodyPoint::RightHand => "the right hand",
            BodyPoint::LeftHip => "the left hip",
            BodyPoint::RightHip => "the right hip",
            BodyPoint::LeftKnee => "the left knee",
            BodyPoint::RightKnee => "the right knee",
            BodyPoint::LeftFoot => "the left foot",
            BodyPoint::RightFoot => "the right foot",
        }
    }
}

/// Where one body point is relative to another: height, depth along the body's facing, or
/// side, each with the neutral band of the per-limb codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Relation {
    /// Higher by more than [`super::HEIGHT_BAND_M`].
    Above,
    /// Lower by more than the height band.
    Below,
    /// Within the height band.
    LevelWith,
    /// Further forward (along the body's facing) by more than [`super::DEPTH_BAND_M`].
    InFrontOf,
    /// Further back by more than the depth band.
    Behind,
    /// Further to the character's own left by more than [`super::MIDLINE_BAND_M`].
    LeftOf,
    /// Further to the character's own right by more than the midline band.
    RightOf,
}

impl Relation {
    /// Every category, from the first to the last.
    pub const ALL: [Relation; 7] = [
        Relation::Above,
        Relation::Below,
        Relation::LevelWith,
        Relation::InFrontOf,
        Relation::Behind,
        Relation::LeftOf,
        Relation::RightOf,
    ];

    /// Which axis of the body frame the relation reads: 0 left, 1 up, 2 forward.
    pub fn axis(self) -> usize {
        match self {
            Relation::Above | Relation::Below | Relation::LevelWith => 1,
            Relation::InFrontOf | Relation::Behind => 2,
            Relation::LeftOf | Relation::RightOf => 0,
        }
    }

    /// The relation of `b` to `a` when `a` has this one to `b`.
    pub fn converse(self) -> Relation {
        match self {
            Relation::Above => Relation::Below,
            Relation::Below => Relation::Above,
            Relation::LevelWith => Relation::LevelWith,
            Relation::InFrontOf => Relation::Behind,
            Relation::Behind => Relation::InFrontOf,
            Relation::LeftOf => Relation::RightOf,
            Relation::RightOf => Relation::LeftOf,
        }
    }

    /// Words for the relation ("in front of").
    pub fn as_str(self) -> &'static str {
        match self {
            Relation::Above => "above",
            Relation::Below => "below",
            Relation::LevelWith => "level with",
            Relation::InFrontOf => "in front of",
            Relation::Behind => "behind",
            Relation::LeftOf => "to the left of",
            Relation::RightOf => "to the right of",
        }
    }

    /// Whether an offset (metres, `a` minus `b` along [`Relation::axis`]) reads as this
    /// relation.
    pub fn holds_for(self, offset: f64) -> bool {
        match self {
            Relation::Above => Vertical::from_offset(offset) == Vertical::Above,
            Relation::Below => Vertical::from_offset(offset) == Vertical::Below,
            Relation::LevelWith => Vertical::from_offset(offset) == Vertical::Level,
            Relation::InFrontOf => Depth::from_offset(offset) == Depth::InFront,
            Relation::Behind => Depth::from_offset(offset) == Depth::Behind,
            Relation::LeftOf => Side::from_offset(offset) == Side::Left,
            Relation::RightOf => Side::from_offset(offset) == Side::Right,
        }
    }
}

/// Offset of `a` from `b` in metres along `axis` of the pose's body frame (0 left, 1 up,
/// 2 forward; see [`super::facing`]).
pub fn relative_offset(pose: &Pose, a: BodyPoint, b: BodyPoint, axis: usize) -> f64 {
    let body = BodyFrame::of(pose);
    body.dir(geom::sub(pose[a.joint()], pose[b.joint()]))[axis]
}

/// A bone a posture script can orient.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Limb {
    LeftUpperArm,
    RightUpperArm,
    LeftForearm,
    RightForearm,
    LeftThigh,
    RightThigh,
    LeftShin,
    RightShin,
    /// Pelvis to neck.
    Torso,
}

impl Limb {
    /// Every limb, in the order of the schema.
    pub const ALL: [Limb; 9] = [
        Limb::LeftUpperArm,
        Limb::RightUpperArm,
        Limb::LeftForearm,
        Limb::RightForearm,
        Limb::LeftThigh,
        Limb::RightThigh,
        Limb::LeftShin,
        Limb::RightShin,
        Limb::Torso,
    ];

    /// The joints at the limb's two ends (from, to).
    pub fn joints(self) -> (usize, usize) {
        match self {
            Limb::LeftUpperArm => (joint::L_SHOULDER, joint::L_ELBOW),
            Limb::RightUpperArm => (joint::R_SHOULDER, joint::R_ELBOW),
            Limb::LeftForearm => (joint::L_ELBOW, joint::L_WRIST),
            Limb::RightForearm => (joint::R_ELBOW, joint::R_WRIST),
            Limb::LeftThigh => (joint::L_HIP, joint::L_KNEE),
            Limb::RightThigh => (joint::R_HIP, joint::R_KNEE),
            Limb::LeftShin => (joint::L_KNEE, joint::L_ANKLE),
            Limb::RightShin => (joint::R_KNEE, joint::R_ANKLE),
            Limb::Torso => (joint::PELVIS, joint::NECK),
        }
    }

    /// Words for the limb ("the left upper arm").
    pub fn as_str(self) -> &'static str {
        match self {
            Limb::LeftUpperArm => "the left upper arm",
            Limb::RightUpperArm => "the right upper arm",
            Limb::LeftForearm => "the left forearm",
            Limb::RightForearm => "the right forearm",
            Limb::LeftThigh => "the left thigh",
            Limb::RightThigh => "the right thigh",
            Limb::LeftShin => "the left shin",
            Limb::RightShin => "the right shin",
            Limb::Torso => "the torso",
        }
    }

    /// The bone as a vector (metres, world frame).
    pub fn vector(self, pose: &Pose) -> Vec3 {
        let (a, b) = self.joints();
        geom::sub(pose[b], pose[a])
    }
}

/// Angle of a bone from the vertical in degrees, 0 to 90 (up and down are not told apart).
pub fn angle_from_vertical_deg(bone: Vec3) -> f64 {
    let n = geom::norm(bone);
    if n < 1e-9 {
        return 0.0;
    }
    (bone[1].abs() / n).clamp(0.0, 1.0).acos().to_degrees()
}

/// Something that can rest on the ground.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Support {
    LeftFoot,
    RightFoot,
    LeftKnee,
    RightKnee,
    LeftHand,
    RightHand,
    Pelvis,
}

impl Support {
    /// Every support, in the order of the schema.
    pub const ALL: [Support; 7] = [
        Support::LeftFoot,
        Support::RightFoot,
        Support::LeftKnee,
        Support::RightKnee,
        Support::LeftHand,
        Support::RightHand,
        Support::Pelvis,
    ];

    /// Words for the support ("the left knee").
    pub fn as_str(self) -> &'static str {
        match self {
            Support::LeftFoot => "the left foot",
            Support::RightFoot => "the right foot",
            Support::LeftKnee => "the left knee",
            Support::RightKnee => "the right knee",
            Support::LeftHand => "the left hand",
            Support::RightHand => "the right hand",
            Support::Pelvis => "the pelvis",
        }
    }

    /// How far the support is above the floor (metres) and the clearance under which it
    /// touches: a foot by the lower of its ankle and toe joints, a knee, wrist or pelvis by its
    /// joint.
    pub fn clearance(self, pose: &Pose, floor: f64) -> (f64, f64) {
        let foot = |leg: &super::frame::LegJoints| pose[leg.ankle][1].min(pose[leg.foot][1]);
        match self {
            Support::LeftFoot => (foot(&LEFT_LEG) - floor, FOOT_CONTACT_M),
            Support::RightFoot => (foot(&RIGHT_LEG) - floor, FOOT_CONTACT_M),
            Support::LeftKnee => (pose[joint::L_KNEE][1] - floor, KNEE_CONTACT_M),
            Support::RightKnee => (pose[joint::R_KNEE][1] - floor, KNEE_CONTACT_M),
            Support::LeftHand => (pose[joint::L_WRIST][1] - floor, HAND_CONTACT_M),
            Support::RightHand => (pose[joint::R_WRIST][1] - floor, HAND_CONTACT_M),
            Support::Pelvis => (pose[joint::PELVIS][1] - floor, PELVIS_CONTACT_M),
        }
    }

    /// Whether the support touches a floor at height `floor`.
    pub fn on_ground(self, pose: &Pose, floor: f64) -> bool {
        let (height, limit) = self.clearance(pose, floor);
        height < limit
    }
}

/// Which way the torso (pelvis to neck) leans, judged in the frame of the hips so that a
/// twisted chest does not change it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Lean {
    /// Within [`UPRIGHT_MAX_DEG`] of the vertical.
    Upright,
    Forward,
    Backward,
    Left,
    Right,
}

impl Lean {
    /// Every category, from the first to the last.
    pub const ALL: [Lean; 5] = [
        Lean::Upright,
        Lean::Forward,
        Lean::Backward,
        Lean::Left,
        Lean::Right,
    ];

    /// Words for the lean ("leans forward").
    pub fn as_str(self) -> &'static str {
        match self {
            Lean::Upright => "is upright",
            Lean::Forward => "leans forward",
            Lean::Backward => "leans backward",
            Lean::Left => "leans to the left",
            Lean::Right => "leans to the right",
        }
    }
}

/// The torso's direction (pelvis to neck, unit) in the hips' frame `[left, up, forward]`: the
/// left axis runs across the hips, forward is perpendicular to it on the ground plane.
pub fn torso_in_hip_frame(pose: &Pose) -> Vec3 {
    let left = horizontal_unit(geom::sub(pose[joint::L_HIP], pose[joint::R_HIP]));
    let forward = geom::cross(left, UP);
    let torso = geom::normalize(geom::sub(pose[joint::NECK], pose[joint::PELVIS]));
    [geom::dot(torso, left), torso[1], geom::dot(torso, forward)]
}

/// The torso's lean: upright within [`UPRIGHT_MAX_DEG`], otherwise the larger of its forward
/// and sideways tilt.
pub fn torso_lean(pose: &Pose) -> Lean {
    let [left, up, forward] = torso_in_hip_frame(pose);
    let from_vertical = up.clamp(-1.0, 1.0).acos().to_degrees();
    if from_vertical <= UPRIGHT_MAX_DEG {
        Lean::Upright
    } else if forward.abs() >= left.abs() {
        if forward > 0.0 {
            Lean::Forward
        } else {
            Lean::Backward
        }
    } else if left > 0.0 {
        Lean::Left
    } else {
        Lean::Right
    }
}

/// How the shoulders are turned against the hips, about the torso's own axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Twist {
    /// Within [`TWIST_MIN_DEG`].
    None,
    /// Shoulders turned to the character's left (counter-clockwise seen from the head).
    Left,
    /// Shoulders turned to the right.
    Right,
}

impl Twist {
    /// Every category, from the first to the last.
    pub const ALL: [Twist; 3] = [Twist::None, Twist::Left, Twist::Right];

    /// Words for the twist.
    pub fn as_str(self) -> &'static str {
        match self {
            Twist::None => "is not twisted",
            Twist::Left => "is twisted to the left",
            Twist::Right => "is twisted to the right",
        }
    }
}

/// The angle (degrees, positive to the character's left) by which the shoulder line is turned
/// against the hip line about the torso axis.
pub fn torso_twist_deg(pose: &Pose) -> f64 {
    let axis = geom::normalize(geom::sub(pose[joint::NECK], pose[joint::PELVIS]));
    let flat = |v: Vec3| geom::sub(v, geom::scale(axis, geom::dot(v, axis)));
    // Both lines point from the right side to the left side of the body.
    let hips = flat(geom::sub(pose[joint::L_HIP], pose[joint::R_HIP]));
    let shoulders = flat(geom::sub(pose[joint::L_SHOULDER], pose[joint::R_SHOULDER]));
    if geom::norm(hips) < 1e-9 || geom::norm(shoulders) < 1e-9 {
        return 0.0;
    }
    let sin = geom::dot(geom::cross(hips, shoulders), axis);
    let cos = geom::dot(hips, shoulders);
    // A left-side point moving towards the front is a turn to the right, so the sign flips.
    -sin.atan2(cos).to_degrees()
}

/// The twist's category.
pub fn torso_twist(pose: &Pose) -> Twist {
    let deg = torso_twist_deg(pose);
    if deg > TWIST_MIN_DEG {
        Twist::Left
    } else if deg < -TWIST_MIN_DEG {
        Twist::Right
    } else {
        Twist::None
    }
}

/// How high the body is, by the pelvis and what it rests on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PelvisLevel {
    /// Pelvis at least [`CROUCH_PELVIS_M`] above the floor.
    Standing,
    /// Pelvis lower, on the feet (squat, lunge, crouch, sitting on a chair).
    Crouching,
    /// A knee on the ground (and not lying).
    Kneeling,
    /// The pelvis on the ground with the torso up.
    Sitting,
    /// The torso near horizontal and the pelvis low (on the back, the front, a side, a plank).
    Lying,
}

impl PelvisLevel {
    /// Every category, from the first to the last.
    pub const ALL: [PelvisLevel; 5] = [
        PelvisLevel::Standing,
        PelvisLevel::Crouching,
        PelvisLevel::Kneeling,
        PelvisLevel::Sitting,
        PelvisLevel::Lying,
    ];

    /// Words for the level ("kneeling").
    pub fn as_str(self) -> &'static str {
        match self {
            PelvisLevel::Standing => "standing",
            PelvisLevel::Crouching => "crouching",
            PelvisLevel::Kneeling => "kneeling",
            PelvisLevel::Sitting => "sitting on the floor",
            PelvisLevel::Lying => "lying",
        }
    }
}

/// The body's level on a floor at height `floor` (metres), from the pelvis height, the torso's
/// angle from the vertical and the knees: a low, horizontal torso is lying; then a knee on the
/// ground is kneeling; a horizontal torso up to [`PLANK_PELVIS_M`] is lying (a plank); a pelvis
/// on the ground is sitting; below [`CROUCH_PELVIS_M`] crouching; otherwise standing.
pub fn body_level(pose: &Pose, floor: f64) -> PelvisLevel {
    let pelvis = pose[joint::PELVIS][1] - floor;
    let torso = angle_from_vertical_deg(Limb::Torso.vector(pose));
    let flat = torso > LYING_MIN_DEG;
    let kneeling =
        Support::LeftKnee.on_ground(pose, floor) || Support::RightKnee.on_ground(pose, floor);
    if flat && pelvis < LYING_PELVIS_M {
        PelvisLevel::Lying
    } else if kneeling {
        PelvisLevel::Kneeling
    } else if flat && pelvis < PLANK_PELVIS_M {
        PelvisLevel::Lying
    } else if pelvis < PELVIS_CONTACT_M {
        PelvisLevel::Sitting
    } else if pelvis < CROUCH_PELVIS_M {
        PelvisLevel::Crouching
    } else {
        PelvisLevel::Standing
    }
}
