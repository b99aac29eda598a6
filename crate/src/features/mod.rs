//! The 263-float HumanML3D motion features, computed from joint positions and turned back into
//! joint positions, plus their normalisation and left/right mirroring.
//!
//! One row per frame at 20 fps (a motion of `T` joint frames gives `T − 1` rows):
//!
//! | columns    | meaning                                                                  |
//! |------------|--------------------------------------------------------------------------|
//! | 0          | root angular velocity about +Y, radians per frame, stored as half-angle |
//! | 1..3       | root linear velocity (x, z) in the root's facing frame, m per frame      |
//! | 3          | root (pelvis) height above the floor, m                                  |
//! | 4..67      | joints 1–21 relative to the root, in the facing frame, m (21 × 3)        |
//! | 67..193    | 6D rotations of joints 1–21 relative to their parents (21 × 6)           |
//! | 193..259   | velocities of joints 0–21 in the facing frame, m per frame (22 × 3)      |
//! | 259..263   | foot contacts (left ankle, left foot, right ankle, right foot), 0 or 1   |

use crate::geom::{self, Quat, Vec3};
use crate::npy::{NpyArray, NpyError};
use crate::skeleton::{self, joint, Offsets, Pose, NUM_JOINTS};
use std::ops::Range;

pub mod check;

/// Floats per frame.
pub const FEATURE_DIM: usize = 263;
/// Root angular velocity (column 0).
pub const ROOT_ROT_VEL: Range<usize> = 0..1;
/// Root linear velocity on the ground plane (columns 1, 2).
pub const ROOT_LIN_VEL: Range<usize> = 1..3;
/// Root height (column 3).
pub const ROOT_HEIGHT: Range<usize> = 3..4;
/// Root-relative joint positions ("ric").
pub const POSITIONS: Range<usize> = 4..67;
/// 6D joint rotations.
pub const ROTATIONS: Range<usize> = 67..193;
/// Joint velocities.
pub const VELOCITIES: Range<usize> = 193..259;
/// Foot contacts.
pub const CONTACTS: Range<usize> = 259..263;

/// Named column groups, for reports and per-group normalisation.
pub const GROUPS: [(&str, Range<usize>); 7] = [
    ("root angular velocity", ROOT_ROT_VEL),
    ("root linear velocity", ROOT_LIN_VEL),
    ("root height", ROOT_HEIGHT),
    ("joint positions", POSITIONS),
    ("6D rotations", ROTATIONS),
    ("joint velocities", VELOCITIES),
    ("foot contacts", CONTACTS),
];

/// Squared per-frame displacement (m²) under which a foot joint counts as in contact.
pub const FOOT_CONTACT_THRESHOLD: f64 = 0.002;

/// One frame of features.
pub type FeatureFrame = [f32; FEATURE_DIM];

/// Motion features, one row per frame.
pub type Features = Vec<FeatureFrame>;

/// Why features could not be computed or read.
#[derive(Debug, thiserror::Error)]
pub enum FeatureError {
    #[error("a motion needs at least 2 frames, got {0}")]
    TooShort(usize),
    #[error("motion contains a non-finite value (NaN or infinity) at frame {0}")]
    NonFinite(usize),
    #[error(transparent)]
    Npy(#[from] NpyError),
}

/// Converts joint positions (any skeleton of the 22 SMPL joints, any place and facing) into
/// features, the way HumanML3D builds its dataset: bones take the `target` lengths, the
/// motion is put on the floor, moved so the first frame's root is at the origin and turned so
/// the first frame faces +Z. Returns the `T − 1` feature rows and the `T` processed joint
/// positions they describe.
pub fn joints_to_features(
    poses: &[Pose],
    target: &Offsets,
) -> Result<(Features, Vec<Pose>), FeatureError> {
    if poses.len() < 2 {
        return Err(FeatureError::TooShort(poses.len()));
    }
    if let Some(t) = poses
        .iter()
        .position(|p| p.iter().flatten().any(|v| !v.is_finite()))
    {
        return Err(FeatureError::NonFinite(t));
    }
    let mut positions = skeleton::uniform_skeleton(poses, target);

    // On the floor, first root at the origin on the ground plane, first frame facing +Z.
    let floor = positions
        .iter()
        .flat_map(|p| p.iter().map(|v| v[1]))
        .fold(f64::INFINITY, f64::min);
    let first = positions[0];
    let origin = [first[0][0], floor, first[0][2]];
    let [r_hip, l_hip, r_sdr, l_sdr] = skeleton::FACE_JOINTS;
    let across = geom::normalize(geom::add(
        geom::sub(first[r_hip], first[l_hip]),
        geom::sub(first[r_sdr], first[l_sdr]),
    ));
    let forward = geom::normalize(geom::cross([0.0, 1.0, 0.0], across));
    let face = Quat::between(forward, [0.0, 0.0, 1.0]);
    for pose in &mut positions {
        for p in pose.iter_mut() {
            *p = face.rotate(geom::sub(*p, origin));
        }
    }
    let global = positions.clone();
    let t_rows = positions.len() - 1;

    let contact = |j: usize, t: usize| -> f32 {
        let d = geom::sub(global[t + 1][j], global[t][j]);
        (geom::dot(d, d) < FOOT_CONTACT_THRESHOLD) as u8 as f32
    };

    // Per-bone rotations with a smoothed facing; the root rotation turns world into facing.
    let rotations = skeleton::inverse_kinematics(&positions, true);
    let root_rot: Vec<Quat> = rotations.iter().map(|r| r[0]).collect();

    let mut rows = Vec::with_capacity(t_rows);
    for t in 0..t_rows {
        let mut row = [0f32; FEATURE_DIM];
        let r_vel = root_rot[t + 1].mul(root_rot[t].inv());
        row[0] = r_vel.0[2].clamp(-1.0, 1.0).asin() as f32;
        let lin = root_rot[t + 1].rotate(geom::sub(global[t + 1][0], global[t][0]));
        row[1] = lin[0] as f32;
        row[2] = lin[2] as f32;
        row[3] = global[t][0][1] as f32;
        let root = global[t][0];
        for j in 1..NUM_JOINTS {
            let local = [
                global[t][j][0] - root[0],
                global[t][j][1],
                global[t][j][2] - root[2],
            ];
            let p = root_rot[t].rotate(local);
            let c = POSITIONS.start + (j - 1) * 3;
            row[c..c + 3].copy_from_slice(&p.map(|v| v as f32));
            let m = rotations[t][j].to_matrix();
            let c = ROTATIONS.start + (j - 1) * 6;
            let six = [m[0][0], m[1][0], m[2][0], m[0][1], m[1][1], m[2][1]];
            row[c..c + 6].copy_from_slice(&six.map(|v| v as f32));
        }
        for (j, (next, now)) in global[t + 1].iter().zip(&global[t]).enumerate() {
            let v = root_rot[t].rotate(geom::sub(*next, *now));
            let c = VELOCITIES.start + j * 3;
            row[c..c + 3].copy_from_slice(&v.map(|v| v as f32));
        }
        row[CONTACTS.start] = contact(joint::L_ANKLE, t);
        row[CONTACTS.start + 1] = contact(joint::L_FOOT, t);
        row[CONTACTS.start + 2] = contact(joint::R_ANKLE, t);
        row[CONTACTS.start + 3] = contact(joint::R_FOOT, t);
        rows.push(row);
    }
    Ok((rows, global))
}

/// The root's facing rotation (about +Y) and position per frame, integrated from the root
/// velocities of the features: the motion starts at the origin facing +Z.
pub fn recover_root(features: &[FeatureFrame]) -> (Vec<Quat>, Vec<Vec3>) {
    let mut rots = Vec::with_capacity(features.len());
    let mut pos = Vec::with_capacity(features.len());
    let mut angle = 0.0f64;
    let mut p = [0.0f64; 3];
    for (t, row) in features.iter().enumerate() {
        if t > 0 {
            let prev = &features[t - 1];
            angle += prev[0] as f64;
            // Velocity of frame t−1 is expressed in the facing of frame t.
            let q = Quat([angle.cos(), 0.0, angle.sin(), 0.0]);
            let step = q.inv().rotate([prev[1] as f64, 0.0, prev[2] as f64]);
            p = geom::add(p, step);
        }
        rots.push(Quat([angle.cos(), 0.0, angle.sin(), 0.0]));
        pos.push([p[0], row[3] as f64, p[2]]);
    }
    (rots, pos)
}

/// Joint positions (metres, world frame) from features: integrates the root and places the
/// root-relative positions around it. One pose per feature row.
pub fn features_to_joints(features: &[FeatureFrame]) -> Vec<Pose> {
    let (rots, root) = recover_root(features);
    features
        .iter()
        .zip(rots.iter().zip(&root))
        .map(|(row, (q, r))| {
            let inv = q.inv();
            let mut pose = [[0.0; 3]; NUM_JOINTS];
            pose[0] = *r;
            for (j, slot) in pose.iter_mut().enumerate().skip(1) {
                let c = POSITIONS.start + (j - 1) * 3;
                let local = inv.rotate([row[c] as f64, row[c + 1] as f64, row[c + 2] as f64]);
                *slot = [local[0] + r[0], local[1], local[2] + r[2]];
            }
            pose
        })
        .collect()
}

/// The feature columns a body part's encoder sees: the root-relative position, 6D rotation
/// and velocity of each of the part's joints; the legs also see the root features (columns
/// 0–3), the pelvis velocity and their own foot contacts. Parts overlap as their joints do.
pub fn part_columns(part: crate::skeleton::BodyPart) -> Vec<usize> {
    use crate::skeleton::BodyPart;
    let mut cols = Vec::new();
    let legs = matches!(part, BodyPart::LeftLeg | BodyPart::RightLeg);
    if legs {
        cols.extend(0..4);
    }
    let mut joints = part.joints().to_vec();
    joints.sort_unstable();
    for j in joints {
        if j > 0 {
            cols.extend(POSITIONS.start + (j - 1) * 3..POSITIONS.start + j * 3);
            cols.extend(ROTATIONS.start + (j - 1) * 6..ROTATIONS.start + j * 6);
        }
        cols.extend(VELOCITIES.start + j * 3..VELOCITIES.start + (j + 1) * 3);
    }
    match part {
        BodyPart::LeftLeg => cols.extend([CONTACTS.start, CONTACTS.start + 1]),
        BodyPart::RightLeg => cols.extend([CONTACTS.start + 2, CONTACTS.start + 3]),
        _ => {}
    }
    cols
}

/// Every pose the features describe: `T − 1` rows describe `T` frames, and the last one is
/// reached by adding the last row's joint velocities (stored in the facing frame) to the
/// last recovered pose. Feature code that smooths over time needs that final frame to
/// reproduce a file exactly.
pub fn features_to_joints_with_final(features: &[FeatureFrame]) -> Vec<Pose> {
    let mut poses = features_to_joints(features);
    if let (Some(row), Some(last)) = (features.last(), poses.last().copied()) {
        let (rots, _) = recover_root(features);
        let inv = rots[rots.len() - 1].inv();
        let next = std::array::from_fn(|j| {
            let c = VELOCITIES.start + j * 3;
            let v = inv.rotate([row[c] as f64, row[c + 1] as f64, row[c + 2] as f64]);
            geom::add(last[j], v)
        });
        poses.push(next);
    }
    poses
}

/// The same motion on the reference skeleton: the features of
/// [`skeleton::fixed_bones`] of the joints they describe, so that
/// [`features_to_joints`] of the result gives every bone its reference length (to f32
/// precision) while the root path, the facing and every bone's direction stay. Rewritten
/// columns: the root height (where a frame is lifted off the floor), the root-relative
/// positions and the joint velocities (differences of the new joints; the last row's leads
/// to the new last pose's successor). The 6D rotations and the foot contacts are kept: they
/// depend only on bone directions and on motion that the new lengths do not change.
pub fn with_reference_bones(features: &[FeatureFrame]) -> Features {
    with_reference_bones_fitted(features, &reference_fit(features))
}

/// What [`with_reference_bones`] keeps of a motion as a whole (its floor and the mean shape
/// of the pelvis's and the upper spine's triangles of bones): fitted on the frames shown, not
/// on the extra pose the last velocities lead to, so the shown joints are exactly
/// `fixed_bones` of the joints shown before.
pub fn reference_fit(features: &[FeatureFrame]) -> skeleton::SkeletonFit {
    skeleton::SkeletonFit::of(&features_to_joints(features))
}

/// [`with_reference_bones`] with a fit of one's own. The fit is of the whole motion, and
/// everything else is frame by frame: a motion with body-part clips laid as layers takes its
/// base motion's fit, so that a clip (its collars move the upper spine's triangle, its feet
/// the floor) changes no frame outside its span.
pub fn with_reference_bones_fitted(
    features: &[FeatureFrame],
    fit: &skeleton::SkeletonFit,
) -> Features {
    if features.is_empty() {
        return Vec::new();
    }
    let poses = fit.apply(&features_to_joints_with_final(features));
    let (rots, _) = recover_root(features);
    features
        .iter()
        .enumerate()
        .map(|(t, row)| {
            let mut out = *row;
            write_pose_columns(&mut out, &poses[t], &poses[t + 1], rots[t]);
            out
        })
        .collect()
}

/// Features whose 6D rotation columns are those of their own joints, computed as the
/// dataset computes them from its joints ([`skeleton::inverse_kinematics`]: each bone's
/// shortest turn from its rest direction, relative to its parent, facing smoothed); every
/// other column is kept. The motion model predicts rotations and positions apart, and its
/// rotations drift from its positions. The engine's clean-up ([`crate::session::finish`])
/// starts from these: with them (and the body carried back only around a jump, see
/// [`crate::feet`]) the cleaned motions' FID on the test split went from 0.097 to 0.092
/// (`EVAL.md`, `coma eval` as its first line says, at 14c1547 and 1711a32). Motions of fewer
/// than 2 rows come back unchanged.
pub fn with_joint_rotations(features: &[FeatureFrame]) -> Features {
    if features.len() < 2 {
        return features.to_vec();
    }
    let poses = features_to_joints_with_final(features);
    if poses.iter().flatten().flatten().any(|v| !v.is_finite()) {
        return features.to_vec();
    }
    let rotations = skeleton::inverse_kinematics(&poses, true);
    features
        .iter()
        .zip(&rotations)
        .map(|(row, rotations)| {
            let mut out = *row;
            for (j, q) in rotations.iter().enumerate().skip(1) {
                set_rotation_6d(&mut out, j, *q);
            }
            out
        })
        .collect()
}

/// The 6D rotation (relative to its parent) of joint `j` (1–21) in a feature row.
pub fn rotation_6d(row: &FeatureFrame, j: usize) -> Quat {
    let c = ROTATIONS.start + (j - 1) * 6;
    let v = |k: usize| row[c + k] as f64;
    let b1 = geom::normalize([v(0), v(1), v(2)]);
    let a2 = [v(3), v(4), v(5)];
    let b2 = geom::normalize(geom::sub(a2, geom::scale(b1, geom::dot(b1, a2))));
    Quat::from_columns(b1, b2, geom::cross(b1, b2))
}

/// Writes joint `j`'s (1–21) rotation relative to its parent into a feature row's 6D
/// columns (the first two columns of its matrix, as HumanML3D stores them).
pub fn set_rotation_6d(row: &mut FeatureFrame, j: usize, q: Quat) {
    let m = q.to_matrix();
    let six = [m[0][0], m[1][0], m[2][0], m[0][1], m[1][1], m[2][1]];
    let c = ROTATIONS.start + (j - 1) * 6;
    row[c..c + 6].copy_from_slice(&six.map(|v| v as f32));
}

/// Writes the columns of `row` that follow from where the joints are: the root height, the
/// root-relative positions of `pose` and the joint velocities towards `next` (the following
/// pose), both turned into the body's `facing` frame. The root's turn and travel and the 6D
/// rotations are left as they are.
pub fn write_pose_columns(row: &mut FeatureFrame, pose: &Pose, next: &Pose, facing: Quat) {
    let root = pose[0];
    row[ROOT_HEIGHT.start] = root[1] as f32;
    for (j, p) in pose.iter().enumerate().skip(1) {
        let local = [p[0] - root[0], p[1], p[2] - root[2]];
        let c = POSITIONS.start + (j - 1) * 3;
        row[c..c + 3].copy_from_slice(&facing.rotate(local).map(|v| v as f32));
    }
    for (j, (now, then)) in pose.iter().zip(next).enumerate() {
        let v = facing.rotate(geom::sub(*then, *now));
        let c = VELOCITIES.start + j * 3;
        row[c..c + 3].copy_from_slice(&v.map(|v| v as f32));
    }
}

/// Mirrors features left/right: the result describes exactly the mirrored joints (X negated,
/// left and right swapped) on the same body. Applying it twice is the identity. (Computing
/// features from mirrored joints gives slightly different numbers, because the reference
/// skeleton's left and right bones differ in length by a few millimetres.)
pub fn mirror_features(features: &[FeatureFrame]) -> Features {
    features
        .iter()
        .map(|row| {
            let mut out = *row;
            out[0] = -row[0];
            out[1] = -row[1];
            for j in 1..NUM_JOINTS {
                let m = skeleton::mirror_joint(j);
                let (src, dst) = (POSITIONS.start + (j - 1) * 3, POSITIONS.start + (m - 1) * 3);
                out[dst] = -row[src];
                out[dst + 1] = row[src + 1];
                out[dst + 2] = row[src + 2];
                // A rotation matrix M mirrors to S·M·S with S = diag(−1, 1, 1).
                let (src, dst) = (ROTATIONS.start + (j - 1) * 6, ROTATIONS.start + (m - 1) * 6);
                let signs = [1.0, -1.0, -1.0, -1.0, 1.0, 1.0];
                for k in 0..6 {
                    out[dst + k] = row[src + k] * signs[k];
                }
            }
            for j in 0..NUM_JOINTS {
                let m = skeleton::mirror_joint(j);
                let (src, dst) = (VELOCITIES.start + j * 3, VELOCITIES.start + m * 3);
                out[dst] = -row[src];
                out[dst + 1] = row[src + 1];
                out[dst + 2] = row[src + 2];
            }
            let c = CONTACTS.start;
            out[c..c + 2].copy_from_slice(&row[c + 2..c + 4]);
            out[c + 2..c + 4].copy_from_slice(&row[c..c + 2]);
            out
        })
        .collect()
}

/// The same motion played `speed` times as fast (features, not normalised): row `k` of the
/// result is the motion at source frame `k · speed`, linearly interpolated, with every
/// per-frame displacement (root turn, root and joint velocities) scaled by `speed` and the
/// foot contacts read again from the scaled foot velocities with the dataset's threshold.
/// Training uses it to show a model the timings that a few actors did not perform; it is
/// approximate (a 6D rotation interpolated linearly is not exactly a rotation), which
/// training tolerates and exports never see. Returns as many rows as fit in the motion:
/// `⌊(T − 1) / speed⌋ + 1`, or none for no rows or a speed that is not positive and finite.
pub fn retime(features: &[FeatureFrame], speed: f64) -> Features {
    if features.is_empty() || !(speed.is_finite() && speed > 0.0) {
        return Vec::new();
    }
    let last = features.len() - 1;
    let rows = retimed_rows(features.len(), speed);
    let scaled = |c: usize| {
        ROOT_ROT_VEL.contains(&c) || ROOT_LIN_VEL.contains(&c) || VELOCITIES.contains(&c)
    };
    (0..rows)
        .map(|k| {
            let at = (k as f64 * speed).min(last as f64);
            let i = (at.floor() as usize).min(last);
            let (a, b) = (&features[i], &features[(i + 1).min(last)]);
            let w = (at - i as f64) as f32;
            let mut row: FeatureFrame = std::array::from_fn(|c| a[c] + (b[c] - a[c]) * w);
            for (c, v) in row.iter_mut().enumerate() {
                if scaled(c) {
                    *v *= speed as f32;
                }
            }
            for (slot, j) in [joint::L_ANKLE, joint::L_FOOT, joint::R_ANKLE, joint::R_FOOT]
                .into_iter()
                .enumerate()
            {
                let c = VELOCITIES.start + j * 3;
                let sq: f32 = row[c..c + 3].iter().map(|v| v * v).sum();
                row[CONTACTS.start + slot] = ((sq as f64) < FOOT_CONTACT_THRESHOLD) as u8 as f32;
            }
            row
        })
        .collect()
}

/// The same motion performed with another posture habit: the bone of joint `j` (from its
/// parent) is turned by `turns[j]` in the body's facing frame, and every turn is carried
/// down its chain, so a turned spine takes the head and the arms with it, as a different
/// performer's stoop would. Bone lengths, the root path and the pelvis height stay; the
/// rotations, velocities and foot contacts are computed again from the new joints (features,
/// not normalised; `turns[0]` is ignored). Training uses it to show a model performers its
/// few actors are not: an unseen HDM05 actor reconstructs 10–14 mm worse than the seen ones
/// (docs/experiments.md, Posture augmentation). Returns as many rows as given (none for a motion of fewer than
/// 2 rows).
pub fn vary_posture(features: &[FeatureFrame], turns: &[Quat; NUM_JOINTS]) -> Features {
    if features.len() < 2 {
        return Vec::new();
    }
    let (rots, _) = recover_root(features);
    let mut chain = [Quat::IDENTITY; NUM_JOINTS];
    for j in 1..NUM_JOINTS {
        let parent = skeleton::PARENTS[j].expect("non-root joint has a parent");
        chain[j] = chain[parent].mul(turns[j]);
    }
    let poses: Vec<Pose> = features_to_joints_with_final(features)
        .iter()
        .enumerate()
        .map(|(t, pose)| {
            // The final pose (reached by the last row's velocities) keeps the last facing.
            let facing = rots[t.min(rots.len() - 1)];
            let mut varied = *pose;
            for j in 1..NUM_JOINTS {
                let parent = skeleton::PARENTS[j].expect("non-root joint has a parent");
                let bone = facing.rotate(geom::sub(pose[j], pose[parent]));
                let turned = facing.inv().rotate(chain[j].rotate(bone));
                varied[j] = geom::add(varied[parent], turned);
            }
            varied
        })
        .collect();
    let Ok((mut rows, _)) = joints_to_features(&poses, &Offsets::from_pose(&poses[0])) else {
        return Vec::new();
    };
    // `joints_to_features` puts the lowest joint of these frames on the floor; a stretch in
    // the air (a crop of a jump) stays at the height it was captured at.
    let lift = features[0][ROOT_HEIGHT.start] - rows[0][ROOT_HEIGHT.start];
    for row in &mut rows {
        row[ROOT_HEIGHT.start] += lift;
        for j in 1..NUM_JOINTS {
            row[POSITIONS.start + (j - 1) * 3 + 1] += lift;
        }
    }
    rows
}

/// Rows that [`retime`] makes of `rows` rows at `speed` (positive): `⌊(rows − 1) / speed⌋ + 1`.
pub fn retimed_rows(rows: usize, speed: f64) -> usize {
    match rows {
        0 => 0,
        _ => ((rows - 1) as f64 / speed + 1e-9).floor() as usize + 1,
    }
}

/// Source rows that `rows` rows at `speed` span: the least `n` with
/// `retimed_rows(n, speed) ≥ rows`.
pub fn source_rows(rows: usize, speed: f64) -> usize {
    ((rows.max(1) - 1) as f64 * speed - 1e-9).ceil() as usize + 1
}

/// Running sums over feature rows, to fit a [`Normalizer`] without keeping the rows.
#[derive(Clone, Debug)]
pub struct FeatureStats {
    rows: f64,
    sum: Vec<f64>,
    sum_sq: Vec<f64>,
}

impl Default for FeatureStats {
    fn default() -> Self {
        FeatureStats {
            rows: 0.0,
            sum: vec![0.0; FEATURE_DIM],
            sum_sq: vec![0.0; FEATURE_DIM],
        }
    }
}

impl FeatureStats {
    /// Adds the rows of one motion.
    pub fn add(&mut self, motion: &[FeatureFrame]) {
        for row in motion {
            self.rows += 1.0;
            for (k, v) in row.iter().enumerate() {
                self.sum[k] += *v as f64;
                self.sum_sq[k] += (*v as f64) * (*v as f64);
            }
        }
    }

    /// Combines two partial sums.
    pub fn merge(mut self, other: FeatureStats) -> FeatureStats {
        self.rows += other.rows;
        for k in 0..FEATURE_DIM {
            self.sum[k] += other.sum[k];
            self.sum_sq[k] += other.sum_sq[k];
        }
        self
    }

    /// Mean per column and, as in HumanML3D, one standard deviation per feature group (the
    /// group's average), so no single column dominates a loss; a floor keeps constant groups
    /// from dividing by zero.
    pub fn finish(&self) -> Normalizer {
        let n = self.rows.max(1.0);
        let mean: Vec<f64> = self.sum.iter().map(|s| s / n).collect();
        let var: Vec<f64> = self
            .sum_sq
            .iter()
            .zip(&mean)
            .map(|(s, m)| (s / n - m * m).max(0.0))
            .collect();
        let mut std = vec![0f64; FEATURE_DIM];
        for (_, range) in GROUPS {
            let avg = range.clone().map(|k| var[k].sqrt()).sum::<f64>() / range.len() as f64;
            for k in range {
                std[k] = avg.max(1e-6);
            }
        }
        Normalizer {
            mean: mean.iter().map(|v| *v as f32).collect(),
            std: std.iter().map(|v| *v as f32).collect(),
        }
    }
}

/// Per-column mean and standard deviation of features over a training set; models see
/// `(x − mean) / std`.
#[derive(Clone, Debug, PartialEq)]
pub struct Normalizer {
    pub mean: Vec<f32>,
    pub std: Vec<f32>,
}

impl Normalizer {
    /// Statistics of the given motions (see [`FeatureStats::finish`]).
    pub fn fit<'a>(motions: impl IntoIterator<Item = &'a [FeatureFrame]>) -> Normalizer {
        let mut stats = FeatureStats::default();
        for m in motions {
            stats.add(m);
        }
        stats.finish()
    }

    /// Writes `Mean.npy` and `Std.npy` (each of shape (263,), float32).
    pub fn write(
        &self,
        mean: impl AsRef<std::path::Path>,
        std: impl AsRef<std::path::Path>,
    ) -> Result<(), NpyError> {
        let arr =
            |v: &[f32]| NpyArray::new(vec![FEATURE_DIM], v.iter().map(|x| *x as f64).collect());
        arr(&self.mean).write_f32(mean)?;
        arr(&self.std).write_f32(std)
    }

    /// Reads `Mean.npy` and `Std.npy` (each of shape (263,)).
    pub fn read(
        mean: impl AsRef<std::path::Path>,
        std: impl AsRef<std::path::Path>,
    ) -> Result<Normalizer, NpyError> {
        Self::from_arrays(NpyArray::read(mean)?, NpyArray::read(std)?)
    }

    /// The statistics from the bytes of `Mean.npy` and `Std.npy` (in the page).
    pub fn from_npy_bytes(mean: &[u8], std: &[u8]) -> Result<Normalizer, NpyError> {
        Self::from_arrays(NpyArray::from_bytes(mean)?, NpyArray::from_bytes(std)?)
    }

    fn from_arrays(m: NpyArray, s: NpyArray) -> Result<Normalizer, NpyError> {
        m.expect_shape(&[Some(FEATURE_DIM)])?;
        s.expect_shape(&[Some(FEATURE_DIM)])?;
        Ok(Normalizer {
            mean: m.data.iter().map(|v| *v as f32).collect(),
            std: s.data.iter().map(|v| *v as f32).collect(),
        })
    }

    /// `(x − mean) / std`, row by row.
    pub fn normalize(&self, features: &[FeatureFrame]) -> Features {
        features
            .iter()
            .map(|row| std::array::from_fn(|k| (row[k] - self.mean[k]) / self.std[k]))
            .collect()
    }

    /// `x · std + mean`, row by row.
    pub fn denormalize(&self, features: &[FeatureFrame]) -> Features {
        features
            .iter()
            .map(|row| std::array::from_fn(|k| row[k] * self.std[k] + self.mean[k]))
            .collect()
    }
}

/// Features as a (T, 263) array for `.npy` export.
pub fn features_to_npy(features: &[FeatureFrame]) -> NpyArray {
    NpyArray::new(
        vec![features.len(), FEATURE_DIM],
        features.iter().flatten().map(|v| *v as f64).collect(),
    )
}

/// Features from a (T, 263) array.
pub fn features_from_npy(array: &NpyArray) -> Result<Features, FeatureError> {
    array.expect_shape(&[None, Some(FEATURE_DIM)])?;
    Ok(array
        .data
        .chunks_exact(FEATURE_DIM)
        .map(|c| std::array::from_fn(|k| c[k] as f32))
        .collect())
}

/// Joint positions as a (T, 22, 3) array.
pub fn joints_to_npy(poses: &[Pose]) -> NpyArray {
    NpyArray::new(
        vec![poses.len(), NUM_JOINTS, 3],
        poses.iter().flatten().flatten().copied().collect(),
    )
}

/// Joint positions from a (T, 22, 3) array; wider skeletons (such as the 52 SMPL-H joints)
/// keep their first 22 joints.
pub fn joints_from_npy(array: &NpyArray) -> Result<Vec<Pose>, FeatureError> {
    let (frames, joints) = match array.shape.as_slice() {
        [t, j, 3] if *j >= NUM_JOINTS => (*t, *j),
        [j, 3] if *j >= NUM_JOINTS => (1, *j),
        _ => {
            return Err(NpyError::Shape {
                expected: "(T, 22, 3)".into(),
                found: array.shape.clone(),
            }
            .into())
        }
    };
    Ok((0..frames)
        .map(|t| {
            std::array::from_fn(|j| {
                let c = (t * joints + j) * 3;
                [array.data[c], array.data[c + 1], array.data[c + 2]]
            })
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A synthetic walk-like motion: the root moves forward and turns slowly while the arms
    /// swing, on a skeleton with rest-direction bones.
    fn synthetic(frames: usize) -> Vec<Pose> {
        let offsets = Offsets(skeleton::RAW_OFFSETS.map(|d| geom::scale(d, 0.15)));
        let rots: Vec<_> = (0..frames)
            .map(|t| {
                let s = (t as f64 * 0.3).sin();
                let mut r = [Quat::IDENTITY; NUM_JOINTS];
                r[0] = Quat::from_yaw(0.02 * t as f64 + 0.5);
                r[joint::L_SHOULDER] = Quat::from_axis_angle([1.0, 0.0, 0.0], 0.6 * s);
                r[joint::R_SHOULDER] = Quat::from_axis_angle([1.0, 0.0, 0.0], -0.6 * s);
                r[joint::L_HIP] = Quat::from_axis_angle([1.0, 0.0, 0.0], -0.4 * s);
                r[joint::R_HIP] = Quat::from_axis_angle([1.0, 0.0, 0.0], 0.4 * s);
                r
            })
            .collect();
        let root: Vec<Vec3> = (0..frames).map(|t| [0.3, 0.9, 0.05 * t as f64]).collect();
        skeleton::forward_kinematics(&rots, &offsets, &root)
    }

    #[test]
    fn joint_rotations_are_the_datasets_and_nothing_else_changes() {
        let (feats, _) = joints_to_features(&synthetic(40), &Offsets::reference()).unwrap();
        // Rotations as a motion model predicts them: apart from its positions.
        let mut drifted = feats.clone();
        for (t, row) in drifted.iter_mut().enumerate() {
            for (c, v) in row[ROTATIONS].iter_mut().enumerate() {
                *v += 0.2 * ((t * 5 + c * 11) as f32 * 0.31).sin();
            }
        }
        let fixed = with_joint_rotations(&drifted);
        assert_eq!(fixed.len(), feats.len());
        for ((a, b), d) in fixed.iter().zip(&feats).zip(&drifted) {
            for c in 0..FEATURE_DIM {
                let want = if ROTATIONS.contains(&c) { b[c] } else { d[c] };
                assert!((a[c] - want).abs() < 1e-4, "column {c}: {} vs {want}", a[c]);
            }
        }
        assert_eq!(with_joint_rotations(&feats[..1]), feats[..1].to_vec());
    }

    #[test]
    fn with_reference_bones_describes_the_fixed_joints() {
        let (mut feats, _) = joints_to_features(&synthetic(40), &Offsets::reference()).unwrap();
        // Bones stretched as a motion model's predictions stretch them.
        for (t, row) in feats.iter_mut().enumerate() {
            for (c, v) in row[POSITIONS].iter_mut().enumerate() {
                *v += 0.03 * ((t * 7 + c * 13) as f32 * 0.37).sin();
            }
        }
        let stretched = features_to_joints(&feats);
        assert!(skeleton::max_bone_deviation(&stretched) > 0.02);
        let fixed = with_reference_bones(&feats);
        assert_eq!(fixed.len(), feats.len());
        let joints = features_to_joints(&fixed);
        assert!(skeleton::max_bone_deviation(&joints) < 1e-5);
        assert!(skeleton::max_joint_distance(&joints, &skeleton::fixed_bones(&stretched)) < 1e-5);
        // The last velocities lead to a pose on the same skeleton, and the root keeps its
        // path and facing.
        let with_final = features_to_joints_with_final(&fixed);
        assert!(skeleton::max_bone_deviation(&with_final[with_final.len() - 1..]) < 1e-5);
        let ((rots_a, root_a), (rots_b, root_b)) = (recover_root(&feats), recover_root(&fixed));
        assert_eq!(rots_a, rots_b);
        for (a, b) in root_a.iter().zip(&root_b) {
            assert_eq!([a[0], a[2]], [b[0], b[2]]);
        }
        // Fixing twice changes nothing more, but for a limb stretched to full reach: the
        // features' f32 rounding of its length (~1e-7 m) bends its knee or elbow by the square
        // root of that, a fraction of a millimetre.
        let again = features_to_joints(&with_reference_bones(&fixed));
        let moved = skeleton::max_joint_distance(&joints, &again);
        assert!(moved < 1e-3, "fixing again moved a joint by {moved} m");
    }

    #[test]
    fn features_have_shape_and_round_trip_to_joints() {
        let poses = synthetic(40);
        let target = Offsets::from_pose(&poses[0]);
        let (feats, global) = joints_to_features(&poses, &target).unwrap();
        assert_eq!(feats.len(), 39);
        let back = features_to_joints(&feats);
        for t in 0..feats.len() {
            for j in 0..NUM_JOINTS {
                assert!(
                    geom::dist(back[t][j], global[t][j]) < 1e-5,
                    "frame {t} joint {j}"
                );
            }
        }
    }

    #[test]
    fn retimed_features_match_features_of_the_joints_taken_at_that_speed() {
        let poses = synthetic(81);
        let target = Offsets::from_pose(&poses[0]);
        let (feats, _) = joints_to_features(&poses, &target).unwrap();
        assert_eq!(retime(&feats, 1.0), feats);
        assert_eq!(retime(&feats, 0.5).len(), 2 * (feats.len() - 1) + 1);
        assert!(retime(&feats, 0.0).is_empty() && retime(&feats, f64::NAN).is_empty());
        // Twice as fast is every other joint frame; a displacement over two frames is twice
        // the one-frame one up to the motion's curvature. (The facing frame that velocities are
        // written in is smoothed over neighbouring frames, which differ at the two rates, so
        // speeds are compared, not components.)
        let every_other: Vec<Pose> = poses.iter().step_by(2).copied().collect();
        let (truth, _) = joints_to_features(&every_other, &target).unwrap();
        let fast = retime(&feats, 2.0);
        assert_eq!(fast.len(), 40);
        let norm = |v: &[f32]| v.iter().map(|x| x * x).sum::<f32>().sqrt();
        for (t, (a, b)) in fast.iter().zip(&truth).enumerate() {
            assert!((a[3] - b[3]).abs() < 1e-4, "frame {t} root height");
            for j in 0..NUM_JOINTS - 1 {
                let c = POSITIONS.start + j * 3;
                let across = |r: &FeatureFrame| norm(&[r[c], r[c + 2]]);
                assert!(
                    (a[c + 1] - b[c + 1]).abs() < 1e-4,
                    "frame {t} joint {}",
                    j + 1
                );
                assert!(
                    (across(a) - across(b)).abs() < 1e-4,
                    "frame {t} joint {}",
                    j + 1
                );
            }
            for j in 0..NUM_JOINTS {
                let c = VELOCITIES.start + j * 3;
                let (u, v) = (norm(&a[c..c + 3]), norm(&b[c..c + 3]));
                assert!((u - v).abs() < 0.03, "frame {t} joint {j}: {u} vs {v}");
            }
            let (u, v) = (norm(&a[ROOT_LIN_VEL]), norm(&b[ROOT_LIN_VEL]));
            assert!((u - v).abs() < 0.03, "frame {t} root: {u} vs {v}");
        }
        // The feet of the synthetic walk slide, so faster play reads fewer contacts.
        let contacts = |f: &[FeatureFrame]| {
            f.iter()
                .map(|r| r[CONTACTS].iter().sum::<f32>())
                .sum::<f32>()
                / f.len() as f32
        };
        assert!(contacts(&retime(&feats, 3.0)) <= contacts(&feats));
    }

    #[test]
    fn a_varied_posture_turns_the_asked_bones_and_their_chains_only() {
        let poses = synthetic(30);
        let target = Offsets::from_pose(&poses[0]);
        let (feats, _) = joints_to_features(&poses, &target).unwrap();
        let joints = features_to_joints(&feats);
        // No turn: the same joints, to float precision.
        let same = features_to_joints(&vary_posture(&feats, &[Quat::IDENTITY; NUM_JOINTS]));
        assert_eq!(same.len(), joints.len());
        assert!(skeleton::max_joint_distance(&same, &joints) < 1e-4);
        // The left elbow turned by 10°: the left wrist moves by the chord of 10° at the
        // forearm's length, the rest of the body and the pelvis height stay.
        let mut turns = [Quat::IDENTITY; NUM_JOINTS];
        turns[joint::L_WRIST] = Quat::from_axis_angle([0.0, 0.0, 1.0], 10f64.to_radians());
        let varied = vary_posture(&feats, &turns);
        assert_eq!(varied.len(), feats.len());
        let moved = features_to_joints(&varied);
        let forearm = geom::dist(joints[0][joint::L_WRIST], joints[0][joint::L_ELBOW]);
        let chord = 2.0 * forearm * 5f64.to_radians().sin();
        for (t, (a, b)) in joints.iter().zip(&moved).enumerate() {
            let relative = |p: &Pose, j: usize| geom::sub(p[j], p[0]);
            let shift = geom::dist(relative(a, joint::L_WRIST), relative(b, joint::L_WRIST));
            assert!(
                (shift - chord).abs() < 2e-3,
                "frame {t}: {shift} against {chord}"
            );
            for j in (0..NUM_JOINTS).filter(|&j| j != joint::L_WRIST) {
                let d = geom::dist(relative(a, j), relative(b, j));
                assert!(d < 1e-3, "frame {t} joint {j} moved {d}");
            }
            assert!((a[0][1] - b[0][1]).abs() < 1e-4, "frame {t} pelvis height");
        }
        // A turned spine carries the head and both wrists.
        let mut turns = [Quat::IDENTITY; NUM_JOINTS];
        turns[joint::SPINE2] = Quat::from_axis_angle([1.0, 0.0, 0.0], 10f64.to_radians());
        let stooped = features_to_joints(&vary_posture(&feats, &turns));
        for j in [joint::HEAD, joint::L_WRIST, joint::R_WRIST] {
            let d = geom::dist(
                geom::sub(stooped[5][j], stooped[5][0]),
                geom::sub(joints[5][j], joints[5][0]),
            );
            assert!(d > 0.01, "joint {j} moved only {d}");
        }
        assert!(vary_posture(&feats[..1], &turns).is_empty());
    }

    #[test]
    fn mirrored_features_match_features_of_mirrored_joints() {
        let poses = synthetic(30);
        let target = Offsets::from_pose(&poses[0]);
        let (feats, _) = joints_to_features(&poses, &target).unwrap();
        let (mirrored, _) = joints_to_features(&skeleton::mirror_poses(&poses), &target).unwrap();
        let direct = mirror_features(&feats);
        for (a, b) in direct.iter().zip(&mirrored) {
            for k in 0..FEATURE_DIM {
                assert!(
                    (a[k] - b[k]).abs() < 1e-4,
                    "column {k}: {} vs {}",
                    a[k],
                    b[k]
                );
            }
        }
        assert_eq!(mirror_features(&direct), feats);
    }

    #[test]
    fn part_columns_cover_every_feature() {
        use crate::skeleton::BodyPart;
        let sizes: Vec<usize> = BodyPart::ALL
            .iter()
            .map(|p| part_columns(*p).len())
            .collect();
        assert_eq!(sizes, [108, 108, 57, 57]);
        let mut all: Vec<usize> = BodyPart::ALL
            .iter()
            .flat_map(|p| part_columns(*p))
            .collect();
        all.sort_unstable();
        all.dedup();
        assert_eq!(all, (0..FEATURE_DIM).collect::<Vec<_>>());
    }

    #[test]
    fn rejects_short_and_nan_motions() {
        let target = Offsets(skeleton::RAW_OFFSETS);
        let one = synthetic(1);
        assert!(matches!(
            joints_to_features(&one, &target),
            Err(FeatureError::TooShort(1))
        ));
        let mut bad = synthetic(5);
        bad[3][4][1] = f64::NAN;
        assert!(matches!(
            joints_to_features(&bad, &target),
            Err(FeatureError::NonFinite(3))
        ));
    }

    #[test]
    fn normalizer_round_trips() {
        let poses = synthetic(30);
        let (feats, _) = joints_to_features(&poses, &Offsets::from_pose(&poses[0])).unwrap();
        let norm = Normalizer::fit([feats.as_slice()]);
        let back = norm.denormalize(&norm.normalize(&feats));
        for (a, b) in back.iter().zip(&feats) {
            for k in 0..FEATURE_DIM {
                assert!((a[k] - b[k]).abs() < 1e-4);
            }
        }
    }
}
