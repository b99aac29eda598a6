//! The training data of the transformers: every training motion as VQ tokens, with the
//! sentence embeddings of its captions and per-part sentences, and masked batches of it.

use crate::dataset::motions::MotionSet;
use crate::model::transformer::{TransformerConfig, PARTS, TEXT_DIM};
use crate::model::vq::MotionVq;
use crate::rng::Rng;
use crate::skeleton::BodyPart;
use anyhow::Result;
use burn::prelude::*;
use burn::tensor::{Bool, Int, TensorData};
use std::collections::HashMap;

/// Turns a batch of texts into one sentence embedding each.
pub type TextEmbedder<'a> = &'a dyn Fn(&[&str]) -> Result<Vec<[f32; TEXT_DIM]>>;

/// One motion as tokens and text.
#[derive(Clone, Debug)]
pub struct TokenItem {
    /// `[part][layer][step]` codes.
    pub tokens: Vec<Vec<Vec<u32>>>,
    /// Indices of the item's global captions in [`TokenSet::texts`].
    pub captions: Vec<usize>,
    /// Index of each part's sentence in [`TokenSet::texts`], where the dataset has one.
    pub parts: [Option<usize>; PARTS],
    /// The action it shows, where the dataset names it.
    pub content: Option<String>,
}

/// Token items plus the embeddings of every text they use.
#[derive(Clone, Debug, Default)]
pub struct TokenSet {
    pub items: Vec<TokenItem>,
    pub texts: Vec<String>,
    pub embeddings: Vec<[f32; TEXT_DIM]>,
}

/// How a batch is drawn: its size, how its texts are chosen and how its motions are weighted.
#[derive(Clone, Copy, Debug)]
pub struct BatchDraw<'a> {
    pub batch: usize,
    /// Probability that a part is conditioned on its own sentence.
    pub part_text: f32,
    /// Probability that a motion's whole text is dropped (guidance training).
    pub drop_text: f32,
    /// Relative draw weight of every item (see [`TokenSet::draw_weights`]); `None` is uniform.
    pub weights: Option<&'a [f64]>,
}

/// A batch for the transformers: inputs, targets and conditions.
#[derive(Debug)]
pub struct TokenBatch {
    /// `[B, 4, L, N]` all layers' tokens, padded with the pad id, row-major.
    pub tokens: Vec<i32>,
    /// `(B, L, N)` of `tokens`.
    pub dims: (usize, usize, usize),
    /// `[B, 4, 384]` per-part text.
    pub text: Tensor<3>,
    /// `[B, 4]` 1 keeps the text, 0 drops it (guidance training).
    pub keep_text: Tensor<2>,
    /// `[B, N]` true after the end of a motion.
    pub pad: Tensor<2, Bool>,
    /// Real steps of each motion.
    pub lengths: Vec<usize>,
}

impl TokenSet {
    /// Tokenizes every motion of `set` with `vq` (each cut to a multiple of 4 frames) and
    /// embeds every distinct text with `embed` (a batch of texts → one vector each).
    pub fn build(
        set: &MotionSet,
        vq: &MotionVq,
        device: &Device,
        embed: TextEmbedder,
        progress: &dyn Fn(&str),
    ) -> Result<TokenSet> {
        let mut texts: Vec<String> = Vec::new();
        let mut index: HashMap<String, usize> = HashMap::new();
        let mut intern = |t: &str| -> usize {
            *index.entry(t.to_string()).or_insert_with(|| {
                texts.push(t.to_string());
                texts.len() - 1
            })
        };
        let mut items = Vec::with_capacity(set.items.len());
        for (i, item) in set.items.iter().enumerate() {
            let tokens = vq.tokenize_motion(&item.features, device);
            let captions = item.captions.iter().map(|c| intern(c)).collect();
            let parts =
                std::array::from_fn(|p| item.parts.get(&BodyPart::ALL[p]).map(|s| intern(s)));
            items.push(TokenItem {
                tokens,
                captions,
                parts,
                content: item.content.clone(),
            });
            if (i + 1) % 500 == 0 {
                progress(&format!("tokenized {}/{} motions", i + 1, set.items.len()));
            }
        }
        let mut embeddings = Vec::with_capacity(texts.len());
        for chunk in texts.chunks(64) {
            let refs: Vec<&str> = chunk.iter().map(String::as_str).collect();
            embeddings.extend(embed(&refs)?);
        }
        progress(&format!("embedded {} distinct texts", texts.len()));
        Ok(TokenSet {
            items,
            texts,
            embeddings,
        })
    }

    /// How often each item is drawn, relative to the others: `n^-balance` for an item whose
    /// action has `n` items (unlabelled items count as one action). 0 draws every item
    /// equally often; 1 draws every action equally often, however rare.
    pub fn draw_weights(&self, balance: f64) -> Vec<f64> {
        let mut counts: HashMap<Option<&str>, usize> = HashMap::new();
        for item in &self.items {
            *counts.entry(item.content.as_deref()).or_default() += 1;
        }
        self.items
            .iter()
            .map(|i| (counts[&i.content.as_deref()] as f64).powf(-balance))
            .collect()
    }

    /// The share of draws each action gets with `weights` (uniform when `None`), unlabelled
    /// items under `"(unlabelled)"`, for the training log.
    pub fn action_shares(
        &self,
        weights: Option<&[f64]>,
    ) -> std::collections::BTreeMap<String, f64> {
        crate::dataset::motions::action_shares(
            self.items
                .iter()
                .enumerate()
                .map(|(i, item)| (item.content.as_deref(), weights.map_or(1.0, |w| w[i]))),
        )
    }

    /// A random batch of `draw.batch` motions of similar length (between ¾ of and the length
    /// of a randomly drawn one), drawn in proportion to `draw.weights`. Each part's condition
    /// is the motion's own sentence for that part with probability `draw.part_text`, else one
    /// of its global captions (the same for all parts that use it); the whole text is dropped
    /// with probability `draw.drop_text`.
    pub fn batch(
        &self,
        config: &TransformerConfig,
        rng: &mut Rng,
        draw: &BatchDraw,
        device: &Device,
    ) -> TokenBatch {
        let BatchDraw {
            batch,
            part_text,
            drop_text,
            weights,
        } = *draw;
        let total: f64 = weights.map_or(0.0, |w| w.iter().sum());
        let draw = |rng: &mut Rng| match weights {
            None => rng.below(self.items.len()),
            Some(w) => {
                let mut x = rng.uniform() as f64 * total;
                w.iter()
                    .position(|wi| {
                        x -= wi;
                        x < 0.0
                    })
                    .unwrap_or(w.len() - 1)
            }
        };
        // Motions of similar length go together, so little of the batch is padding.
        let anchor = self.items[draw(rng)].tokens[0][0].len();
        let similar = |len: usize| len <= anchor && len * 4 >= anchor * 3;
        let mut picks: Vec<&TokenItem> = Vec::with_capacity(batch);
        for _ in 0..batch * 50 {
            if picks.len() == batch {
                break;
            }
            let item = &self.items[draw(rng)];
            if similar(item.tokens[0][0].len()) {
                picks.push(item);
            }
        }
        while picks.len() < batch {
            picks.push(&self.items[draw(rng)]);
        }
        let lengths: Vec<usize> = picks.iter().map(|i| i.tokens[0][0].len()).collect();
        let n = lengths.iter().copied().max().unwrap_or(1);
        let layers = picks[0].tokens[0].len();
        let pad_id = config.pad_id() as i32;
        let mut tokens = Vec::with_capacity(batch * PARTS * layers * n);
        let mut text = Vec::with_capacity(batch * PARTS * TEXT_DIM);
        let mut keep = Vec::with_capacity(batch * PARTS);
        let mut pad = Vec::with_capacity(batch * n);
        for item in &picks {
            for part in &item.tokens {
                for layer in part {
                    tokens.extend(layer.iter().map(|t| *t as i32));
                    tokens.extend(std::iter::repeat_n(pad_id, n - layer.len()));
                }
            }
            let global = item.captions.get(rng.below(item.captions.len())).copied();
            let dropped = rng.uniform() < drop_text;
            for p in 0..PARTS {
                let own = item.parts[p].filter(|_| rng.uniform() < part_text);
                let chosen = own.or(global);
                match chosen {
                    Some(t) => text.extend_from_slice(&self.embeddings[t]),
                    None => text.extend(std::iter::repeat_n(0.0, TEXT_DIM)),
                }
                keep.push(if dropped || chosen.is_none() {
                    0.0
                } else {
                    1.0
                });
            }
            let len = item.tokens[0][0].len();
            pad.extend((0..n).map(|s| (s >= len) as i32));
        }
        TokenBatch {
            tokens,
            dims: (batch, layers, n),
            text: Tensor::from_data(TensorData::new(text, [batch, PARTS, TEXT_DIM]), device),
            keep_text: Tensor::from_data(TensorData::new(keep, [batch, PARTS]), device),
            pad: Tensor::<2, Int>::from_data(TensorData::new(pad, [batch, n]), device)
                .equal_elem(1),
            lengths,
        }
    }
}
