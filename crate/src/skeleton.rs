//! The 22-joint SMPL body skeleton used everywhere in the product (HumanML3D conventions):
//! joint order, kinematic chains, rest directions, body parts, left/right pairs, and the
//! inverse and forward kinematics that turn joint positions into per-bone rotations and back.
//!
//! Units are metres, Y is up, a character at rest faces +Z and its left side is +X.

use crate::geom::{self, Quat, Vec3};

/// Number of body joints.
pub const NUM_JOINTS: usize = 22;

/// One pose: the world position of every joint, in metres.
pub type Pose = [Vec3; NUM_JOINTS];

/// Joint names in index order.
pub const JOINT_NAMES: [&str; NUM_JOINTS] = [
    "pelvis",
    "l_hip",
    "r_hip",
    "spine1",
    "l_knee",
    "r_knee",
    "spine2",
    "l_ankle",
    "r_ankle",
    "spine3",
    "l_foot",
    "r_foot",
    "neck",
    "l_collar",
    "r_collar",
    "head",
    "l_shoulder",
    "r_shoulder",
    "l_elbow",
    "r_elbow",
    "l_wrist",
    "r_wrist",
];

/// Joint indices by name.
pub mod joint {
    pub const PELVIS: usize = 0;
    pub const L_HIP: usize = 1;
    pub const R_HIP: usize = 2;
    pub const SPINE1: usize = 3;
    pub const L_KNEE: usize = 4;
    pub const R_KNEE: usize = 5;
    pub const SPINE2: usize = 6;
    pub const L_ANKLE: usize = 7;
    pub const R_ANKLE: usize = 8;
    pub const SPINE3: usize = 9;
    pub const L_FOOT: usize = 10;
    pub const R_FOOT: usize = 11;
    pub const NECK: usize = 12;
    pub const L_COLLAR: usize = 13;
    pub const R_COLLAR: usize = 14;
    pub const HEAD: usize = 15;
    pub const L_SHOULDER: usize = 16;
    pub const R_SHOULDER: usize = 17;
    pub const L_ELBOW: usize = 18;
    pub const R_ELBOW: usize = 19;
    pub const L_WRIST: usize = 20;
    pub const R_WRIST: usize = 21;
}

/// Kinematic chains from the pelvis outwards: right leg, left leg, spine to head, right arm,
/// left arm. Every joint but the pelvis appears once as a child.
pub const CHAINS: [&[usize]; 5] = [
    &[0, 2, 5, 8, 11],
    &[0, 1, 4, 7, 10],
    &[0, 3, 6, 9, 12, 15],
    &[9, 14, 17, 19, 21],
    &[9, 13, 16, 18, 20],
];

/// Parent of each joint (`None` for the pelvis).
pub const PARENTS: [Option<usize>; NUM_JOINTS] = [
    None,
    Some(0),
    Some(0),
    Some(0),
    Some(1),
    Some(2),
    Some(3),
    Some(4),
    Some(5),
    Some(6),
    Some(7),
    Some(8),
    Some(9),
    Some(9),
    Some(9),
    Some(12),
    Some(13),
    Some(14),
    Some(16),
    Some(17),
    Some(18),
    Some(19),
];

/// Rest direction of each bone (child from parent) as a unit vector: the pose in which every
/// joint rotation is the identity. Arms hang down, feet point forward (+Z).
pub const RAW_OFFSETS: [Vec3; NUM_JOINTS] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [-1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.0, 0.0, 1.0],
    [0.0, 1.0, 0.0],
    [1.0, 0.0, 0.0],
    [-1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.0, -1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, -1.0, 0.0],
];

/// Left/right joint pairs `(left, right)`, for mirroring.
pub const LEFT_RIGHT_PAIRS: [(usize, usize); 8] = [
    (1, 2),
    (4, 5),
    (7, 8),
    (10, 11),
    (13, 14),
    (16, 17),
    (18, 19),
    (20, 21),
];

/// The joint a joint becomes under a left/right mirror.
pub fn mirror_joint(j: usize) -> usize {
    for (l, r) in LEFT_RIGHT_PAIRS {
        if j == l {
            return r;
        }
        if j == r {
            return l;
        }
    }
    j
}

/// Joints whose positions define the facing direction: right hip, left hip, right shoulder,
/// left shoulder.
pub const FACE_JOINTS: [usize; 4] = [
    joint::R_HIP,
    joint::L_HIP,
    joint::R_SHOULDER,
    joint::L_SHOULDER,
];

/// The four body parts the model and the user work with. Parts overlap, as in CoMA: the torso
/// belongs to both upper parts and the pelvis to both lower parts.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "snake_case")]
pub enum BodyPart {
    LeftArm,
    RightArm,
    LeftLeg,
    RightLeg,
}

impl BodyPart {
    /// All parts in model order.
    pub const ALL: [BodyPart; 4] = [
        BodyPart::LeftArm,
        BodyPart::RightArm,
        BodyPart::LeftLeg,
        BodyPart::RightLeg,
    ];

    /// The words a user types for the part ("left arm").
    pub fn name(self) -> &'static str {
        match self {
            BodyPart::LeftArm => "left arm",
            BodyPart::RightArm => "right arm",
            BodyPart::LeftLeg => "left leg",
            BodyPart::RightLeg => "right leg",
        }
    }

    /// Parses "left arm", "left_arm", "left-arm" (case-insensitive).
    pub fn parse(text: &str) -> Option<BodyPart> {
        let t = text.trim().to_ascii_lowercase().replace(['_', '-'], " ");
        BodyPart::ALL.into_iter().find(|p| p.name() == t)
    }

    /// The part on the other side of the body.
    pub fn mirrored(self) -> BodyPart {
        match self {
            BodyPart::LeftArm => BodyPart::RightArm,
            BodyPart::RightArm => BodyPart::LeftArm,
            BodyPart::LeftLeg => BodyPart::RightLeg,
            BodyPart::RightLeg => BodyPart::LeftLeg,
        }
    }

    /// Joints of the part (overlapping: the torso is in both arms, the pelvis in both legs).
    pub fn joints(self) -> &'static [usize] {
        match self {
            BodyPart::LeftArm => &[13, 16, 18, 20, 9, 6, 3, 12, 15],
            BodyPart::RightArm => &[14, 17, 19, 21, 9, 6, 3, 12, 15],
            BodyPart::LeftLeg => &[0, 1, 4, 7, 10],
            BodyPart::RightLeg => &[0, 2, 5, 8, 11],
        }
    }

    /// The limb's own joints only (no shared torso or pelvis): collar/hip to hand/foot.
    pub fn limb_joints(self) -> &'static [usize] {
        match self {
            BodyPart::LeftArm => &[13, 16, 18, 20],
            BodyPart::RightArm => &[14, 17, 19, 21],
            BodyPart::LeftLeg => &[1, 4, 7, 10],
            BodyPart::RightLeg => &[2, 5, 8, 11],
        }
    }
}

/// Bone lengths (metres, child from parent) of HumanML3D's reference skeleton
/// (`skeleton_example_h3d.npy`, first frame), which every motion is rescaled to so that all
/// data shares one body. Index 0 (the pelvis) has no bone.
pub const REFERENCE_BONE_LENGTHS: [f64; NUM_JOINTS] = [
    0.0,
    0.10307396801404012,
    0.10988336793155128,
    0.13156824272391562,
    0.39362320104637244,
    0.3901882263567628,
    0.14319021469648505,
    0.43243308125288354,
    0.4256433445515134,
    0.057364735143330216,
    0.14338181866410357,
    0.1494190728208926,
    0.2193600528916467,
    0.137486767617009,
    0.1433828328285533,
    0.10303921946937832,
    0.13161404584007272,
    0.12298437803931866,
    0.2568400048098033,
    0.2630917441711329,
    0.2660117216252147,
    0.2698764031509594,
];

/// Bone vectors of a skeleton: for each joint, the offset from its parent in the rest pose
/// (rest direction × bone length, metres). Joint 0's offset is zero.
#[derive(Clone, Debug, PartialEq)]
pub struct Offsets(pub [Vec3; NUM_JOINTS]);

impl Offsets {
    /// The reference skeleton's bones along the rest directions.
    pub fn reference() -> Offsets {
        Offsets(std::array::from_fn(|j| {
            geom::scale(RAW_OFFSETS[j], REFERENCE_BONE_LENGTHS[j])
        }))
    }

    /// The offsets of a skeleton whose bone lengths are those of `pose`, along the rest
    /// directions.
    pub fn from_pose(pose: &Pose) -> Offsets {
        let mut out = [[0.0; 3]; NUM_JOINTS];
        for j in 1..NUM_JOINTS {
            let parent = PARENTS[j].expect("non-root joint has a parent");
            out[j] = geom::scale(RAW_OFFSETS[j], geom::dist(pose[j], pose[parent]));
        }
        Offsets(out)
    }

    /// Leg length used to scale motions between skeletons: the right shin plus the right
    /// thigh's child bone (HumanML3D measures knee and ankle offsets).
    pub fn leg_length(&self) -> f64 {
        let max_abs = |v: Vec3| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        max_abs(self.0[joint::R_KNEE]) + max_abs(self.0[joint::R_ANKLE])
    }
}

/// Joint rotations of one frame: `[0]` is the root (facing) rotation, `[j]` rotates bone `j`
/// relative to its parent's accumulated rotation.
pub type Rotations = [Quat; NUM_JOINTS];

/// The facing ("forward") direction of a pose on the ground plane, unnormalised, computed the
/// way HumanML3D's inverse kinematics does it (hips taken left minus right, shoulders right
/// minus left; the shoulders dominate). Kept as is because the reference features depend on it.
fn ik_forward(pose: &Pose) -> Vec3 {
    let across = geom::add(
        geom::sub(pose[joint::L_HIP], pose[joint::R_HIP]),
        geom::sub(pose[joint::R_SHOULDER], pose[joint::L_SHOULDER]),
    );
    let across = geom::normalize(across);
    geom::cross([0.0, 1.0, 0.0], across)
}

/// Inverse kinematics: per-frame joint rotations from joint positions. Each bone gets the
/// shortest rotation from its rest direction to its current direction (no twist), expressed
/// relative to its parent. The root rotation turns the facing direction onto +Z; with
/// `smooth_forward` the facing is first smoothed over time with a Gaussian of σ = 20 frames.
/// As in HumanML3D, the first frame's root rotation is the identity.
pub fn inverse_kinematics(poses: &[Pose], smooth_forward: bool) -> Vec<Rotations> {
    let mut forward: Vec<Vec3> = poses.iter().map(ik_forward).collect();
    if smooth_forward {
        forward = geom::gaussian_smooth(&forward, 20.0);
    }
    poses
        .iter()
        .zip(forward)
        .enumerate()
        .map(|(t, (pose, fwd))| {
            let root = if t == 0 {
                Quat::IDENTITY
            } else {
                Quat::between(geom::normalize(fwd), [0.0, 0.0, 1.0])
            };
            let mut rots = [Quat::IDENTITY; NUM_JOINTS];
            rots[0] = root;
            for chain in CHAINS {
                let mut r = root;
                for pair in chain.windows(2) {
                    let dir = geom::normalize(geom::sub(pose[pair[1]], pose[pair[0]]));
                    let global = Quat::between(RAW_OFFSETS[pair[1]], dir);
                    let local = r.inv().mul(global);
                    rots[pair[1]] = local;
                    r = r.mul(local);
                }
            }
            rots
        })
        .collect()
}

/// Forward kinematics: joint positions from rotations, bone offsets and root positions.
pub fn forward_kinematics(rotations: &[Rotations], offsets: &Offsets, root: &[Vec3]) -> Vec<Pose> {
    rotations
        .iter()
        .zip(root)
        .map(|(rots, &root_pos)| {
            let mut pose = [[0.0; 3]; NUM_JOINTS];
            pose[0] = root_pos;
            for chain in CHAINS {
                let mut r = rots[0];
                for pair in chain.windows(2) {
                    r = r.mul(rots[pair[1]]);
                    pose[pair[1]] = geom::add(pose[pair[0]], r.rotate(offsets.0[pair[1]]));
                }
            }
            pose
        })
        .collect()
}

/// Retargets a motion onto the bone lengths of `target`: joint directions are kept, bones get
/// the target's lengths, and the root path is scaled by the ratio of leg lengths so that feet
/// do not slide. Bone lengths of the source are read from its first frame.
pub fn uniform_skeleton(poses: &[Pose], target: &Offsets) -> Vec<Pose> {
    if poses.is_empty() {
        return Vec::new();
    }
    let source = Offsets::from_pose(&poses[0]);
    let ratio = target.leg_length() / source.leg_length();
    let root: Vec<Vec3> = poses.iter().map(|p| geom::scale(p[0], ratio)).collect();
    let rotations = inverse_kinematics(poses, false);
    forward_kinematics(&rotations, target, &root)
}

/// The largest distance (metres) between corresponding joints of two motions, over the frames
/// both have.
pub fn max_joint_distance(a: &[Pose], b: &[Pose]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(p, q)| p.iter().zip(q).map(|(x, y)| geom::dist(*x, *y)))
        .fold(0.0, f64::max)
}

/// Mirrors poses left/right: negates X and swaps left and right joints. Applying it twice
/// gives back the input exactly.
pub fn mirror_poses(poses: &[Pose]) -> Vec<Pose> {
    poses
        .iter()
        .map(|pose| {
            let mut out = [[0.0; 3]; NUM_JOINTS];
            for (j, p) in pose.iter().enumerate() {
                out[mirror_joint(j)] = [-p[0], p[1], p[2]];
            }
            out
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rest_pose() -> Pose {
        let offsets = Offsets(RAW_OFFSETS.map(|d| geom::scale(d, 0.2)));
        forward_kinematics(
            &[[Quat::IDENTITY; NUM_JOINTS]],
            &offsets,
            &[[0.0, 1.0, 0.0]],
        )[0]
    }

    #[test]
    fn parents_agree_with_chains() {
        for chain in CHAINS {
            for pair in chain.windows(2) {
                assert_eq!(PARENTS[pair[1]], Some(pair[0]));
            }
        }
    }

    #[test]
    fn ik_then_fk_reproduces_positions() {
        let mut pose = rest_pose();
        // Bend the left elbow and lift the right knee.
        pose[joint::L_WRIST] = geom::add(pose[joint::L_ELBOW], [0.0, 0.0, 0.2]);
        pose[joint::R_ANKLE] = geom::add(pose[joint::R_KNEE], [0.0, -0.1, 0.1732]);
        pose[joint::R_FOOT] = geom::add(pose[joint::R_ANKLE], [0.0, 0.0, 0.2]);
        let rots = inverse_kinematics(&[pose, pose], false);
        let offsets = Offsets::from_pose(&pose);
        let back = forward_kinematics(&rots, &offsets, &[pose[0], pose[0]]);
        for frame in &back {
            for (j, (p, q)) in frame.iter().zip(&pose).enumerate() {
                assert!(geom::dist(*p, *q) < 1e-4, "joint {j}");
            }
        }
    }

    #[test]
    fn mirror_twice_is_identity() {
        let pose = rest_pose();
        let twice = mirror_poses(&mirror_poses(&[pose]));
        assert_eq!(twice[0], pose);
    }

    #[test]
    fn body_part_names_parse() {
        for p in BodyPart::ALL {
            assert_eq!(BodyPart::parse(p.name()), Some(p));
        }
        assert_eq!(BodyPart::parse("Left_Arm"), Some(BodyPart::LeftArm));
        assert_eq!(BodyPart::parse("tail"), None);
    }
}
