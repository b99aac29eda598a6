//! Body-part clips as layers over the base (whole-body) motion: the features of a motion whose
//! tokens carry base patches (see [`crate::model::tokens`]) are the base motion's everywhere,
//! but for the channels of a clip's parts over the clip's span, which come from the final
//! tokens' decoding.
//!
//! Why not decode the final tokens alone: SPAM's decoder is shared by the four parts and reads
//! the whole sequence (dilated convolutions), and the root's turn is integrated over time, so
//! a clip's tokens on one arm would move every frame a little and turn everything after it.
//! Composed this way, a clip moved or deleted leaves every frame outside its spans exactly as
//! it was.
//!
//! Which channels are a part's (HumanML3D rows, see the table in [`crate::features`]):
//! - the root (turn, travel, height, the pelvis's velocity) is the whole body's: always the
//!   base's;
//! - a limb's own joints ([`BodyPart::limb_joints`]: collar, shoulder, elbow, wrist; hip,
//!   knee, ankle, toe) with their root-relative positions, 6D rotations and velocities, and a
//!   leg's two foot contacts, follow that part's layer;
//! - the torso (spine, neck, head), which both arm parts share, follows the arms only where
//!   both arms are under a clip (the weaker of their two weights): a clip of one arm leaves
//!   the trunk, and so the other arm, to the base.
//!
//! Over a patch the weight is 1, easing in (smoothstep) over its first
//! [`SEAM_STEPS`] token steps and out over its last (8 frames, 0.4 s at 20 fps: the seams
//! where the tokens move into and out of the clip), except at the motion's own first and last
//! frame; outside every patch it is 0, and the base's numbers are kept bit for bit.

use super::edit::SEAM_STEPS;
use super::tokens::{MotionTokens, PARTS};
use crate::features::{
    FeatureFrame, Features, CONTACTS, POSITIONS, ROOT_HEIGHT, ROTATIONS, VELOCITIES,
};
use crate::geom;
use crate::skeleton::{joint, BodyPart, NUM_JOINTS};
use crate::timing::FRAMES_PER_TOKEN;

/// Frames (20 fps) over which a layer eases in at its start and out at its end.
pub const MARGIN_FRAMES: usize = SEAM_STEPS * FRAMES_PER_TOKEN;

/// Per frame (20 fps, `tokens.frames()` of them), how much each part (model order) follows
/// its clip layer rather than the base: 0 outside every patch, 1 inside, eased over
/// [`MARGIN_FRAMES`] at a patch's ends (but at the motion's first and last frame).
pub fn layer_weights(tokens: &MotionTokens) -> Vec<[f32; PARTS]> {
    let frames = tokens.frames();
    let mut weights = vec![[0.0f32; PARTS]; frames];
    for patch in tokens.base_patches() {
        let steps = patch.steps();
        let (a, b) = (steps.start * FRAMES_PER_TOKEN, steps.end * FRAMES_PER_TOKEN);
        for (f, w) in weights.iter_mut().enumerate().take(b.min(frames)).skip(a) {
            let ramp = |from_end: f64| geom::ease(from_end / MARGIN_FRAMES as f64);
            // Half a frame in: the first frame of a patch already leans a little its way, the
            // frame before it not at all.
            let rise = if a == 0 {
                1.0
            } else {
                ramp(f as f64 + 0.5 - a as f64)
            };
            let fall = if b >= frames {
                1.0
            } else {
                ramp(b as f64 - f as f64 - 0.5)
            };
            w[patch.part] = w[patch.part].max(rise.min(fall) as f32);
        }
    }
    weights
}

/// How much joint `j` follows the layers at a frame whose part weights are `w`: the root
/// none, a limb's joint as its part, a torso joint as the weaker arm.
pub fn joint_weight(j: usize, w: &[f32; PARTS]) -> f32 {
    if j == joint::PELVIS {
        return 0.0;
    }
    BodyPart::ALL
        .iter()
        .position(|part| part.limb_joints().contains(&j))
        .map_or_else(|| w[0].min(w[1]), |p| w[p])
}

/// The feature columns (not the root's) of joint `j`: its root-relative position, its 6D
/// rotation and its velocity (the pelvis has only a velocity, and it is the root's).
fn joint_columns(j: usize) -> impl Iterator<Item = usize> {
    let own = if j == 0 {
        0..0
    } else {
        POSITIONS.start + (j - 1) * 3..POSITIONS.start + j * 3
    };
    let turn = if j == 0 {
        0..0
    } else {
        ROTATIONS.start + (j - 1) * 6..ROTATIONS.start + j * 6
    };
    own.chain(turn)
        .chain(VELOCITIES.start + j * 3..VELOCITIES.start + (j + 1) * 3)
}

/// The motion of a base and its clip layers: `base` (features of the base tokens, one row per
/// frame) with each joint's columns moved towards `layered` (features of the final tokens) by
/// its [`joint_weight`], and each leg's foot contacts by the leg's weight; the root's columns
/// are the base's. `weights` are [`layer_weights`]; a row without one (or past `layered`) is
/// the base's. Where a weight is 0 the base's numbers are kept exactly.
///
/// A joint's height (stored above the floor, not above the pelvis) is taken from `layered`
/// relative to its pelvis and put on the base's pelvis, so a limb stays on the body where the
/// two motions carry the pelvis at different heights.
pub fn compose(
    base: &[FeatureFrame],
    layered: &[FeatureFrame],
    weights: &[[f32; PARTS]],
) -> Features {
    let contacts = [
        (2, CONTACTS.start..CONTACTS.start + 2),
        (3, CONTACTS.start + 2..CONTACTS.end),
    ];
    base.iter()
        .enumerate()
        .map(|(t, row)| {
            let mut out = *row;
            let (Some(w), Some(top)) = (weights.get(t), layered.get(t)) else {
                return out;
            };
            let mut top = *top;
            let lift = row[ROOT_HEIGHT.start] - top[ROOT_HEIGHT.start];
            for j in 1..NUM_JOINTS {
                top[POSITIONS.start + (j - 1) * 3 + 1] += lift;
            }
            let mut mix = |cols: &mut dyn Iterator<Item = usize>, k: f32| {
                if k <= 0.0 {
                    return;
                }
                for c in cols {
                    out[c] = if k >= 1.0 {
                        top[c]
                    } else {
                        row[c] + k * (top[c] - row[c])
                    };
                }
            };
            for j in 1..NUM_JOINTS {
                mix(&mut joint_columns(j), joint_weight(j, w));
            }
            for (part, cols) in &contacts {
                mix(&mut cols.clone(), w[*part]);
            }
            out
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::{FEATURE_DIM, ROOT_LIN_VEL, ROOT_ROT_VEL};
    use crate::model::tokens::BasePatch;

    /// 30 steps (120 frames) of 1 layer, with a left-arm patch over steps 10..15.
    fn left_arm_clip() -> MotionTokens {
        MotionTokens::new(vec![vec![vec![0; 30]; 1]; 4])
            .unwrap()
            .with_base(vec![BasePatch {
                part: 0,
                start: 10,
                codes: vec![vec![1; 5]],
            }])
            .unwrap()
    }

    #[test]
    fn a_layer_eases_in_and_out_over_its_seams_and_is_nothing_outside() {
        let w = layer_weights(&left_arm_clip());
        assert_eq!(w.len(), 120);
        let arm: Vec<f32> = w.iter().map(|w| w[0]).collect();
        assert!(arm[..40].iter().chain(&arm[60..]).all(|&x| x == 0.0));
        assert!(w.iter().all(|w| w[1..] == [0.0; 3]));
        // Rising over frames 40..48, 1 over 48..52, falling over 52..60, symmetric.
        assert!(arm[40] > 0.0 && arm[40] < 0.02, "{}", arm[40]);
        assert!(arm[40..48].windows(2).all(|p| p[0] < p[1]));
        assert!(arm[48..52].iter().all(|&x| x == 1.0));
        for k in 0..8 {
            assert_eq!(arm[40 + k], arm[59 - k]);
        }
        assert!((arm[44] - 0.5).abs() < 0.1, "{}", arm[44]);
        // At the motion's ends no easing: a clip from the start is whole from frame 0.
        let from_start = MotionTokens::new(vec![vec![vec![0; 30]; 1]; 4])
            .unwrap()
            .with_base(vec![BasePatch {
                part: 3,
                start: 0,
                codes: vec![vec![1; 4]],
            }])
            .unwrap();
        let w = layer_weights(&from_start);
        assert_eq!(w[0][3], 1.0);
        assert_eq!(w[7][3], 1.0);
        assert!(w[15][3] > 0.0 && w[16][3] == 0.0);
    }

    #[test]
    fn only_the_clips_parts_follow_the_layer_and_never_the_root() {
        let tokens = left_arm_clip();
        let weights = layer_weights(&tokens);
        let base: Features = (0..120).map(|t| [t as f32; FEATURE_DIM]).collect();
        let mut layered: Features = (0..120).map(|t| [1000.0 + t as f32; FEATURE_DIM]).collect();
        // The same pelvis height as the base's, but for frame 50's, 0.25 m lower.
        for (t, row) in layered.iter_mut().enumerate() {
            row[ROOT_HEIGHT.start] = t as f32 - if t == 50 { 0.25 } else { 0.0 };
        }
        let out = compose(&base, &layered, &weights);
        // Frame 50's arm is as high above its pelvis as in the layer.
        let wrist_y = POSITIONS.start + (joint::L_WRIST - 1) * 3 + 1;
        assert_eq!(out[50][wrist_y], 1050.25);
        layered[50][ROOT_HEIGHT.start] = 50.0;
        let cols_of = |joints: &[usize]| -> Vec<usize> {
            joints.iter().flat_map(|&j| joint_columns(j)).collect()
        };
        let arm = cols_of(BodyPart::LeftArm.limb_joints());
        assert_eq!(arm.len(), 4 * 12);
        let out = compose(&base, &layered, &weights);
        for (t, row) in out.iter().enumerate() {
            for c in 0..FEATURE_DIM {
                let expected = if arm.contains(&c) {
                    base[t][c] + weights[t][0] * 1000.0
                } else {
                    base[t][c]
                };
                assert!(
                    (row[c] - expected).abs() < 1e-3,
                    "frame {t}, column {c}: {} for {expected}",
                    row[c]
                );
                if !arm.contains(&c) || weights[t][0] == 0.0 {
                    assert_eq!(
                        row[c].to_bits(),
                        base[t][c].to_bits(),
                        "frame {t}, column {c}"
                    );
                }
            }
        }
        assert_eq!(out[50][arm[0]], layered[50][arm[0]]);
        // The root's columns, the pelvis's velocity, the trunk, the other parts, the contacts.
        for c in ROOT_ROT_VEL
            .chain(ROOT_LIN_VEL)
            .chain(ROOT_HEIGHT)
            .chain(VELOCITIES.start..VELOCITIES.start + 3)
            .chain(cols_of(&[joint::SPINE3, joint::NECK, joint::HEAD]))
            .chain(cols_of(BodyPart::RightArm.limb_joints()))
            .chain(cols_of(BodyPart::LeftLeg.limb_joints()))
            .chain(CONTACTS)
        {
            assert_eq!(out[50][c], base[50][c], "column {c}");
        }
    }

    #[test]
    fn the_trunk_follows_only_where_both_arms_are_layered() {
        let mut w = [1.0, 0.0, 0.0, 0.0];
        assert_eq!(joint_weight(joint::SPINE2, &w), 0.0);
        assert_eq!(joint_weight(joint::L_WRIST, &w), 1.0);
        assert_eq!(joint_weight(joint::PELVIS, &w), 0.0);
        w[1] = 0.5;
        assert_eq!(joint_weight(joint::HEAD, &w), 0.5);
        assert_eq!(joint_weight(joint::R_WRIST, &w), 0.5);
        w[3] = 1.0;
        assert_eq!(joint_weight(joint::R_FOOT, &w), 1.0);
        assert_eq!(joint_weight(joint::L_KNEE, &w), 0.0);
    }
}
