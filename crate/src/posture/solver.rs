//! The posture solver: a posture script → a pose of the 22-joint skeleton.
//!
//! The body is driven by 24 anatomical angles ([`Angles`]): the whole body's pitch and roll,
//! the spine's bend, side bend and twist, the head's nod, and per leg the hip's flexion,
//! abduction and rotation, the knee and the ankle, per arm the upper arm's elevation, its plane
//! (to the side, forward, across) and twist, and the elbow. Each angle has a joint limit; the
//! bones have the reference skeleton's lengths ([`crate::skeleton::REFERENCE_BONE_LENGTHS`]),
//! and the lowest joint is put on the floor, so no pose goes below it.
//!
//! ```text
//!  script ──► cost(angles) = Σ constraint violations (continuous, with a margin inside
//!             │              each describer band)
//!             │            + balance (centre of mass outside the support)
//!             │            + prior (distance to the starting pose: the previous key
//!             │              pose, or a natural rest pose)
//!             ▼
//!  projected descent from a few deterministic starts (the start pose, a base pose for the
//!  script's level) ──► the angles whose pose the describer reads back best
//! ```
//!
//! Everything is deterministic and bounded: a fixed number of starts and iterations, no
//! randomness, no allocation in the inner loop. A script that cannot be met in full still gives
//! the best pose found, with the constraints it misses.

use super::script::{Constraint, PostureScript};
use crate::geom::{self, Vec3};
use crate::posecodes::Bend;
use crate::posecodes::{
    angle_from_vertical_deg, relative_offset, torso_in_hip_frame, torso_twist_deg, Distance, Lean,
    Limb, Orientation, PelvisLevel, Relation, Support, Twist, CLOSE_MAX_M, CROUCH_PELVIS_M,
    DEPTH_BAND_M, FOOT_CONTACT_M, HAND_CONTACT_M, HEIGHT_BAND_M, HORIZONTAL_MIN_DEG,
    KNEE_CONTACT_M, LYING_MIN_DEG, LYING_PELVIS_M, MIDLINE_BAND_M, PARTIALLY_BENT_MIN_DEG,
    PELVIS_CONTACT_M, PLANK_PELVIS_M, SHOULDER_WIDTH_MAX_M, SLIGHTLY_BENT_MIN_DEG, SPREAD_MAX_M,
    STRAIGHT_MIN_DEG, TWIST_MIN_DEG, UPRIGHT_MAX_DEG, VERTICAL_MAX_DEG,
};
use crate::skeleton::{joint, Pose, NUM_JOINTS, REFERENCE_BONE_LENGTHS};

/// Number of solver angles.
pub const NUM_ANGLES: usize = 24;

/// Indices of the angles in [`Angles`]. Left and right limbs use the same sign convention
/// mirrored: a positive abduction moves either limb away from the body.
pub mod angle {
    /// Whole body tipped forward (+) or back (−) about the left axis, radians.
    pub const PITCH: usize = 0;
    /// Whole body tipped to its left (+) or right (−).
    pub const ROLL: usize = 1;
    /// Spine bent forward (+) or arched back (−), spread over its three joints.
    pub const SPINE_BEND: usize = 2;
    /// Spine bent to the left (+) or right (−).
    pub const SPINE_SIDE: usize = 3;
    /// Shoulders turned to the left (+) or right (−) against the hips.
    pub const SPINE_TWIST: usize = 4;
    /// Head nodded forward (+) or tipped back (−), spread over neck and head.
    pub const HEAD: usize = 5;
    /// First angle of the left leg: hip flexion, hip abduction, hip rotation, knee, ankle.
    pub const LEFT_LEG: usize = 6;
    /// First angle of the right leg.
    pub const RIGHT_LEG: usize = 11;
    /// First angle of the left arm: elevation, plane, twist, elbow.
    pub const LEFT_ARM: usize = 16;
    /// First angle of the right arm.
    pub const RIGHT_ARM: usize = 20;
    /// Offsets within a leg.
    pub const HIP_FLEX: usize = 0;
    pub const HIP_ABDUCT: usize = 1;
    pub const HIP_ROTATE: usize = 2;
    pub const KNEE: usize = 3;
    pub const ANKLE: usize = 4;
    /// Offsets within an arm.
    pub const ARM_ELEVATION: usize = 0;
    pub const ARM_PLANE: usize = 1;
    pub const ARM_TWIST: usize = 2;
    pub const ELBOW: usize = 3;
}

/// The solver's angles (radians), indexed by [`angle`].
pub type Angles = [f64; NUM_ANGLES];

/// Joint limits in degrees, `[low, high]` per angle: what a healthy adult reaches, a little
/// generous so that poses like a split or a deep squat stay possible.
pub const LIMITS_DEG: [[f64; 2]; NUM_ANGLES] = {
    let leg = [
        [-30.0, 130.0],
        [-30.0, 85.0],
        [-45.0, 45.0],
        [0.0, 155.0],
        [-40.0, 45.0],
    ];
    // Elevation 0 hangs the arm down, 90 holds it out level, 180 straight up; plane 0 is out to
    // the side, 90 straight forward, beyond it across the body, negative behind.
    let arm = [[0.0, 180.0], [-60.0, 140.0], [-90.0, 90.0], [0.0, 150.0]];
    [
        [-100.0, 100.0],
        [-100.0, 100.0],
        [-30.0, 90.0],
        [-40.0, 40.0],
        [-50.0, 50.0],
        [-40.0, 50.0],
        leg[0],
        leg[1],
        leg[2],
        leg[3],
        leg[4],
        leg[0],
        leg[1],
        leg[2],
        leg[3],
        leg[4],
        arm[0],
        arm[1],
        arm[2],
        arm[3],
        arm[0],
        arm[1],
        arm[2],
        arm[3],
    ]
};

/// The natural rest pose's angles: standing straight, arms hanging a little away from the
/// body with the elbows softly bent.
pub fn rest_angles() -> Angles {
    let mut a = [0.0; NUM_ANGLES];
    for arm in [angle::LEFT_ARM, angle::RIGHT_ARM] {
        a[arm + angle::ARM_ELEVATION] = 8f64.to_radians();
        a[arm + angle::ELBOW] = 12f64.to_radians();
    }
    a
}

/// Angles clamped into [`LIMITS_DEG`]; non-finite angles take the rest value.
pub fn clamp_angles(mut a: Angles) -> Angles {
    let rest = rest_angles();
    for (i, v) in a.iter_mut().enumerate() {
        let [lo, hi] = LIMITS_DEG[i];
        *v = if v.is_finite() {
            v.clamp(lo.to_radians(), hi.to_radians())
        } else {
            rest[i]
        };
    }
    a
}

type Mat = [[f64; 3]; 3];

fn rx(t: f64) -> Mat {
    let (s, c) = t.sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}

fn ry(t: f64) -> Mat {
    let (s, c) = t.sin_cos();
    [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
}

fn rz(t: f64) -> Mat {
    let (s, c) = t.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

fn mul(a: &Mat, b: &Mat) -> Mat {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn apply(m: &Mat, v: Vec3) -> Vec3 {
    std::array::from_fn(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

/// Rest directions (body frame: +X left, +Y up, +Z forward) of the bones no angle drives
/// directly: read as rounded directions off standing frames of the reference data (hips a
/// little below the pelvis, neck and head tipped forward, collars up and out, shoulders out,
/// feet forward and down).
fn rest_direction(j: usize) -> Vec3 {
    let d = match j {
        joint::L_HIP => [0.78, -0.62, 0.0],
        joint::R_HIP => [-0.78, -0.62, 0.0],
        joint::SPINE1 => [0.0, 1.0, -0.15],
        joint::SPINE2 | joint::SPINE3 => [0.0, 1.0, 0.05],
        joint::NECK => [0.0, 0.95, 0.3],
        joint::HEAD => [0.0, 0.85, 0.5],
        joint::L_COLLAR => [0.3, 0.94, 0.1],
        joint::R_COLLAR => [-0.3, 0.94, 0.1],
        joint::L_SHOULDER => [0.95, -0.1, 0.0],
        joint::R_SHOULDER => [-0.95, -0.1, 0.0],
        joint::L_FOOT | joint::R_FOOT => [0.0, -0.45, 0.89],
        _ => [0.0, -1.0, 0.0],
    };
    geom::normalize(d)
}

/// The pose of a set of angles: bones of the reference lengths, pelvis above the origin, body
/// facing +Z, lowest joint on the floor (y = 0).
pub fn pose_of(a: &Angles) -> Pose {
    let mut p = [[0.0; 3]; NUM_JOINTS];
    let put = |p: &mut Pose, j: usize, parent: usize, frame: &Mat, dir: Vec3| {
        p[j] = geom::add(
            p[parent],
            geom::scale(apply(frame, dir), REFERENCE_BONE_LENGTHS[j]),
        );
    };
    let root = mul(&rx(a[angle::PITCH]), &rz(-a[angle::ROLL]));
    let third = |i: usize| a[i] / 3.0;
    let spine_step = mul(
        &mul(
            &ry(third(angle::SPINE_TWIST)),
            &rx(third(angle::SPINE_BEND)),
        ),
        &rz(-third(angle::SPINE_SIDE)),
    );
    let s1 = mul(&root, &spine_step);
    let s2 = mul(&s1, &spine_step);
    let s3 = mul(&s2, &spine_step);
    put(
        &mut p,
        joint::SPINE1,
        joint::PELVIS,
        &s1,
        rest_direction(joint::SPINE1),
    );
    put(
        &mut p,
        joint::SPINE2,
        joint::SPINE1,
        &s2,
        rest_direction(joint::SPINE2),
    );
    put(
        &mut p,
        joint::SPINE3,
        joint::SPINE2,
        &s3,
        rest_direction(joint::SPINE3),
    );
    let nod = rx(a[angle::HEAD] / 2.0);
    let neck = mul(&s3, &nod);
    let head = mul(&neck, &nod);
    put(
        &mut p,
        joint::NECK,
        joint::SPINE3,
        &neck,
        rest_direction(joint::NECK),
    );
    put(
        &mut p,
        joint::HEAD,
        joint::NECK,
        &head,
        rest_direction(joint::HEAD),
    );

    let limbs = [
        (1.0, angle::LEFT_LEG, angle::LEFT_ARM, LEFT),
        (-1.0, angle::RIGHT_LEG, angle::RIGHT_ARM, RIGHT),
    ];
    for (side, leg, arm, j) in limbs {
        put(&mut p, j.hip, joint::PELVIS, &root, rest_direction(j.hip));
        let thigh = mul(
            &mul(
                &mul(&root, &rz(side * a[leg + angle::HIP_ABDUCT])),
                &rx(-a[leg + angle::HIP_FLEX]),
            ),
            &ry(side * a[leg + angle::HIP_ROTATE]),
        );
        put(&mut p, j.knee, j.hip, &thigh, [0.0, -1.0, 0.0]);
        let shin = mul(&thigh, &rx(a[leg + angle::KNEE]));
        put(&mut p, j.ankle, j.knee, &shin, [0.0, -1.0, 0.0]);
        let foot = mul(&shin, &rx(-a[leg + angle::ANKLE]));
        put(&mut p, j.foot, j.ankle, &foot, rest_direction(j.foot));

        put(
            &mut p,
            j.collar,
            joint::SPINE3,
            &s3,
            rest_direction(j.collar),
        );
        put(
            &mut p,
            j.shoulder,
            j.collar,
            &s3,
            rest_direction(j.shoulder),
        );
        let upper = mul(
            &mul(
                &mul(&s3, &ry(-side * a[arm + angle::ARM_PLANE])),
                &rz(side * a[arm + angle::ARM_ELEVATION]),
            ),
            &ry(side * a[arm + angle::ARM_TWIST]),
        );
        put(&mut p, j.elbow, j.shoulder, &upper, [0.0, -1.0, 0.0]);
        let fore = mul(&upper, &rx(-a[arm + angle::ELBOW]));
        put(&mut p, j.wrist, j.elbow, &fore, [0.0, -1.0, 0.0]);
    }
    let lowest = p.iter().map(|v| v[1]).fold(f64::INFINITY, f64::min);
    for v in p.iter_mut() {
        v[1] -= lowest;
    }
    p
}

struct SideJoints {
    hip: usize,
    knee: usize,
    ankle: usize,
    foot: usize,
    collar: usize,
    shoulder: usize,
    elbow: usize,
    wrist: usize,
}

const LEFT: SideJoints = SideJoints {
    hip: joint::L_HIP,
    knee: joint::L_KNEE,
    ankle: joint::L_ANKLE,
    foot: joint::L_FOOT,
    collar: joint::L_COLLAR,
    shoulder: joint::L_SHOULDER,
    elbow: joint::L_ELBOW,
    wrist: joint::L_WRIST,
};

const RIGHT: SideJoints = SideJoints {
    hip: joint::R_HIP,
    knee: joint::R_KNEE,
    ankle: joint::R_ANKLE,
    foot: joint::R_FOOT,
    collar: joint::R_COLLAR,
    shoulder: joint::R_SHOULDER,
    elbow: joint::R_ELBOW,
    wrist: joint::R_WRIST,
};

/// How far inside each describer band the solver aims, so that the describer reads the
/// category back despite rounding: degrees for angles, metres for lengths.
const MARGIN_DEG: f64 = 5.0;
const MARGIN_M: f64 = 0.03;

/// Squared distance of `v` outside `[lo, hi]`, in units of `scale`.
fn outside(v: f64, lo: f64, hi: f64, scale: f64) -> f64 {
    let d = if v < lo {
        lo - v
    } else if v > hi {
        v - hi
    } else {
        0.0
    };
    (d / scale) * (d / scale)
}

const DEG: f64 = 10.0;
const M: f64 = 0.05;

fn bend_band(is: Bend) -> (f64, f64) {
    match is {
        Bend::Straight => (STRAIGHT_MIN_DEG + MARGIN_DEG, 180.0),
        Bend::SlightlyBent => (
            SLIGHTLY_BENT_MIN_DEG + MARGIN_DEG,
            STRAIGHT_MIN_DEG - MARGIN_DEG,
        ),
        Bend::PartiallyBent => (
            PARTIALLY_BENT_MIN_DEG + MARGIN_DEG,
            SLIGHTLY_BENT_MIN_DEG - MARGIN_DEG,
        ),
        Bend::CompletelyBent => (0.0, PARTIALLY_BENT_MIN_DEG - MARGIN_DEG),
    }
}

fn distance_band(is: Distance) -> (f64, f64) {
    match is {
        Distance::Close => (0.0, CLOSE_MAX_M - MARGIN_M),
        Distance::ShoulderWidth => (CLOSE_MAX_M + MARGIN_M, SHOULDER_WIDTH_MAX_M - MARGIN_M),
        Distance::Spread => (SHOULDER_WIDTH_MAX_M + MARGIN_M, SPREAD_MAX_M - MARGIN_M),
        Distance::Wide => (SPREAD_MAX_M + MARGIN_M, f64::INFINITY),
    }
}

fn relation_band(is: Relation) -> (f64, f64) {
    let inf = f64::INFINITY;
    match is {
        Relation::Above => (HEIGHT_BAND_M + MARGIN_M, inf),
        Relation::Below => (-inf, -HEIGHT_BAND_M - MARGIN_M),
        Relation::LevelWith => (-HEIGHT_BAND_M + 0.02, HEIGHT_BAND_M - 0.02),
        Relation::InFrontOf => (DEPTH_BAND_M + MARGIN_M, inf),
        Relation::Behind => (-inf, -DEPTH_BAND_M - MARGIN_M),
        Relation::LeftOf => (MIDLINE_BAND_M + MARGIN_M, inf),
        Relation::RightOf => (-inf, -MIDLINE_BAND_M - MARGIN_M),
    }
}

fn orientation_band(is: Orientation) -> (f64, f64) {
    match is {
        Orientation::Vertical => (0.0, VERTICAL_MAX_DEG - MARGIN_DEG),
        Orientation::Diagonal => (
            VERTICAL_MAX_DEG + MARGIN_DEG,
            HORIZONTAL_MIN_DEG - MARGIN_DEG,
        ),
        Orientation::Horizontal => (HORIZONTAL_MIN_DEG + MARGIN_DEG, 90.0),
    }
}

/// Clearance (metres above the floor) a support must stay under to touch, or over to be off.
fn contact_band(point: Support, on_ground: bool) -> (f64, f64) {
    let limit = match point {
        Support::LeftFoot | Support::RightFoot => FOOT_CONTACT_M,
        Support::LeftKnee | Support::RightKnee => KNEE_CONTACT_M,
        Support::LeftHand | Support::RightHand => HAND_CONTACT_M,
        Support::Pelvis => PELVIS_CONTACT_M,
    };
    if on_ground {
        (-f64::INFINITY, limit - MARGIN_M)
    } else {
        (limit + MARGIN_M, f64::INFINITY)
    }
}

fn knee_clearance(pose: &Pose) -> f64 {
    pose[joint::L_KNEE][1].min(pose[joint::R_KNEE][1])
}

/// How far a pose is from meeting one constraint: zero inside the band (with the margin),
/// growing with the square of the distance outside it. The floor is at y = 0.
pub fn violation(c: &Constraint, pose: &Pose) -> f64 {
    match *c {
        Constraint::Bend { joint, is } => {
            let (lo, hi) = bend_band(is);
            outside(joint.angle_deg(pose), lo, hi, DEG)
        }
        Constraint::Distance { a, b, is } => {
            let (lo, hi) = distance_band(is);
            outside(geom::dist(pose[a.joint()], pose[b.joint()]), lo, hi, M)
        }
        Constraint::Relation { a, b, is } => {
            let (lo, hi) = relation_band(is);
            outside(relative_offset(pose, a, b, is.axis()), lo, hi, M)
        }
        Constraint::Orientation { limb, is } => {
            let (lo, hi) = orientation_band(is);
            outside(angle_from_vertical_deg(limb.vector(pose)), lo, hi, DEG)
        }
        Constraint::Contact { point, on_ground } => {
            let (lo, hi) = contact_band(point, on_ground);
            outside(point.clearance(pose, 0.0).0, lo, hi, M)
        }
        Constraint::Lean { is } => lean_violation(pose, is),
        Constraint::Twist { is } => {
            let deg = torso_twist_deg(pose);
            let t = TWIST_MIN_DEG;
            match is {
                Twist::None => outside(deg, -t + MARGIN_DEG, t - MARGIN_DEG, DEG),
                Twist::Left => outside(deg, t + MARGIN_DEG, 180.0, DEG),
                Twist::Right => outside(deg, -180.0, -t - MARGIN_DEG, DEG),
            }
        }
        Constraint::Level { is } => level_violation(pose, is),
    }
}

fn lean_violation(pose: &Pose, is: Lean) -> f64 {
    let [left, up, forward] = torso_in_hip_frame(pose);
    let tilt = up.clamp(-1.0, 1.0).acos().to_degrees();
    let leaning = outside(tilt, UPRIGHT_MAX_DEG + MARGIN_DEG, 180.0, DEG);
    // The chosen direction must beat the other axis by a clear share of the tilt.
    let lead = |main: f64, other: f64| outside(main - other.abs(), 0.1, f64::INFINITY, 0.1);
    match is {
        Lean::Upright => outside(tilt, 0.0, UPRIGHT_MAX_DEG - MARGIN_DEG, DEG),
        Lean::Forward => leaning + lead(forward, left),
        Lean::Backward => leaning + lead(-forward, left),
        Lean::Left => leaning + lead(left, forward),
        Lean::Right => leaning + lead(-left, forward),
    }
}

fn level_violation(pose: &Pose, is: PelvisLevel) -> f64 {
    let pelvis = pose[joint::PELVIS][1];
    let torso = angle_from_vertical_deg(Limb::Torso.vector(pose));
    let knees_up = outside(
        knee_clearance(pose),
        KNEE_CONTACT_M + MARGIN_M,
        f64::INFINITY,
        M,
    );
    let not_flat = outside(torso, 0.0, LYING_MIN_DEG - MARGIN_DEG, DEG);
    match is {
        PelvisLevel::Standing => {
            outside(pelvis, CROUCH_PELVIS_M + MARGIN_M, f64::INFINITY, M) + knees_up
        }
        PelvisLevel::Crouching => {
            outside(
                pelvis,
                PELVIS_CONTACT_M + MARGIN_M,
                CROUCH_PELVIS_M - MARGIN_M,
                M,
            ) + knees_up
                // A low horizontal torso would read as a plank.
                + if pelvis < PLANK_PELVIS_M + MARGIN_M { not_flat } else { 0.0 }
        }
        PelvisLevel::Kneeling => {
            let knee_down = outside(knee_clearance(pose), -1.0, KNEE_CONTACT_M - MARGIN_M, M);
            let not_lying = if pelvis < LYING_PELVIS_M + MARGIN_M {
                not_flat
            } else {
                0.0
            };
            knee_down + not_lying
        }
        PelvisLevel::Sitting => {
            outside(pelvis, -1.0, PELVIS_CONTACT_M - MARGIN_M, M) + knees_up + not_flat
        }
        PelvisLevel::Lying => {
            outside(torso, LYING_MIN_DEG + MARGIN_DEG, 90.0, DEG)
                + outside(pelvis, -1.0, LYING_PELVIS_M - MARGIN_M, M)
        }
    }
}

/// Share of body mass at each joint, roughly by segment (trunk and head heavy, hands light):
/// only the balance term uses it.
const MASS: [f64; NUM_JOINTS] = [
    0.14, 0.06, 0.06, 0.10, 0.05, 0.05, 0.10, 0.02, 0.02, 0.10, 0.01, 0.01, 0.02, 0.01, 0.01, 0.08,
    0.02, 0.02, 0.02, 0.02, 0.01, 0.01,
];

/// Joints within this height of the floor carry weight, metres.
const SUPPORT_M: f64 = 0.03;
/// The centre of mass may be this far outside the support before it counts as off balance,
/// metres: joints are points, while a real foot or hand has an area.
const BALANCE_SLACK_M: f64 = 0.04;

/// Horizontal distance (metres) of the centre of mass outside the convex hull of what touches
/// the floor (joints within [`SUPPORT_M`], and a whole foot from heel to toe when the foot is on
/// the ground), less [`BALANCE_SLACK_M`]: zero when the pose can stand still.
pub fn imbalance_m(pose: &Pose) -> f64 {
    let total: f64 = MASS.iter().sum();
    let com = pose.iter().zip(MASS).fold([0.0; 2], |acc, (p, m)| {
        [acc[0] + p[0] * m / total, acc[1] + p[2] * m / total]
    });
    let mut support: Vec<[f64; 2]> = pose
        .iter()
        .filter(|p| p[1] < SUPPORT_M)
        .map(|p| [p[0], p[2]])
        .collect();
    for (ankle, toe) in [
        (joint::L_ANKLE, joint::L_FOOT),
        (joint::R_ANKLE, joint::R_FOOT),
    ] {
        if pose[ankle][1].min(pose[toe][1]) < FOOT_CONTACT_M {
            support.push([pose[ankle][0], pose[ankle][2]]);
            support.push([pose[toe][0], pose[toe][2]]);
        }
    }
    (distance_outside_hull(com, &mut support) - BALANCE_SLACK_M).max(0.0)
}

/// Distance from `q` to the convex hull of `points` (zero inside). Written here because it is a
/// dozen lines on at most 22 points; no geometry crate is otherwise needed.
fn distance_outside_hull(q: [f64; 2], points: &mut [[f64; 2]]) -> f64 {
    let seg = |a: [f64; 2], b: [f64; 2]| {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len2 = dx * dx + dy * dy;
        let t = if len2 > 0.0 {
            (((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        ((q[0] - a[0] - t * dx).powi(2) + (q[1] - a[1] - t * dy).powi(2)).sqrt()
    };
    match points.len() {
        0 => return 0.0,
        1 => return seg(points[0], points[0]),
        _ => {}
    }
    points.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(points.len() * 2);
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    if hull.len() < 3 {
        return hull
            .iter()
            .zip(hull.iter().cycle().skip(1))
            .map(|(a, b)| seg(*a, *b))
            .fold(f64::INFINITY, f64::min);
    }
    let inside = hull
        .iter()
        .zip(hull.iter().cycle().skip(1))
        .all(|(a, b)| cross(*a, *b, q) >= 0.0);
    if inside {
        0.0
    } else {
        hull.iter()
            .zip(hull.iter().cycle().skip(1))
            .map(|(a, b)| seg(*a, *b))
            .fold(f64::INFINITY, f64::min)
    }
}

/// Weight of the balance term per squared metre outside the support.
const BALANCE_WEIGHT: f64 = 40.0;
/// Weight of the prior per squared radian away from the starting pose, per angle: small next
/// to a missed constraint (1 per 10° or 5 cm outside its band), so it decides what the script
/// leaves open; tipping the whole body or bending the spine costs more than moving a limb, so
/// that a script about the arms does not lean the body to reach them.
const PRIOR_WEIGHT: [f64; NUM_ANGLES] = {
    let mut w = [0.05; NUM_ANGLES];
    w[angle::PITCH] = 1.0;
    w[angle::ROLL] = 1.0;
    w[angle::SPINE_BEND] = 0.5;
    w[angle::SPINE_SIDE] = 0.5;
    w[angle::SPINE_TWIST] = 0.5;
    w[angle::HEAD] = 0.3;
    w
};
/// Weight per squared radian of difference between the left and the right limb's angles:
/// people stand, squat and kneel symmetrically unless asked otherwise.
const SYMMETRY_WEIGHT: f64 = 0.05;

fn cost(script: &PostureScript, weights: &[f64], a: &Angles, prior: &Angles) -> f64 {
    let pose = pose_of(a);
    let constraints: f64 = script
        .constraints
        .iter()
        .zip(weights)
        .map(|(c, w)| w * violation(c, &pose))
        .sum();
    let balance = BALANCE_WEIGHT * imbalance_m(&pose).powi(2);
    let prior_cost: f64 = a
        .iter()
        .zip(prior)
        .zip(PRIOR_WEIGHT)
        .map(|((x, p), w)| w * (x - p) * (x - p))
        .sum();
    let asymmetry: f64 = (0..5)
        .map(|i| (a[angle::LEFT_LEG + i] - a[angle::RIGHT_LEG + i]).powi(2))
        .chain((0..4).map(|i| (a[angle::LEFT_ARM + i] - a[angle::RIGHT_ARM + i]).powi(2)))
        .sum();
    constraints + balance + prior_cost + SYMMETRY_WEIGHT * asymmetry
}

/// A solved key pose.
#[derive(Clone, Debug, PartialEq)]
pub struct Solved {
    /// The solver's angles (radians, within [`LIMITS_DEG`]).
    pub angles: Angles,
    /// The pose: reference bone lengths, pelvis above the origin, facing +Z, floor at y = 0.
    pub pose: Pose,
    /// Constraints the describer does not read back from the pose (empty when solved).
    pub unmet: Vec<Constraint>,
    /// Centre of mass outside the support, metres (0 when balanced).
    pub imbalance_m: f64,
}

/// Iterations of descent per round.
const ITERATIONS: usize = 300;
/// Rounds after the first two starts in which the constraints still missed weigh more.
const REWEIGHT_ROUNDS: usize = 4;
/// Restarts from a shaken best pose when reweighting did not meet the script.
const SHAKES: usize = 4;

/// Solves a checked script. `start` is the previous key pose's angles when the pose is one of a
/// sequence: the solver starts there and prefers to stay near it; otherwise the rest pose.
///
/// Descent runs from the start and from a base pose for the script's level; while constraints
/// are still missed, further rounds continue from the best pose with the missed constraints
/// weighing four times more each round (a penalty method: the prior and balance can no longer
/// outweigh them).
pub fn solve(script: &PostureScript, start: Option<&Angles>) -> Solved {
    let prior = start.map(|s| clamp_angles(*s)).unwrap_or_else(rest_angles);
    let mut weights = vec![1.0; script.constraints.len()];
    let mut starts = vec![prior];
    if let Some(base) = level_base(script) {
        starts.push(base);
    }
    let score = |a: &Angles, weights: &[f64]| {
        let pose = pose_of(a);
        (
            script.unmet(&pose, 0.0).len(),
            cost(script, weights, a, &prior),
        )
    };
    let mut best: Option<((usize, f64), Angles)> = None;
    for s in starts {
        let a = descend(script, &weights, s, &prior);
        let sc = score(&a, &weights);
        if best.as_ref().is_none_or(|(b, _)| sc < *b) {
            best = Some((sc, a));
        }
        if sc.0 == 0 {
            break;
        }
    }
    let (mut best_score, mut angles) = best.expect("at least one start");
    for _ in 0..REWEIGHT_ROUNDS {
        if best_score.0 == 0 {
            break;
        }
        let pose = pose_of(&angles);
        for (c, w) in script.constraints.iter().zip(weights.iter_mut()) {
            if !c.holds(&pose, 0.0) {
                *w *= 4.0;
            }
        }
        let a = descend(script, &weights, angles, &prior);
        let unmet = script.unmet(&pose_of(&a), 0.0).len();
        if unmet < best_score.0 {
            best_score = (unmet, cost(script, &weights, &a, &prior));
            angles = a;
        }
    }
    // Still stuck: shake the best pose (a fixed sequence of shakes, so solving stays
    // deterministic) and descend again.
    let mut shake = crate::rng::Rng::new(0x5eed);
    for _ in 0..SHAKES {
        if best_score.0 == 0 {
            break;
        }
        let mut s = angles;
        for (i, v) in s.iter_mut().enumerate() {
            let [lo, hi] = LIMITS_DEG[i].map(f64::to_radians);
            *v += (hi - lo) * 0.15 * shake.normal() as f64;
        }
        let a = descend(script, &weights, s, &prior);
        let unmet = script.unmet(&pose_of(&a), 0.0).len();
        if unmet < best_score.0 {
            best_score = (unmet, cost(script, &weights, &a, &prior));
            angles = a;
        }
    }
    let pose = pose_of(&angles);
    Solved {
        angles,
        unmet: script.unmet(&pose, 0.0),
        imbalance_m: imbalance_m(&pose),
        pose,
    }
}

/// A starting pose near the script's level (crouched, kneeling, seated, lying), where descent
/// from a standing pose would have to cross a long flat valley.
fn level_base(script: &PostureScript) -> Option<Angles> {
    let level = script.constraints.iter().find_map(|c| match c {
        Constraint::Level { is } => Some(*is),
        _ => None,
    })?;
    let lean = script.constraints.iter().find_map(|c| match c {
        Constraint::Lean { is } => Some(*is),
        _ => None,
    });
    let mut a = rest_angles();
    let d = f64::to_radians;
    let legs = |a: &mut Angles, flex: f64, knee: f64, ankle: f64| {
        for leg in [angle::LEFT_LEG, angle::RIGHT_LEG] {
            a[leg + angle::HIP_FLEX] = d(flex);
            a[leg + angle::KNEE] = d(knee);
            a[leg + angle::ANKLE] = d(ankle);
        }
    };
    match level {
        PelvisLevel::Standing => return None,
        PelvisLevel::Crouching => {
            legs(&mut a, 90.0, 110.0, 30.0);
            a[angle::PITCH] = d(25.0);
        }
        PelvisLevel::Kneeling => legs(&mut a, 0.0, 90.0, -30.0),
        PelvisLevel::Sitting => legs(&mut a, 90.0, 0.0, 0.0),
        PelvisLevel::Lying => {
            a[angle::PITCH] = if lean == Some(Lean::Forward) {
                d(90.0)
            } else {
                d(-90.0)
            };
        }
    }
    Some(clamp_angles(a))
}

/// Projected gradient descent with momentum on [`cost`], with central-difference gradients:
/// 24 angles make 48 pose evaluations a step, cheap next to anything learned.
fn descend(script: &PostureScript, weights: &[f64], start: Angles, prior: &Angles) -> Angles {
    const H: f64 = 1e-4;
    let mut a = clamp_angles(start);
    let mut velocity = [0.0; NUM_ANGLES];
    let mut step = 0.05;
    let mut current = cost(script, weights, &a, prior);
    for _ in 0..ITERATIONS {
        let mut grad = [0.0; NUM_ANGLES];
        for i in 0..NUM_ANGLES {
            let mut up = a;
            up[i] += H;
            let mut down = a;
            down[i] -= H;
            grad[i] = (cost(script, weights, &up, prior) - cost(script, weights, &down, prior))
                / (2.0 * H);
        }
        let norm = grad.iter().map(|g| g * g).sum::<f64>().sqrt();
        if norm < 1e-6 {
            break;
        }
        // Normalised steps: the cost's scale varies by orders of magnitude between terms.
        let mut next = a;
        for i in 0..NUM_ANGLES {
            velocity[i] = 0.7 * velocity[i] - step * grad[i] / norm;
            next[i] += velocity[i];
        }
        let next = clamp_angles(next);
        let c = cost(script, weights, &next, prior);
        if c < current {
            a = next;
            current = c;
            step = (step * 1.1).min(0.2);
        } else {
            velocity = [0.0; NUM_ANGLES];
            step *= 0.5;
            if step < 1e-4 {
                break;
            }
        }
    }
    a
}
