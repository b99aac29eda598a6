//! SPAM's masked transformers over body-part tokens, with factorised attention and a text
//! condition per body part.
//!
//! The motion is a grid of tokens: 4 body parts × N time steps (one step = 4 frames = 0.2 s).
//! A text token per part is put in front of that part's stream (time index 0), so the grid the
//! layers see is `[B, N + 1, 4, W]`:
//!
//! ```text
//!  text per part [B, 4, 384] ─► adapter ─► [B, 1, 4, W] ─┐
//!  tokens [B, 4, N] ─► part embeddings (+ lower layers) ─►├─ cat on time ─► + time, part embeddings
//!                                                         ▼
//!      depth × [ x += SpatialAttn(LN x)   (the 4 parts of one time step)
//!               x += TemporalAttn(LN x)  (the N + 1 steps of one part, padding masked)
//!               x += FFN(LN x) ]
//!                                                         ▼
//!      LN ─► drop the text step ─► logits per part = h · (that part's code embeddings)ᵀ ─► [B, 4, N, K]
//! ```
//!
//! The base transformer predicts layer-0 tokens from a partly masked grid; the residual
//! transformer predicts layer `j` from the sum of the embeddings of layers `0..j` and an
//! embedding of `j`. Output logits reuse the token embedding tables (weight tying), which keeps
//! the models small enough to ship in the page.

use super::gelu::gelu;
use burn::module::Param;
use burn::nn::attention::{MhaInput, MultiHeadAttention, MultiHeadAttentionConfig};
use burn::nn::{
    Dropout, DropoutConfig, Embedding, EmbeddingConfig, LayerNorm, LayerNormConfig, Linear,
    LinearConfig,
};
use burn::prelude::*;
use burn::tensor::{Bool, Distribution, Int};

/// Number of body parts (token streams).
pub const PARTS: usize = 4;
/// Dimension of a sentence embedding (all-MiniLM-L6-v2).
pub const TEXT_DIM: usize = 384;

/// Sizes of a transformer.
#[derive(Config, Debug)]
pub struct TransformerConfig {
    /// Width of the hidden states.
    #[config(default = 256)]
    pub width: usize,
    /// Number of (spatial, temporal, feed-forward) layers.
    #[config(default = 4)]
    pub depth: usize,
    #[config(default = 8)]
    pub heads: usize,
    /// Hidden width of the feed-forward blocks.
    #[config(default = 1024)]
    pub ff_width: usize,
    #[config(default = 0.1)]
    pub dropout: f64,
    /// Codes per codebook of the VQ-VAE.
    #[config(default = 256)]
    pub codebook_size: usize,
    /// Quantizer layers of the VQ-VAE (the residual transformer predicts layers 1..).
    #[config(default = 4)]
    pub vq_layers: usize,
    /// Longest motion in time steps (196 frames / 4 = 49).
    #[config(default = 50)]
    pub max_steps: usize,
}

impl TransformerConfig {
    /// Token id meaning "masked: predict me".
    pub fn mask_id(&self) -> usize {
        self.codebook_size
    }

    /// Token id of padding after the end of a shorter motion.
    pub fn pad_id(&self) -> usize {
        self.codebook_size + 1
    }

    /// Floating-point operations (a multiply-add counts two) of the matrix products of one
    /// forward pass over `batch` motions of `steps` time steps (4 frames each): the text
    /// adapter, per layer the attention projections and products across parts and across time
    /// and the feed-forward block, and the tied output logits. Layer norms, activations, masks
    /// and embedding look-ups are left out (well under 1 % at the default sizes). The
    /// benchmark divides this by the time taken to report achieved GFLOP/s.
    pub fn forward_flops(&self, batch: usize, steps: usize) -> f64 {
        let (b, n, w) = (batch as f64, steps as f64, self.width as f64);
        let p = PARTS as f64;
        let grid = b * p * (n + 1.0); // text step + token steps, per part
        let text = b * p * (TEXT_DIM as f64 * w + w * w) * 2.0;
        // Q, K, V and output projections, then scores and weighted sums over sequences of
        // length `len`: (grid / len) sequences × len² × width × 2 products.
        let attention = |len: f64| 4.0 * grid * w * w * 2.0 + 2.0 * grid * len * w * 2.0;
        let feed_forward = 2.0 * grid * w * self.ff_width as f64 * 2.0;
        let layer = attention(p) + attention(n + 1.0) + feed_forward;
        let logits = b * p * n * w * self.codebook_size as f64 * 2.0;
        text + self.depth as f64 * layer + logits
    }
}

/// One factorised layer: attention across parts, attention across time, feed-forward.
#[derive(Module, Debug)]
pub struct FactorisedLayer {
    spatial_norm: LayerNorm,
    spatial: MultiHeadAttention,
    temporal_norm: LayerNorm,
    temporal: MultiHeadAttention,
    ff_norm: LayerNorm,
    ff_in: Linear,
    ff_out: Linear,
    dropout: Dropout,
}

impl FactorisedLayer {
    fn new(config: &TransformerConfig, device: &Device) -> FactorisedLayer {
        let w = config.width;
        let mha = || {
            MultiHeadAttentionConfig::new(w, config.heads)
                .with_dropout(config.dropout)
                .init(device)
        };
        FactorisedLayer {
            spatial_norm: LayerNormConfig::new(w).init(device),
            spatial: mha(),
            temporal_norm: LayerNormConfig::new(w).init(device),
            temporal: mha(),
            ff_norm: LayerNormConfig::new(w).init(device),
            ff_in: LinearConfig::new(w, config.ff_width).init(device),
            ff_out: LinearConfig::new(config.ff_width, w).init(device),
            dropout: DropoutConfig::new(config.dropout).init(),
        }
    }

    /// `x`: `[B, S, 4, W]` (S = N + 1 steps); `pad`: `[B·4, S]`, true where a step is padding.
    fn forward(&self, x: Tensor<4>, pad: Tensor<2, Bool>) -> Tensor<4> {
        let [b, s, p, w] = x.dims();
        // Across the parts of one time step.
        let h = self.spatial_norm.forward(x.clone()).reshape([b * s, p, w]);
        let h = self
            .spatial
            .forward(MhaInput::self_attn(h))
            .context
            .reshape([b, s, p, w]);
        let x = x + self.dropout.forward(h);
        // Across the time steps of one part.
        let h = self
            .temporal_norm
            .forward(x.clone())
            .swap_dims(1, 2)
            .reshape([b * p, s, w]);
        let h = self
            .temporal
            .forward(MhaInput::self_attn(h).mask_pad(pad))
            .context;
        let h = h.reshape([b, p, s, w]).swap_dims(1, 2);
        let x = x + self.dropout.forward(h);
        let h = self
            .ff_out
            .forward(gelu(self.ff_in.forward(self.ff_norm.forward(x.clone()))));
        x + self.dropout.forward(h)
    }
}

/// What both transformers share: the text adapter, position embeddings and the layers.
#[derive(Module, Debug)]
pub struct Backbone {
    text_in: Linear,
    text_out: Linear,
    /// Condition used when the text is dropped (classifier-free guidance).
    null_text: Param<Tensor<1>>,
    time: Embedding,
    part: Embedding,
    layers: Vec<FactorisedLayer>,
    final_norm: LayerNorm,
}

impl Backbone {
    fn new(config: &TransformerConfig, device: &Device) -> Backbone {
        let w = config.width;
        Backbone {
            text_in: LinearConfig::new(TEXT_DIM, w).init(device),
            text_out: LinearConfig::new(w, w).init(device),
            null_text: Param::from_tensor(Tensor::random(
                [w],
                Distribution::Normal(0.0, 0.02),
                device,
            )),
            time: EmbeddingConfig::new(config.max_steps + 1, w).init(device),
            part: EmbeddingConfig::new(PARTS, w).init(device),
            layers: (0..config.depth)
                .map(|_| FactorisedLayer::new(config, device))
                .collect(),
            final_norm: LayerNormConfig::new(w).init(device),
        }
    }

    /// Runs the layers over token embeddings `[B, 4, N, W]` with per-part text `[B, 4, 384]`;
    /// `keep_text` `[B, 4]` (1 keeps the text, 0 uses the null condition); `pad` `[B, N]`.
    /// Returns hidden states `[B, 4, N, W]`.
    fn forward(
        &self,
        tokens: Tensor<4>,
        text: Tensor<3>,
        keep_text: Tensor<2>,
        pad: Tensor<2, Bool>,
    ) -> Tensor<4> {
        let [b, p, n, w] = tokens.dims();
        let device = tokens.device();
        let cond = self.text_out.forward(gelu(self.text_in.forward(text))); // [B, 4, W]
        let keep = keep_text.reshape([b, p, 1]);
        let null = self.null_text.val().reshape([1, 1, w]);
        let cond = cond * keep.clone() + null * (keep.neg() + 1.0);
        let x = Tensor::cat(vec![cond.reshape([b, p, 1, w]), tokens], 2); // [B, 4, N+1, W]
        let steps = Tensor::<1, Int>::arange(0..(n as i64 + 1), &device).reshape([1, n + 1]);
        let parts = Tensor::<1, Int>::arange(0..p as i64, &device).reshape([1, p]);
        let x = x
            + self.time.forward(steps).reshape([1, 1, n + 1, w])
            + self.part.forward(parts).reshape([1, p, 1, w]);
        let mut x = x.swap_dims(1, 2); // [B, N+1, 4, W]
                                       // The text step is never padding; padding is per motion, the same for all parts.
        let text_step = Tensor::<2, Int>::zeros([b, 1], &device).equal_elem(1);
        let pad = Tensor::cat(vec![text_step, pad], 1);
        let pad = pad
            .reshape([b, 1, n + 1])
            .repeat_dim(1, p)
            .reshape([b * p, n + 1]);
        for layer in &self.layers {
            x = layer.forward(x, pad.clone());
        }
        let x = self.final_norm.forward(x);
        x.swap_dims(1, 2).slice(s![.., .., 1..n + 1, ..])
    }
}

/// Logits `[B, 4, N, K]` of hidden states `[B, 4, N, W]` against per-part embedding tables
/// (`[K + 2, W]` each; only the first `K` rows are codes), scaled by 1/√W: unit-variance
/// states against unit-variance codes would otherwise start with logits of spread √W and a
/// loss many times ln K.
fn tied_logits(h: Tensor<4>, tables: Vec<Tensor<2>>, k: usize) -> Tensor<4> {
    let [b, _, n, w] = h.dims();
    let h = h / (w as f64).sqrt();
    let parts: Vec<Tensor<3>> = tables
        .into_iter()
        .enumerate()
        .map(|(i, table)| {
            let codes = table.slice(s![0..k, ..]).transpose(); // [W, K]
            h.clone()
                .slice(s![.., i..i + 1, .., ..])
                .reshape([b * n, w])
                .matmul(codes)
                .reshape([b, n, k])
        })
        .collect();
    Tensor::stack::<4>(parts, 1)
}

/// Embeds `[B, 4, N]` token ids with one table per part → `[B, 4, N, W]`.
fn embed_parts(tables: &[Embedding], tokens: Tensor<3, Int>) -> Tensor<4> {
    let [b, _, n] = tokens.dims();
    let parts: Vec<Tensor<3>> = tables
        .iter()
        .enumerate()
        .map(|(i, table)| table.forward(tokens.clone().slice(s![.., i..i + 1, ..]).reshape([b, n])))
        .collect();
    Tensor::stack::<4>(parts, 1)
}

/// Predicts the layer-0 tokens of all four parts from a partly masked grid.
#[derive(Module, Debug)]
pub struct BaseTransformer {
    tokens: Vec<Embedding>,
    backbone: Backbone,
    codebook_size: usize,
}

impl BaseTransformer {
    /// A base transformer with random weights.
    pub fn new(config: &TransformerConfig, device: &Device) -> BaseTransformer {
        BaseTransformer {
            tokens: (0..PARTS)
                .map(|_| EmbeddingConfig::new(config.codebook_size + 2, config.width).init(device))
                .collect(),
            backbone: Backbone::new(config, device),
            codebook_size: config.codebook_size,
        }
    }

    /// Logits `[B, 4, N, K]` for tokens `[B, 4, N]` (codes, mask or pad ids).
    pub fn forward(
        &self,
        tokens: Tensor<3, Int>,
        text: Tensor<3>,
        keep_text: Tensor<2>,
        pad: Tensor<2, Bool>,
    ) -> Tensor<4> {
        let x = embed_parts(&self.tokens, tokens);
        let h = self.backbone.forward(x, text, keep_text, pad);
        tied_logits(
            h,
            self.tokens.iter().map(|e| e.weight.val()).collect(),
            self.codebook_size,
        )
    }
}

/// Predicts the tokens of residual layer `j` from layers `0..j`.
#[derive(Module, Debug)]
pub struct ResidualTransformer {
    /// Per part, per VQ layer: `[K + 2, W]` tables.
    tokens: Vec<Vec<Embedding>>,
    /// Embedding of the layer being predicted.
    layer: Embedding,
    backbone: Backbone,
    codebook_size: usize,
}

impl ResidualTransformer {
    /// A residual transformer with random weights.
    pub fn new(config: &TransformerConfig, device: &Device) -> ResidualTransformer {
        ResidualTransformer {
            tokens: (0..PARTS)
                .map(|_| {
                    (0..config.vq_layers)
                        .map(|_| {
                            EmbeddingConfig::new(config.codebook_size + 2, config.width)
                                .init(device)
                        })
                        .collect()
                })
                .collect(),
            layer: EmbeddingConfig::new(config.vq_layers, config.width).init(device),
            backbone: Backbone::new(config, device),
            codebook_size: config.codebook_size,
        }
    }

    /// Logits `[B, 4, N, K]` of layer `j` (1 ≤ j < layers) given `lower` tokens
    /// `[B, 4, j, N]` of layers `0..j`.
    pub fn forward(
        &self,
        lower: Tensor<4, Int>,
        j: usize,
        text: Tensor<3>,
        keep_text: Tensor<2>,
        pad: Tensor<2, Bool>,
    ) -> Tensor<4> {
        let [b, p, layers, n] = lower.dims();
        let device = lower.device();
        let w = self.layer.weight.val().dims()[1];
        let mut x: Tensor<4> = Tensor::zeros([b, p, n, w], &device);
        for l in 0..layers.min(j) {
            let ids = lower
                .clone()
                .slice(s![.., .., l..l + 1, ..])
                .reshape([b, p, n]);
            let tables: Vec<Embedding> = self.tokens.iter().map(|t| t[l].clone()).collect();
            x = x + embed_parts(&tables, ids);
        }
        let which = Tensor::<1, Int>::from_ints([j as i32], &device).reshape([1, 1]);
        x = x + self.layer.forward(which).reshape([1, 1, 1, w]);
        let h = self.backbone.forward(x, text, keep_text, pad);
        tied_logits(
            h,
            self.tokens.iter().map(|t| t[j].weight.val()).collect(),
            self.codebook_size,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::tensor::TensorData;

    fn small() -> TransformerConfig {
        TransformerConfig::new()
            .with_width(32)
            .with_depth(2)
            .with_heads(4)
            .with_ff_width(64)
            .with_codebook_size(16)
            .with_vq_layers(3)
    }

    fn inputs(
        b: usize,
        n: usize,
        device: &Device,
    ) -> (Tensor<3, Int>, Tensor<3>, Tensor<2>, Tensor<2, Bool>) {
        let tokens = Tensor::<3, Int>::from_data(
            TensorData::new(
                (0..b * PARTS * n)
                    .map(|i| (i % 16) as i32)
                    .collect::<Vec<_>>(),
                [b, PARTS, n],
            ),
            device,
        );
        let text = Tensor::random([b, PARTS, TEXT_DIM], Distribution::Normal(0.0, 1.0), device);
        let keep = Tensor::ones([b, PARTS], device);
        let pad = Tensor::<2, Int>::zeros([b, n], device).equal_elem(1);
        (tokens, text, keep, pad)
    }

    #[test]
    fn base_logits_have_one_row_per_part_and_step() {
        let device = Device::flex();
        let model = BaseTransformer::new(&small(), &device);
        let (tokens, text, keep, pad) = inputs(2, 5, &device);
        assert_eq!(
            model.forward(tokens, text, keep, pad).dims(),
            [2, PARTS, 5, 16]
        );
    }

    #[test]
    fn residual_logits_for_each_layer() {
        let device = Device::flex();
        let model = ResidualTransformer::new(&small(), &device);
        let (tokens, text, keep, pad) = inputs(2, 5, &device);
        let lower = tokens.reshape([2, PARTS, 1, 5]).repeat_dim(2, 2);
        for j in 1..3 {
            let out = model.forward(lower.clone(), j, text.clone(), keep.clone(), pad.clone());
            assert_eq!(out.dims(), [2, PARTS, 5, 16]);
        }
    }

    #[test]
    fn padding_does_not_change_the_real_steps() {
        let device = Device::flex();
        let model = BaseTransformer::new(&small(), &device);
        let (tokens, text, keep, _) = inputs(1, 6, &device);
        let short_pad = Tensor::<2, Int>::from_ints([[0, 0, 0, 0, 1, 1]], &device).equal_elem(1);
        let a = model.forward(
            tokens.clone(),
            text.clone(),
            keep.clone(),
            short_pad.clone(),
        );
        // Change the padded steps' tokens: the first four steps' logits must not move.
        let other = tokens.slice_assign(
            [0..1, 0..PARTS, 4..6],
            Tensor::<3, Int>::zeros([1, PARTS, 2], &device),
        );
        let b = model.forward(other, text, keep, short_pad);
        let a = a.slice(s![.., .., 0..4, ..]);
        let b = b.slice(s![.., .., 0..4, ..]);
        assert!(a.all_close(b, Some(1e-4), Some(1e-4)));
    }

    #[test]
    fn flops_of_the_default_sizes_match_a_count_by_hand() {
        // Width 256, 4 layers, FFN 1024, 256 codes; a guided pair over 49 steps: 400 grid rows.
        // Per layer: projections 2 × 4 × 400 × 256² × 2, scores and sums across parts
        // 2 × 400 × 4 × 256 × 2 and across time 2 × 400 × 50 × 256 × 2, FFN 2 × 400 × 256 ×
        // 1024 × 2; text 8 × (384 + 256) × 256 × 2; logits 392 × 256 × 256 × 2.
        let per_layer = 2.0 * 4.0 * 400.0 * 65536.0 * 2.0
            + 2.0 * 400.0 * 4.0 * 256.0 * 2.0
            + 2.0 * 400.0 * 50.0 * 256.0 * 2.0
            + 2.0 * 400.0 * 256.0 * 1024.0 * 2.0;
        let expected = 8.0 * 640.0 * 256.0 * 2.0 + 4.0 * per_layer + 392.0 * 65536.0 * 2.0;
        let flops = TransformerConfig::new().forward_flops(2, 49);
        assert!((flops - expected).abs() < 1.0, "{flops} vs {expected}");
        // About 3.5 GFLOP a pass: 35 GFLOP for the 10 guided iterations of a 196-frame motion.
        assert!((3.4e9..3.6e9).contains(&flops));
    }

    #[test]
    fn dropping_the_text_changes_the_prediction() {
        let device = Device::flex();
        let model = BaseTransformer::new(&small(), &device);
        let (tokens, text, keep, pad) = inputs(1, 4, &device);
        let with = model.forward(tokens.clone(), text.clone(), keep.clone(), pad.clone());
        let without = model.forward(tokens, text, keep.zeros_like(), pad);
        assert!(!with.all_close(without, Some(1e-5), Some(1e-5)));
    }
}
