//! The training dataset: Bandai-Namco motion capture converted into the HumanML3D layout.
//!
//! `coma data build --bandai <archive> --out <dir>` writes:
//!
//! | path                    | content                                                        |
//! |-------------------------|----------------------------------------------------------------|
//! | `new_joint_vecs/<n>.npy`| (T, 263) float32 features, 20 fps, T ≤ 196                      |
//! | `new_joints/<n>.npy`    | (T, 22, 3) float32 joints recovered from those features, metres |
//! | `texts/<n>.txt`         | global captions, one per line, HumanML3D style: `caption#tokens#0.0#0.0`, tokens are the lower-cased words tagged `/OTHER` (we run no part-of-speech tagger) |
//! | `part_texts/<n>.txt`    | one line per body part: `left arm#<sentence>` (also `right arm`, `left leg`, `right leg`), from the pose-code describer |
//! | `train.txt` `val.txt` `test.txt` | item names, split by source clip: every window and mirror of a clip is in one split |
//! | `Mean.npy` `Std.npy`    | (263,) float32 statistics of the training split              |
//! | `dataset.json`          | counts, hours, licence, vocabulary and every item's record    |
//!
//! Item names: the source file stem with the dataset shortened (`bn2_wave-left-hand_normal_001`),
//! `_w<k>` when a long clip is cut into windows, and an `M` prefix for the left/right mirror
//! (whose captions swap left and right).

pub mod bandai;
pub mod captions;
pub mod motions;

use crate::bvh::{self, Bvh};
use crate::features::{self, FeatureStats};
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
/// Licence of the source data, which every derived file and weight inherits.
pub const LICENCE: &str = "CC BY-NC 4.0";
/// Attribution required by the licence.
pub const ATTRIBUTION: &str = "Bandai Namco Research Motion Datasets 1 and 2 (Kobayashi et al. 2023, \"Motion Capture Dataset for Practical Use of AI-based Motion Editing and Stylization\", arXiv:2306.08861)";

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
}

/// What to build.
#[derive(Clone, Debug)]
pub struct BuildOptions {
    /// The Bandai-Namco `.tar.xz` archive or a folder it was extracted into.
    pub source: PathBuf,
    /// Output folder (replaced only once the new build is complete).
    pub out: PathBuf,
    /// Use only this many source clips, spread over the whole set (for quick builds and tests).
    pub limit: Option<usize>,
}

/// The record of one item in `dataset.json`.
#[derive(Clone, Debug, Serialize)]
pub struct ItemRecord {
    pub name: String,
    /// Source file stem.
    pub clip: String,
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

/// Summary written as `dataset.json`.
#[derive(Clone, Debug, Serialize)]
pub struct DatasetSummary {
    pub name: String,
    pub licence: String,
    pub attribution: String,
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

/// Everything derived from one window, before it is written.
struct Item {
    record: ItemRecord,
    features: features::Features,
    joints: Vec<Pose>,
}

fn process_clip(clip: &bandai::SourceClip, split: Split) -> Result<Vec<Item>> {
    let bvh = Bvh::parse(&clip.bvh).with_context(|| format!("{}.bvh", clip.stem))?;
    let poses = bvh::bandai::retarget(&bvh).with_context(|| format!("{}.bvh", clip.stem))?;
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
            captions::mirror_content(&clip.content)
        } else {
            clip.content.clone()
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
                    clip: clip.stem.clone(),
                    split,
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
    progress(&format!("reading {}", options.source.display()));
    let selection = options
        .limit
        .map_or(bandai::Selection::All, bandai::Selection::Spread);
    let clips = bandai::read_clips(&options.source, &selection)?;
    progress(&format!(
        "read {} clips in {:.1} s",
        clips.len(),
        started.elapsed().as_secs_f64()
    ));
    let splits = assign_splits(&clips);

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
            let split = splits[&clip.stem];
            let items = process_clip(clip, split)?;
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
    let summary = summarise(clips.len(), skipped, records);
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
    source_clips: usize,
    skipped_clips: Vec<String>,
    items: Vec<ItemRecord>,
) -> DatasetSummary {
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
        name: "bandai-namco-humanml3d".into(),
        licence: LICENCE.into(),
        attribution: ATTRIBUTION.into(),
        fps: FPS,
        feature_dim: features::FEATURE_DIM,
        max_frames: MAX_FRAMES,
        source_clips,
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
        },
        items,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
