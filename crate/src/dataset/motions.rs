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
    /// The motion capture source it comes from (`bandai`, `hdm05`, `cmu`, `deepmimic`), where
    /// `dataset.json` names it: measurements are reported per source.
    pub source: Option<String>,
}

/// A loaded split.
#[derive(Clone, Debug)]
pub struct MotionSet {
    pub items: Vec<MotionItem>,
    /// The dataset's Mean/Std (of its training split).
    pub normalizer: Normalizer,
    /// Running sums of the items' draw weights when crops are balanced by action
    /// ([`MotionSet::balance`]); empty draws in proportion to length alone.
    cumulative: Vec<f64>,
}

/// What `dataset.json` says of one item.
#[derive(serde::Deserialize)]
struct Labelled {
    name: String,
    content: String,
    /// Absent in datasets built before there was more than one source.
    source: Option<String>,
}

/// Item name → its labels, from `<dir>/dataset.json` (our builder writes one; a dataset in the
/// plain HumanML3D layout has none, and its items go unlabelled).
fn item_labels(dir: &Path) -> HashMap<String, Labelled> {
    #[derive(serde::Deserialize)]
    struct Summary {
        items: Vec<Labelled>,
    }
    std::fs::read(dir.join("dataset.json"))
        .ok()
        .and_then(|bytes| serde_json::from_slice::<Summary>(&bytes).ok())
        .map(|s| s.items.into_iter().map(|i| (i.name.clone(), i)).collect())
        .unwrap_or_default()
}

/// Each action's share of the total weight of `(action, weight)` pairs; unlabelled items go
/// under `"(unlabelled)"`. Training logs it to show how often rare actions are drawn.
pub fn action_shares<'a>(
    weights: impl IntoIterator<Item = (Option<&'a str>, f64)>,
) -> BTreeMap<String, f64> {
    let mut shares: BTreeMap<String, f64> = BTreeMap::new();
    for (label, weight) in weights {
        *shares
            .entry(label.unwrap_or("(unlabelled)").to_string())
            .or_default() += weight;
    }
    let total: f64 = shares.values().sum();
    shares
        .values_mut()
        .for_each(|v| *v /= total.max(f64::MIN_POSITIVE));
    shares
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
        let labels = item_labels(dir);
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
                content: labels.get(name).map(|l| l.content.clone()),
                source: labels.get(name).and_then(|l| l.source.clone()),
            });
        }
        if items.is_empty() {
            bail!("{} lists no items", dir.join(split.file_name()).display());
        }
        Ok(MotionSet {
            items,
            normalizer,
            cumulative: Vec::new(),
        })
    }

    /// Draws crops from an item in proportion to its length times `n^-balance`, where `n` is
    /// the number of frames of its action: 0 is plain length-proportional drawing, 1 gives
    /// every action the same share of crops however few frames it has. Unlabelled items count
    /// as one action.
    pub fn balance(&mut self, balance: f64) {
        if balance == 0.0 {
            self.cumulative.clear();
            return;
        }
        let mut frames: HashMap<Option<&str>, usize> = HashMap::new();
        for item in &self.items {
            *frames.entry(item.content.as_deref()).or_default() += item.features.len();
        }
        let mut sum = 0.0;
        self.cumulative = self
            .items
            .iter()
            .map(|item| {
                let n = frames[&item.content.as_deref()] as f64;
                sum += item.features.len() as f64 * n.powf(-balance);
                sum
            })
            .collect();
    }

    /// The share of crops each action gets under the current drawing (unlabelled items under
    /// `"(unlabelled)"`), for the training log.
    pub fn action_shares(&self) -> BTreeMap<String, f64> {
        let mut previous = 0.0;
        action_shares(self.items.iter().enumerate().map(|(i, item)| {
            let weight = match self.cumulative.get(i) {
                Some(c) => {
                    let w = c - previous;
                    previous = *c;
                    w
                }
                None => item.features.len() as f64,
            };
            (item.content.as_deref(), weight)
        }))
    }

    /// The items `keep` accepts, with the same normalisation (and plain length-proportional
    /// drawing).
    pub fn subset(&self, keep: impl Fn(&MotionItem) -> bool) -> MotionSet {
        MotionSet {
            items: self.items.iter().filter(|i| keep(i)).cloned().collect(),
            normalizer: self.normalizer.clone(),
            cumulative: Vec::new(),
        }
    }

    /// The sources named in the set, sorted (empty when `dataset.json` names none).
    pub fn sources(&self) -> Vec<String> {
        let mut sources: Vec<String> = self.items.iter().filter_map(|i| i.source.clone()).collect();
        sources.sort();
        sources.dedup();
        sources
    }

    /// Total frames over all items.
    pub fn frames(&self) -> usize {
        self.items.iter().map(|i| i.features.len()).sum()
    }

    /// An item index drawn with probability proportional to its length, or to its balanced
    /// weight ([`MotionSet::balance`]).
    fn weighted_item(&self, rng: &mut Rng, total: usize) -> usize {
        if let Some(&sum) = self.cumulative.last() {
            let x = rng.uniform() as f64 * sum;
            return self
                .cumulative
                .partition_point(|&c| c <= x)
                .min(self.items.len() - 1);
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn item(content: &str, frames: usize) -> MotionItem {
        MotionItem {
            name: format!("{content}_{frames}"),
            features: vec![[0.0; FEATURE_DIM]; frames],
            captions: Vec::new(),
            parts: BTreeMap::new(),
            content: Some(content.to_string()),
            source: None,
        }
    }

    fn set() -> MotionSet {
        let mut items: Vec<MotionItem> = (0..9).map(|_| item("walk", 100)).collect();
        items.push(item("squat", 100));
        MotionSet {
            items,
            normalizer: Normalizer {
                mean: vec![0.0; FEATURE_DIM],
                std: vec![1.0; FEATURE_DIM],
            },
            cumulative: Vec::new(),
        }
    }

    #[test]
    fn balancing_raises_the_share_of_rare_actions() {
        let mut set = set();
        let plain = set.action_shares();
        assert!((plain["squat"] - 0.1).abs() < 1e-9, "{plain:?}");
        set.balance(1.0);
        let even = set.action_shares();
        assert!((even["squat"] - 0.5).abs() < 1e-9, "{even:?}");
        // The draws follow the shares.
        let mut rng = Rng::new(5);
        let squats = (0..4000)
            .filter(|_| set.weighted_item(&mut rng, set.frames()) == 9)
            .count();
        assert!((1800..2200).contains(&squats), "{squats} of 4000");
        set.balance(0.0);
        assert_eq!(set.action_shares(), plain);
    }
}
