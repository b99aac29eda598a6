//! Retarget of the Bandai-Namco Research motion capture skeleton onto our 22 SMPL joints.
//!
//! The Bandai-Namco files (datasets 1 and 2) share one hierarchy: `joint_Root` (fixed at the
//! origin) → `Hips` → `Spine` → `Chest` → `Neck` → `Head`, `Chest` → `Shoulder_*` →
//! `UpperArm_*` → `LowerArm_*` → `Hand_*`, and `Hips` → `UpperLeg_*` → `LowerLeg_*` →
//! `Foot_*` → `Toes_*`, every joint with six channels, 30 fps, centimetres, Y up. `_L` is the
//! performer's left.
//!
//! We take world joint positions, not rotations, because the two skeletons' rest poses and
//! local axes differ while their joint centres correspond. Which Bandai joint drives which
//! SMPL joint:
//!
//! | SMPL joint        | from                                   |
//! |-------------------|----------------------------------------|
//! | pelvis            | Hips                                   |
//! | l_hip / r_hip     | UpperLeg_L / UpperLeg_R                |
//! | l_knee / r_knee   | LowerLeg_L / LowerLeg_R                |
//! | l_ankle / r_ankle | Foot_L / Foot_R                        |
//! | l_foot / r_foot   | Toes_L / Toes_R                        |
//! | spine1            | Spine                                  |
//! | spine2            | synthesised: midpoint of Spine and Chest (Bandai has no joint there) |
//! | spine3            | Chest                                  |
//! | neck              | Neck                                   |
//! | head              | Head                                   |
//! | l_collar / r_collar | Shoulder_L / Shoulder_R              |
//! | l_shoulder / r_shoulder | UpperArm_L / UpperArm_R          |
//! | l_elbow / r_elbow | LowerArm_L / LowerArm_R                |
//! | l_wrist / r_wrist | Hand_L / Hand_R                        |
//!
//! Positions are converted from centimetres to metres and resampled from the file's rate
//! (30 fps) to 20 fps by linear interpolation. Bone lengths are made uniform later, when
//! features are computed ([`crate::features::joints_to_features`]).

use super::{resample_positions, Bvh, BvhError};
use crate::geom;
use crate::skeleton::{Pose, NUM_JOINTS};

/// Centimetres to metres.
const CM: f64 = 0.01;

/// Where an SMPL joint comes from.
#[derive(Clone, Copy, Debug)]
pub enum JointSource {
    /// The position of one Bandai joint.
    Joint(&'static str),
    /// The point `t` of the way from the first joint to the second.
    Between(&'static str, &'static str, f64),
}

/// The source of each SMPL joint, in SMPL joint order.
pub const MAPPING: [JointSource; NUM_JOINTS] = [
    JointSource::Joint("Hips"),
    JointSource::Joint("UpperLeg_L"),
    JointSource::Joint("UpperLeg_R"),
    JointSource::Joint("Spine"),
    JointSource::Joint("LowerLeg_L"),
    JointSource::Joint("LowerLeg_R"),
    JointSource::Between("Spine", "Chest", 0.5),
    JointSource::Joint("Foot_L"),
    JointSource::Joint("Foot_R"),
    JointSource::Joint("Chest"),
    JointSource::Joint("Toes_L"),
    JointSource::Joint("Toes_R"),
    JointSource::Joint("Neck"),
    JointSource::Joint("Shoulder_L"),
    JointSource::Joint("Shoulder_R"),
    JointSource::Joint("Head"),
    JointSource::Joint("UpperArm_L"),
    JointSource::Joint("UpperArm_R"),
    JointSource::Joint("LowerArm_L"),
    JointSource::Joint("LowerArm_R"),
    JointSource::Joint("Hand_L"),
    JointSource::Joint("Hand_R"),
];

fn names() -> impl Iterator<Item = &'static str> {
    MAPPING.iter().flat_map(|s| match *s {
        JointSource::Joint(a) => vec![a],
        JointSource::Between(a, b, _) => vec![a, b],
    })
}

/// True when every joint the retarget needs is present.
pub fn is_bandai(bvh: &Bvh) -> bool {
    names().all(|n| bvh.joint_index(n).is_some())
}

/// The motion on our 22 joints, 20 fps, metres, Y up (place and facing as captured).
pub fn retarget(bvh: &Bvh) -> Result<Vec<Pose>, BvhError> {
    if bvh.frames.is_empty() {
        return Err(BvhError::Empty);
    }
    let index = |name: &str| {
        bvh.joint_index(name).ok_or_else(|| {
            BvhError::UnknownSkeleton(format!("Bandai-Namco joint '{name}' is missing"))
        })
    };
    let sources = MAPPING
        .iter()
        .map(|s| {
            Ok(match *s {
                JointSource::Joint(a) => (index(a)?, index(a)?, 0.0),
                JointSource::Between(a, b, t) => (index(a)?, index(b)?, t),
            })
        })
        .collect::<Result<Vec<_>, BvhError>>()?;
    Ok(resample_positions(bvh)
        .iter()
        .map(|row| {
            std::array::from_fn(|j| {
                let (a, b, t) = sources[j];
                geom::scale(geom::lerp(row[a], row[b], t), CM)
            })
        })
        .collect())
}
