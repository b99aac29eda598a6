//! The training dataset: every motion capture source we have, converted into one dataset in
//! the HumanML3D layout.
//!
//! `coma data build [--bandai <archive>] [--hdm05 <archive>] [--cmu <archive>]
//! [--deepmimic <folder>] --out <dir>` (each source optional, at least one) writes:
//!
//! | path                    | content                                                        |
//! |-------------------------|----------------------------------------------------------------|
//! | `new_joint_vecs/<n>.npy`| (T, 263) float32 features, 20 fps, T ≤ 196                      |
//! | `new_joints/<n>.npy`    | (T, 22, 3) float32 joints recovered from those features, metres |
//! | `texts/<n>.txt`         | global captions, one per line, HumanML3D style: `caption#tokens#0.0#0.0`, tokens are the lower-cased words tagged `/OTHER` (we run no part-of-speech tagger) |
//! | `part_texts/<n>.txt`    | one line per body part: `left arm#<sentence>` (also `right arm`, `left leg`, `right leg`), from the pose-code describer |
//! | `train.txt` `val.txt` `test.txt` | item names, split by source clip and actor: every window and mirror of a clip is in one split, and no test actor performs in training ([`Source::split`]) |
//! | `Mean.npy` `Std.npy`    | (263,) float32 statistics of the training split              |
//! | `dataset.json`          | counts, hours, licences per source, vocabulary and every item's record |
//!
//! Item names: the source file stem (`HDM_bd_squat1Reps_001`, `cmu_train_soccer_3`,
//! `deepmimic_kick`; Bandai-Namco's with the dataset shortened, `bn2_wave-left-hand_normal_001`),
//! `_w<k>` when a long clip is cut into windows, and an `M` prefix for the left/right mirror
//! (whose labels and captions swap left and right). Source labels become our content labels in
//! [`labels`] (one-sided actions get the side the motion shows).

pub mod bandai;
pub mod captions;
pub mod labels;
pub mod motions;

use crate::bvh::{self, Bvh};
use crate::features::{self, FeatureStats};
use crate::geom;
use crate::mocap;
use crate::posecodes;
use crate::skeleton::{self, Offsets, Pose};
use crate::timing::{FPS, MAX_FRAMES};
use anyhow::{Context, Result};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Fewest feature rows in one item (1 s); shorter clips are skipped. HumanML3D keeps 2 s and
/// more, but dataset 2's raise-hand clips last 1.2 s and carry most of the left/right arm
/// vocabulary, so we keep them.
pub const MIN_FRAMES: usize = 20;
/// Global captions written per item.
pub const CAPTIONS_PER_ITEM: usize = 4;
/// HDM05 actors whose clips are held out for testing (one of five; every class has clips by
/// this actor), so no test performer is seen in training.
pub const HDM05_TEST_ACTORS: [&str; 1] = ["tr"];

pub use crate::mocap::Source;

/// Where a source's clips go.
impl Source {
    /// Which split a clip of this source goes to, when the source itself decides it: HDM05 by
    /// actor (`hdm05_test_actors` are held out for testing), CMU by the source's own split,
    /// DeepMimic always training (one clip per action, so holding one out would remove the
    /// action). `None` for Bandai-Namco, which is split by clip within each label
    /// ([`assign_splits`]).
    pub fn split(
        self,
        actor: &str,
        source_test: bool,
        hdm05_test_actors: &[String],
    ) -> Option<Split> {
        match self {
            Source::Bandai => None,
            Source::Hdm05 if hdm05_test_actors.iter().any(|a| a == actor) => Some(Split::Test),
            Source::Cmu if source_test => Some(Split::Test),
            _ => Some(Split::Train),
        }
    }
}

/// Which part of the data an item belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Split {
    Train,
    Val,
    Test,
}

impl Split {
    /// File name of the split's list.
    pub fn file_name(self) -> &'static str {
        match self {
            Split::Train => "train.txt",
            Split::Val => "val.txt",
            Split::Test => "test.txt",
        }
    }

    /// The split's name as command lines and reports spell it.
    pub fn name(self) -> &'static str {
        match self {
            Split::Train => "train",
            Split::Val => "val",
            Split::Test => "test",
        }
    }
}

impl std::str::FromStr for Split {
    type Err = String;

    fn from_str(s: &str) -> Result<Split, String> {
        [Split::Train, Split::Val, Split::Test]
            .into_iter()
            .find(|split| split.name() == s)
            .ok_or_else(|| format!("unknown split '{s}' (train, val or test)"))
    }
}

/// What to build. Every source is optional; at least one must be given.
#[derive(Clone, Debug, Default)]
pub struct BuildOptions {
    /// The Bandai-Namco `.tar.xz` archive or a folder it was extracted into.
    pub bandai: Option<PathBuf>,
    /// HDM05's `hdm05-subset-amc.tar.xz` or its extracted folder.
    pub hdm05: Option<PathBuf>,
    /// CMU's `cmu-8action-expmap.tar.xz` or its extracted folder.
    pub cmu: Option<PathBuf>,
    /// The `deepmimic` folder (`humanoid3d.txt` and `motions/`).
    pub deepmimic: Option<PathBuf>,
    /// Output folder (replaced only once the new build is complete).
    pub out: PathBuf,
    /// Use only this many clips of each source, spread over it (for quick builds and tests).
    pub limit: Option<usize>,
    /// HDM05 actors held out for testing instead of [`HDM05_TEST_ACTORS`]: how well the
    /// networks carry over to a performer they never saw can be measured for other actors
    /// (a dataset built so is for such measurements, not for the shipped model).
    pub hdm05_test_actors: Option<Vec<String>>,
}

/// The record of one item in `dataset.json`.
#[derive(Clone, Debug, Serialize)]
pub struct ItemRecord {
    pub name: String,
    pub source: Source,
    /// Source file stem.
    pub clip: String,
    /// Who performed it, where the source says (HDM05's actors); else a name for the source.
    pub actor: String,
    pub split: Split,
    /// Feature rows (frames at 20 fps).
    pub frames: usize,
    pub mirrored: bool,
    /// Content label as it applies to this item (mirrors swap left and right).
    pub content: String,
    pub style: String,
    pub captions: Vec<String>,
    /// Per-part sentences from the pose-code describer, keyed by part name.
    pub parts: BTreeMap<String, String>,
}

/// What one source contributed, in `dataset.json`.
#[derive(Clone, Debug, Serialize)]
pub struct SourceSummary {
    pub licence: String,
    pub attribution: String,
    /// Source clips read.
    pub source_clips: usize,
    /// Items written per split, mirrors included.
    pub items: BTreeMap<Split, usize>,
    /// Feature rows over its items.
    pub frames: usize,
    /// Items per content label.
    pub actions: BTreeMap<String, usize>,
}

/// Summary written as `dataset.json`.
#[derive(Clone, Debug, Serialize)]
pub struct DatasetSummary {
    pub name: String,
    /// The licences of the sources used, joined; the strictest terms bind the whole (weights
    /// trained on Bandai-Namco are non-commercial).
    pub licence: String,
    pub attribution: String,
    /// Per source: counts and terms.
    pub sources: BTreeMap<Source, SourceSummary>,
    pub fps: f64,
    pub feature_dim: usize,
    pub max_frames: usize,
    /// Source clips read.
    pub source_clips: usize,
    /// Source clips too short to use.
    pub skipped_clips: Vec<String>,
    /// Items written ("clips" of the HumanML3D layout), mirrors included.
    pub clips: usize,
    pub clips_per_split: BTreeMap<Split, usize>,
    /// Feature rows over all items.
    pub frames: usize,
    /// Hours of motion at 20 fps over all items.
    pub hours: f64,
    /// Caption lines over all items (global captions).
    pub captions: usize,
    /// What the model knows: action labels, styles, and every word of every caption.
    pub vocabulary: Vocabulary,
    pub items: Vec<ItemRecord>,
}

/// The words and labels a planner may use (shipped with the weights as `vocabulary.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Vocabulary {
    /// Action labels with their item counts.
    pub actions: BTreeMap<String, usize>,
    /// Style labels with their item counts.
    pub styles: BTreeMap<String, usize>,
    /// Example caption per action.
    pub examples: BTreeMap<String, String>,
    /// Every word used in captions and part sentences, sorted.
    pub words: Vec<String>,
    /// The motion data behind the weights, per source (`bandai`, `hdm05`, …): the terms the
    /// weights and the motions they generate inherit. `coma export vocabulary` fills it from
    /// `dataset.json`; files exported before it was listed have none.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub sources: BTreeMap<String, DataTerms>,
}

/// A motion data source's terms as a model trained on it must pass them on.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct DataTerms {
    /// E.g. "CC BY-NC 4.0".
    pub licence: String,
    /// The credit line the licence asks for.
    pub attribution: String,
}

/// Start and end (exclusive) joint frames of the windows a clip of `frames` joint frames is
/// cut into: each window has at most `MAX_FRAMES + 1` joint frames (giving `MAX_FRAMES`
/// feature rows); windows are spread evenly and overlap a little rather than leave a short
/// tail. Empty when the clip is too short.
pub fn windows(frames: usize) -> Vec<(usize, usize)> {
    let w = MAX_FRAMES + 1;
    if frames < MIN_FRAMES + 1 {
        return Vec::new();
    }
    if frames <= w {
        return vec![(0, frames)];
    }
    let k = (frames - 1).div_ceil(MAX_FRAMES);
    (0..k)
        .map(|i| {
            let start = ((i * (frames - w)) as f64 / (k - 1) as f64).round() as usize;
            (start, start + w)
        })
        .collect()
}

/// Assigns each source clip to a split: within each (dataset, content) group, clips are
/// ordered by a hash of their name and about 15 % go to test and 5 % to validation.
pub fn assign_splits(clips: &[bandai::SourceClip]) -> BTreeMap<String, Split> {
    let mut groups: BTreeMap<(u8, &str), Vec<&str>> = BTreeMap::new();
    for c in clips {
        groups
            .entry((c.dataset, c.content.as_str()))
            .or_default()
            .push(&c.stem);
    }
    let mut out = BTreeMap::new();
    for (_, mut stems) in groups {
        stems.sort_by_key(|s| (captions::stable_hash(s), s.to_string()));
        let n = stems.len();
        let test = if n >= 3 {
            ((n as f64 * 0.15).round() as usize).max(1)
        } else {
            0
        };
        let val = if n >= 8 {
            ((n as f64 * 0.05).round() as usize).max(1)
        } else {
            0
        };
        for (i, s) in stems.into_iter().enumerate() {
            let split = if i < test {
                Split::Test
            } else if i < test + val {
                Split::Val
            } else {
                Split::Train
            };
            out.insert(s.to_string(), split);
        }
    }
    out
}

/// The item name of a window of a clip.
fn item_name(stem: &str, window: usize, windows: usize, mirrored: bool) -> String {
    let base = stem
        .replacen("dataset-1_", "bn1_", 1)
        .replacen("dataset-2_", "bn2_", 1);
    let base = if windows > 1 {
        format!("{base}_w{window}")
    } else {
        base
    };
    if mirrored {
        format!("M{base}")
    } else {
        base
    }
}

/// A source clip of any source, before conversion.
struct Clip {
    source: Source,
    stem: String,
    actor: String,
    reading: labels::Reading,
    style: String,
    split: Split,
    motion: ClipMotion,
}

/// A clip's motion as its reader gives it: Bandai-Namco's BVH text is parsed in the parallel
/// conversion, the other readers hand over joint positions.
enum ClipMotion {
    Bvh(String),
    Poses(Vec<Pose>),
}

/// Everything derived from one window, before it is written.
struct Item {
    record: ItemRecord,
    features: features::Features,
    joints: Vec<Pose>,
}

fn process_clip(clip: &Clip) -> Result<Vec<Item>> {
    let poses = match &clip.motion {
        ClipMotion::Bvh(text) => {
            let bvh = Bvh::parse(text).with_context(|| format!("{}.bvh", clip.stem))?;
            bvh::bandai::retarget(&bvh).with_context(|| format!("{}.bvh", clip.stem))?
        }
        ClipMotion::Poses(poses) => poses.clone(),
    };
    if floor_dip(&poses) > MAX_FLOOR_DIP_M {
        // Skipped (listed in `dataset.json`): the whole clip would float above the floor.
        return Ok(Vec::new());
    }
    let content = labels::content_of(&clip.reading, &poses);
    let target = Offsets::reference();
    let spans = windows(poses.len());
    let mut items = Vec::new();
    for mirrored in [false, true] {
        let poses = if mirrored {
            skeleton::mirror_poses(&poses)
        } else {
            poses.clone()
        };
        let content = if mirrored {
            captions::mirror_content(&content)
        } else {
            content.clone()
        };
        for (w, (start, end)) in spans.iter().enumerate() {
            let name = item_name(&clip.stem, w, spans.len(), mirrored);
            let (features, global) = features::joints_to_features(&poses[*start..*end], &target)
                .with_context(|| format!("features of {name}"))?;
            let parts = posecodes::part_sentences(&global[..features.len()])
                .into_iter()
                .map(|(part, text)| (part.name().to_string(), text))
                .collect();
            let captions =
                captions::global_captions(&content, &clip.style, &name, CAPTIONS_PER_ITEM);
            let joints = features::features_to_joints(&features);
            items.push(Item {
                record: ItemRecord {
                    frames: features.len(),
                    name,
                    source: clip.source,
                    clip: clip.stem.clone(),
                    actor: clip.actor.clone(),
                    split: clip.split,
                    mirrored,
                    content: content.clone(),
                    style: clip.style.clone(),
                    captions,
                    parts,
                },
                features,
                joints,
            });
        }
    }
    Ok(items)
}

/// A clip whose lowest joint dips further than this below where it usually is (metres) has a
/// capture error: features put the floor at the lowest point of the whole clip, so the body
/// would float that high for the rest of it. (HDM05's `HDM_dg_lieDownFloor_014` sends a knee
/// 0.21 m through the floor for a moment.)
pub const MAX_FLOOR_DIP_M: f64 = 0.1;

/// How far the lowest joint of the lowest frame is below the 10th percentile of every
/// frame's lowest joint, metres: near zero for clean captures, whatever the action (a jump's
/// flight raises frames, it does not lower them).
pub fn floor_dip(poses: &[Pose]) -> f64 {
    let mut lows: Vec<f64> = poses
        .iter()
        .map(|p| p.iter().map(|v| v[1]).fold(f64::INFINITY, f64::min))
        .collect();
    if lows.is_empty() {
        return 0.0;
    }
    lows.sort_by(f64::total_cmp);
    lows[lows.len() / 10] - lows[0]
}

/// Up to `n` of `items` spread evenly over the list, so a small build still sees many labels.
pub(crate) fn spread<T>(items: Vec<T>, n: usize) -> Vec<T> {
    if n >= items.len() {
        return items;
    }
    let step = items.len() as f64 / n as f64;
    let wanted: Vec<usize> = (0..n).map(|i| (i as f64 * step) as usize).collect();
    items
        .into_iter()
        .enumerate()
        .filter(|(i, _)| wanted.binary_search(i).is_ok())
        .map(|(_, c)| c)
        .collect()
}

/// Reads every source the options name, with each clip's label and split.
fn read_sources(options: &BuildOptions, progress: &(dyn Fn(&str) + Sync)) -> Result<Vec<Clip>> {
    let mut clips = Vec::new();
    if let Some(path) = &options.bandai {
        progress(&format!("reading Bandai-Namco from {}", path.display()));
        let selection = options
            .limit
            .map_or(bandai::Selection::All, bandai::Selection::Spread);
        let source = bandai::read_clips(path, &selection)?;
        let splits = assign_splits(&source);
        clips.extend(source.into_iter().map(|c| Clip {
            source: Source::Bandai,
            split: splits[&c.stem],
            actor: format!("bandai-namco-{}", c.dataset),
            reading: labels::bandai(&c.content),
            stem: c.stem,
            style: c.style,
            motion: ClipMotion::Bvh(c.bvh),
        }));
    }
    let hdm05_test_actors: Vec<String> = match &options.hdm05_test_actors {
        Some(actors) => actors.clone(),
        None => HDM05_TEST_ACTORS.iter().map(|a| a.to_string()).collect(),
    };
    type Reader = fn(&Path) -> Result<Vec<mocap::Take>>;
    type Labeller = fn(&str) -> Option<labels::Reading>;
    let readers: [(&Option<PathBuf>, Reader, Labeller, &str); 3] = [
        (
            &options.hdm05,
            mocap::asf_amc::read_hdm05,
            labels::hdm05,
            "HDM05",
        ),
        (
            &options.cmu,
            mocap::cmu_expmap::read_cmu,
            labels::cmu,
            "CMU",
        ),
        (
            &options.deepmimic,
            mocap::deepmimic::read_deepmimic,
            labels::deepmimic,
            "DeepMimic",
        ),
    ];
    for (path, read, label, name) in readers {
        let Some(path) = path else { continue };
        progress(&format!("reading {name} from {}", path.display()));
        let takes =
            read(path).with_context(|| format!("reading {name} from {}", path.display()))?;
        let mut takes = chain_short_takes(takes);
        if let Some(n) = options.limit {
            takes = spread(takes, n);
        }
        for take in takes {
            let reading = label(&take.label).ok_or_else(|| {
                anyhow::anyhow!(
                    "{name} clip {} has the label '{}', which the dataset has no words for",
                    take.stem,
                    take.label
                )
            })?;
            let source = take.source;
            let source_test = mocap::cmu_expmap::source_split_is_test(&take.stem);
            let split = source
                .split(&take.actor, source_test, &hdm05_test_actors)
                .unwrap_or(Split::Train);
            clips.push(Clip {
                source,
                split,
                reading,
                style: "normal".into(),
                stem: take.stem,
                actor: take.actor,
                motion: ClipMotion::Poses(take.poses),
            });
        }
    }
    if clips.is_empty() {
        anyhow::bail!(
            "no source given: name at least one of --bandai, --hdm05, --cmu, --deepmimic"
        );
    }
    train_every_label(&mut clips);
    Ok(clips)
}

/// Clips with fewer joint frames than this are too short to train on alone ([`MIN_FRAMES`]
/// feature rows) and are joined with the clips cut right after them from the same take,
/// where there are such. Longer one-repetition clips (a squat, a kick) stay single, so their
/// captions ("does a squat") stay true.
pub const CHAIN_FRAMES: usize = MIN_FRAMES + 1;

/// Mean joint distance, metres, under which the last pose of one clip and the first of the
/// next count as one continuous take cut in two: HDM05's one-repetition cuts of a take meet
/// within a few centimetres (the cut falls between two 120 Hz frames), while clips from
/// different takes start metres apart.
pub const CONTINUOUS_GAP_M: f64 = 0.1;

/// Joins each clip shorter than [`CHAIN_FRAMES`] with the following clips of the same actor
/// and label that continue it (see [`CONTINUOUS_GAP_M`]), until the chain is long enough, and
/// a short clip with the chain before it that it continues.
/// HDM05 cut one hop or one arm circle per clip (0.5–1 s): alone they are too short to train
/// on, and joined they are the repeated action as it was captured. The chain keeps the first
/// clip's stem with the last clip's number appended (`HDM_bd_hopBothLegs1hops_001-003`).
/// `takes` are in stem order, which is capture order within a class.
pub fn chain_short_takes(takes: Vec<mocap::Take>) -> Vec<mocap::Take> {
    let continues = |a: &mocap::Take, b: &mocap::Take| {
        a.actor == b.actor
            && a.label == b.label
            && match (a.poses.last(), b.poses.first()) {
                (Some(end), Some(start)) => {
                    let gap = end
                        .iter()
                        .zip(start)
                        .map(|(p, q)| geom::dist(*p, *q))
                        .sum::<f64>()
                        / end.len() as f64;
                    gap < CONTINUOUS_GAP_M
                }
                _ => false,
            }
    };
    let mut out: Vec<mocap::Take> = Vec::with_capacity(takes.len());
    let mut chained_last: Option<String> = None;
    for take in takes {
        // A short clip also joins a chain it continues, rather than be left out alone.
        let extend = out.last().is_some_and(|prev: &mocap::Take| {
            (prev.poses.len() < CHAIN_FRAMES || take.poses.len() < CHAIN_FRAMES)
                && continues(prev, &take)
        });
        if extend {
            let prev = out.last_mut().expect("checked above");
            prev.poses.extend(take.poses);
            let number = take
                .stem
                .rsplit('_')
                .next()
                .unwrap_or(&take.stem)
                .to_string();
            let first = chained_last.take().unwrap_or_else(|| prev.stem.clone());
            prev.stem = format!("{first}-{number}");
            chained_last = Some(first);
        } else {
            chained_last = None;
            out.push(take);
        }
    }
    out
}

/// A label whose every clip of a source went to test or validation could not be learned at
/// all (CMU's only window-washing take is in its test split): those clips train instead.
fn train_every_label(clips: &mut [Clip]) {
    let trained: BTreeSet<(Source, String)> = clips
        .iter()
        .filter(|c| c.split == Split::Train)
        .map(|c| (c.source, c.reading.content.clone()))
        .collect();
    for clip in clips.iter_mut() {
        if !trained.contains(&(clip.source, clip.reading.content.clone())) {
            clip.split = Split::Train;
        }
    }
}

/// A HumanML3D text line: the caption, its tokens, and the whole-motion time span.
fn text_line(caption: &str) -> String {
    let tokens: Vec<String> = caption
        .split_whitespace()
        .map(|w| {
            format!(
                "{}/OTHER",
                w.trim_matches(|c: char| !c.is_alphanumeric() && c != '-')
                    .to_lowercase()
            )
        })
        .collect();
    format!("{caption}#{}#0.0#0.0", tokens.join(" "))
}

fn write_item(dir: &Path, item: &Item) -> Result<()> {
    let name = &item.record.name;
    features::features_to_npy(&item.features)
        .write_f32(dir.join("new_joint_vecs").join(format!("{name}.npy")))?;
    features::joints_to_npy(&item.joints)
        .write_f32(dir.join("new_joints").join(format!("{name}.npy")))?;
    let texts: Vec<String> = item.record.captions.iter().map(|c| text_line(c)).collect();
    std::fs::write(
        dir.join("texts").join(format!("{name}.txt")),
        texts.join("\n") + "\n",
    )?;
    let parts: Vec<String> = item
        .record
        .parts
        .iter()
        .map(|(p, s)| format!("{p}#{s}"))
        .collect();
    std::fs::write(
        dir.join("part_texts").join(format!("{name}.txt")),
        parts.join("\n") + "\n",
    )?;
    Ok(())
}

/// Builds the dataset, reporting progress lines through `progress`. The output folder is
/// replaced only when the build has finished.
pub fn build(options: &BuildOptions, progress: &(dyn Fn(&str) + Sync)) -> Result<DatasetSummary> {
    let started = Instant::now();
    let clips = read_sources(options, progress)?;
    progress(&format!(
        "read {} clips in {:.1} s",
        clips.len(),
        started.elapsed().as_secs_f64()
    ));

    let partial = options.out.with_extension("partial");
    if partial.exists() {
        std::fs::remove_dir_all(&partial)
            .with_context(|| format!("removing {}", partial.display()))?;
    }
    for sub in ["new_joint_vecs", "new_joints", "texts", "part_texts"] {
        std::fs::create_dir_all(partial.join(sub))
            .with_context(|| format!("creating {}", partial.display()))?;
    }

    let done = AtomicUsize::new(0);
    let total = clips.len();
    let report_every = (total / 50).max(1);
    let results: Vec<Result<(Vec<ItemRecord>, FeatureStats)>> = clips
        .par_iter()
        .map(|clip| {
            let split = clip.split;
            let items = process_clip(clip)?;
            let mut stats = FeatureStats::default();
            for item in &items {
                write_item(&partial, item)?;
                if split == Split::Train {
                    stats.add(&item.features);
                }
            }
            let n = done.fetch_add(1, Ordering::Relaxed) + 1;
            if n % report_every == 0 || n == total {
                let elapsed = started.elapsed().as_secs_f64();
                let eta = elapsed / n as f64 * (total - n) as f64;
                progress(&format!(
                    "[{n:>5}/{total}] clips converted, {elapsed:.0} s elapsed, ETA {eta:.0} s"
                ));
            }
            Ok((items.into_iter().map(|i| i.record).collect(), stats))
        })
        .collect();

    let mut records = Vec::new();
    let mut stats = FeatureStats::default();
    let mut skipped = Vec::new();
    for (clip, r) in clips.iter().zip(results) {
        let (recs, s) = r?;
        if recs.is_empty() {
            skipped.push(clip.stem.clone());
        }
        records.extend(recs);
        stats = stats.merge(s);
    }
    records.sort_by(|a, b| a.name.cmp(&b.name));
    stats
        .finish()
        .write(partial.join("Mean.npy"), partial.join("Std.npy"))?;
    for split in [Split::Train, Split::Val, Split::Test] {
        let names: Vec<&str> = records
            .iter()
            .filter(|r| r.split == split)
            .map(|r| r.name.as_str())
            .collect();
        std::fs::write(partial.join(split.file_name()), names.join("\n") + "\n")?;
    }
    let mut read: BTreeMap<Source, usize> = BTreeMap::new();
    for clip in &clips {
        *read.entry(clip.source).or_default() += 1;
    }
    let summary = summarise(&read, skipped, records);
    std::fs::write(
        partial.join("dataset.json"),
        serde_json::to_string_pretty(&summary)?,
    )?;

    if options.out.exists() {
        std::fs::remove_dir_all(&options.out)
            .with_context(|| format!("replacing {}", options.out.display()))?;
    }
    std::fs::rename(&partial, &options.out)
        .with_context(|| format!("moving the build to {}", options.out.display()))?;
    progress(&format!("done in {:.0} s", started.elapsed().as_secs_f64()));
    Ok(summary)
}

fn summarise(
    read: &BTreeMap<Source, usize>,
    skipped_clips: Vec<String>,
    items: Vec<ItemRecord>,
) -> DatasetSummary {
    let mut sources: BTreeMap<Source, SourceSummary> = read
        .iter()
        .map(|(s, n)| {
            let summary = SourceSummary {
                licence: s.licence().into(),
                attribution: s.attribution().into(),
                source_clips: *n,
                items: BTreeMap::new(),
                frames: 0,
                actions: BTreeMap::new(),
            };
            (*s, summary)
        })
        .collect();
    for r in &items {
        if let Some(s) = sources.get_mut(&r.source) {
            *s.items.entry(r.split).or_default() += 1;
            *s.actions.entry(r.content.clone()).or_default() += 1;
            s.frames += r.frames;
        }
    }
    let join = |f: fn(Source) -> &'static str, sep: &str| {
        read.keys().map(|s| f(*s)).collect::<Vec<_>>().join(sep)
    };
    let frames: usize = items.iter().map(|r| r.frames).sum();
    let mut clips_per_split = BTreeMap::new();
    let mut actions = BTreeMap::new();
    let mut styles = BTreeMap::new();
    let mut examples = BTreeMap::new();
    let mut words = BTreeSet::new();
    for r in &items {
        *clips_per_split.entry(r.split).or_insert(0) += 1;
        *actions.entry(r.content.clone()).or_insert(0) += 1;
        *styles.entry(r.style.clone()).or_insert(0) += 1;
        if let Some(c) = r.captions.first() {
            examples
                .entry(r.content.clone())
                .or_insert_with(|| c.clone());
        }
        for text in r.captions.iter().chain(r.parts.values()) {
            for w in text.split(|c: char| !c.is_alphanumeric() && c != '-') {
                if !w.is_empty() {
                    words.insert(w.to_lowercase());
                }
            }
        }
    }
    DatasetSummary {
        name: "coma-motions".into(),
        licence: join(Source::licence, "; "),
        attribution: join(Source::attribution, " "),
        sources,
        fps: FPS,
        feature_dim: features::FEATURE_DIM,
        max_frames: MAX_FRAMES,
        source_clips: read.values().sum(),
        skipped_clips,
        clips: items.len(),
        clips_per_split,
        frames,
        hours: frames as f64 / FPS / 3600.0,
        captions: items.iter().map(|r| r.captions.len()).sum(),
        vocabulary: Vocabulary {
            actions,
            styles,
            examples,
            words: words.into_iter().collect(),
            sources: BTreeMap::new(),
        },
        items,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_parse_from_their_names_and_name_the_choices_otherwise() {
        for split in [Split::Train, Split::Val, Split::Test] {
            assert_eq!(split.name().parse::<Split>(), Ok(split));
        }
        assert_eq!(
            "validation".parse::<Split>(),
            Err("unknown split 'validation' (train, val or test)".to_string())
        );
    }

    #[test]
    fn windows_cover_long_clips_without_short_tails() {
        assert!(windows(20).is_empty());
        assert_eq!(windows(25), vec![(0, 25)]);
        assert_eq!(windows(100), vec![(0, 100)]);
        assert_eq!(windows(197), vec![(0, 197)]);
        let w = windows(500);
        assert_eq!(w.len(), 3);
        assert_eq!(w[0].0, 0);
        assert_eq!(w[2].1, 500);
        assert!(w.iter().all(|(s, e)| e - s == MAX_FRAMES + 1));
    }

    #[test]
    fn text_lines_follow_humanml3d_format() {
        let line = text_line("a person waves the left hand");
        let fields: Vec<&str> = line.split('#').collect();
        assert_eq!(fields.len(), 4);
        assert_eq!(fields[0], "a person waves the left hand");
        assert_eq!(fields[1].split(' ').count(), 6);
        assert!(fields[1].starts_with("a/OTHER person/OTHER"));
    }

    fn take(stem: &str, actor: &str, frames: usize, from_x: f64) -> mocap::Take {
        mocap::Take {
            source: mocap::Source::Hdm05,
            stem: stem.into(),
            actor: actor.into(),
            label: "hopBothLegs1hops".into(),
            poses: (0..frames)
                .map(|t| [[from_x + 0.01 * t as f64, 0.9, 0.0]; 22])
                .collect(),
        }
    }

    #[test]
    fn short_clips_join_the_clips_that_continue_them() {
        let takes = vec![
            // 001 → 002 → 003 continue each other: 001 and 002 are too short alone, 003 would
            // be left alone too short; 004 does not continue once the chain is long enough.
            take("HDM_bd_hop_001", "bd", 10, 0.0),
            take("HDM_bd_hop_002", "bd", 10, 0.10),
            take("HDM_bd_hop_003", "bd", 10, 0.20),
            take("HDM_bd_hop_004", "bd", 25, 0.30),
            // Starts metres away: another take.
            take("HDM_bd_hop_005", "bd", 10, 3.0),
            // Another actor never joins.
            take("HDM_bk_hop_006", "bk", 10, 3.10),
        ];
        let chained = chain_short_takes(takes);
        let stems: Vec<&str> = chained.iter().map(|t| t.stem.as_str()).collect();
        assert_eq!(
            stems,
            [
                "HDM_bd_hop_001-003",
                "HDM_bd_hop_004",
                "HDM_bd_hop_005",
                "HDM_bk_hop_006"
            ]
        );
        assert_eq!(chained[0].poses.len(), 30);
        assert_eq!(chained[1].poses.len(), 25);
    }

    #[test]
    fn a_knee_through_the_floor_is_a_dip_and_a_jump_is_not() {
        let standing = |lift: f64| [[0.0, 0.05 + lift, 0.0]; 22];
        let mut jump: Vec<Pose> = (0..40).map(|_| standing(0.0)).collect();
        for pose in &mut jump[15..25] {
            *pose = standing(0.3);
        }
        assert!(floor_dip(&jump).abs() < 1e-9);
        let mut broken = jump.clone();
        broken[30][4][1] = -0.16;
        assert!((floor_dip(&broken) - 0.21).abs() < 1e-9);
    }
}
