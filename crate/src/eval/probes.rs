//! Control probes: does the model do what was asked where it was asked?
//!
//! - left/right: over many seeds, raising or waving the left (right) hand must lift the left
//!   (right) wrist higher than the other;
//! - edit locality: editing one arm of a motion must leave the legs where they were;
//! - continuity: the join of two blended segments must not be faster than real motion ever is;
//! - left/right for legs: kicking with the left (right) foot must lift the left (right) ankle
//!   higher than the other;
//! - actions: "a person bows" must bend the trunk forward about as far as the dataset's bows
//!   do, "a person waves the left hand" must move that hand about as much as its waves do, and
//!   squats, jumps, lying down, kicks and throws likewise by one measure each ([`ACTIONS`]).

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

/// The highest a joint (a wrist, an ankle) gets above its own starting height, in metres.
fn joint_rise(poses: &[Pose], j: usize) -> f64 {
    let start = poses.first().map_or(0.0, |p| p[j][1]);
    poses
        .iter()
        .map(|p| p[j][1] - start)
        .fold(f64::MIN, f64::max)
}

/// Raises and waves each hand with `seeds` seeds each; a sample is correct when the asked
/// wrist rises more than the other one.
pub fn left_right(model: &MotionModel, seeds: u64, seconds: f64) -> LeftRightReport {
    sided_prompts(model, &ARM_PROMPTS, seeds, seconds)
}

/// Kicks with each foot with `seeds` seeds each; a sample is correct when the asked ankle
/// rises more than the other one.
pub fn left_right_legs(model: &MotionModel, seeds: u64, seconds: f64) -> LeftRightReport {
    sided_prompts(model, &LEG_PROMPTS, seeds, seconds)
}

/// The legs' left/right prompts: the asked ankle, then the other.
pub const LEG_PROMPTS: [(&str, usize, usize); 2] = [
    (
        "a person kicks with the left foot",
        joint::L_ANKLE,
        joint::R_ANKLE,
    ),
    (
        "a person kicks with the right foot",
        joint::R_ANKLE,
        joint::L_ANKLE,
    ),
];

fn sided_prompts(
    model: &MotionModel,
    prompts: &[(&str, usize, usize)],
    seeds: u64,
    seconds: f64,
) -> LeftRightReport {
    let frames = (seconds * FPS) as usize;
    let mut rows = Vec::new();
    let (mut good, mut total) = (0, 0);
    for &(prompt, asked, other) in prompts {
        let correct = (0..seeds)
            .filter(|seed| {
                let poses = block_on(async {
                    model
                        .joints(&model.generate(prompt, &[], frames, *seed).await)
                        .await
                });
                joint_rise(&poses, asked) > joint_rise(&poses, other)
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

/// The arms' left/right prompts: the asked wrist, then the other.
pub const ARM_PROMPTS: [(&str, usize, usize); 4] = [
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
        left_wrist_rise_gain_cm: (joint_rise(&b, joint::L_WRIST) - joint_rise(&a, joint::L_WRIST))
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
    /// Short name (`coma probe action <name>`).
    pub name: &'static str,
    pub prompt: &'static str,
    /// The dataset's content labels of the real performances (see `dataset.json`).
    pub contents: &'static [&'static str],
    /// What [`ActionProbe::measure`] gives, and its unit.
    pub measure_name: &'static str,
    pub unit: &'static str,
    pub measure: fn(&[Pose]) -> f64,
}

/// "A person bows", by the [`trunk_lean`] (degrees).
pub const BOW: ActionProbe = ActionProbe {
    name: "bow",
    prompt: "a person bows",
    contents: &["bow"],
    measure_name: "trunk lean",
    unit: "°",
    measure: trunk_lean,
};

/// "A person waves the left hand", by the [`left_wrist_speed`] (m/s).
pub const LEFT_WAVE: ActionProbe = ActionProbe {
    name: "wave",
    prompt: "a person waves the left hand",
    contents: &["wave-left-hand"],
    measure_name: "left-wrist speed about the pelvis",
    unit: " m/s",
    measure: left_wrist_speed,
};

/// The pelvis height of the first frames (median of the first 5), metres: where a motion
/// starts from, robust to one odd frame.
fn start_height(poses: &[Pose]) -> f64 {
    quantile(
        poses.iter().take(5).map(|p| p[joint::PELVIS][1]).collect(),
        0.5,
    )
}

/// How far the pelvis drops below its starting height at the lowest point, metres: a squat
/// lowers it by about half the leg length; a walk's bob is a few centimetres.
pub fn pelvis_drop(poses: &[Pose]) -> f64 {
    let low = poses
        .iter()
        .map(|p| p[joint::PELVIS][1])
        .fold(f64::INFINITY, f64::min);
    if poses.is_empty() {
        0.0
    } else {
        start_height(poses) - low
    }
}

/// How far the pelvis rises above its starting height at the highest point, metres: a
/// jump lifts it by the flight's height plus the push-off's extension.
pub fn pelvis_rise(poses: &[Pose]) -> f64 {
    let high = poses
        .iter()
        .map(|p| p[joint::PELVIS][1])
        .fold(f64::NEG_INFINITY, f64::max);
    if poses.is_empty() {
        0.0
    } else {
        high - start_height(poses)
    }
}

/// Rise of the pelvis above its starting height (metres) beyond which a frame is part of a
/// jump: a walk bobs it by a few centimetres, a jump lifts it by 0.2 m or more.
pub const JUMP_RISE_M: f64 = 0.1;

/// Horizontal distance the pelvis covers per jump, metres: from the first frame to the last,
/// divided by the jumps (stretches of frames with the pelvis more than [`JUMP_RISE_M`] above
/// its starting height; at least one). A standing two-footed jump forward covers about a
/// metre in the training clips.
pub fn travel_per_jump(poses: &[Pose]) -> f64 {
    let (Some(first), Some(last)) = (poses.first(), poses.last()) else {
        return 0.0;
    };
    let start = start_height(poses);
    let up: Vec<bool> = poses
        .iter()
        .map(|p| p[joint::PELVIS][1] - start > JUMP_RISE_M)
        .collect();
    let jumps = (0..up.len())
        .filter(|&t| up[t] && (t == 0 || !up[t - 1]))
        .count();
    let (a, b) = (first[joint::PELVIS], last[joint::PELVIS]);
    (a[0] - b[0]).hypot(a[2] - b[2]) / jumps.max(1) as f64
}

/// How much lower the pelvis is over the last half second than at the start, metres: lying
/// down ends with it near the floor, about 0.8 m below standing.
pub fn pelvis_lowered_at_end(poses: &[Pose]) -> f64 {
    let tail = (FPS / 2.0) as usize;
    let end: Vec<f64> = poses
        .iter()
        .rev()
        .take(tail.max(1))
        .map(|p| p[joint::PELVIS][1])
        .collect();
    if poses.is_empty() {
        0.0
    } else {
        start_height(poses) - end.iter().sum::<f64>() / end.len() as f64
    }
}

/// The highest either ankle rises above its starting height, metres: a front kick swings
/// the foot to hip height or above; a walk's step lifts it some 15 cm.
pub fn ankle_rise(poses: &[Pose]) -> f64 {
    joint_rise(poses, joint::L_ANKLE).max(joint_rise(poses, joint::R_ANKLE))
}

/// The fastest either wrist moves about the pelvis in one frame, m/s: a throw whips the
/// throwing hand well past a wave's or a walk's arm swing.
pub fn peak_wrist_speed(poses: &[Pose]) -> f64 {
    [joint::L_WRIST, joint::R_WRIST]
        .iter()
        .flat_map(|&w| {
            poses.windows(2).map(move |p| {
                let a = geom::sub(p[0][w], p[0][joint::PELVIS]);
                let b = geom::sub(p[1][w], p[1][joint::PELVIS]);
                geom::dist(a, b) * FPS
            })
        })
        .fold(0.0, f64::max)
}

/// "A person does a squat", by the [`pelvis_drop`] (m).
pub const SQUAT: ActionProbe = ActionProbe {
    name: "squat",
    prompt: "a person does a squat",
    contents: &["squat"],
    measure_name: "pelvis drop",
    unit: " m",
    measure: pelvis_drop,
};

/// "A person jumps with both feet", by the [`pelvis_rise`] (m).
pub const JUMP: ActionProbe = ActionProbe {
    name: "jump",
    prompt: "a person jumps with both feet",
    contents: &["jump", "jump-forward"],
    measure_name: "pelvis rise",
    unit: " m",
    measure: pelvis_rise,
};

/// "A person jumps forward", by the [`travel_per_jump`] (m): the 90th percentile of the
/// training clips bounds it from above as the 10th does from below.
pub const JUMP_TRAVEL: ActionProbe = ActionProbe {
    name: "jump-travel",
    prompt: "a person jumps forward",
    contents: &["jump", "jump-forward"],
    measure_name: "travel per jump",
    unit: " m",
    measure: travel_per_jump,
};

/// "A person lies down on the floor", by the [`pelvis_lowered_at_end`] (m).
pub const LIE_DOWN: ActionProbe = ActionProbe {
    name: "lie-down",
    prompt: "a person lies down on the floor",
    contents: &["lie-down"],
    measure_name: "pelvis lowered at the end",
    unit: " m",
    measure: pelvis_lowered_at_end,
};

/// "A person kicks forward", by the [`ankle_rise`] (m).
pub const KICK: ActionProbe = ActionProbe {
    name: "kick",
    prompt: "a person kicks forward",
    contents: &["kick", "kick-left-leg", "kick-right-leg"],
    measure_name: "ankle rise",
    unit: " m",
    measure: ankle_rise,
};

/// "A person throws a ball", by the [`peak_wrist_speed`] (m/s).
pub const THROW: ActionProbe = ActionProbe {
    name: "throw",
    prompt: "a person throws a ball",
    contents: &["throw", "throw-left-hand", "throw-right-hand"],
    measure_name: "peak wrist speed about the pelvis",
    unit: " m/s",
    measure: peak_wrist_speed,
};

/// Every action probe.
pub const ACTIONS: [&ActionProbe; 8] = [
    &BOW,
    &LEFT_WAVE,
    &SQUAT,
    &JUMP,
    &JUMP_TRAVEL,
    &LIE_DOWN,
    &KICK,
    &THROW,
];

/// The probe's measure of each motion of `set` that shows its action.
pub fn real_performances(set: &MotionSet, probe: &ActionProbe) -> Vec<f64> {
    set.items
        .iter()
        .filter(|i| probe.shows(i))
        .map(|i| (probe.measure)(&set.joints(i)))
        .collect()
}

impl ActionProbe {
    /// Whether a dataset motion is labelled with the probe's action.
    pub fn shows(&self, item: &crate::dataset::motions::MotionItem) -> bool {
        item.content
            .as_deref()
            .is_some_and(|c| self.contents.contains(&c))
    }
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
                        // Measured as the engine shows it (feet planted).
                        let shown = crate::session::finish(&model.features(&tokens).await);
                        (probe.measure)(&crate::features::features_to_joints(&shown))
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
    fn action_measures_read_heights_and_speeds() {
        let stand = |h: f64| {
            let mut p = [[0.0; 3]; 22];
            p[joint::PELVIS][1] = h;
            p[joint::L_ANKLE][1] = 0.08;
            p[joint::R_ANKLE][1] = 0.08;
            p
        };
        // Squat: 0.95 m down to 0.5 m and back.
        let squat: Vec<Pose> = [0.95, 0.95, 0.95, 0.95, 0.95, 0.9, 0.7, 0.5, 0.6, 0.95]
            .iter()
            .map(|&h| stand(h))
            .collect();
        assert!((pelvis_drop(&squat) - 0.45).abs() < 1e-9);
        assert!(pelvis_rise(&squat).abs() < 1e-9);
        // Lying down: ends 0.15 m above the floor for the last half second.
        let mut lie: Vec<Pose> = (0..30).map(|_| stand(0.95)).collect();
        lie.extend((0..10).map(|_| stand(0.15)));
        assert!((pelvis_lowered_at_end(&lie) - 0.8).abs() < 1e-9);
        // Kick: the right ankle to 0.7 m.
        let mut kick = squat.clone();
        kick[7][joint::R_ANKLE][1] = 0.7;
        assert!((ankle_rise(&kick) - 0.62).abs() < 1e-9);
        // Throw: the right wrist moves 0.5 m in one frame: 10 m/s at 20 fps.
        let mut throw = vec![stand(0.95); 3];
        throw[2][joint::R_WRIST] = [0.0, 0.0, 0.5];
        assert!((peak_wrist_speed(&throw) - 10.0).abs() < 1e-9);
        assert_eq!(pelvis_drop(&[]), 0.0);
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
        assert!((joint_rise(&poses, joint::L_WRIST) - 0.6).abs() < 1e-12);
    }
}
