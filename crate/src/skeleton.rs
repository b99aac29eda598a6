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

/// The character's own left or right: of a limb, of what a hand touches, of a turn or of the
/// way a path bends, of the performer's side a motion was done with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    Left,
    Right,
}

impl Side {
    /// The word for it ("left").
    pub fn name(self) -> &'static str {
        match self {
            Side::Left => "left",
            Side::Right => "right",
        }
    }

    /// Whether a turn to this side is clockwise seen from above (looking down −Y): a turn to
    /// the right is.
    pub fn is_clockwise(self) -> bool {
        self == Side::Right
    }

    /// The other side.
    pub fn other(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }

    /// The side a word names ("left", "right").
    pub fn of_word(word: &str) -> Option<Side> {
        match word {
            "left" => Some(Side::Left),
            "right" => Some(Side::Right),
            _ => None,
        }
    }
}

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

/// The height (metres) of the lowest joint of a motion: its floor (`+∞` for no frames).
pub fn lowest_joint(poses: &[Pose]) -> f64 {
    poses
        .iter()
        .flat_map(|p| p.iter().map(|v| v[1]))
        .fold(f64::INFINITY, f64::min)
}

/// The joints that carry three bones, with the bones as the BVH export frames them: the
/// parent, its left and right children (the frame's X axis runs from right to left) and the
/// child above (its Y axis). Their three bones form a rigid triangle on any rigid skeleton.
const BRANCHES: [(usize, [usize; 3]); 2] = [
    (joint::PELVIS, [joint::L_HIP, joint::R_HIP, joint::SPINE1]),
    (
        joint::SPINE3,
        [joint::L_COLLAR, joint::R_COLLAR, joint::NECK],
    ),
];

/// Unit direction of every bone of a pose (child from parent); a bone of zero length points
/// along its rest direction. Index 0 is unused.
fn bone_directions(pose: &Pose) -> [Vec3; NUM_JOINTS] {
    std::array::from_fn(|j| match PARENTS[j] {
        None => [0.0; 3],
        Some(parent) => {
            let bone = geom::sub(pose[j], pose[parent]);
            if geom::norm(bone) > 1e-9 {
                geom::normalize(bone)
            } else {
                RAW_OFFSETS[j]
            }
        }
    })
}

/// The frame of a branch's three bones in a pose (directions `dirs`, reference lengths):
/// X from the right child to the left, Y towards the upper child. `None` when degenerate.
fn branch_frame(dirs: &[Vec3; NUM_JOINTS], [left, right, up]: [usize; 3]) -> Option<Quat> {
    let across = geom::sub(
        geom::scale(dirs[left], REFERENCE_BONE_LENGTHS[left]),
        geom::scale(dirs[right], REFERENCE_BONE_LENGTHS[right]),
    );
    let z = geom::cross(across, dirs[up]);
    if geom::norm(across) < 1e-9 || geom::norm(z) < 1e-9 {
        return None;
    }
    let x = geom::normalize(across);
    let z = geom::normalize(z);
    Some(Quat::from_columns(x, geom::cross(z, x), z))
}

/// The limbs [`fixed_bones`] bends back onto their ends: root, middle and end joint, and
/// the joint beyond the end that keeps its direction from it (the toe), if any.
const LIMBS: [[usize; 3]; 4] = [
    [joint::L_HIP, joint::L_KNEE, joint::L_ANKLE],
    [joint::R_HIP, joint::R_KNEE, joint::R_ANKLE],
    [joint::L_SHOULDER, joint::L_ELBOW, joint::L_WRIST],
    [joint::R_SHOULDER, joint::R_ELBOW, joint::R_WRIST],
];

/// Bends each limb of `out` (rebuilt outwards from the pelvis) so that its end reaches where
/// it is in `pose`, as near as the reference bones allow, by two-bone IK in the limb's own
/// plane; a toe keeps its direction from the ankle. Rebuilding outwards adds up the small
/// errors of every bone's direction at the ends of the chains, so a foot the model held still
/// would drift (generated foot skating 0.212 became 0.275) and a hand would miss what it
/// touches; ends put back, the motion keeps the model's contacts.
fn reach_limb_ends(out: &mut Pose, pose: &Pose) {
    // Facing +Z with the left hip on +X, forward is across × up: a straight knee bends
    // forward, a straight elbow backward.
    let across = geom::sub(out[joint::L_HIP], out[joint::R_HIP]);
    let forward = geom::normalize(geom::cross(across, [0.0, 1.0, 0.0]));
    for [root, mid, end] in LIMBS {
        let lengths = [REFERENCE_BONE_LENGTHS[mid], REFERENCE_BONE_LENGTHS[end]];
        // The limb bends in its own plane; only a straight one (no plane) takes the hint,
        // which would otherwise tilt the plane a little.
        let (upper, whole) = (
            geom::sub(out[mid], out[root]),
            geom::sub(out[end], out[root]),
        );
        let bend = geom::norm(geom::cross(upper, geom::normalize(whole)));
        let hint = match (bend > 1e-4, root == joint::L_HIP || root == joint::R_HIP) {
            (true, _) => [0.0; 3],
            (false, true) => forward,
            (false, false) => geom::scale(forward, -1.0),
        };
        let (m, e) = crate::limb::two_bone(
            [out[root], out[mid], out[end]],
            pose[end],
            lengths,
            hint,
            0.0,
        );
        let toe = [joint::L_FOOT, joint::R_FOOT]
            .into_iter()
            .find(|&toe| PARENTS[toe] == Some(end));
        if let Some(toe) = toe {
            let direction = geom::sub(out[toe], out[end]);
            out[toe] = geom::add(e, direction);
        }
        out[mid] = m;
        out[end] = e;
    }
}

/// What [`fixed_bones`] keeps of a motion as a whole: its floor, and the shape of the two
/// triangles of bones at the pelvis (hips and spine) and at the upper spine (collars and
/// neck), averaged over the frames. Fitted on one motion, it can be applied to the same
/// frames with one more (the pose that features' last velocities lead to).
#[derive(Clone, Debug, PartialEq)]
pub struct SkeletonFit {
    /// No frame is lowered below this height (metres): the motion's lowest joint.
    pub floor: f64,
    /// Per entry of [`BRANCHES`], the mean direction of its three bones in the branch's
    /// frame (unit vectors).
    branches: [[Vec3; 3]; 2],
}

impl SkeletonFit {
    /// The fit of a motion.
    pub fn of(poses: &[Pose]) -> SkeletonFit {
        let mut branches = [[[0.0; 3]; 3]; 2];
        for pose in poses {
            let dirs = bone_directions(pose);
            for (sums, (_, kids)) in branches.iter_mut().zip(BRANCHES) {
                if let Some(frame) = branch_frame(&dirs, kids) {
                    let inv = frame.inv();
                    for (sum, kid) in sums.iter_mut().zip(kids) {
                        *sum = geom::add(*sum, inv.rotate(dirs[kid]));
                    }
                }
            }
        }
        SkeletonFit {
            floor: lowest_joint(poses),
            branches: branches.map(|sums| sums.map(geom::normalize)),
        }
    }

    /// The poses on the reference skeleton with this fit's triangles, standing no lower
    /// than its floor (see [`fixed_bones`]).
    pub fn apply(&self, poses: &[Pose]) -> Vec<Pose> {
        poses
            .iter()
            .map(|pose| {
                let mut dirs = bone_directions(pose);
                for (mean, (_, kids)) in self.branches.iter().zip(BRANCHES) {
                    let usable = mean.iter().all(|d| geom::norm(*d) > 0.5);
                    if let (true, Some(frame)) = (usable, branch_frame(&dirs, kids)) {
                        for (d, kid) in mean.iter().zip(kids) {
                            dirs[kid] = frame.rotate(*d);
                        }
                    }
                }
                let mut out = [pose[0]; NUM_JOINTS];
                for chain in CHAINS {
                    for pair in chain.windows(2) {
                        let (parent, child) = (pair[0], pair[1]);
                        let bone = geom::scale(dirs[child], REFERENCE_BONE_LENGTHS[child]);
                        out[child] = geom::add(out[parent], bone);
                    }
                }
                reach_limb_ends(&mut out, pose);
                let lift = self.floor - lowest_joint(std::slice::from_ref(&out));
                if lift > 0.0 && lift.is_finite() {
                    for p in &mut out {
                        p[1] += lift;
                    }
                }
                out
            })
            .collect()
    }
}

/// The motion on the one skeleton of the product: every bone gets its reference length
/// ([`REFERENCE_BONE_LENGTHS`]), the pelvis keeps its position, and the joints are rebuilt
/// outwards along the [`CHAINS`]. Bones keep their directions, but for the two groups of
/// three that a skeleton holds rigid: the hips and the spine at the pelvis, and the collars
/// and the neck at the upper spine, which take the motion's mean shape of their triangle,
/// turned as the frame's own triangle is turned (X from the right hip or collar to the
/// left, Y up the spine); a rigid skeleton such as the BVH export's could not carry them
/// otherwise. Then each arm and leg bends, in its own plane, to put its wrist or ankle back
/// where it was (as near as the bones reach; the toe keeps its direction from the ankle), so
/// the chains' small errors do not add up at the hands and feet.
/// Where the new lengths would take a frame below the motion's floor (its lowest joint
/// before), that frame is lifted just enough to stand on it, so feet never sink.
///
/// Generated motions need it: the motion model predicts each joint's position on its own,
/// so bones stretch and shrink (a wrist by several centimetres) and no rigid skeleton, the
/// BVH export's included, could show them as they are. A motion already on the reference
/// skeleton with rigid triangles (the dataset's) comes back unchanged.
pub fn fixed_bones(poses: &[Pose]) -> Vec<Pose> {
    SkeletonFit::of(poses).apply(poses)
}

/// The largest difference (metres) between a bone's length in `poses` and its reference
/// length ([`REFERENCE_BONE_LENGTHS`]), over every bone and frame.
pub fn max_bone_deviation(poses: &[Pose]) -> f64 {
    poses
        .iter()
        .flat_map(|pose| {
            (1..NUM_JOINTS).map(move |j| {
                let parent = PARENTS[j].expect("non-root joint has a parent");
                (geom::dist(pose[j], pose[parent]) - REFERENCE_BONE_LENGTHS[j]).abs()
            })
        })
        .fold(0.0, f64::max)
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

    /// A motion on the reference skeleton whose hip and collar triangles are rigid and
    /// shaped as a body's (hips below the pelvis, collars above the upper spine): the
    /// triangle bones keep one rotation, the limbs swing, the root walks and turns.
    fn skeleton_motion(frames: usize) -> Vec<Pose> {
        let rots: Vec<Rotations> = (0..frames)
            .map(|t| {
                let s = (t as f64 * 0.3).sin();
                let mut r = [Quat::IDENTITY; NUM_JOINTS];
                r[0] = Quat::from_yaw(0.03 * t as f64);
                r[joint::L_HIP] = Quat::from_axis_angle([0.0, 0.0, 1.0], -0.33);
                r[joint::R_HIP] = Quat::from_axis_angle([0.0, 0.0, 1.0], 0.31);
                r[joint::L_KNEE] = Quat::from_axis_angle([1.0, 0.0, 0.0], 0.33)
                    .mul(Quat::from_axis_angle([1.0, 0.0, 0.0], -0.5 * s));
                r[joint::R_KNEE] = Quat::from_axis_angle([1.0, 0.0, 0.0], 0.5 * s);
                r[joint::L_ANKLE] = Quat::from_axis_angle([1.0, 0.0, 0.0], 0.4 * s.abs());
                r[joint::L_COLLAR] = Quat::from_axis_angle([0.0, 0.0, 1.0], 0.31);
                r[joint::R_COLLAR] = Quat::from_axis_angle([0.0, 0.0, 1.0], -0.42);
                r[joint::NECK] = Quat::from_axis_angle([0.0, 0.0, 1.0], 0.06);
                r[joint::L_SHOULDER] = Quat::from_axis_angle([1.0, 0.0, 0.0], 0.8 * s);
                r[joint::R_ELBOW] = Quat::from_axis_angle([0.2, 0.0, 1.0], 1.0 + s);
                r[joint::L_WRIST] = Quat::from_axis_angle([1.0, 0.0, 0.0], -0.7);
                r
            })
            .collect();
        let root: Vec<Vec3> = (0..frames).map(|t| [0.1, 0.95, 0.04 * t as f64]).collect();
        forward_kinematics(&rots, &Offsets::reference(), &root)
    }

    /// The same motion as a motion model might predict it: every bone stretched or shrunk
    /// by up to 25 %, differently in every frame, and (with `wobble`) the hip and collar
    /// bones turned by a few degrees, differently in every frame.
    fn predicted(poses: &[Pose], wobble: f64) -> Vec<Pose> {
        let mut rng = crate::rng::Rng::new(17);
        poses
            .iter()
            .map(|pose| {
                let mut out = [pose[0]; NUM_JOINTS];
                for chain in CHAINS {
                    for pair in chain.windows(2) {
                        let (p, c) = (pair[0], pair[1]);
                        let mut bone = geom::sub(pose[c], pose[p]);
                        if matches!(c, 1 | 2 | 3 | 12 | 13 | 14) {
                            let axis = [rng.normal(), rng.normal(), rng.normal()].map(f64::from);
                            let angle = wobble * f64::from(rng.normal());
                            bone = Quat::from_axis_angle(axis, angle).rotate(bone);
                        }
                        let stretch = 1.0 + 0.25 * (2.0 * f64::from(rng.uniform()) - 1.0);
                        out[c] = geom::add(out[p], geom::scale(bone, stretch));
                    }
                }
                out
            })
            .collect()
    }

    fn angle(a: Vec3, b: Vec3) -> f64 {
        geom::dot(geom::normalize(a), geom::normalize(b))
            .clamp(-1.0, 1.0)
            .acos()
    }

    #[test]
    fn fixed_bones_keeps_a_motion_on_the_skeleton() {
        let motion = skeleton_motion(60);
        assert!(max_bone_deviation(&motion) < 1e-12);
        let fixed = fixed_bones(&motion);
        // Bending a limb back onto its end is exact up to the law of cosines' rounding.
        assert!(max_joint_distance(&motion, &fixed) < 1e-6);
    }

    #[test]
    fn fixed_bones_gives_reference_lengths_keeps_directions_and_limb_ends() {
        let truth = skeleton_motion(60);
        let stretched = predicted(&truth, 0.0);
        assert!(max_bone_deviation(&stretched) > 0.05);
        let fixed = fixed_bones(&stretched);
        assert!(max_bone_deviation(&fixed) < 1e-9);
        let bent: Vec<usize> = LIMBS.iter().flat_map(|l| [l[1], l[2]]).collect();
        let mut ends_moved = 0.0f64;
        for (before, after) in stretched.iter().zip(&fixed) {
            // The pelvis stays where it was on the ground plane and is only ever lifted.
            assert!(
                geom::dist(
                    [before[0][0], before[0][2], 0.0],
                    [after[0][0], after[0][2], 0.0]
                ) < 1e-12
            );
            let lift = after[0][1] - before[0][1];
            assert!(lift >= -1e-12);
            for j in (1..NUM_JOINTS).filter(|j| !bent.contains(j)) {
                let p = PARENTS[j].unwrap();
                let turned = angle(
                    geom::sub(before[j], before[p]),
                    geom::sub(after[j], after[p]),
                );
                assert!(turned < 1e-6, "bone {j} turned by {turned} rad");
            }
            // Each wrist and ankle is back where it was (up to the frame's lift), unless the
            // reference bones cannot reach that far.
            for [root, mid, end] in LIMBS {
                let wanted = geom::add(before[end], [0.0, lift, 0.0]);
                let reach = REFERENCE_BONE_LENGTHS[mid] + REFERENCE_BONE_LENGTHS[end];
                let short = (geom::dist(after[root], wanted) - reach).max(0.0);
                let missed = geom::dist(after[end], wanted);
                assert!(missed < short + 1e-6, "joint {end} missed by {missed} m");
                ends_moved = ends_moved.max(missed);
            }
        }
        // Stretched limbs straighten where they cannot reach; most frames reach exactly.
        assert!(ends_moved < 0.2, "{ends_moved}");
    }

    #[test]
    fn fixed_bones_makes_the_hip_and_collar_triangles_rigid() {
        let wobbly = predicted(&skeleton_motion(60), 0.05);
        let fixed = fixed_bones(&wobbly);
        assert!(max_bone_deviation(&fixed) < 1e-9);
        for (parent, [l, r, u]) in BRANCHES {
            let sides = |p: &Pose| {
                [
                    geom::dist(p[l], p[r]),
                    geom::dist(p[l], p[u]),
                    geom::dist(p[r], p[u]),
                    geom::dist(p[parent], p[u]),
                ]
            };
            let first = sides(&fixed[0]);
            for pose in &fixed {
                for (a, b) in sides(pose).iter().zip(first) {
                    assert!((a - b).abs() < 1e-9, "triangle at {parent}: {a} vs {b}");
                }
            }
        }
        // So the BVH export, whose skeleton is rigid, carries the motion exactly.
        let bvh = crate::bvh::writer::write_bvh(&fixed, 20.0).unwrap();
        let back = crate::bvh::to_smpl_motion(&crate::bvh::Bvh::parse(&bvh).unwrap()).unwrap();
        assert!(max_joint_distance(&fixed, &back) < 1e-4);
        let wobbly_back = crate::bvh::to_smpl_motion(
            &crate::bvh::Bvh::parse(&crate::bvh::writer::write_bvh(&wobbly, 20.0).unwrap())
                .unwrap(),
        )
        .unwrap();
        assert!(max_joint_distance(&wobbly, &wobbly_back) > 0.01);
    }

    #[test]
    fn fixed_bones_does_not_sink_feet() {
        // Shins 10 cm short, standing on the floor at y = 0.
        let mut motion = skeleton_motion(30);
        for pose in &mut motion {
            for j in [joint::L_ANKLE, joint::L_FOOT, joint::R_ANKLE, joint::R_FOOT] {
                let k = if j == joint::L_ANKLE || j == joint::L_FOOT {
                    joint::L_KNEE
                } else {
                    joint::R_KNEE
                };
                let a = if j == joint::L_ANKLE || j == joint::L_FOOT {
                    joint::L_ANKLE
                } else {
                    joint::R_ANKLE
                };
                let shorten = geom::scale(geom::normalize(geom::sub(pose[a], pose[k])), -0.1);
                pose[j] = geom::add(pose[j], shorten);
            }
        }
        let floor = lowest_joint(&motion);
        for pose in &mut motion {
            for p in pose.iter_mut() {
                p[1] -= floor;
            }
        }
        let fixed = fixed_bones(&motion);
        assert!(max_bone_deviation(&fixed) < 1e-9);
        for (before, after) in motion.iter().zip(&fixed) {
            let low = lowest_joint(std::slice::from_ref(after));
            assert!(low > -1e-9, "a joint sank to {low} m");
            // Lifted by the 10 cm the legs grew, no more.
            let lift = after[0][1] - before[0][1];
            assert!((-1e-12..0.1 + 1e-9).contains(&lift), "lifted by {lift} m");
        }
        assert!(
            lowest_joint(&fixed).abs() < 1e-9,
            "the lowest frame stands on the floor"
        );
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
