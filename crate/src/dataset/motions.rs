//! A split of a HumanML3D-layout dataset held in memory for training: normalised features,
//! captions and per-part sentences, and random crops of it.

use crate::dataset::Split;
use crate::features::{self, FeatureFrame, Normalizer, FEATURE_DIM};
use crate::npy::NpyArray;
use crate::rng::Rng;
use crate::skeleton::{BodyPart, Pose};
use anyhow::{bail, Context, Result};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// One motion of the split.
#[derive(Clone, Debug)]
pub struct MotionItem {
    /// Item name (file stem).
    pub name: String,
    /// Normalised features, one row per frame at 20 fps.
    pub features: Vec<FeatureFrame>,
    /// Global captions.
    pub captions: Vec<String>,
    /// Per-part sentences, where the dataset has them.
    pub parts: BTreeMap<BodyPart, String>,
    /// The action it shows ("bow", "walk-turn-left"), where `dataset.json` names it:
    /// training can balance rare actions against frequent ones by it.
    pub content: Option<String>,
}

/// A loaded split.
#[derive(Clone, Debug)]
pub struct MotionSet {
    pub items: Vec<MotionItem>,
    /// The dataset's Mean/Std (of its training split).
    pub normalizer: Normalizer,
}

/// Item name → content label, from `<dir>/dataset.json` (our builder writes one; a dataset
/// in the plain HumanML3D layout has none, and its items go unlabelled).
fn content_labels(dir: &Path) -> HashMap<String, String> {
    #[derive(serde::Deserialize)]
    struct Summary {
        items: Vec<Labelled>,
    }
    #[derive(serde::Deserialize)]
    struct Labelled {
        name: String,
        content: String,
    }
    std::fs::read(dir.join("dataset.json"))
        .ok()
        .and_then(|bytes| serde_json::from_slice::<Summary>(&bytes).ok())
        .map(|s| s.items.into_iter().map(|i| (i.name, i.content)).collect())
        .unwrap_or_default()
}

/// A batch of equal-length crops, flattened as `batch × frames × 263` (normalised).
#[derive(Clone, Debug)]
pub struct CropBatch {
    pub batch: usize,
    pub frames: usize,
    pub data: Vec<f32>,
    /// Which item and first frame each crop came from.
    pub sources: Vec<(usize, usize)>,
}

impl MotionSet {
    /// The item's joint positions (metres, Y up, 20 fps), from its features.
    pub fn joints(&self, item: &MotionItem) -> Vec<Pose> {
        features::features_to_joints(&self.normalizer.denormalize(&item.features))
    }

    /// Reads the items listed in `<dir>/<split>.txt`.
    pub fn load(dir: &Path, split: Split) -> Result<MotionSet> {
        let normalizer = Normalizer::read(dir.join("Mean.npy"), dir.join("Std.npy"))
            .with_context(|| format!("{} has no usable Mean.npy/Std.npy", dir.display()))?;
        let list = std::fs::read_to_string(dir.join(split.file_name()))
            .with_context(|| format!("cannot read {}", dir.join(split.file_name()).display()))?;
        let contents = content_labels(dir);
        let mut items = Vec::new();
        for name in list.lines().map(str::trim).filter(|l| !l.is_empty()) {
            let path = dir.join("new_joint_vecs").join(format!("{name}.npy"));
            let raw = features::features_from_npy(&NpyArray::read(&path)?)
                .with_context(|| path.display().to_string())?;
            let captions = std::fs::read_to_string(dir.join("texts").join(format!("{name}.txt")))
                .map(|t| {
                    t.lines()
                        .filter_map(|l| l.split('#').next())
                        .map(str::trim)
                        .filter(|c| !c.is_empty())
                        .map(String::from)
                        .collect()
                })
                .unwrap_or_default();
            let parts = std::fs::read_to_string(dir.join("part_texts").join(format!("{name}.txt")))
                .map(|t| {
                    t.lines()
                        .filter_map(|l| l.split_once('#'))
                        .filter_map(|(p, s)| Some((BodyPart::parse(p)?, s.trim().to_string())))
                        .collect()
                })
                .unwrap_or_default();
            items.push(MotionItem {
                name: name.to_string(),
                features: normalizer.normalize(&raw),
                captions,
                parts,
                content: contents.get(name).cloned(),
            });
        }
        if items.is_empty() {
            bail!("{} lists no items", dir.join(split.file_name()).display());
        }
        Ok(MotionSet { items, normalizer })
    }

    /// Total frames over all items.
    pub fn frames(&self) -> usize {
        self.items.iter().map(|i| i.features.len()).sum()
    }

    /// An item index drawn with probability proportional to its length.
    fn weighted_item(&self, rng: &mut Rng, total: usize) -> usize {
        let mut x = rng.below(total);
        for (i, item) in self.items.iter().enumerate() {
            if x < item.features.len() {
                return i;
            }
            x -= item.features.len();
        }
        self.items.len() - 1
    }

    /// `batch` random crops of one length: an anchor item (drawn in proportion to its length)
    /// sets the length to at most `max_frames`, rounded down to a multiple of `multiple`; the
    /// other crops come from items at least that long. Short motions thus train too, in
    /// batches of their own length.
    pub fn sample_crops(
        &self,
        rng: &mut Rng,
        batch: usize,
        max_frames: usize,
        multiple: usize,
    ) -> CropBatch {
        let total = self.frames();
        let anchor = self.weighted_item(rng, total);
        let len = self.items[anchor].features.len().min(max_frames);
        let frames = (len / multiple * multiple).max(multiple.min(len));
        let mut sources = Vec::with_capacity(batch);
        let mut data = Vec::with_capacity(batch * frames * FEATURE_DIM);
        let mut pick = anchor;
        while sources.len() < batch {
            let item = &self.items[pick];
            if item.features.len() >= frames {
                let start = rng.below(item.features.len() - frames + 1);
                for row in &item.features[start..start + frames] {
                    data.extend_from_slice(row);
                }
                sources.push((pick, start));
            }
            pick = self.weighted_item(rng, total);
        }
        CropBatch {
            batch,
            frames,
            data,
            sources,
        }
    }
}
