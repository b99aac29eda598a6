//! Motion files on disk: reading a motion from `.npy` (HumanML3D features or joints) or `.bvh`,
//! and writing it as `.bvh`, `.npy`, `.json` or `.glb` (glTF binary, [`crate::gltf`]). Every reader returns 22-joint poses at 20 fps in
//! metres.

use crate::bvh::{self, Bvh};
use crate::features::{self, FEATURE_DIM};
use crate::gltf::{self, JointNames};
use crate::npy::NpyArray;
use crate::skeleton::{Pose, JOINT_NAMES, NUM_JOINTS};
use crate::timing::FPS;
use anyhow::{bail, Context, Result};
use std::path::Path;

/// What a motion file holds.
#[derive(Clone, Debug, PartialEq)]
pub enum MotionData {
    /// HumanML3D features, one 263-float row per frame (not normalised).
    Features(features::Features),
    /// Joint positions, metres.
    Joints(Vec<Pose>),
}

impl MotionData {
    /// Joint positions of the motion (features are integrated from the origin).
    pub fn joints(&self) -> Vec<Pose> {
        match self {
            MotionData::Features(f) => features::features_to_joints(f),
            MotionData::Joints(j) => j.clone(),
        }
    }
}

/// The lower-cased file extension ("" when there is none).
fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase()
}

/// Reads `.npy` (shape (T, 263) features or (T, 22, 3) joints) or `.bvh` (our skeleton or
/// Bandai-Namco's).
pub fn read_motion(path: &Path) -> Result<MotionData> {
    let ext = extension(path);
    match ext.as_str() {
        "npy" => {
            let array = NpyArray::read(path)?;
            let data = match array.shape.as_slice() {
                [_, FEATURE_DIM] => MotionData::Features(features::features_from_npy(&array)?),
                [_, j, 3] if *j >= NUM_JOINTS => MotionData::Joints(features::joints_from_npy(&array)?),
                s => bail!(
                    "{}: expected features of shape (T, {FEATURE_DIM}) or joints of shape (T, 22, 3), found {s:?}",
                    path.display()
                ),
            };
            Ok(data)
        }
        "bvh" => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("cannot read {}", path.display()))?;
            let bvh = Bvh::parse(&text).with_context(|| path.display().to_string())?;
            Ok(MotionData::Joints(
                bvh::to_smpl_motion(&bvh).with_context(|| path.display().to_string())?,
            ))
        }
        _ => bail!(
            "{}: unknown motion format (expected .npy or .bvh)",
            path.display()
        ),
    }
}

/// Joint positions as JSON: `{"fps": 20, "joint_names": [...], "frames": [[[x, y, z], ...], ...]}`
/// in metres, rounded to 0.1 mm.
pub fn joints_to_json(poses: &[Pose]) -> serde_json::Value {
    let round = |v: f64| (v * 1e4).round() / 1e4;
    serde_json::json!({
        "fps": FPS,
        "units": "metres",
        "up": "+Y",
        "joint_names": JOINT_NAMES,
        "frames": poses.iter().map(|p| p.iter().map(|j| j.map(round).to_vec()).collect::<Vec<_>>()).collect::<Vec<_>>(),
    })
}

/// Writes a motion as `.bvh`, `.json` (joints), `.glb` (a skinned figure with the motion as
/// its animation, joints named as in [`JOINT_NAMES`]) or `.npy` (features when the motion has
/// them or `as_features` asks for them, joints otherwise).
pub fn write_motion(path: &Path, motion: &MotionData, as_features: bool) -> Result<()> {
    write_motion_with(
        path,
        motion,
        WriteOptions {
            as_features,
            ..WriteOptions::default()
        },
    )
}

/// The choices [`write_motion_with`] takes beyond the file's extension.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WriteOptions {
    /// `.npy`: write HumanML3D features even when the motion holds joints.
    pub as_features: bool,
    /// `.glb`: how the joint nodes are named (SMPL's lower-case names or Mixamo's).
    pub joint_names: JointNames,
}

/// [`write_motion`] with every choice spelled out.
pub fn write_motion_with(path: &Path, motion: &MotionData, options: WriteOptions) -> Result<()> {
    let ext = extension(path);
    let as_features = options.as_features;
    match ext.as_str() {
        "bvh" => std::fs::write(path, bvh::writer::write_bvh(&motion.joints(), FPS)?)?,
        "glb" => std::fs::write(
            path,
            gltf::write_glb(&motion.joints(), FPS, options.joint_names)?,
        )?,
        "json" => std::fs::write(
            path,
            serde_json::to_string(&joints_to_json(&motion.joints()))?,
        )?,
        "npy" => {
            let array = match (motion, as_features) {
                (MotionData::Features(f), _) => features::features_to_npy(f),
                (MotionData::Joints(j), true) => {
                    let (f, _) =
                        features::joints_to_features(j, &crate::skeleton::Offsets::reference())?;
                    features::features_to_npy(&f)
                }
                (MotionData::Joints(j), false) => features::joints_to_npy(j),
            };
            array.write_f32(path)?
        }
        _ => bail!(
            "{}: unknown output format (expected .bvh, .glb, .json or .npy)",
            path.display()
        ),
    }
    Ok(())
}
