//! Control probes: does the model do what was asked where it was asked?
//!
//! - left/right: over many seeds, raising or waving the left (right) hand must lift the left
//!   (right) wrist higher than the other;
//! - edit locality: editing one arm of a motion must leave the legs where they were;
//! - continuity: the join of two blended segments must not be faster than real motion ever is;
//! - actions: "a person bows" must bend the trunk forward about as far as the dataset's bows
//!   do, "a person waves the left hand" must move that hand about as much as its waves do.

use crate::dataset::motions::MotionSet;
use crate::executor::block_on;
use crate::features::{FeatureFrame, POSITIONS};
use crate::geom::{self, Vec3};
use crate::model::generate::SamplingOptions;
use crate::model::motion_model::sampling;
use crate::model::MotionModel;
use crate::skeleton::{joint, BodyPart, Pose};
use crate::timing::FPS;

/// Result of the left/right probe.
#[derive(Clone, Debug, serde::Serialize)]
pub struct LeftRightReport {
    /// Per prompt: how many samples lifted the asked wrist higher, out of how many.
    pub prompts: Vec<(String, usize, usize)>,
    /// Overall rate of correct samples.
    pub rate: f64,
}

/// The highest the wrist gets above its own starting height, in metres.
fn wrist_rise(poses: &[Pose], wrist: usize) -> f64 {
    let start = poses.first().map_or(0.0, |p| p[wrist][1]);
    poses
        .iter()
        .map(|p| p[wrist][1] - start)
        .fold(f64::MIN, f64::max)
}

/// Raises and waves each hand with `seeds` seeds each; a sample is correct when the asked
/// wrist rises more than the other one.
pub fn left_right(model: &MotionModel, seeds: u64, seconds: f64) -> LeftRightReport {
    let prompts = [
        (
            "a person raises the left hand",
            joint::L_WRIST,
            joint::R_WRIST,
        ),
        (
            "a person raises the right hand",
            joint::R_WRIST,
            joint::L_WRIST,
        ),
        (
            "a person waves the left hand",
            joint::L_WRIST,
            joint::R_WRIST,
        ),
        (
            "a person waves the right hand",
            joint::R_WRIST,
            joint::L_WRIST,
        ),
    ];
    let frames = (seconds * FPS) as usize;
    let mut rows = Vec::new();
    let (mut good, mut total) = (0, 0);
    for (prompt, asked, other) in prompts {
        let correct = (0..seeds)
            .filter(|seed| {
                let poses = block_on(async {
                    model
                        .joints(&model.generate(prompt, &[], frames, *seed).await)
                        .await
                });
                wrist_rise(&poses, asked) > wrist_rise(&poses, other)
            })
            .count();
        good += correct;
        total += seeds as usize;
        rows.push((prompt.to_string(), correct, seeds as usize));
    }
    LeftRightReport {
        prompts: rows,
        rate: good as f64 / total.max(1) as f64,
    }
}

/// The motion the edit-locality probe edits.
pub const LOCALITY_BASE: &str = "a person walks forward";
/// The left arm's new instruction in the edit-locality probe.
pub const LOCALITY_EDIT: &str = "the person waves the left hand above the head";
/// Seeds the edit-locality probe averages over by default (0..5): one seed's figure varies
/// by about half a centimetre.
pub const LOCALITY_SEEDS: u64 = 5;

/// Result of the edit-locality probe, averaged over its seeds.
#[derive(Clone, Debug, serde::Serialize)]
pub struct LocalityReport {
    /// Mean displacement of the leg joints between the original and the edited motion, cm.
    pub leg_change_cm: f64,
    /// How much higher the left wrist rises after the edit than before, cm.
    pub left_wrist_rise_gain_cm: f64,
    /// Both figures for each seed, in seed order.
    pub per_seed: Vec<LocalitySample>,
}

/// The edit-locality figures of one seed.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct LocalitySample {
    pub seed: u64,
    pub leg_change_cm: f64,
    pub left_wrist_rise_gain_cm: f64,
}

/// For each seed, generates `base` (a walk), edits the left arm with `instruction`, and
/// measures how much the legs moved and what the arm did. The legs are compared in the body's
/// own frame (the features' joint positions: relative to the root, facing +Z), so a changed
/// path or heading does not count as a leg change.
pub fn edit_locality(
    model: &MotionModel,
    base: &str,
    instruction: &str,
    seeds: std::ops::Range<u64>,
) -> LocalityReport {
    let per_seed: Vec<LocalitySample> = seeds
        .map(|seed| edit_locality_sample(model, base, instruction, seed))
        .collect();
    let mean = |f: fn(&LocalitySample) -> f64| {
        per_seed.iter().map(f).sum::<f64>() / per_seed.len().max(1) as f64
    };
    LocalityReport {
        leg_change_cm: mean(|s| s.leg_change_cm),
        left_wrist_rise_gain_cm: mean(|s| s.left_wrist_rise_gain_cm),
        per_seed,
    }
}

fn edit_locality_sample(
    model: &MotionModel,
    base: &str,
    instruction: &str,
    seed: u64,
) -> LocalitySample {
    let original = block_on(model.generate(base, &[], 120, seed));
    let edited =
        block_on(model.edit_parts(&original, instruction, &[BodyPart::LeftArm], base, seed + 1));
    let legs = [
        joint::L_HIP,
        joint::R_HIP,
        joint::L_KNEE,
        joint::R_KNEE,
        joint::L_ANKLE,
        joint::R_ANKLE,
        joint::L_FOOT,
        joint::R_FOOT,
    ];
    let local = |f: &FeatureFrame, j: usize| -> Vec3 {
        let at = POSITIONS.start + (j - 1) * 3;
        [f[at] as f64, f[at + 1] as f64, f[at + 2] as f64]
    };
    let (fa, fb) = (
        block_on(model.features(&original)),
        block_on(model.features(&edited)),
    );
    let mut total = 0.0;
    let mut count = 0;
    for (p, q) in fa.iter().zip(&fb) {
        for j in legs {
            total += geom::dist(local(p, j), local(q, j));
            count += 1;
        }
    }
    let (a, b) = (
        block_on(model.joints(&original)),
        block_on(model.joints(&edited)),
    );
    LocalitySample {
        seed,
        leg_change_cm: total / count.max(1) as f64 * 100.0,
        left_wrist_rise_gain_cm: (wrist_rise(&b, joint::L_WRIST) - wrist_rise(&a, joint::L_WRIST))
            * 100.0,
    }
}

// The pure measures of a motion live with the key-posture checks, which hold motions to the
// same figures and sit below this module (the plan, which the evaluation reads, holds posture
// tracks); the probes use them from there.
pub use crate::posture::measure::{
    foot_skating, frame_speeds, quantile, CONTACT_HEIGHT, SKATE_SPEED,
};

/// Result of the continuity probe.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ContinuityReport {
    /// Fastest root and joint speeds within ±2 frames of the join (m/s).
    pub join_root_speed: f64,
    pub join_joint_speed: f64,
    /// 99th percentiles of those speeds over the reference motions (m/s).
    pub p99_root_speed: f64,
    pub p99_joint_speed: f64,
}

impl ContinuityReport {
    /// True when the join is no faster than the 99th percentile of real motion.
    pub fn passes(&self) -> bool {
        self.join_root_speed <= self.p99_root_speed && self.join_joint_speed <= self.p99_joint_speed
    }
}

/// Blends two generated segments and compares the speeds at the join with the 99th
/// percentile of `reference` motions' frame-to-frame speeds.
pub fn continuity(
    model: &MotionModel,
    first: &str,
    second: &str,
    reference: &[Vec<Pose>],
    seed: u64,
) -> ContinuityReport {
    let (ta, tb) = (model.condition(first, &[]), model.condition(second, &[]));
    let a = block_on(model.generate(first, &[], 100, seed));
    let b = block_on(model.generate(second, &[], 100, seed + 1));
    let joined = block_on(model.spam.blend(&a, &b, &ta, &tb, 2, &sampling(seed + 2)));
    let poses = block_on(model.joints(&joined));
    let join = a[0][0].len() * crate::timing::FRAMES_PER_TOKEN;
    let speeds = frame_speeds(&poses);
    let near = &speeds[join.saturating_sub(2).min(speeds.len())..(join + 2).min(speeds.len())];
    let all: Vec<(f64, f64)> = reference.iter().flat_map(|m| frame_speeds(m)).collect();
    ContinuityReport {
        join_root_speed: near.iter().map(|s| s.0).fold(0.0, f64::max),
        join_joint_speed: near.iter().map(|s| s.1).fold(0.0, f64::max),
        p99_root_speed: quantile(all.iter().map(|s| s.0).collect(), 0.99),
        p99_joint_speed: quantile(all.iter().map(|s| s.1).collect(), 0.99),
    }
}

/// The furthest the trunk leans from upright over a motion: the largest angle, in degrees,
/// between the pelvis-to-head line and the vertical (Y up). About 15° for a walk; a bow is a
/// forward lean well beyond it.
pub fn trunk_lean(poses: &[Pose]) -> f64 {
    poses
        .iter()
        .map(|p| {
            let v = geom::sub(p[joint::HEAD], p[joint::PELVIS]);
            v[0].hypot(v[2]).atan2(v[1]).to_degrees()
        })
        .fold(0.0, f64::max)
}

/// How fast the left wrist moves about the pelvis, in m/s, averaged over the motion: a wave
/// swings it back and forth; a walk's arm swing is slower, standing still is near zero.
pub fn left_wrist_speed(poses: &[Pose]) -> f64 {
    let relative: Vec<Vec3> = poses
        .iter()
        .map(|p| geom::sub(p[joint::L_WRIST], p[joint::PELVIS]))
        .collect();
    if relative.len() < 2 {
        return 0.0;
    }
    let path: f64 = relative
        .windows(2)
        .map(|w| geom::norm(geom::sub(w[1], w[0])))
        .sum();
    path * FPS / (relative.len() - 1) as f64
}

/// An action of the dataset, the prompt asking for it, and one number saying how much of it a
/// motion performs, so generated motions can be held against the dataset's own performances.
pub struct ActionProbe {
    pub prompt: &'static str,
    /// The dataset's content label of the real performances (see `dataset.json`).
    pub content: &'static str,
    /// What [`ActionProbe::measure`] gives, and its unit.
    pub measure_name: &'static str,
    pub unit: &'static str,
    pub measure: fn(&[Pose]) -> f64,
}

/// "A person bows", by the [`trunk_lean`] (degrees).
pub const BOW: ActionProbe = ActionProbe {
    prompt: "a person bows",
    content: "bow",
    measure_name: "trunk lean",
    unit: "°",
    measure: trunk_lean,
};

/// "A person waves the left hand", by the [`left_wrist_speed`] (m/s).
pub const LEFT_WAVE: ActionProbe = ActionProbe {
    prompt: "a person waves the left hand",
    content: "wave-left-hand",
    measure_name: "left-wrist speed about the pelvis",
    unit: "m/s",
    measure: left_wrist_speed,
};

/// The probe's measure of each motion of `set` that shows its action.
pub fn real_performances(set: &MotionSet, probe: &ActionProbe) -> Vec<f64> {
    set.items
        .iter()
        .filter(|i| i.content.as_deref() == Some(probe.content))
        .map(|i| (probe.measure)(&set.joints(i)))
        .collect()
}

/// Result of an action probe for one guidance scale.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ActionReport {
    pub guidance: f32,
    /// The measure of each seed's motion.
    pub values: Vec<f64>,
    /// Share of seeds that reach the 10th percentile of the real performances.
    pub reaching: f64,
}

/// Generates the probe's prompt (`seconds` long) with each seed at each guidance scale of the
/// base transformer (the other sampling options from `options`, whose seed is replaced), and
/// measures each motion against `real_p10`, the 10th percentile of [`real_performances`].
pub fn action(
    model: &MotionModel,
    probe: &ActionProbe,
    seeds: u64,
    seconds: f64,
    options: &SamplingOptions,
    guidance: &[f32],
    real_p10: f64,
) -> Vec<ActionReport> {
    let frames = (seconds * FPS) as usize;
    guidance
        .iter()
        .map(|&g| {
            let values: Vec<f64> = (0..seeds)
                .map(|seed| {
                    let options = SamplingOptions {
                        base_guidance: g,
                        seed,
                        ..options.clone()
                    };
                    block_on(async {
                        let tokens = model
                            .generate_with(probe.prompt, &[], frames, &options)
                            .await;
                        (probe.measure)(&model.joints(&tokens).await)
                    })
                })
                .collect();
            let reaching = values.iter().filter(|&&v| v >= real_p10).count() as f64
                / values.len().max(1) as f64;
            ActionReport {
                guidance: g,
                values,
                reaching,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_left_wrist_speed_is_about_the_pelvis() {
        // The whole body walks forward at 1.2 m/s: no speed about the pelvis.
        let walk: Vec<Pose> = (0..20)
            .map(|t| {
                let mut p = [[0.0; 3]; 22];
                for j in p.iter_mut() {
                    j[2] = 0.06 * t as f64;
                }
                p
            })
            .collect();
        assert!(left_wrist_speed(&walk).abs() < 1e-9);
        // The wrist swings ±0.1 m sideways each frame: 0.2 m a frame, 4 m/s at 20 fps.
        let wave: Vec<Pose> = (0..21)
            .map(|t| {
                let mut p = [[0.0; 3]; 22];
                p[joint::L_WRIST][0] = if t % 2 == 0 { 0.1 } else { -0.1 };
                p
            })
            .collect();
        assert!((left_wrist_speed(&wave) - 4.0).abs() < 1e-9);
        assert_eq!(left_wrist_speed(&wave[..1]), 0.0);
    }

    #[test]
    fn an_upright_trunk_leans_zero_and_a_bent_one_its_angle() {
        let mut upright = [[0.0; 3]; 22];
        upright[joint::HEAD] = [0.0, 0.6, 0.0];
        let mut bent = upright;
        // Head as far forward (+Z) as it is above the pelvis: 45°.
        bent[joint::HEAD] = [0.0, 0.4, 0.4];
        assert!(trunk_lean(&[upright]).abs() < 1e-9);
        assert!((trunk_lean(&[upright, bent, upright]) - 45.0).abs() < 1e-9);
        // Sideways counts the same as forward.
        bent[joint::HEAD] = [-0.3, 0.3 * 3f64.sqrt(), 0.0];
        assert!((trunk_lean(&[bent]) - 30.0).abs() < 1e-9);
    }

    #[test]
    fn quantiles_and_speeds() {
        assert_eq!(quantile(vec![3.0, 1.0, 2.0], 0.0), 1.0);
        assert_eq!(quantile(vec![3.0, 1.0, 2.0], 1.0), 3.0);
        assert!(quantile(vec![], 0.5).is_nan());
        let a = [[0.0; 3]; 22];
        let mut b = a;
        b[0] = [0.05, 0.0, 0.0];
        b[20] = [0.0, 0.1, 0.0];
        let s = frame_speeds(&[a, b]);
        assert!((s[0].0 - 1.0).abs() < 1e-9 && (s[0].1 - 2.0).abs() < 1e-9);
    }

    #[test]
    fn a_planted_foot_does_not_skate_and_a_sliding_one_does() {
        let mut poses = vec![[[0.0; 3]; 22]; 11];
        for (t, p) in poses.iter_mut().enumerate() {
            for j in p.iter_mut() {
                j[1] = 0.5;
            }
            // Left foot planted, right foot lifted and swinging forward.
            p[joint::L_ANKLE] = [0.1, 0.02, 0.0];
            p[joint::L_FOOT] = [0.1, 0.0, 0.1];
            p[joint::R_ANKLE] = [-0.1, 0.2, t as f64 * 0.05];
            p[joint::R_FOOT] = [-0.1, 0.2, t as f64 * 0.05 + 0.1];
        }
        assert_eq!(foot_skating(&poses), 0.0);
        // Now the planted foot slides 5 cm a frame (1 m/s) for half the motion.
        for (t, p) in poses.iter_mut().enumerate().skip(5) {
            p[joint::L_FOOT][2] = 0.1 + (t - 5) as f64 * 0.05;
        }
        assert!(
            (foot_skating(&poses) - 0.5).abs() < 1e-12,
            "{}",
            foot_skating(&poses)
        );
    }

    #[test]
    fn wrist_rise_is_relative_to_the_start() {
        let mut poses = vec![[[0.0; 3]; 22]; 3];
        poses[0][joint::L_WRIST][1] = 1.0;
        poses[1][joint::L_WRIST][1] = 1.6;
        poses[2][joint::L_WRIST][1] = 1.2;
        assert!((wrist_rise(&poses, joint::L_WRIST) - 0.6).abs() < 1e-12);
    }
}
