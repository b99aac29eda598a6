//! How far two evaluators (f32 weights and their shipped f16 or quantized copy, say) disagree on the same
//! motions and captions: `coma export evaluator` prints it before the page gets the rounding.

use crate::features::FeatureFrame;
use crate::metrics::r_precision;
use crate::model::evaluator::{alignment_score, Evaluator, EvaluatorConfig};
use crate::model::transformer::TEXT_DIM;
use burn::prelude::*;

/// How far two evaluators (f32 weights and their shipped f16 or quantized copy, say) disagree on the same
/// motions and captions (see [`agreement`]).
#[derive(Clone, Debug, serde::Serialize)]
pub struct Agreement {
    /// Motion–caption pairs compared (whole batches of 32).
    pub pairs: usize,
    /// Largest difference of [`alignment_score`] (0–100) over every caption–motion
    /// combination of the pairs, matching or not.
    pub max_score_difference: f64,
    /// Mean of that difference.
    pub mean_score_difference: f64,
    /// R-precision top-1, top-2 and top-3 (batches of 32, as the protocol) with the first
    /// and with the second evaluator.
    pub r_precision: [[f64; 3]; 2],
    /// Captions whose nearest motion within their batch differs between the two.
    pub changed_nearest: usize,
}

/// Embeds `motions` (normalised features) and their captions' MiniLM `sentences` (one each)
/// with `a` and `b`, both of the sizes `config`, and measures how far the scores and
/// R-precision move. A last batch short of 32 is dropped.
pub fn agreement(
    a: &Evaluator,
    b: &Evaluator,
    config: &EvaluatorConfig,
    motions: &[&[FeatureFrame]],
    sentences: &[[f32; TEXT_DIM]],
    device: &Device,
) -> Agreement {
    const BATCH: usize = 32;
    let n = motions.len().min(sentences.len()) / BATCH * BATCH;
    let embed = |e: &Evaluator| {
        (
            e.embed_texts(&sentences[..n], device),
            e.embed_motions(config, &motions[..n], device),
        )
    };
    let (ta, ma) = embed(a);
    let (tb, mb) = embed(b);
    let (mut max, mut sum) = (0f64, 0f64);
    for i in 0..n {
        for j in 0..n {
            let d = (alignment_score(&ta[i], &ma[j]) - alignment_score(&tb[i], &mb[j])).abs();
            max = max.max(d);
            sum += d;
        }
    }
    let nearest = |t: &[Vec<f32>], m: &[Vec<f32>], i: usize| {
        let start = i / BATCH * BATCH;
        (start..start + BATCH)
            .max_by(|&x, &y| {
                alignment_score(&t[i], &m[x]).total_cmp(&alignment_score(&t[i], &m[y]))
            })
            .unwrap_or(i)
    };
    Agreement {
        pairs: n,
        max_score_difference: max,
        mean_score_difference: sum / (n * n).max(1) as f64,
        r_precision: [r_precision(&ta, &ma, BATCH), r_precision(&tb, &mb, BATCH)],
        changed_nearest: (0..n)
            .filter(|&i| nearest(&ta, &ma, i) != nearest(&tb, &mb, i))
            .count(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::evaluator::tests::{motion, tiny};

    #[test]
    fn f16_weights_score_as_the_original() {
        let device = Device::flex();
        let cfg = tiny();
        let full = cfg.init(&device);
        let f16_bytes = full.to_shipped_bytes(None).unwrap();
        let text = serde_json::to_string(&cfg).unwrap();
        let (half, _) = Evaluator::from_bytes(&text, &f16_bytes, &device).unwrap();
        let motions: Vec<Vec<FeatureFrame>> = (0..64)
            .map(|i| motion(8 + i % 17, (i as f32 * 0.37).sin()))
            .collect();
        let refs: Vec<&[FeatureFrame]> = motions.iter().map(Vec::as_slice).collect();
        let sentences: Vec<[f32; TEXT_DIM]> = (0..64)
            .map(|i| std::array::from_fn(|k| ((i * 7 + k) as f32 * 0.11).cos()))
            .collect();
        let same = agreement(&full, &full, &cfg, &refs, &sentences, &device);
        assert_eq!(same.pairs, 64);
        assert_eq!(same.max_score_difference, 0.0);
        assert_eq!(same.changed_nearest, 0);
        assert_eq!(same.r_precision[0], same.r_precision[1]);
        let rounded = agreement(&full, &half, &cfg, &refs, &sentences, &device);
        assert!(
            rounded.max_score_difference < 0.5,
            "f16 moves a score by {}",
            rounded.max_score_difference
        );
    }
}
