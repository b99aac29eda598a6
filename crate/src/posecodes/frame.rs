//! Per-frame categorical pose codes.

use crate::geom::{self, Vec3};
use crate::skeleton::{joint, Pose};
use serde::{Deserialize, Serialize};

const UP: Vec3 = [0.0, 1.0, 0.0];

/// A knee or elbow whose inner angle is above this many degrees is "straight".
pub const STRAIGHT_MIN_DEG: f64 = 160.0;
/// Inner angle (degrees) from which a joint is "slightly bent" up to [`STRAIGHT_MIN_DEG`].
pub const SLIGHTLY_BENT_MIN_DEG: f64 = 130.0;
/// Inner angle (degrees) from which a joint is "partially bent" up to
/// [`SLIGHTLY_BENT_MIN_DEG`]; below it the joint is "completely bent".
pub const PARTIALLY_BENT_MIN_DEG: f64 = 90.0;

/// Two joints closer than this (metres) are "close" (hands together, feet together).
pub const CLOSE_MAX_M: f64 = 0.15;
/// Up to this distance (metres) two joints are "shoulder width" apart.
pub const SHOULDER_WIDTH_MAX_M: f64 = 0.50;
/// Up to this distance (metres) two joints are "spread"; beyond it they are "wide" apart.
pub const SPREAD_MAX_M: f64 = 0.90;

/// Half-width (metres) of the neutral band for above/below: a wrist within this height of the
/// head or shoulder is "level" with it.
pub const HEIGHT_BAND_M: f64 = 0.05;
/// Half-width (metres) of the neutral band for in front of/behind, along the facing direction
/// (a wrist against the pelvis, one ankle against the other).
pub const DEPTH_BAND_M: f64 = 0.10;
/// Half-width (metres) of the body midline band: a wrist within it of the pelvis, sideways, is
/// "in the middle"; beyond it on the other side, the arm is crossed.
pub const MIDLINE_BAND_M: f64 = 0.05;

/// A bone within this many degrees of the vertical (pointing up or down) is "vertical".
pub const VERTICAL_MAX_DEG: f64 = 25.0;
/// A bone more than this many degrees from the vertical is "horizontal"; in between it is
/// "diagonal".
pub const HORIZONTAL_MIN_DEG: f64 = 65.0;

/// A foot is on the ground when the lower of its ankle and toe joints is within this many
/// metres of the floor. The toe joint sits almost on the floor when standing, the ankle about
/// 8 cm above it.
pub const FOOT_CONTACT_M: f64 = 0.05;
/// A knee is on the ground (kneeling) when the knee joint is within this many metres of the
/// floor; the joint is inside the leg, a few centimetres above the kneecap.
pub const KNEE_CONTACT_M: f64 = 0.12;

/// The horizontal direction a pose faces, as a unit vector: perpendicular to the line across
/// the hips and shoulders, on the side the toes point to. A character at rest facing +Z gets
/// `[0, 0, 1]`. Falls back to +Z when the hips and shoulders give no direction.
pub fn facing(pose: &Pose) -> Vec3 {
    let across = geom::add(
        geom::sub(pose[joint::R_HIP], pose[joint::L_HIP]),
        geom::sub(pose[joint::R_SHOULDER], pose[joint::L_SHOULDER]),
    );
    horizontal_unit(geom::cross(UP, across))
}

/// The floor under a motion in metres: the lowest height any joint reaches in any frame, as
/// HumanML3D puts motions on the floor. Zero for an empty motion.
pub fn floor_height(poses: &[Pose]) -> f64 {
    let lowest = poses
        .iter()
        .flat_map(|p| p.iter().map(|j| j[1]))
        .fold(f64::INFINITY, f64::min);
    if lowest.is_finite() {
        lowest
    } else {
        0.0
    }
}

/// `v` flattened onto the ground plane and made unit length; +Z if nothing is left.
pub(super) fn horizontal_unit(v: Vec3) -> Vec3 {
    let h = [v[0], 0.0, v[2]];
    if geom::norm(h) < 1e-9 {
        [0.0, 0.0, 1.0]
    } else {
        geom::normalize(h)
    }
}

/// Heading of a horizontal direction in degrees: 0 for +Z, +90 for +X. Increasing heading is a
/// turn to the character's left (counter-clockwise seen from above).
pub(super) fn heading_deg(forward: Vec3) -> f64 {
    forward[0].atan2(forward[2]).to_degrees()
}

/// The body frame of one frame: origin at the pelvis, axes left, up, forward. With forward +Z
/// the left axis is +X, matching the skeleton convention.
#[derive(Clone, Copy, Debug)]
pub(super) struct BodyFrame {
    pub origin: Vec3,
    pub forward: Vec3,
    pub left: Vec3,
}

impl BodyFrame {
    pub fn new(origin: Vec3, forward: Vec3) -> BodyFrame {
        BodyFrame {
            origin,
            forward,
            left: geom::cross(UP, forward),
        }
    }

    pub fn of(pose: &Pose) -> BodyFrame {
        BodyFrame::new(pose[joint::PELVIS], facing(pose))
    }

    /// `[left, up, forward]` coordinates of a direction.
    pub fn dir(&self, v: Vec3) -> Vec3 {
        [geom::dot(v, self.left), v[1], geom::dot(v, self.forward)]
    }

    /// `[left, up, forward]` coordinates of a point relative to the pelvis.
    pub fn point(&self, p: Vec3) -> Vec3 {
        self.dir(geom::sub(p, self.origin))
    }
}

/// Joints of one arm; `outward` is +1 when the arm's own side is the body's +left axis.
#[derive(Clone, Copy, Debug)]
pub(super) struct ArmJoints {
    pub shoulder: usize,
    pub elbow: usize,
    pub wrist: usize,
    pub outward: f64,
}

/// Joints of one leg; `outward` as for [`ArmJoints`].
#[derive(Clone, Copy, Debug)]
pub(super) struct LegJoints {
    pub hip: usize,
    pub knee: usize,
    pub ankle: usize,
    pub foot: usize,
    pub outward: f64,
}

pub(super) const LEFT_ARM: ArmJoints = ArmJoints {
    shoulder: joint::L_SHOULDER,
    elbow: joint::L_ELBOW,
    wrist: joint::L_WRIST,
    outward: 1.0,
};
pub(super) const RIGHT_ARM: ArmJoints = ArmJoints {
    shoulder: joint::R_SHOULDER,
    elbow: joint::R_ELBOW,
    wrist: joint::R_WRIST,
    outward: -1.0,
};
pub(super) const LEFT_LEG: LegJoints = LegJoints {
    hip: joint::L_HIP,
    knee: joint::L_KNEE,
    ankle: joint::L_ANKLE,
    foot: joint::L_FOOT,
    outward: 1.0,
};
pub(super) const RIGHT_LEG: LegJoints = LegJoints {
    hip: joint::R_HIP,
    knee: joint::R_KNEE,
    ankle: joint::R_ANKLE,
    foot: joint::R_FOOT,
    outward: -1.0,
};

/// Height of a foot above the floor in metres: the lower of its ankle and toe joints.
pub(super) fn foot_clearance(pose: &Pose, leg: &LegJoints, floor: f64) -> f64 {
    pose[leg.ankle][1].min(pose[leg.foot][1]) - floor
}

/// The inner angle at `b` between the bones to `a` and `c`, in degrees; 180 when a bone has no
/// length, so a degenerate limb reads as straight rather than as NaN.
pub fn joint_angle_deg(a: Vec3, b: Vec3, c: Vec3) -> f64 {
    let u = geom::sub(a, b);
    let v = geom::sub(c, b);
    let (nu, nv) = (geom::norm(u), geom::norm(v));
    if nu < 1e-9 || nv < 1e-9 {
        return 180.0;
    }
    (geom::dot(u, v) / (nu * nv))
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

/// How bent a knee or elbow is, from the inner angle between its two bones.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Bend {
    /// Inner angle above [`STRAIGHT_MIN_DEG`] (160°).
    Straight,
    /// 130° to 160°.
    SlightlyBent,
    /// 90° to 130°.
    PartiallyBent,
    /// Below [`PARTIALLY_BENT_MIN_DEG`] (90°): the bones fold onto each other.
    CompletelyBent,
}

impl Bend {
    /// Every category, from the first to the last.
    pub const ALL: [Bend; 4] = [
        Bend::Straight,
        Bend::SlightlyBent,
        Bend::PartiallyBent,
        Bend::CompletelyBent,
    ];

    /// The category of an inner joint angle in degrees (180 = fully extended).
    pub fn from_angle(deg: f64) -> Bend {
        if deg > STRAIGHT_MIN_DEG {
            Bend::Straight
        } else if deg >= SLIGHTLY_BENT_MIN_DEG {
            Bend::SlightlyBent
        } else if deg >= PARTIALLY_BENT_MIN_DEG {
            Bend::PartiallyBent
        } else {
            Bend::CompletelyBent
        }
    }

    /// Words for the category ("slightly bent").
    pub fn as_str(self) -> &'static str {
        match self {
            Bend::Straight => "straight",
            Bend::SlightlyBent => "slightly bent",
            Bend::PartiallyBent => "partially bent",
            Bend::CompletelyBent => "completely bent",
        }
    }
}

/// How far apart two joints are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Distance {
    /// Under [`CLOSE_MAX_M`] (0.15 m): touching or nearly.
    Close,
    /// 0.15 m to [`SHOULDER_WIDTH_MAX_M`] (0.50 m).
    ShoulderWidth,
    /// 0.50 m to [`SPREAD_MAX_M`] (0.90 m).
    Spread,
    /// Beyond 0.90 m (arms stretched out, a split).
    Wide,
}

impl Distance {
    /// Every category, from the first to the last.
    pub const ALL: [Distance; 4] = [
        Distance::Close,
        Distance::ShoulderWidth,
        Distance::Spread,
        Distance::Wide,
    ];

    /// The category of a distance in metres.
    pub fn from_metres(d: f64) -> Distance {
        if d < CLOSE_MAX_M {
            Distance::Close
        } else if d < SHOULDER_WIDTH_MAX_M {
            Distance::ShoulderWidth
        } else if d < SPREAD_MAX_M {
            Distance::Spread
        } else {
            Distance::Wide
        }
    }

    /// Words for the category ("shoulder width").
    pub fn as_str(self) -> &'static str {
        match self {
            Distance::Close => "close",
            Distance::ShoulderWidth => "shoulder width",
            Distance::Spread => "spread",
            Distance::Wide => "wide",
        }
    }
}

/// Height of one joint relative to another, with a neutral band of [`HEIGHT_BAND_M`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Vertical {
    /// More than the band higher.
    Above,
    /// Within the band.
    Level,
    /// More than the band lower.
    Below,
}

impl Vertical {
    /// The category of a height difference in metres (joint minus reference).
    pub fn from_offset(dy: f64) -> Vertical {
        if dy > HEIGHT_BAND_M {
            Vertical::Above
        } else if dy < -HEIGHT_BAND_M {
            Vertical::Below
        } else {
            Vertical::Level
        }
    }

    /// Words for the category ("above").
    pub fn as_str(self) -> &'static str {
        match self {
            Vertical::Above => "above",
            Vertical::Level => "level with",
            Vertical::Below => "below",
        }
    }
}

/// Position of one joint relative to another along the body's facing direction, with a neutral
/// band of [`DEPTH_BAND_M`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Depth {
    /// More than the band further forward.
    InFront,
    /// Within the band.
    Level,
    /// More than the band further back.
    Behind,
}

impl Depth {
    /// The category of a forward offset in metres (joint minus reference, along the facing).
    pub fn from_offset(d: f64) -> Depth {
        if d > DEPTH_BAND_M {
            Depth::InFront
        } else if d < -DEPTH_BAND_M {
            Depth::Behind
        } else {
            Depth::Level
        }
    }

    /// Words for the category ("in front of").
    pub fn as_str(self) -> &'static str {
        match self {
            Depth::InFront => "in front of",
            Depth::Level => "level with",
            Depth::Behind => "behind",
        }
    }
}

/// Which side of the body midline (through the pelvis, along the facing) a joint is on, with a
/// neutral band of [`MIDLINE_BAND_M`]. Sides are the character's own.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// On the character's left.
    Left,
    /// On the midline.
    Middle,
    /// On the character's right.
    Right,
}

impl Side {
    /// The category of a sideways offset in metres, positive to the character's left.
    pub fn from_offset(left: f64) -> Side {
        if left > MIDLINE_BAND_M {
            Side::Left
        } else if left < -MIDLINE_BAND_M {
            Side::Right
        } else {
            Side::Middle
        }
    }

    /// Words for the category ("left").
    pub fn as_str(self) -> &'static str {
        match self {
            Side::Left => "left",
            Side::Middle => "middle",
            Side::Right => "right",
        }
    }
}

/// Orientation of a bone (upper arm, forearm, thigh, shin) by its angle to the vertical; up and
/// down are not told apart (heights say that).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Orientation {
    /// Within [`VERTICAL_MAX_DEG`] (25°) of the vertical.
    Vertical,
    /// Between 25° and 65° from the vertical.
    Diagonal,
    /// More than [`HORIZONTAL_MIN_DEG`] (65°) from the vertical.
    Horizontal,
}

impl Orientation {
    /// Every category, from the first to the last.
    pub const ALL: [Orientation; 3] = [
        Orientation::Vertical,
        Orientation::Diagonal,
        Orientation::Horizontal,
    ];

    /// The category of a bone vector (child joint minus parent joint).
    pub fn of(bone: Vec3) -> Orientation {
        let n = geom::norm(bone);
        if n < 1e-9 {
            return Orientation::Vertical;
        }
        let from_vertical = (bone[1].abs() / n).clamp(0.0, 1.0).acos().to_degrees();
        if from_vertical < VERTICAL_MAX_DEG {
            Orientation::Vertical
        } else if from_vertical > HORIZONTAL_MIN_DEG {
            Orientation::Horizontal
        } else {
            Orientation::Diagonal
        }
    }

    /// Words for the category ("horizontal").
    pub fn as_str(self) -> &'static str {
        match self {
            Orientation::Vertical => "vertical",
            Orientation::Diagonal => "diagonal",
            Orientation::Horizontal => "horizontal",
        }
    }
}

/// Pose codes of one arm in one frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ArmCodes {
    /// Inner elbow angle in degrees (180 = arm straight).
    pub elbow_angle_deg: f64,
    /// Category of the elbow angle.
    pub elbow: Bend,
    /// Distance from the wrist to the head joint.
    pub wrist_to_head: Distance,
    /// Wrist height relative to the head joint.
    pub wrist_vs_head: Vertical,
    /// Wrist height relative to this arm's shoulder joint.
    pub wrist_vs_shoulder: Vertical,
    /// Wrist relative to the pelvis along the facing direction.
    pub wrist_depth: Depth,
    /// Side of the body midline the wrist is on.
    pub wrist_side: Side,
    /// The wrist is beyond the midline band on the opposite side of the body (arm across the
    /// body).
    pub crossed: bool,
    /// Orientation of the upper arm (shoulder to elbow).
    pub upper_arm: Orientation,
    /// Orientation of the forearm (elbow to wrist).
    pub forearm: Orientation,
}

/// Pose codes of one leg in one frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LegCodes {
    /// Inner knee angle in degrees (180 = leg straight).
    pub knee_angle_deg: f64,
    /// Category of the knee angle.
    pub knee: Bend,
    /// This ankle relative to the other ankle along the facing direction (a step forward puts
    /// the front ankle "in front").
    pub ankle_vs_other: Depth,
    /// Orientation of the thigh (hip to knee).
    pub thigh: Orientation,
    /// Orientation of the shin (knee to ankle).
    pub shin: Orientation,
    /// The foot is within [`FOOT_CONTACT_M`] of the floor.
    pub foot_on_ground: bool,
    /// The knee is within [`KNEE_CONTACT_M`] of the floor (kneeling).
    pub knee_on_ground: bool,
}

/// Categorical pose codes of one frame, per limb plus the two between-limb distances.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FrameCodes {
    /// Codes of the left arm.
    pub left_arm: ArmCodes,
    /// Codes of the right arm.
    pub right_arm: ArmCodes,
    /// Codes of the left leg.
    pub left_leg: LegCodes,
    /// Codes of the right leg.
    pub right_leg: LegCodes,
    /// Distance between the two wrists.
    pub wrists: Distance,
    /// Distance between the two ankles (how far apart the feet are).
    pub ankles: Distance,
}

/// The pose codes of one pose (world positions, metres) standing on a floor at height `floor`
/// (metres; see [`floor_height`]). Front, behind and sides are judged in the pose's own body
/// frame (see [`facing`]).
pub fn frame_codes(pose: &Pose, floor: f64) -> FrameCodes {
    let body = BodyFrame::of(pose);
    FrameCodes {
        left_arm: arm_codes(pose, &body, &LEFT_ARM),
        right_arm: arm_codes(pose, &body, &RIGHT_ARM),
        left_leg: leg_codes(pose, &body, &LEFT_LEG, &RIGHT_LEG, floor),
        right_leg: leg_codes(pose, &body, &RIGHT_LEG, &LEFT_LEG, floor),
        wrists: Distance::from_metres(geom::dist(pose[joint::L_WRIST], pose[joint::R_WRIST])),
        ankles: Distance::from_metres(geom::dist(pose[joint::L_ANKLE], pose[joint::R_ANKLE])),
    }
}

fn arm_codes(pose: &Pose, body: &BodyFrame, arm: &ArmJoints) -> ArmCodes {
    let (shoulder, elbow, wrist) = (pose[arm.shoulder], pose[arm.elbow], pose[arm.wrist]);
    let head = pose[joint::HEAD];
    let local = body.point(wrist);
    let angle = joint_angle_deg(shoulder, elbow, wrist);
    ArmCodes {
        elbow_angle_deg: angle,
        elbow: Bend::from_angle(angle),
        wrist_to_head: Distance::from_metres(geom::dist(wrist, head)),
        wrist_vs_head: Vertical::from_offset(wrist[1] - head[1]),
        wrist_vs_shoulder: Vertical::from_offset(wrist[1] - shoulder[1]),
        wrist_depth: Depth::from_offset(local[2]),
        wrist_side: Side::from_offset(local[0]),
        crossed: local[0] * arm.outward < -MIDLINE_BAND_M,
        upper_arm: Orientation::of(geom::sub(elbow, shoulder)),
        forearm: Orientation::of(geom::sub(wrist, elbow)),
    }
}

fn leg_codes(
    pose: &Pose,
    body: &BodyFrame,
    leg: &LegJoints,
    other: &LegJoints,
    floor: f64,
) -> LegCodes {
    let (hip, knee, ankle) = (pose[leg.hip], pose[leg.knee], pose[leg.ankle]);
    let angle = joint_angle_deg(hip, knee, ankle);
    let ahead = body.point(ankle)[2] - body.point(pose[other.ankle])[2];
    LegCodes {
        knee_angle_deg: angle,
        knee: Bend::from_angle(angle),
        ankle_vs_other: Depth::from_offset(ahead),
        thigh: Orientation::of(geom::sub(knee, hip)),
        shin: Orientation::of(geom::sub(ankle, knee)),
        foot_on_ground: foot_clearance(pose, leg, floor) < FOOT_CONTACT_M,
        knee_on_ground: knee[1] - floor < KNEE_CONTACT_M,
    }
}
