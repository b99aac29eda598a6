//! Checks our feature code against a real HumanML3D file pair: recover joints from
//! `new_joint_vecs/<id>.npy` and compare with `new_joints/<id>.npy`, then recompute features
//! from those joints and compare with the feature file, group by group.

use super::{
    features_from_npy, features_to_joints_with_final, joints_from_npy, joints_to_features,
    FeatureError, GROUPS,
};
use crate::geom;
use crate::npy::NpyArray;
use crate::skeleton::Offsets;
use std::path::Path;

/// Joint positions must agree within this many metres.
pub const JOINT_TOLERANCE: f64 = 1e-4;
/// Every feature group but the 6D rotations must agree within this.
pub const FEATURE_TOLERANCE: f64 = 1e-3;

/// Largest absolute errors found by [`check_reference`].
#[derive(Clone, Debug)]
pub struct CheckReport {
    /// Motion id that was checked.
    pub id: String,
    /// Frames compared.
    pub frames: usize,
    /// Largest joint position error in metres (features → joints).
    pub joint_error: f64,
    /// Largest absolute error per feature group (joints → features), in group order.
    pub group_errors: Vec<(&'static str, f64)>,
}

impl CheckReport {
    /// True when the joints and every group other than the 6D rotations are within tolerance.
    pub fn passes(&self) -> bool {
        self.joint_error <= JOINT_TOLERANCE
            && self
                .group_errors
                .iter()
                .all(|(name, e)| *name == "6D rotations" || *e <= FEATURE_TOLERANCE)
    }
}

impl std::fmt::Display for CheckReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "motion {} ({} frames)", self.id, self.frames)?;
        writeln!(
            f,
            "  features → joints: max |error| = {:.3e} m (tolerance {:.0e})",
            self.joint_error, JOINT_TOLERANCE
        )?;
        writeln!(f, "  joints → features, max |error| per group:")?;
        for (name, e) in &self.group_errors {
            let tol = if *name == "6D rotations" {
                "aim 1e-3"
            } else {
                "tolerance 1e-3"
            };
            writeln!(f, "    {name:<22} {e:.3e}  ({tol})")?;
        }
        write!(
            f,
            "  result: {}",
            if self.passes() { "PASS" } else { "FAIL" }
        )
    }
}

/// Runs both comparisons on `<dir>/new_joint_vecs/<id>.npy` and `<dir>/new_joints/<id>.npy`,
/// taking target bone lengths from `<dir>/skeleton_example_h3d.npy`.
pub fn check_reference(dir: &Path, id: &str) -> Result<CheckReport, FeatureError> {
    let feats = features_from_npy(&NpyArray::read(
        dir.join("new_joint_vecs").join(format!("{id}.npy")),
    )?)?;
    let joints = joints_from_npy(&NpyArray::read(
        dir.join("new_joints").join(format!("{id}.npy")),
    )?)?;
    let skeleton = joints_from_npy(&NpyArray::read(dir.join("skeleton_example_h3d.npy"))?)?;
    let target = Offsets::from_pose(&skeleton[0]);

    let recovered = features_to_joints_with_final(&feats);
    let frames = joints.len().min(feats.len());
    let joint_error = (0..frames)
        .flat_map(|t| (0..recovered[t].len()).map(move |j| (t, j)))
        .map(|(t, j)| {
            let d = geom::sub(recovered[t][j], joints[t][j]);
            d.iter().fold(0.0f64, |m, v| m.max(v.abs()))
        })
        .fold(0.0, f64::max);

    // T − 1 feature rows describe T frames; the final one comes from the last row's
    // velocities, so the time smoothing of the facing sees the same frames as the original.
    let (again, _) = joints_to_features(&recovered, &target)?;
    let rows = again.len().min(feats.len());
    let group_errors = GROUPS
        .iter()
        .map(|(name, range)| {
            let e = (0..rows)
                .flat_map(|t| range.clone().map(move |k| (t, k)))
                .map(|(t, k)| (again[t][k] as f64 - feats[t][k] as f64).abs())
                .fold(0.0, f64::max);
            (*name, e)
        })
        .collect();
    Ok(CheckReport {
        id: id.to_string(),
        frames,
        joint_error,
        group_errors,
    })
}
