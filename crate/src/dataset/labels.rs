//! What each source's action labels become in our content vocabulary, and which side a
//! one-sided action was performed with.
//!
//! Content labels are lower-case words joined by `-` (`squat`, `kick-left-leg`); a label that
//! names a side is mirrored by swapping `left` and `right` ([`super::captions::mirror_content`]).
//! Sources label many one-sided actions without their side (Bandai-Namco's `kick` and `punch`,
//! CMU's `soccer`, DeepMimic's `kick`), yet "kicks with the left foot" must move the left foot.
//! So for those the side is read off the motion itself ([`performed_side`]): the foot that rises
//! clearly higher, or the wrist that moves clearly faster, names it; a clip that uses both
//! sides alike keeps the label without a side.

use crate::geom;
use crate::skeleton::{joint, Pose};

/// Which limb pair a one-sided action uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Limb {
    Leg,
    Arm,
}

/// A source label read as our content label, and the limb whose side the motion decides
/// (`None` when the label needs no side, or already names it).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Reading {
    pub content: String,
    pub sided: Option<Limb>,
}

fn plain(content: &str) -> Option<Reading> {
    Some(Reading {
        content: content.to_string(),
        sided: None,
    })
}

fn sided(content: &str, limb: Limb) -> Option<Reading> {
    Some(Reading {
        content: content.to_string(),
        sided: Some(limb),
    })
}

/// Bandai-Namco content labels (already our vocabulary): only the one-sided ones change.
pub fn bandai(content: &str) -> Reading {
    match content {
        "kick" => sided("kick", Limb::Leg),
        "punch" => sided("punch", Limb::Arm),
        "slash" => sided("slash", Limb::Arm),
        _ => None,
    }
    .unwrap_or(Reading {
        content: content.to_string(),
        sided: None,
    })
}

/// HDM05 motion classes (`squat1Reps`): the class name with its repetition count and starting
/// side dropped where they do not change what the motion is called.
pub fn hdm05(class: &str) -> Option<Reading> {
    match class {
        "squat1Reps" => plain("squat"),
        "hopBothLegs1hops" => plain("jump-forward"),
        "lieDownFloor" => plain("lie-down"),
        "depositFloorR" => plain("put-down-right-hand"),
        "grabHighR" => plain("reach-up-right-hand"),
        "kickLFront1Reps" => plain("kick-left-leg"),
        "elbowToKnee1RepsLelbowStart" => plain("elbow-to-knee"),
        "jogLeftCircle4StepsRstart" => plain("jog-circle-left"),
        "rotateArmsBothBackward1Reps" => plain("arm-circles"),
        "sneak2StepsLStart" => plain("sneak"),
        "throwBasketball" => sided("throw", Limb::Arm),
        _ => None,
    }
}

/// The CMU 8-action subset's folder names.
pub fn cmu(action: &str) -> Option<Reading> {
    match action {
        "basketball" => plain("basketball"),
        "basketball_signal" => plain("referee-signals"),
        "directing_traffic" => plain("direct-traffic"),
        "jumping" => plain("jump"),
        "running" => plain("run"),
        "soccer" => sided("kick-ball", Limb::Leg),
        "walking" => plain("walk"),
        "washwindow" => plain("wash-window"),
        _ => None,
    }
}

/// DeepMimic's clip names (`humanoid3d_<name>.txt`).
pub fn deepmimic(name: &str) -> Option<Reading> {
    match name {
        "backflip" => plain("backflip"),
        "cartwheel" => plain("cartwheel"),
        "crawl" => plain("crawl"),
        "dance_a" | "dance_b" => plain("dance"),
        "dance_spin" => plain("dance-spin"),
        "getup_facedown" => plain("get-up-face-down"),
        "getup_faceup" => plain("get-up-face-up"),
        "jog" => plain("jog"),
        "jump" => plain("jump"),
        "kick" => sided("kick", Limb::Leg),
        "punch" => sided("punch", Limb::Arm),
        "ready_to_walk_mirror" => plain("start-walking"),
        "walk_to_ready_mirror" => plain("stop-walking"),
        "roll" => plain("roll"),
        "run" => plain("run"),
        "sideflip" => plain("sideflip"),
        "spin" => plain("spin"),
        "spinkick" => sided("spin-kick", Limb::Leg),
        "stealthy_walk" => plain("sneak"),
        "walk" => plain("walk"),
        "zombie_walk" => plain("zombie-walk"),
        _ => None,
    }
}

/// The performer's side a motion was done with.
pub use crate::skeleton::Side;

/// How much more one side must do than the other before the clip counts as one-sided: a kick
/// lifts the kicking foot several times higher than the standing foot rises, while alternating
/// or two-handed actions stay well under this ratio.
pub const SIDE_RATIO: f64 = 1.5;

/// The side `limb` was used with in `poses` (20 fps, metres, Y up, any place and facing), or
/// `None` when neither side clearly dominates. Legs: the ankle's highest rise above its own
/// median height. Arms: the wrist's top speed relative to the pelvis, so walking along does
/// not count.
pub fn performed_side(poses: &[Pose], limb: Limb) -> Option<Side> {
    if poses.len() < 3 {
        return None;
    }
    let measure = |j: usize| -> f64 {
        match limb {
            Limb::Leg => {
                let mut heights: Vec<f64> = poses.iter().map(|p| p[j][1]).collect();
                heights.sort_by(f64::total_cmp);
                heights[heights.len() - 1] - heights[heights.len() / 2]
            }
            Limb::Arm => poses
                .windows(2)
                .map(|w| {
                    let a = geom::sub(w[0][j], w[0][0]);
                    let b = geom::sub(w[1][j], w[1][0]);
                    geom::dist(a, b)
                })
                .fold(0.0, f64::max),
        }
    };
    let (l, r) = match limb {
        Limb::Leg => (measure(joint::L_ANKLE), measure(joint::R_ANKLE)),
        Limb::Arm => (measure(joint::L_WRIST), measure(joint::R_WRIST)),
    };
    if l > SIDE_RATIO * r {
        Some(Side::Left)
    } else if r > SIDE_RATIO * l {
        Some(Side::Right)
    } else {
        None
    }
}

/// The content label of a clip: the reading's label, with the side appended when the motion
/// shows one (`kick` → `kick-left-leg`, `punch` → `punch-right-hand`).
pub fn content_of(reading: &Reading, poses: &[Pose]) -> String {
    let Some(limb) = reading.sided else {
        return reading.content.clone();
    };
    match (performed_side(poses, limb), limb) {
        (None, _) => reading.content.clone(),
        (Some(side), limb) => {
            let side = match side {
                Side::Left => "left",
                Side::Right => "right",
            };
            let limb = match limb {
                Limb::Leg => "leg",
                Limb::Arm => "hand",
            };
            format!("{}-{side}-{limb}", reading.content)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton;

    fn standing(frames: usize) -> Vec<Pose> {
        let offsets = skeleton::Offsets::reference();
        let rest = skeleton::forward_kinematics(
            &[[geom::Quat::IDENTITY; skeleton::NUM_JOINTS]],
            &offsets,
            &[[0.0, 0.9, 0.0]],
        )[0];
        vec![rest; frames]
    }

    #[test]
    fn the_foot_that_rises_names_the_side() {
        let mut poses = standing(20);
        for (t, pose) in poses.iter_mut().enumerate() {
            let lift = if (8..12).contains(&t) { 0.6 } else { 0.0 };
            pose[joint::R_ANKLE][1] += lift;
            pose[joint::L_ANKLE][1] += if t == 3 { 0.1 } else { 0.0 };
        }
        assert_eq!(performed_side(&poses, Limb::Leg), Some(Side::Right));
        let r = Reading {
            content: "kick".into(),
            sided: Some(Limb::Leg),
        };
        assert_eq!(content_of(&r, &poses), "kick-right-leg");
        let mirrored = skeleton::mirror_poses(&poses);
        assert_eq!(content_of(&r, &mirrored), "kick-left-leg");
    }

    #[test]
    fn both_sides_alike_keep_the_label_unsided() {
        let mut poses = standing(20);
        for (t, pose) in poses.iter_mut().enumerate() {
            pose[joint::L_WRIST][2] += 0.05 * t as f64;
            pose[joint::R_WRIST][2] += 0.06 * t as f64;
        }
        let r = Reading {
            content: "punch".into(),
            sided: Some(Limb::Arm),
        };
        assert_eq!(content_of(&r, &poses), "punch");
        assert_eq!(performed_side(&standing(20), Limb::Arm), None);
    }

    #[test]
    fn every_source_label_has_a_reading() {
        for class in [
            "squat1Reps",
            "hopBothLegs1hops",
            "lieDownFloor",
            "depositFloorR",
            "grabHighR",
            "kickLFront1Reps",
            "elbowToKnee1RepsLelbowStart",
            "jogLeftCircle4StepsRstart",
            "rotateArmsBothBackward1Reps",
            "sneak2StepsLStart",
            "throwBasketball",
        ] {
            assert!(hdm05(class).is_some(), "{class}");
        }
        assert!(hdm05("cartwheelLHandStart1Reps").is_none());
        assert_eq!(cmu("soccer").unwrap().sided, Some(Limb::Leg));
        assert_eq!(deepmimic("stealthy_walk").unwrap().content, "sneak");
        assert_eq!(bandai("walk").content, "walk");
        assert_eq!(bandai("kick").sided, Some(Limb::Leg));
    }
}
