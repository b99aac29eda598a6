//! The dataset's real motions that the control probes hold generated motions against: the
//! training performances of an action (`coma probe bow|wave|squat|…`), and the test motions whose
//! frame-to-frame speeds bound how fast a blend's join may be (`coma probe continuity`,
//! `coma eval`).

use super::probes::{continuity, quantile, ActionProbe, ContinuityReport};
use crate::dataset::motions::MotionSet;
use crate::dataset::Split;
use crate::model::MotionModel;
use crate::skeleton::Pose;
use crate::timing::FPS;
use anyhow::Result;
use std::path::Path;

/// Generation's time step, seconds (one token: 4 frames at 20 fps).
const STEP_SECONDS: f64 = 0.2;

/// How much of an action the dataset's own performances show, by the probe's measure (in
/// its unit): the bar generated motions of the action's prompt are held to.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ActionReference {
    /// Training motions labelled with the action.
    pub motions: usize,
    /// Median of their measures.
    pub median: f64,
    /// 10th percentile of their measures: a generated motion that reaches it performs the
    /// action about as much as the dataset does.
    pub p10: f64,
    /// 90th percentile of their measures: a generated motion far beyond it overdoes the action
    /// (a jump that flies three metres).
    pub p90: f64,
    /// Median length of those motions, seconds, on generation's 0.2 s grid (1 to 9.8 s): how
    /// long a generated performance is asked to be. A kick takes under 2 s and lying down
    /// about 6; a fixed length would ask for a kick held or a lying down cut short.
    pub seconds: f64,
}

/// The probe's measure over the training motions of `data` that show its action; an error
/// when none is labelled with it.
pub fn action_reference(data: &Path, probe: &ActionProbe) -> Result<ActionReference> {
    let set = MotionSet::load(data, Split::Train)?;
    ActionReference::of(&set, probe).ok_or_else(|| {
        anyhow::anyhow!(
            "no training motion of {} is labelled {}",
            data.display(),
            probe.contents.join(" or ")
        )
    })
}

impl ActionReference {
    /// The probe's measure over the motions of `set` that show its action; `None` when none
    /// is labelled with it.
    pub fn of(set: &MotionSet, probe: &ActionProbe) -> Option<ActionReference> {
        let (real, frames): (Vec<f64>, Vec<f64>) = set
            .items
            .iter()
            .filter(|i| probe.shows(i))
            .map(|i| ((probe.measure)(&set.joints(i)), i.features.len() as f64))
            .unzip();
        let step = 1.0 / STEP_SECONDS;
        (!real.is_empty()).then(|| ActionReference {
            motions: real.len(),
            p10: quantile(real.clone(), 0.1),
            p90: quantile(real.clone(), 0.9),
            median: quantile(real, 0.5),
            seconds: ((quantile(frames, 0.5) / FPS * step).round() / step).clamp(1.0, 9.8),
        })
    }
}

/// Every motion of `set` as joint positions (metres, Y up, 20 fps): the real motion whose
/// speeds [`continuity`] compares a join with.
pub fn reference_motions(set: &MotionSet) -> Vec<Vec<Pose>> {
    set.items.iter().map(|i| set.joints(i)).collect()
}

/// The first segment of the continuity probe: a walk...
pub const CONTINUITY_FIRST: &str = "a person walks forward";
/// ...blended into a bow, a change of pace and posture that a bad join shows as a jump.
pub const CONTINUITY_SECOND: &str = "a person bows";

/// The continuity probe as `coma probe continuity` and `coma eval` run it: a walk blended
/// into a bow (seed `seed`), its join's speeds against the 99th percentile of the motions of
/// `reference` (the test split).
pub fn walk_to_bow(model: &MotionModel, reference: &MotionSet, seed: u64) -> ContinuityReport {
    continuity(
        model,
        CONTINUITY_FIRST,
        CONTINUITY_SECOND,
        &reference_motions(reference),
        seed,
    )
}
