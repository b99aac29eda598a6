//! Generation: iterative masked decoding of the base tokens, layer-by-layer residual tokens
//! (each step guided, see [`super::guidance`]), and seeded sampling done in plain Rust so a
//! seed gives the same motion on every backend.

use super::guidance::{Pass, PassInputs};
use super::prior::PriorOptions;
use super::transformer::{PARTS, TEXT_DIM};
use super::{Residual, Spam};
use crate::rng::Rng;

/// How to sample.
#[derive(Clone, Debug)]
pub struct SamplingOptions {
    /// Unmasking iterations of the base layer.
    pub iterations: usize,
    /// Guidance scale `s` of the base transformer: logits = (1 + s)·cond − s·uncond.
    pub base_guidance: f32,
    /// Guidance scale of the residual transformer.
    pub residual_guidance: f32,
    /// Softmax temperature of the base tokens (0 takes the most likely code).
    pub temperature: f32,
    /// Softmax temperature of the residual layers' tokens (0 takes the most likely code).
    /// They carry detail, not the action: on the validation split the most likely codes gave
    /// FID 0.107 against 0.123 when sampled at 1, top-3 R-precision level within noise
    /// (`runs/res2/eval-val-greedy.md`, `eval-val-sampled.md`).
    pub residual_temperature: f32,
    /// Sample only among the `k` most likely codes.
    pub top_k: Option<usize>,
    /// How a new motion uses the model's retrieval prior; `None` takes the model's own
    /// options (`spam.json`), and a `keep` of 0 generates from the text alone.
    pub prior: Option<PriorOptions>,
    pub seed: u64,
}

impl Default for SamplingOptions {
    fn default() -> Self {
        SamplingOptions {
            iterations: 10,
            // Chosen on the validation split for the dataset v2 model (`coma eval --split val
            // --guidance G`, docs/experiments.md): top-3 R-precision 0.64 at 2, 0.69 at 4, 0.74 at
            // 6, 0.72 at 9.
            base_guidance: 6.0,
            residual_guidance: 5.0,
            temperature: 1.0,
            residual_temperature: 0.0,
            top_k: None,
            prior: None,
            seed: 0,
        }
    }
}

pub use super::tokens::MotionTokens;

/// Fraction of tokens still masked at progress `t` ∈ [0, 1] (1 at the start, 0 at the end).
pub fn mask_schedule(t: f64) -> f64 {
    (t * std::f64::consts::FRAC_PI_2).cos()
}

/// Probabilities of one row of logits after temperature and top-k.
fn probabilities(logits: &[f32], temperature: f32, top_k: Option<usize>) -> Vec<f32> {
    let mut cut = f32::NEG_INFINITY;
    if let Some(k) = top_k.filter(|k| *k < logits.len()) {
        let mut sorted = logits.to_vec();
        sorted.sort_by(|a, b| b.total_cmp(a));
        cut = sorted[k.max(1) - 1];
    }
    let t = temperature.max(1e-4);
    let max = logits.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let mut p: Vec<f32> = logits
        .iter()
        .map(|l| {
            if *l >= cut {
                ((l - max) / t).exp()
            } else {
                0.0
            }
        })
        .collect();
    let sum: f32 = p.iter().sum();
    p.iter_mut().for_each(|x| *x /= sum.max(1e-30));
    p
}

/// Draws a code (most likely one at temperature 0) and returns it with its probability.
fn sample(logits: &[f32], temperature: f32, top_k: Option<usize>, rng: &mut Rng) -> (u32, f32) {
    if temperature <= 0.0 {
        let (i, _) = logits
            .iter()
            .enumerate()
            .fold(
                (0, f32::NEG_INFINITY),
                |b, (i, l)| if *l > b.1 { (i, *l) } else { b },
            );
        return (i as u32, 1.0);
    }
    let p = probabilities(logits, temperature, top_k);
    let u = rng.uniform();
    let mut acc = 0.0;
    for (i, pi) in p.iter().enumerate() {
        acc += pi;
        if u < acc {
            return (i as u32, *pi);
        }
    }
    let last = p.iter().rposition(|x| *x > 0.0).unwrap_or(0);
    (last as u32, p[last])
}

/// Fewest masked tokens one unmasking pass of [`Spam::decode_base`] places, on average.
pub const TOKENS_PER_PASS: usize = 4;

impl Spam {
    /// Fills the masked layer-0 tokens by iterative unmasking. `fixed[p][n]` holds tokens that
    /// must stay (editing); `None` everywhere generates from scratch. Returns `[part][step]`.
    pub async fn decode_base(
        &self,
        text: &[[f32; TEXT_DIM]; PARTS],
        fixed: &[Vec<Option<u32>>],
        options: &SamplingOptions,
        rng: &mut Rng,
    ) -> Vec<Vec<u32>> {
        let (config, device) = (&self.base_config, &self.device);
        let n = fixed[0].len();
        let k = config.codebook_size;
        let mask = config.mask_id() as u32;
        let inputs = PassInputs::new(text, n, device);
        let mut ids: Vec<u32> = fixed
            .iter()
            .flat_map(|p| p.iter().map(|t| t.unwrap_or(mask)))
            .collect();
        let free: Vec<usize> = (0..ids.len()).filter(|i| ids[*i] == mask).collect();
        let mut confidence = vec![f32::INFINITY; ids.len()];
        for i in &free {
            confidence[*i] = f32::NEG_INFINITY;
        }
        // A few masked tokens (a blend's transition, a clip's seam) need few passes: each pass
        // places at least TOKENS_PER_PASS of them, so a transition costs a handful of passes
        // and not as many as a whole motion.
        let iterations = options
            .iterations
            .min(free.len().div_ceil(TOKENS_PER_PASS))
            .max(1);
        for it in 0..iterations {
            // Re-mask the least confident free positions, as many as the schedule says.
            let still =
                (mask_schedule(it as f64 / iterations as f64) * free.len() as f64).round() as usize;
            let still = still.max(1).min(free.len());
            let mut order = free.clone();
            order.sort_by(|a, b| confidence[*a].total_cmp(&confidence[*b]));
            for (rank, i) in order.iter().enumerate() {
                if rank < still {
                    ids[*i] = mask;
                }
            }
            let remasked: Vec<usize> = order.into_iter().take(still).collect();
            let pass = Pass {
                layer: 0,
                steps: n,
                tokens: ids.iter().map(|t| *t as i32).collect(),
            };
            let logits = self
                .guided_logits(&pass, &inputs, options.base_guidance)
                .await;
            for i in remasked {
                let row = &logits[i * k..(i + 1) * k];
                let (code, p) = sample(row, options.temperature, options.top_k, rng);
                ids[i] = code;
                confidence[i] = p;
            }
        }
        ids.chunks(n).map(|c| c.to_vec()).collect()
    }

    /// Predicts residual layers `1..layers` from layer 0 (`[part][step]`); positions that `keep`
    /// marks as not editable take the original tokens. Returns `[part][layer][step]`, with
    /// layer 0 alone for a base-only model.
    pub async fn decode_residual(
        &self,
        text: &[[f32; TEXT_DIM]; PARTS],
        base: Vec<Vec<u32>>,
        keep: Option<KeepResidual<'_>>,
        options: &SamplingOptions,
        rng: &mut Rng,
    ) -> MotionTokens {
        let mut layers: Vec<Vec<Vec<u32>>> = base.into_iter().map(|b| vec![b]).collect();
        let Some(Residual { config, .. }) = &self.residual else {
            return MotionTokens::from_model(layers);
        };
        let device = &self.device;
        let n = layers[0][0].len();
        let k = config.codebook_size;
        let inputs = PassInputs::new(text, n, device);
        for j in 1..config.vq_layers {
            let pass = Pass {
                layer: j,
                steps: n,
                tokens: layers
                    .iter()
                    .flat_map(|part| part.iter().flat_map(|l| l.iter().map(|t| *t as i32)))
                    .collect(),
            };
            let logits = self
                .guided_logits(&pass, &inputs, options.residual_guidance)
                .await;
            for (p, part) in layers.iter_mut().enumerate() {
                let row: Vec<u32> = (0..n)
                    .map(|s| {
                        let row = &logits[(p * n + s) * k..(p * n + s + 1) * k];
                        let drawn = sample(row, options.residual_temperature, options.top_k, rng).0;
                        match &keep {
                            Some(keep) if !keep.editable[p][s] => keep.tokens[p][j][s],
                            _ => drawn,
                        }
                    })
                    .collect();
                part.push(row);
            }
        }
        MotionTokens::from_model(layers)
    }
}

/// Residual tokens to keep while editing: the original tokens and, per part and step,
/// whether that position may change.
pub struct KeepResidual<'a> {
    pub tokens: &'a MotionTokens,
    pub editable: &'a [Vec<bool>],
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::executor::block_on;
    use burn::tensor::Device;

    #[test]
    fn schedule_goes_from_all_to_none() {
        assert!((mask_schedule(0.0) - 1.0).abs() < 1e-12);
        assert!(mask_schedule(1.0).abs() < 1e-12);
        assert!(mask_schedule(0.3) > mask_schedule(0.6));
    }

    #[test]
    fn sampling_respects_top_k_and_temperature() {
        let logits = [0.0, 5.0, 1.0, 4.9];
        let mut rng = Rng::new(3);
        let greedy = SamplingOptions {
            temperature: 0.0,
            ..Default::default()
        };
        assert_eq!(
            sample(&logits, greedy.temperature, greedy.top_k, &mut rng).0,
            1
        );
        let top2 = SamplingOptions {
            top_k: Some(2),
            ..Default::default()
        };
        for _ in 0..200 {
            let (c, _) = sample(&logits, top2.temperature, top2.top_k, &mut rng);
            assert!(c == 1 || c == 3);
        }
    }

    use crate::model::transformer::TransformerConfig;
    use crate::model::vq::VqConfig;

    pub(crate) fn small() -> TransformerConfig {
        TransformerConfig::new()
            .with_width(32)
            .with_depth(1)
            .with_heads(4)
            .with_ff_width(64)
            .with_codebook_size(16)
            .with_vq_layers(3)
    }

    pub(crate) fn tiny_vq() -> VqConfig {
        VqConfig::new()
            .with_encoder_width(16)
            .with_decoder_width(16)
            .with_code_dim(8)
            .with_codebook_size(16)
            .with_layers(3)
            .with_res_blocks(1)
    }

    #[test]
    fn same_seed_same_tokens_and_fixed_tokens_stay() {
        let spam = Spam::random(&tiny_vq(), &small(), Some(&small()), &Device::flex());
        let text = [[0.1f32; TEXT_DIM]; PARTS];
        let mut fixed = vec![vec![None; 6]; PARTS];
        fixed[2][0] = Some(7);
        let run = |seed: u64| {
            let options = SamplingOptions {
                seed,
                ..Default::default()
            };
            let mut rng = Rng::new(seed);
            let b = block_on(spam.decode_base(&text, &fixed, &options, &mut rng));
            block_on(spam.decode_residual(&text, b, None, &options, &mut rng))
        };
        let a = run(5);
        assert_eq!(a, run(5));
        assert_ne!(a, run(6));
        assert_eq!(a.len(), PARTS);
        assert_eq!(a[0].len(), 3);
        assert_eq!(a[0][2].len(), 6);
        assert_eq!(a[2][0][0], 7, "a fixed token is kept");
        assert!(
            a.iter().flatten().flatten().all(|t| *t < 16),
            "no mask or pad ids in the output"
        );
    }

    #[test]
    fn greedy_residual_layers_follow_the_base_tokens_not_the_seed() {
        let spam = Spam::random(&tiny_vq(), &small(), Some(&small()), &Device::flex());
        let text = [[0.1f32; TEXT_DIM]; PARTS];
        let base: Vec<Vec<u32>> = (0..PARTS as u32).map(|p| vec![p, 3, 9, 1]).collect();
        let residual = |residual_temperature: f32, seed: u64| {
            let options = SamplingOptions {
                residual_temperature,
                ..Default::default()
            };
            let mut rng = Rng::new(seed);
            block_on(spam.decode_residual(&text, base.clone(), None, &options, &mut rng))
        };
        assert_eq!(residual(0.0, 1), residual(0.0, 2));
        assert_ne!(
            residual(1.0, 1),
            residual(1.0, 2),
            "sampled layers vary by seed"
        );
    }

    #[test]
    fn a_base_only_model_generates_layer_zero() {
        let spam = Spam::random(&tiny_vq(), &small(), None, &Device::flex());
        assert_eq!(spam.generated_layers(), 1);
        let text = [[0.1f32; TEXT_DIM]; PARTS];
        let options = SamplingOptions::default();
        let mut rng = Rng::new(1);
        let b = block_on(spam.decode_base(&text, &vec![vec![None; 6]; PARTS], &options, &mut rng));
        let tokens = block_on(spam.decode_residual(&text, b.clone(), None, &options, &mut rng));
        assert_eq!(tokens.len(), PARTS);
        for (part, base) in tokens.iter().zip(&b) {
            assert_eq!(part, &vec![base.clone()], "one layer, the base tokens");
        }
    }
}
