//! A split of a HumanML3D-layout dataset held in memory for training: normalised features,
//! captions and per-part sentences, and random crops of it.

use crate::dataset::Split;
use crate::features::{self, FeatureFrame, Normalizer, FEATURE_DIM};
use crate::geom::{self, Quat};
use crate::npy::NpyArray;
use crate::rng::Rng;
use crate::skeleton::{BodyPart, Pose, NUM_JOINTS};
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
    /// `batch × frames`: 1 for a frame of the motion, 0 for a frame that pads a shorter
    /// motion (its last frame held). Losses count the frames of the motion only.
    pub mask: Vec<f32>,
    /// Which item each crop came from, its first source frame and its speed (1 = as
    /// captured; see [`CropSpec`]).
    pub sources: Vec<CropDraw>,
}

/// How training crops are drawn.
#[derive(Clone, Copy, Debug)]
pub struct CropSpec {
    /// Longest crop in frames (20 fps).
    pub max_frames: usize,
    /// Crop lengths are multiples of this (the VQ-VAE's frames per token).
    pub multiple: usize,
    /// Chance that a crop is replayed at another speed ([`features::retime`]), in 0..=1.
    pub retime_chance: f64,
    /// The largest speed factor of a replay: factors are drawn log-uniformly in
    /// `[1 / retime_max, retime_max]`; 1 replays nothing.
    pub retime_max: f64,
    /// Chance that a crop is performed with another posture habit
    /// ([`features::vary_posture`]), in 0..=1.
    pub posture_chance: f64,
    /// The largest turn of one bone in such a crop, in degrees: each bone turns about a
    /// random axis by an angle drawn uniformly up to it (chains add up).
    pub posture_degrees: f64,
}

impl CropSpec {
    /// Crops of at most `max_frames`, in multiples of `multiple`, at the captured speed and
    /// posture.
    pub fn plain(max_frames: usize, multiple: usize) -> CropSpec {
        CropSpec {
            max_frames,
            multiple,
            retime_chance: 0.0,
            retime_max: 1.0,
            posture_chance: 0.0,
            posture_degrees: 0.0,
        }
    }
}

/// Turns of every bone for [`features::vary_posture`]: each about an axis drawn uniformly on
/// the sphere, by an angle drawn uniformly in `[0, max_degrees]`.
pub fn random_turns(rng: &mut Rng, max_degrees: f64) -> [Quat; NUM_JOINTS] {
    std::array::from_fn(|_| {
        let axis = [rng.normal(), rng.normal(), rng.normal()].map(f64::from);
        let angle = (max_degrees * rng.uniform() as f64).to_radians();
        // A zero axis (never drawn in practice) would give no unit quaternion.
        match geom::norm(axis) > 1e-9 {
            true => Quat::from_axis_angle(axis, angle),
            false => Quat::IDENTITY,
        }
    })
}

/// One crop of a batch: where it comes from and how many of its frames are the motion's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CropDraw {
    pub item: usize,
    /// First source frame.
    pub start: usize,
    /// Playback speed (1 = as captured).
    pub speed: f64,
    /// Frames of the motion in the crop; the rest of the crop holds its last frame.
    pub real: usize,
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

    /// Where the crops of one batch come from: `batch` items drawn by weight, each replayed
    /// at another speed with the spec's chance, and the batch's length: the longest drawn
    /// (replayed) item, at most `max_frames`, rounded down to a multiple of `multiple`. Every
    /// drawn item trains: one shorter than that is taken whole and padded by holding its last
    /// frame, so short clips (one squat, one hop) get the share of crops their weight asks for.
    pub fn draw_crops(
        &self,
        rng: &mut Rng,
        batch: usize,
        spec: &CropSpec,
    ) -> (usize, Vec<CropDraw>) {
        let total = self.frames();
        let picks: Vec<(usize, f64)> = (0..batch)
            .map(|_| {
                let item = self.weighted_item(rng, total);
                let speed = if spec.retime_max > 1.0 && (rng.uniform() as f64) < spec.retime_chance
                {
                    spec.retime_max.powf(2.0 * rng.uniform() as f64 - 1.0)
                } else {
                    1.0
                };
                (item, speed)
            })
            .collect();
        let longest = picks
            .iter()
            .map(|&(i, s)| features::retimed_rows(self.items[i].features.len(), s))
            .max()
            .unwrap_or(0);
        let multiple = spec.multiple.max(1);
        let frames = (longest.min(spec.max_frames) / multiple * multiple).max(multiple);
        let draws = picks
            .into_iter()
            .map(|(item, speed)| {
                let len = self.items[item].features.len();
                let rows = features::retimed_rows(len, speed);
                if rows >= frames {
                    // Source rows that `frames` rows at this speed span.
                    let span = features::source_rows(frames, speed).min(len);
                    let start = rng.below(len - span + 1);
                    CropDraw {
                        item,
                        start,
                        speed,
                        real: frames,
                    }
                } else {
                    CropDraw {
                        item,
                        start: 0,
                        speed,
                        real: rows,
                    }
                }
            })
            .collect();
        (frames, draws)
    }

    /// Frames of the motions (padding left out) that each source (`(unnamed)` where
    /// `dataset.json` names none) gets over `batches` batches as [`MotionSet::draw_crops`]
    /// draws them, as shares of the total: what training really sees of each source, which
    /// the draw weights alone do not tell when clips are shorter than the crops.
    pub fn crop_frame_shares(
        &self,
        rng: &mut Rng,
        batches: usize,
        batch: usize,
        spec: &CropSpec,
    ) -> BTreeMap<String, f64> {
        let draws: Vec<CropDraw> = (0..batches)
            .flat_map(|_| self.draw_crops(rng, batch, spec).1)
            .collect();
        action_shares(draws.iter().map(|d| {
            (
                Some(self.items[d.item].source.as_deref().unwrap_or("(unnamed)")),
                d.real as f64,
            )
        }))
    }

    /// A batch of crops drawn as [`MotionSet::draw_crops`] says.
    pub fn sample_crops(&self, rng: &mut Rng, batch: usize, spec: &CropSpec) -> CropBatch {
        let (frames, sources) = self.draw_crops(rng, batch, spec);
        let mut data = Vec::with_capacity(batch * frames * FEATURE_DIM);
        let mut mask = Vec::with_capacity(batch * frames);
        for draw in &sources {
            let item = &self.items[draw.item].features;
            // Drawn only when asked for, so runs without it sample what they always did.
            let turns = (spec.posture_degrees > 0.0
                && (rng.uniform() as f64) < spec.posture_chance
                && draw.real >= 2)
                .then(|| random_turns(rng, spec.posture_degrees));
            let rows = if draw.speed == 1.0 && turns.is_none() {
                item[draw.start..draw.start + draw.real].to_vec()
            } else {
                // Both replays work on denormalised rows, normalised once at the end.
                let span =
                    features::source_rows(draw.real, draw.speed).min(item.len() - draw.start);
                let mut raw = self
                    .normalizer
                    .denormalize(&item[draw.start..draw.start + span]);
                if draw.speed != 1.0 {
                    raw = features::retime(&raw, draw.speed);
                    raw.truncate(draw.real);
                }
                if let Some(turns) = &turns {
                    let varied = features::vary_posture(&raw, turns);
                    // Rows that describe no joints (never in a built dataset) stay as they are.
                    if varied.len() == raw.len() {
                        raw = varied;
                    }
                }
                self.normalizer.normalize(&raw)
            };
            for t in 0..frames {
                data.extend_from_slice(&rows[t.min(rows.len() - 1)]);
                mask.push((t < rows.len()) as u8 as f32);
            }
        }
        CropBatch {
            batch,
            frames,
            data,
            mask,
            sources,
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// An item whose row `t` holds `t` in every column, so crops show where they came from.
    fn item(content: &str, frames: usize) -> MotionItem {
        MotionItem {
            name: format!("{content}_{frames}"),
            features: (0..frames).map(|t| [t as f32; FEATURE_DIM]).collect(),
            captions: Vec::new(),
            parts: BTreeMap::new(),
            content: Some(content.to_string()),
            source: None,
        }
    }

    fn set() -> MotionSet {
        let mut items: Vec<MotionItem> = (0..9).map(|_| item("walk", 100)).collect();
        items.push(item("squat", 100));
        plain_set(items)
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

    /// The items with identity normalisation, drawn in proportion to their length.
    pub(crate) fn plain_set(items: Vec<MotionItem>) -> MotionSet {
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
    fn short_items_are_cropped_whole_and_padded_with_their_last_frame() {
        let mut long = item("walk", 200);
        long.source = Some("bandai".into());
        let mut short = item("squat", 10);
        short.source = Some("hdm05".into());
        let mut set = plain_set(vec![long, short]);
        set.balance(1.0);
        let mut rng = Rng::new(3);
        let mut shorts = 0;
        for _ in 0..50 {
            let batch = set.sample_crops(&mut rng, 16, &CropSpec::plain(64, 4));
            assert_eq!(batch.data.len(), 16 * batch.frames * FEATURE_DIM);
            assert_eq!(batch.mask.len(), 16 * batch.frames);
            for (b, draw) in batch.sources.iter().enumerate() {
                let row = |t: usize| batch.data[(b * batch.frames + t) * FEATURE_DIM];
                let mask = &batch.mask[b * batch.frames..(b + 1) * batch.frames];
                if draw.item == 1 {
                    shorts += 1;
                    assert_eq!(draw.real, 10);
                    // Every frame of the clip, then its last frame held, masked out.
                    for (t, &m) in mask.iter().enumerate() {
                        assert_eq!(row(t), t.min(9) as f32);
                        assert_eq!(m, (t < 10) as u8 as f32);
                    }
                } else {
                    assert_eq!(draw.real, batch.frames);
                    assert!(mask.iter().all(|&m| m == 1.0));
                    for t in 0..batch.frames {
                        assert_eq!(row(t), (draw.start + t) as f32);
                    }
                }
            }
        }
        // Balanced, each action is drawn about half the time, and no draw of the short one
        // is thrown away.
        assert!((300..500).contains(&shorts), "{shorts} of 800");
        // Its share of real frames follows: 10 frames a draw against 64.
        let shares = set.crop_frame_shares(&mut rng, 200, 16, &CropSpec::plain(64, 4));
        let expected = 10.0 / (10.0 + 64.0);
        assert!((shares["hdm05"] - expected).abs() < 0.03, "{shares:?}");
    }

    #[test]
    fn crops_are_no_longer_than_the_longest_drawn_item() {
        let set = plain_set(vec![item("squat", 23), item("hop", 17)]);
        let mut rng = Rng::new(9);
        for _ in 0..20 {
            let batch = set.sample_crops(&mut rng, 4, &CropSpec::plain(64, 4));
            let longest = batch
                .sources
                .iter()
                .map(|d| set.items[d.item].features.len())
                .max()
                .unwrap();
            assert_eq!(batch.frames, longest / 4 * 4);
        }
        // A clip shorter than one token still makes a crop of one token.
        let tiny = plain_set(vec![item("tap", 2)]);
        let batch = tiny.sample_crops(&mut rng, 2, &CropSpec::plain(64, 4));
        assert_eq!(
            (batch.frames, batch.mask[..4].to_vec()),
            (4, vec![1.0, 1.0, 0.0, 0.0])
        );
    }

    #[test]
    fn posture_turns_stay_within_their_largest_angle_about_spread_axes() {
        let mut rng = Rng::new(11);
        let turns: Vec<Quat> = (0..50).flat_map(|_| random_turns(&mut rng, 8.0)).collect();
        let angles: Vec<f64> = turns
            .iter()
            .map(|q| 2.0 * q.0[0].clamp(-1.0, 1.0).acos().to_degrees())
            .collect();
        assert!(angles.iter().all(|a| *a <= 8.0 + 1e-9), "{angles:?}");
        let mean = angles.iter().sum::<f64>() / angles.len() as f64;
        assert!((mean - 4.0).abs() < 0.5, "mean turn {mean}°");
        // Axes point every way: their mean (weighted by the turn) is near zero.
        let axis_sum = turns
            .iter()
            .fold([0.0; 3], |acc, q| geom::add(acc, [q.0[1], q.0[2], q.0[3]]));
        let per_turn = geom::norm(axis_sum) / turns.len() as f64;
        assert!(per_turn < 0.005, "mean axis {per_turn}");
        assert_eq!(random_turns(&mut rng, 0.0), [Quat::IDENTITY; NUM_JOINTS]);
    }

    #[test]
    fn replayed_crops_are_the_motion_at_another_speed() {
        let set = plain_set(vec![item("walk", 300)]);
        let spec = CropSpec {
            retime_chance: 1.0,
            retime_max: 1.5,
            ..CropSpec::plain(64, 4)
        };
        let mut rng = Rng::new(4);
        let mut speeds = Vec::new();
        for _ in 0..10 {
            let batch = set.sample_crops(&mut rng, 4, &spec);
            assert_eq!(batch.frames, 64);
            for (b, draw) in batch.sources.iter().enumerate() {
                assert!((1.0 / 1.5..=1.5).contains(&draw.speed), "{}", draw.speed);
                speeds.push(draw.speed);
                // Row t of the ramp 0, 1, 2, … is frame start + t·speed (velocity columns
                // are scaled by the speed too; column 3 is the root height).
                for t in [0, 31, 63] {
                    let v = batch.data[(b * 64 + t) * FEATURE_DIM + 3];
                    let expected = draw.start as f64 + t as f64 * draw.speed;
                    assert!((v as f64 - expected).abs() < 1e-3, "{v} vs {expected}");
                }
                assert!(batch.mask[b * 64..(b + 1) * 64].iter().all(|&m| m == 1.0));
            }
        }
        assert!(speeds.iter().any(|&s| s < 0.95) && speeds.iter().any(|&s| s > 1.05));
    }
}
