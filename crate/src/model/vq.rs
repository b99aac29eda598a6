//! The spatially-aware residual VQ-VAE of SPAM: four body-part encoders, four residual
//! quantizers and one shared decoder. It turns motion features into discrete tokens (four
//! parts × `layers` codebooks × T/4 time steps) and tokens back into features.
//!
//! ```text
//!  features [B, T, 263] (normalised, 20 fps)
//!     │ per part: its columns (108 arm / 57 leg)
//!     ├──► PartEncoder ─► [B, D, T/4] ─► ResidualQuantizer ─► Σ code vectors [B, D, T/4]   ×4 parts
//!     │                                        └─► tokens [B, layers, T/4]
//!     └──► concat the four parts on channels [B, 4D, T/4] ─► Decoder ─► [B, T, 263]
//! ```
//!
//! Model code is written once against burn's run-time `Device`: the same module trains on an
//! autodiff CPU device and runs inference on WebGPU or CPU.

use crate::features::{part_columns, FEATURE_DIM};
use crate::rng::Rng;
use crate::skeleton::BodyPart;
use burn::module::Param;
use burn::nn::conv::{Conv1d, Conv1dConfig};
use burn::nn::PaddingConfig1d;
use burn::prelude::*;
use burn::tensor::activation::relu;
use burn::tensor::{Distribution, Int, TensorData};

use crate::timing::FRAMES_PER_TOKEN;

/// Sizes and training constants of the VQ-VAE.
#[derive(Config, Debug)]
pub struct VqConfig {
    /// Channels of each part encoder.
    #[config(default = 128)]
    pub encoder_width: usize,
    /// Channels of the shared decoder.
    #[config(default = 256)]
    pub decoder_width: usize,
    /// Dimension of a code vector.
    #[config(default = 64)]
    pub code_dim: usize,
    /// Codes per codebook (at most 512, so a token fits in 9 bits).
    #[config(default = 256)]
    pub codebook_size: usize,
    /// Quantizer layers per part: one base layer and `layers − 1` residual layers.
    #[config(default = 4)]
    pub layers: usize,
    /// Residual blocks per resolution level.
    #[config(default = 2)]
    pub res_blocks: usize,
    /// Probability that a training batch uses only a random number of the first layers.
    #[config(default = 0.2)]
    pub quantize_dropout: f64,
    /// Decay of the codebooks' exponential moving averages.
    #[config(default = 0.99)]
    pub ema_decay: f64,
}

/// A residual block: two convolutions around a ReLU, added to the input.
#[derive(Module, Debug)]
pub struct ResBlock {
    dilated: Conv1d,
    pointwise: Conv1d,
}

impl ResBlock {
    fn new(width: usize, dilation: usize, device: &Device) -> ResBlock {
        ResBlock {
            dilated: Conv1dConfig::new(width, width, 3)
                .with_dilation(dilation)
                .with_padding(PaddingConfig1d::Explicit(dilation, dilation))
                .init(device),
            pointwise: Conv1dConfig::new(width, width, 1).init(device),
        }
    }

    /// `[B, C, T] → [B, C, T]`.
    pub fn forward(&self, x: Tensor<3>) -> Tensor<3> {
        let h = self.dilated.forward(relu(x.clone()));
        x + self.pointwise.forward(relu(h))
    }
}

fn conv3(c_in: usize, c_out: usize, device: &Device) -> Conv1d {
    Conv1dConfig::new(c_in, c_out, 3)
        .with_padding(PaddingConfig1d::Explicit(1, 1))
        .init(device)
}

/// Residual blocks with growing dilation (1, 3, 9, …) so the receptive field spans seconds.
fn res_stack(width: usize, count: usize, device: &Device) -> Vec<ResBlock> {
    (0..count)
        .map(|i| ResBlock::new(width, 3usize.pow(i as u32), device))
        .collect()
}

/// One halving of the time axis, then residual blocks.
#[derive(Module, Debug)]
pub struct DownLevel {
    down: Conv1d,
    blocks: Vec<ResBlock>,
}

/// Encoder of one body part: `[B, C_part, T] → [B, D, T/4]`.
#[derive(Module, Debug)]
pub struct PartEncoder {
    input: Conv1d,
    levels: Vec<DownLevel>,
    output: Conv1d,
}

impl PartEncoder {
    fn new(c_in: usize, config: &VqConfig, device: &Device) -> PartEncoder {
        let w = config.encoder_width;
        PartEncoder {
            input: conv3(c_in, w, device),
            levels: (0..2)
                .map(|_| DownLevel {
                    down: Conv1dConfig::new(w, w, 4)
                        .with_stride(2)
                        .with_padding(PaddingConfig1d::Explicit(1, 1))
                        .init(device),
                    blocks: res_stack(w, config.res_blocks, device),
                })
                .collect(),
            output: conv3(w, config.code_dim, device),
        }
    }

    /// `[B, C_part, T] → [B, D, T/4]`.
    pub fn forward(&self, x: Tensor<3>) -> Tensor<3> {
        let mut h = relu(self.input.forward(x));
        for level in &self.levels {
            h = level.down.forward(h);
            for block in &level.blocks {
                h = block.forward(h);
            }
        }
        self.output.forward(h)
    }
}

/// Residual blocks, then a doubling of the time axis.
#[derive(Module, Debug)]
pub struct UpLevel {
    blocks: Vec<ResBlock>,
    conv: Conv1d,
}

/// The shared decoder: `[B, 4D, T/4] → [B, 263, T]`.
#[derive(Module, Debug)]
pub struct Decoder {
    input: Conv1d,
    levels: Vec<UpLevel>,
    hidden: Conv1d,
    output: Conv1d,
}

impl Decoder {
    fn new(config: &VqConfig, device: &Device) -> Decoder {
        let w = config.decoder_width;
        Decoder {
            input: conv3(4 * config.code_dim, w, device),
            levels: (0..2)
                .map(|_| UpLevel {
                    blocks: res_stack(w, config.res_blocks, device),
                    conv: conv3(w, w, device),
                })
                .collect(),
            hidden: conv3(w, w, device),
            output: conv3(w, FEATURE_DIM, device),
        }
    }

    /// `[B, 4D, N] → [B, 263, 4N]`.
    pub fn forward(&self, x: Tensor<3>) -> Tensor<3> {
        let mut h = relu(self.input.forward(x));
        for level in &self.levels {
            for block in &level.blocks {
                h = block.forward(h);
            }
            // Nearest-neighbour doubling: [B, C, N] → [B, C, N, 2] → [B, C, 2N].
            let [b, c, n] = h.dims();
            h = h
                .unsqueeze_dim::<4>(3)
                .repeat_dim(3, 2)
                .reshape([b, c, 2 * n]);
            h = level.conv.forward(h);
        }
        self.output.forward(relu(self.hidden.forward(h)))
    }
}

/// One part's residual quantizer: `layers` codebooks of `codebook_size` vectors of `code_dim`,
/// updated by exponential moving averages (not by gradients), each quantizing what the
/// previous layers left.
#[derive(Module, Debug)]
pub struct ResidualQuantizer {
    /// `[layers, K, D]` code vectors.
    pub codebooks: Param<Tensor<3>>,
    /// `[layers, K]` moving average of how many vectors each code received.
    ema_counts: Param<Tensor<2>>,
    /// `[layers, K, D]` moving average of the sum of those vectors.
    ema_sums: Param<Tensor<3>>,
}

/// What one layer of a quantizer did in a training step, for the codebook update.
#[derive(Debug)]
pub struct LayerAssignment {
    /// `[M, D]` the vectors this layer quantized (detached).
    pub residuals: Tensor<2>,
    /// `[M]` the chosen code of each.
    pub codes: Tensor<1, Int>,
}

impl ResidualQuantizer {
    fn new(config: &VqConfig, device: &Device) -> ResidualQuantizer {
        let (l, k, d) = (config.layers, config.codebook_size, config.code_dim);
        ResidualQuantizer {
            codebooks: Param::from_tensor(Tensor::random(
                [l, k, d],
                Distribution::Normal(0.0, 1.0),
                device,
            ))
            .set_require_grad(false),
            ema_counts: Param::from_tensor(Tensor::zeros([l, k], device)).set_require_grad(false),
            ema_sums: Param::from_tensor(Tensor::zeros([l, k, d], device)).set_require_grad(false),
        }
    }

    /// Codebook `layer` as `[K, D]`.
    fn codebook(&self, layer: usize) -> Tensor<2> {
        let [_, k, d] = self.codebooks.val().dims();
        self.codebooks
            .val()
            .narrow(0, layer, 1)
            .reshape([k, d])
            .detach()
    }

    /// Squared distance of each row of `x` (`[M, D]`) to each code (`[M, K]`).
    fn squared_distances(x: Tensor<2>, codebook: Tensor<2>) -> Tensor<2> {
        let x_sq = x.clone().powi_scalar(2).sum_dim(1); // [M, 1]
        let c_sq = codebook.clone().powi_scalar(2).sum_dim(1).transpose(); // [1, K]
        x_sq - x.matmul(codebook.transpose()) * 2.0 + c_sq
    }

    /// Index of the nearest code of each row of `x` (`[M, D]` → `[M]`).
    fn nearest(x: Tensor<2>, codebook: Tensor<2>) -> Tensor<1, Int> {
        let dist = Self::squared_distances(x, codebook);
        let [m, _] = dist.dims();
        dist.argmin(1).reshape([m])
    }

    /// Negative squared distances of each row of `x` (`[M, D]`) to the codes of `layer`
    /// (`[M, K]`): logits whose argmax is the code the layer would choose, with a gradient
    /// to `x` (the codebook is held).
    pub fn code_logits(&self, x: Tensor<2>, layer: usize) -> Tensor<2> {
        Self::squared_distances(x, self.codebook(layer)).neg()
    }

    /// Quantizes `z` (`[M, D]`) with the first `active` layers, `detail` (`[M, D]`, from
    /// detail encoders) joining what layer 0 leaves. Returns the summed code vectors (no
    /// gradient), the codes per layer (`[M]` each) and what each layer saw.
    pub fn quantize(
        &self,
        z: Tensor<2>,
        detail: Option<Tensor<2>>,
        active: usize,
    ) -> (Tensor<2>, Vec<LayerAssignment>) {
        let mut residual = z.detach();
        let mut total = residual.zeros_like();
        let mut layers = Vec::with_capacity(active);
        for layer in 0..active {
            let codebook = self.codebook(layer);
            let codes = Self::nearest(residual.clone(), codebook.clone());
            let q = codebook.select(0, codes.clone());
            layers.push(LayerAssignment {
                residuals: residual.clone(),
                codes,
            });
            residual = residual - q.clone();
            if let (0, Some(detail)) = (layer, &detail) {
                residual = residual + detail.clone().detach();
            }
            total = total + q;
        }
        (total, layers)
    }

    /// Sum of the code vectors of `tokens` (`[layers_used, M]`) → `[M, D]`.
    pub fn dequantize(&self, tokens: &[Tensor<1, Int>]) -> Tensor<2> {
        let mut total: Option<Tensor<2>> = None;
        for (layer, codes) in tokens.iter().enumerate() {
            let q = self.codebook(layer).select(0, codes.clone());
            total = Some(match total {
                None => q,
                Some(t) => t + q,
            });
        }
        total.expect("at least one token layer")
    }

    /// Moving-average codebook update from one step's assignments; codes that receive (on
    /// average) less than one vector are reset to random vectors of this batch, so no code
    /// stays dead. The first `held_layers` layers keep their codes and averages. Returns the
    /// number of codes reset.
    pub fn update(
        &mut self,
        assignments: &[LayerAssignment],
        decay: f64,
        held_layers: usize,
        rng: &mut Rng,
    ) -> usize {
        let [layers, k, d] = self.codebooks.val().dims();
        let device = self.codebooks.val().device();
        let mut books = Vec::with_capacity(layers);
        let mut counts_all = Vec::with_capacity(layers);
        let mut sums_all = Vec::with_capacity(layers);
        let mut reset = 0;
        for layer in 0..layers {
            let old_counts = self
                .ema_counts
                .val()
                .narrow(0, layer, 1)
                .reshape([k])
                .detach();
            let old_sums = self
                .ema_sums
                .val()
                .narrow(0, layer, 1)
                .reshape([k, d])
                .detach();
            let Some(a) = assignments.get(layer).filter(|_| layer >= held_layers) else {
                // Layer held, or unused this step (quantization dropout): keep it as it is.
                books.push(self.codebook(layer));
                counts_all.push(old_counts);
                sums_all.push(old_sums);
                continue;
            };
            let [m, _] = a.residuals.dims();
            let one_hot: Tensor<2> = a.codes.clone().one_hot::<2>(k).float(); // [M, K]
            let counts = one_hot.clone().sum_dim(0).reshape([k]);
            let sums = one_hot.transpose().matmul(a.residuals.clone()); // [K, D]
            let counts = old_counts * decay + counts * (1.0 - decay);
            let sums = old_sums * decay + sums * (1.0 - decay);
            let updated = sums.clone() / counts.clone().clamp_min(1e-5).reshape([k, 1]);

            let usage: Vec<f32> = counts.clone().try_into_vec_as::<f32>().unwrap_or_default();
            let alive: Vec<f32> = usage.iter().map(|c| (*c >= 1.0) as u8 as f32).collect();
            reset += alive.iter().filter(|a| **a == 0.0).count();
            let picks: Vec<i32> = (0..k).map(|_| rng.below(m) as i32).collect();
            let random = a.residuals.clone().select(
                0,
                Tensor::<1, Int>::from_data(TensorData::new(picks, [k]), &device),
            );
            let alive =
                Tensor::<1>::from_data(TensorData::new(alive, [k]), &device).reshape([k, 1]);
            let dead = alive.clone().neg() + 1.0;
            books.push(updated * alive.clone() + random.clone() * dead.clone());
            // A reset code starts its averages from the vector it was given.
            counts_all.push(counts * alive.clone().reshape([k]) + dead.clone().reshape([k]));
            sums_all.push(sums * alive + random * dead);
        }
        let stack3 = |v: Vec<Tensor<2>>| Tensor::stack::<3>(v, 0).detach();
        let (books, counts, sums) = (
            stack3(books),
            Tensor::stack::<2>(counts_all, 0).detach(),
            stack3(sums_all),
        );
        self.codebooks = self.codebooks.clone().map(|_| books);
        self.ema_counts = self.ema_counts.clone().map(|_| counts);
        self.ema_sums = self.ema_sums.clone().map(|_| sums);
        reset
    }
}

/// The whole VQ-VAE.
#[derive(Module, Debug)]
pub struct MotionVq {
    encoders: Vec<PartEncoder>,
    /// The detail encoders, one per part (see [`MotionVq::with_detail_encoders`]).
    detail: Option<Vec<PartEncoder>>,
    pub quantizers: Vec<ResidualQuantizer>,
    decoder: Decoder,
    /// Feature columns of each part, `[4]` index tensors kept as plain data.
    #[module(skip)]
    columns: Vec<Vec<usize>>,
    code_dim: usize,
    layers: usize,
}

/// Tokens of a batch of motions: per part (model order), per layer, `[B, N]` codes where
/// `N = T / 4`.
pub type PartTokens = Vec<Vec<Tensor<2, Int>>>;

/// Output of a training forward pass.
#[derive(Debug)]
pub struct VqTrainOutput {
    /// `[B, T, 263]` reconstruction.
    pub reconstruction: Tensor<3>,
    /// Mean squared distance between encoder outputs and their quantized values.
    pub commitment: Tensor<1>,
    /// Per part, what each active layer did (for the codebook update).
    pub assignments: Vec<Vec<LayerAssignment>>,
    /// Per part, the encoder's output as `[B·N, D]` rows (time-major within each motion),
    /// with its gradient: what [`MotionVq::base_code_loss`] pulls toward given codes.
    pub encodings: Vec<Tensor<2>>,
}

impl VqConfig {
    /// A VQ-VAE with random weights on `device`.
    pub fn init(&self, device: &Device) -> MotionVq {
        let columns: Vec<Vec<usize>> = BodyPart::ALL.iter().map(|p| part_columns(*p)).collect();
        MotionVq {
            encoders: columns
                .iter()
                .map(|c| PartEncoder::new(c.len(), self, device))
                .collect(),
            detail: None,
            quantizers: (0..4)
                .map(|_| ResidualQuantizer::new(self, device))
                .collect(),
            decoder: Decoder::new(self, device),
            columns,
            code_dim: self.code_dim,
            layers: self.layers,
        }
    }
}

impl MotionVq {
    /// Quantizer layers per part.
    pub fn layers(&self) -> usize {
        self.layers
    }

    /// Per part, the encoder output `[B, D, T/4]` for `x` `[B, T, 263]` (T a multiple of 4):
    /// what the quantizer's layers together approximate (with detail encoders, the sum of
    /// both encoders' outputs).
    pub fn encode(&self, x: Tensor<3>) -> Vec<Tensor<3>> {
        self.encode_split(x, false)
            .into_iter()
            .map(|(z, detail)| match detail {
                Some(d) => z + d,
                None => z,
            })
            .collect()
    }

    /// Per part, the first encoder's output (what layer 0 quantizes) and the detail
    /// encoder's, if the model has them. With `hold_base` the first encoders run without
    /// gradients.
    fn encode_split(&self, x: Tensor<3>, hold_base: bool) -> Vec<(Tensor<3>, Option<Tensor<3>>)> {
        let base = if hold_base {
            // As in `forward_decoder_train`: no graph for what no gradient reaches.
            let frozen: Vec<PartEncoder> = self.encoders.iter().map(|e| e.valid()).collect();
            self.encode_by(&frozen, x.clone().without_autodiff())
                .into_iter()
                .map(|z| z.autodiff())
                .collect()
        } else {
            self.encode_by(&self.encoders, x.clone())
        };
        let detail = match &self.detail {
            Some(encoders) => self.encode_by(encoders, x).into_iter().map(Some).collect(),
            None => vec![None; base.len()],
        };
        base.into_iter().zip(detail).collect()
    }

    /// Per part, `encoders`' output for that part's columns of `x`.
    fn encode_by(&self, encoders: &[PartEncoder], x: Tensor<3>) -> Vec<Tensor<3>> {
        let device = x.device();
        self.columns
            .iter()
            .zip(encoders)
            .map(|(cols, encoder)| {
                let idx: Vec<i32> = cols.iter().map(|c| *c as i32).collect();
                let idx = Tensor::<1, Int>::from_data(TensorData::new(idx, [cols.len()]), &device);
                encoder.forward(x.clone().select(2, idx).swap_dims(1, 2))
            })
            .collect()
    }

    /// This VQ-VAE with detail encoders added: a second encoder per part whose output joins
    /// the first's after layer 0, so layer 0 quantizes the first encoder's output alone and
    /// the residual layers the rest of the sum. Trained with the first encoders held, they
    /// let the residual layers learn new detail while every layer-0 token, the base
    /// transformer's vocabulary, stays exactly as it was. Each starts as a copy of its part's
    /// encoder whose output convolution is zero: the VQ-VAE reconstructs exactly as before
    /// until training moves them, from features that already describe the part.
    pub fn with_detail_encoders(mut self) -> MotionVq {
        /// New parameter ids for a copy: a clone shares its original's, and the optimizer
        /// would then move the original with the copy's gradients.
        struct FreshParams;
        impl burn::module::ModuleMapper for FreshParams {
            fn map_float<const D: usize>(&mut self, param: Param<Tensor<D>>) -> Param<Tensor<D>> {
                Param::from_tensor(param.val().detach())
            }
        }
        let copies = self
            .encoders
            .iter()
            .map(|encoder| {
                let mut copy = encoder.clone();
                copy.output.weight = copy.output.weight.map(|w| w.zeros_like());
                copy.output.bias = copy.output.bias.map(|b| b.map(|b| b.zeros_like()));
                // After the zeroing, which leaves a constant: these are trainable.
                copy.map(&mut FreshParams)
            })
            .collect();
        self.detail = Some(copies);
        self
    }

    /// `[B, D, N]` → `[B·N, D]` rows, time-major within each motion.
    fn rows(z: Tensor<3>) -> Tensor<2> {
        let [b, d, n] = z.dims();
        z.swap_dims(1, 2).reshape([b * n, d])
    }

    /// `[B·N, D]` rows → `[B, D, N]`.
    fn unrows(q: Tensor<2>, b: usize, n: usize) -> Tensor<3> {
        let [_, d] = q.dims();
        q.reshape([b, n, d]).swap_dims(1, 2)
    }

    /// Training pass: encode, quantize (with quantization dropout drawn from `rng`), decode
    /// with straight-through gradients. `real_frames` gives, per motion, how many of its
    /// leading frames are its own (the rest pad a short clip by holding its last frame); the
    /// commitment and the codebook averages then count only tokens that start on a real
    /// frame, so padding's still poses do not pull the codes. `None`: every frame is real.
    /// With `hold_base`, the first encoders run without gradients: they, and so every
    /// layer-0 token, stay as they are (hold codebook 0 in `update_codebooks` too).
    pub fn forward_train(
        &self,
        x: Tensor<3>,
        real_frames: Option<&[usize]>,
        config: &VqConfig,
        hold_base: bool,
        rng: &mut Rng,
    ) -> VqTrainOutput {
        let active = if (rng.uniform() as f64) < config.quantize_dropout {
            1 + rng.below(self.layers)
        } else {
            self.layers
        };
        let device = x.device();
        let [_, frames, _] = x.dims();
        // Rows are time-major within each motion (see `rows`); `None` when all are real.
        let real_rows = real_frames
            .filter(|real| real.iter().any(|&r| r < frames))
            .map(|real| {
                let n = frames / 4;
                let rows: Vec<i32> = real
                    .iter()
                    .enumerate()
                    .flat_map(|(b, &r)| (0..n.min(r.div_ceil(4))).map(move |t| (b * n + t) as i32))
                    .collect();
                let len = rows.len();
                Tensor::<1, Int>::from_data(TensorData::new(rows, [len]), &device)
            });
        let keep = |t: Tensor<2>| match &real_rows {
            Some(rows) => t.select(0, rows.clone()),
            None => t,
        };
        let mut parts = Vec::with_capacity(4);
        let mut commitment: Option<Tensor<1>> = None;
        let mut assignments = Vec::with_capacity(4);
        let mut encodings = Vec::with_capacity(4);
        let encoded = self.encode_split(x, hold_base);
        for ((z, detail), quantizer) in encoded.into_iter().zip(&self.quantizers) {
            let [b, _, n] = z.dims();
            let base = Self::rows(z);
            let detail = detail.map(Self::rows);
            encodings.push(base.clone());
            let rows = match &detail {
                Some(d) => base.clone() + d.clone(),
                None => base.clone(),
            };
            let (q, layers) = quantizer.quantize(base, detail, active);
            let layers = layers
                .into_iter()
                .map(|a| LayerAssignment {
                    residuals: keep(a.residuals),
                    codes: match &real_rows {
                        Some(rows) => a.codes.select(0, rows.clone()),
                        None => a.codes,
                    },
                })
                .collect();
            let c = (keep(rows.clone()) - keep(q.clone())).powi_scalar(2).mean();
            commitment = Some(match commitment {
                None => c,
                Some(t) => t + c,
            });
            // Straight-through: the decoder sees q, the encoder gets the decoder's gradient.
            let st = rows.clone() + (q - rows).detach();
            parts.push(Self::unrows(st, b, n));
            assignments.push(layers);
        }
        let reconstruction = self.decoder.forward(Tensor::cat(parts, 1)).swap_dims(1, 2);
        VqTrainOutput {
            reconstruction,
            commitment: commitment.expect("four parts") / 4.0,
            assignments,
            encodings,
        }
    }

    /// How far the encoder's outputs (`encodings`, per part `[M, D]` rows) are from choosing
    /// the layer-0 codes `targets` (per part `[M]`): the cross-entropy of their distances to
    /// codebook 0, which vanishes once each output sits well inside its target's cell, and
    /// the share of rows that already choose their target. With codebook 0 held, it lets the
    /// encoder learn while every layer-0 token, the base transformer's vocabulary, stays.
    pub fn base_code_loss(
        &self,
        encodings: &[Tensor<2>],
        targets: &[Tensor<1, Int>],
    ) -> (Tensor<1>, f64) {
        let (mut loss, mut kept, mut rows) = (None::<Tensor<1>>, 0usize, 0usize);
        for ((z, target), quantizer) in encodings.iter().zip(targets).zip(&self.quantizers) {
            let logits = quantizer.code_logits(z.clone(), 0);
            let [m, _] = logits.dims();
            let chosen = logits.clone().argmax(1).reshape([m]);
            kept += chosen
                .equal(target.clone())
                .int()
                .sum()
                .into_scalar::<i64>() as usize;
            rows += m;
            let part = burn::nn::loss::CrossEntropyLossConfig::new()
                .init(&z.device())
                .forward(logits, target.clone());
            loss = Some(match loss {
                None => part,
                Some(sum) => sum + part,
            });
        }
        (
            loss.expect("four parts") / encodings.len() as f64,
            kept as f64 / rows.max(1) as f64,
        )
    }

    /// The reconstruction of `x` `[B, T, 263]` from its first `layers` token layers, with the
    /// encoder and the codebooks held as they are: gradients reach the decoder alone. It
    /// fine-tunes a decoder for motions generated with fewer layers than the VQ-VAE has (a
    /// base-only model decodes layer 0 alone), without changing any token.
    #[cfg(feature = "train")]
    pub fn forward_decoder_train(&self, x: Tensor<3>, layers: usize) -> Tensor<3> {
        // The encoder and the codebooks run without autodiff: a graph that no loss flows back
        // through is never freed, and it filled 24 GiB in a few hundred steps.
        let frozen = self.valid();
        let parts: Vec<Tensor<3>> = frozen
            .encode_split(x.without_autodiff(), false)
            .into_iter()
            .zip(&frozen.quantizers)
            .map(|((z, detail), quantizer)| {
                let [b, _, n] = z.dims();
                let (q, _) = quantizer.quantize(Self::rows(z), detail.map(Self::rows), layers);
                Self::unrows(q, b, n).autodiff()
            })
            .collect();
        self.decoder.forward(Tensor::cat(parts, 1)).swap_dims(1, 2)
    }

    /// The shared decoder (what [`MotionVq::forward_decoder_train`] trains).
    pub fn decoder(&self) -> &Decoder {
        &self.decoder
    }

    /// Tokens of `x` `[B, T, 263]` with every layer.
    pub fn tokenize(&self, x: Tensor<3>) -> PartTokens {
        self.encode_split(x, false)
            .into_iter()
            .zip(&self.quantizers)
            .map(|((z, detail), quantizer)| {
                let [b, _, n] = z.dims();
                let (_, layers) =
                    quantizer.quantize(Self::rows(z), detail.map(Self::rows), self.layers);
                layers
                    .into_iter()
                    .map(|a| a.codes.reshape([b, n]))
                    .collect()
            })
            .collect()
    }

    /// Tokens `[part][layer][step]` of one normalised motion, cut to a multiple of 4 frames
    /// (a motion shorter than 4 frames is padded with zeros, the mean pose).
    pub fn tokenize_motion(
        &self,
        features: &[crate::features::FeatureFrame],
        device: &Device,
    ) -> Vec<Vec<Vec<u32>>> {
        let t = (features.len() / FRAMES_PER_TOKEN * FRAMES_PER_TOKEN).max(FRAMES_PER_TOKEN);
        let mut flat: Vec<f32> = features.iter().take(t).flatten().copied().collect();
        flat.resize(t * FEATURE_DIM, 0.0);
        let x = Tensor::<3>::from_data(TensorData::new(flat, [1, t, FEATURE_DIM]), device);
        self.tokenize(x)
            .into_iter()
            .map(|layers| {
                layers
                    .into_iter()
                    .map(|l| {
                        l.try_into_vec_as::<i64>()
                            .expect("int tokens")
                            .into_iter()
                            .map(|v| v as u32)
                            .collect()
                    })
                    .collect()
            })
            .collect()
    }

    /// Features `[B, 4N, 263]` from tokens (each part may use its first few layers only).
    pub fn decode(&self, tokens: &PartTokens) -> Tensor<3> {
        let parts: Vec<Tensor<3>> = tokens
            .iter()
            .zip(&self.quantizers)
            .map(|(layers, quantizer)| {
                let [b, n] = layers[0].dims();
                let flat: Vec<Tensor<1, Int>> =
                    layers.iter().map(|t| t.clone().reshape([b * n])).collect();
                Self::unrows(quantizer.dequantize(&flat), b, n)
            })
            .collect();
        self.decoder.forward(Tensor::cat(parts, 1)).swap_dims(1, 2)
    }

    /// The decoder applied to the encoder's output itself, unquantized: the reconstruction
    /// that ever more residual layers approach, so its error bounds what adding layers can
    /// gain (a diagnostic; no token sequence decodes to it).
    pub fn reconstruct_unquantized(&self, x: Tensor<3>) -> Tensor<3> {
        self.decoder
            .forward(Tensor::cat(self.encode(x), 1))
            .swap_dims(1, 2)
    }

    /// Encodes and decodes `x` with every layer (inference reconstruction).
    pub fn reconstruct(&self, x: Tensor<3>) -> Tensor<3> {
        self.decode(&self.tokenize(x))
    }

    /// Moving-average update of every codebook after a training step, the first
    /// `held_layers` layers of each part left as they are. Returns codes reset.
    pub fn update_codebooks(
        &mut self,
        assignments: &[Vec<LayerAssignment>],
        decay: f64,
        held_layers: usize,
        rng: &mut Rng,
    ) -> usize {
        self.quantizers
            .iter_mut()
            .zip(assignments)
            .map(|(q, a)| q.update(a, decay, held_layers, rng))
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> VqConfig {
        VqConfig::new()
            .with_encoder_width(16)
            .with_decoder_width(16)
            .with_code_dim(8)
            .with_codebook_size(32)
            .with_layers(3)
            .with_res_blocks(1)
    }

    fn motion(b: usize, t: usize, device: &Device) -> Tensor<3> {
        Tensor::random([b, t, FEATURE_DIM], Distribution::Normal(0.0, 1.0), device)
    }

    #[test]
    fn shapes_of_tokens_and_reconstruction() {
        let device = Device::flex();
        let vq = small().init(&device);
        let x = motion(2, 24, &device);
        let tokens = vq.tokenize(x.clone());
        assert_eq!(tokens.len(), 4);
        assert_eq!(tokens[0].len(), 3);
        assert_eq!(tokens[2][1].dims(), [2, 6]);
        assert_eq!(vq.decode(&tokens).dims(), [2, 24, FEATURE_DIM]);
        let codes: Vec<i64> = tokens[1][0].clone().try_into_vec_as::<i64>().unwrap();
        assert!(codes.iter().all(|c| (0..32).contains(c)));
    }

    #[test]
    fn quantizing_a_code_vector_returns_that_code() {
        let device = Device::flex();
        let vq = small().init(&device);
        let book = vq.quantizers[0].codebook(0);
        let picks = Tensor::<1, Int>::from_data(TensorData::new(vec![3i32, 17, 3], [3]), &device);
        let x = book.select(0, picks);
        let (_, layers) = vq.quantizers[0].quantize(x, None, 1);
        let codes: Vec<i64> = layers[0].codes.clone().try_into_vec_as::<i64>().unwrap();
        assert_eq!(codes, vec![3, 17, 3]);
    }

    #[test]
    fn the_unquantized_reconstruction_does_not_depend_on_the_codebooks() {
        let device = Device::flex();
        let config = small().with_quantize_dropout(0.0);
        let mut vq = config.init(&device);
        let x = motion(2, 16, &device);
        let (plain, coded) = (
            vq.reconstruct_unquantized(x.clone()),
            vq.reconstruct(x.clone()),
        );
        assert_eq!(plain.dims(), [2, 16, FEATURE_DIM]);
        // Decay 0 replaces every used code by the mean of what it quantized.
        let mut rng = Rng::new(3);
        let out = vq.forward_train(x.clone(), None, &config, false, &mut rng);
        vq.update_codebooks(&out.assignments, 0.0, 0, &mut rng);
        let gap = |a: Tensor<3>, b: Tensor<3>| (a - b).abs().max().into_scalar::<f32>();
        assert!(gap(vq.reconstruct_unquantized(x.clone()), plain) < 1e-6);
        assert!(gap(vq.reconstruct(x), coded) > 1e-4, "the codes moved");
    }

    #[test]
    fn padded_tokens_neither_commit_nor_move_the_codebooks() {
        let device = Device::flex();
        let config = small().with_quantize_dropout(0.0);
        let vq = config.init(&device);
        let x = motion(2, 16, &device);
        let mut rng = Rng::new(5);
        // Motion 0 is whole; motion 1 has 5 real frames: tokens 0 and 1 start on real frames.
        let out = vq.forward_train(x.clone(), Some(&[16, 5]), &config, false, &mut rng);
        for part in &out.assignments {
            assert_eq!(part.len(), 3);
            for layer in part {
                assert_eq!(layer.codes.dims(), [4 + 2]);
                assert_eq!(layer.residuals.dims(), [6, 8]);
            }
        }
        assert_eq!(out.reconstruction.dims(), [2, 16, FEATURE_DIM]);
        // Whole motions, said or not, quantize every token.
        for real in [None, Some(&[16, 16][..])] {
            let out = vq.forward_train(x.clone(), real, &config, false, &mut rng);
            assert_eq!(out.assignments[0][0].codes.dims(), [8]);
        }
    }

    #[test]
    fn training_step_reduces_the_loss_and_updates_codebooks() {
        let device = Device::flex().autodiff();
        let config = small();
        let mut vq = config.init(&device);
        let mut optim = burn::optim::AdamConfig::new().init();
        let mut rng = Rng::new(1);
        // Smooth signals, like motion features, rather than white noise.
        let values: Vec<f32> = (0..4 * 16 * FEATURE_DIM)
            .map(|i| {
                let (b, t, c) = (
                    i / (16 * FEATURE_DIM),
                    (i / FEATURE_DIM) % 16,
                    i % FEATURE_DIM,
                );
                (t as f32 * 0.3 + c as f32 * 0.7 + b as f32).sin()
            })
            .collect();
        let x = Tensor::<3>::from_data(TensorData::new(values, [4, 16, FEATURE_DIM]), &device);
        let before = vq.quantizers[0]
            .codebooks
            .val()
            .try_into_vec_as::<f32>()
            .unwrap();
        let mut losses: Vec<f32> = Vec::new();
        for _ in 0..40 {
            let out = vq.forward_train(
                x.clone(),
                None,
                &config.clone().with_quantize_dropout(0.0),
                false,
                &mut rng,
            );
            let loss = (out.reconstruction - x.clone()).abs().mean() + out.commitment * 0.02;
            losses.push(loss.clone().into_scalar::<f32>());
            let grads = burn::optim::GradientsParams::from_grads(loss.backward(), &vq);
            vq = optim.step(3e-3, vq, grads);
            vq.update_codebooks(&out.assignments, config.ema_decay, 0, &mut rng);
        }
        let late = losses[35..].iter().sum::<f32>() / 5.0;
        assert!(late < losses[0] * 0.8, "{losses:?}");
        let after = vq.quantizers[0]
            .codebooks
            .val()
            .try_into_vec_as::<f32>()
            .unwrap();
        assert_ne!(before, after, "codebooks move by moving averages");
    }

    #[test]
    fn decoder_training_moves_the_decoder_and_keeps_every_token() {
        let device = Device::flex().autodiff();
        let config = small();
        let mut vq = config.init(&device);
        let mut optim = burn::optim::AdamConfig::new().init();
        let x = motion(2, 16, &device);
        let tokens = |vq: &MotionVq| -> Vec<i64> {
            vq.tokenize(x.clone())
                .iter()
                .flatten()
                .flat_map(|t| t.clone().try_into_vec_as::<i64>().unwrap())
                .collect()
        };
        let (first_tokens, first_decode) = (tokens(&vq), vq.reconstruct(x.clone()));
        let mut losses = Vec::new();
        for _ in 0..20 {
            let loss = (vq.forward_decoder_train(x.clone(), 1) - x.clone())
                .abs()
                .mean();
            losses.push(loss.clone().into_scalar::<f32>());
            let mut gradients = loss.backward();
            let grads = burn::optim::GradientsParams::from_module(&mut gradients, vq.decoder());
            vq = optim.step(3e-3, vq, grads);
        }
        assert!(losses[19] < losses[0], "{losses:?}");
        assert_eq!(tokens(&vq), first_tokens, "the encoder and codebooks stay");
        let moved = (vq.reconstruct(x.clone()) - first_decode).abs().max();
        assert!(moved.into_scalar::<f32>() > 1e-4, "the decoder changed");
    }

    #[test]
    fn the_base_code_loss_is_low_on_its_targets_and_counts_what_is_kept() {
        let device = Device::flex();
        let vq = small().init(&device);
        let codes = [3i32, 17, 9, 3];
        let picks = Tensor::<1, Int>::from_data(TensorData::new(codes.to_vec(), [4]), &device);
        let on_codes: Vec<Tensor<2>> = vq
            .quantizers
            .iter()
            .map(|q| q.codebook(0).select(0, picks.clone()))
            .collect();
        let targets = |codes: [i32; 4]| -> Vec<Tensor<1, Int>> {
            (0..4)
                .map(|_| Tensor::from_data(TensorData::new(codes.to_vec(), [4]), &device))
                .collect()
        };
        let (right, kept) = vq.base_code_loss(&on_codes, &targets(codes));
        let (wrong, none) = vq.base_code_loss(&on_codes, &targets([5, 6, 7, 8]));
        assert_eq!((kept, none), (1.0, 0.0));
        let (right, wrong) = (right.into_scalar::<f32>(), wrong.into_scalar::<f32>());
        // How low depends on how far apart the randomly initialised codes lie (the test
        // failed now and then on fixed bounds); lower on its targets than on others it is.
        assert!(right < wrong && right.is_finite(), "{right} {wrong}");
    }

    #[test]
    fn holding_layer_0_keeps_its_codes_while_the_rest_learns() {
        let device = Device::flex().autodiff();
        let config = small().with_quantize_dropout(0.0);
        let mut vq = config.init(&device);
        let anchor = vq.valid();
        let mut optim = burn::optim::AdamConfig::new().init();
        let mut rng = Rng::new(7);
        let x = motion(4, 16, &device);
        let books = |vq: &MotionVq, layer: usize| -> Vec<f32> {
            vq.quantizers[1]
                .codebook(layer)
                .try_into_vec_as::<f32>()
                .unwrap()
        };
        let layer0 = |vq: &MotionVq| -> Vec<Vec<i64>> {
            vq.valid()
                .tokenize(x.clone().without_autodiff())
                .into_iter()
                .map(|layers| layers[0].clone().try_into_vec_as::<i64>().unwrap())
                .collect()
        };
        let (first0, first1, first_codes) = (books(&vq, 0), books(&vq, 1), layer0(&vq));
        let first_encoding = vq.encode(x.clone())[0].clone();
        for _ in 0..30 {
            let out = vq.forward_train(x.clone(), None, &config, false, &mut rng);
            let targets: Vec<Tensor<1, Int>> = anchor
                .tokenize(x.clone().without_autodiff())
                .into_iter()
                .map(|layers| {
                    Tensor::from_data(layers[0].clone().reshape([16]).into_data(), &device)
                })
                .collect();
            let (base, _) = vq.base_code_loss(&out.encodings, &targets);
            let loss = (out.reconstruction - x.clone()).abs().mean() + base;
            let grads = burn::optim::GradientsParams::from_grads(loss.backward(), &vq);
            vq = optim.step(3e-3, vq, grads);
            vq.update_codebooks(&out.assignments, config.ema_decay, 1, &mut rng);
        }
        assert_eq!(books(&vq, 0), first0, "codebook 0 is held");
        assert_ne!(books(&vq, 1), first1, "codebook 1 learns");
        let moved = (vq.encode(x.clone())[0].clone() - first_encoding)
            .abs()
            .max();
        assert!(moved.into_scalar::<f32>() > 1e-3, "the encoder learns");
        let (now, first) = (layer0(&vq).concat(), first_codes.concat());
        let same = now.iter().zip(&first).filter(|(a, b)| a == b).count();
        let kept = same as f64 / now.len() as f64;
        assert!(kept >= 0.9, "layer-0 codes kept: {kept}");
    }

    #[test]
    fn detail_encoders_start_as_the_model_and_learn_while_layer_0_stays() {
        let device = Device::flex().autodiff();
        let config = small().with_quantize_dropout(0.0);
        let plain = config.init(&device);
        let x = motion(2, 16, &device);
        let layer0 = |vq: &MotionVq| -> Vec<i64> {
            vq.tokenize(x.clone())
                .iter()
                .flat_map(|layers| layers[0].clone().try_into_vec_as::<i64>().unwrap())
                .collect()
        };
        let gap = |a: Tensor<3>, b: Tensor<3>| (a - b).abs().max().into_scalar::<f32>();
        let mut vq = plain.clone().with_detail_encoders();
        assert!(gap(vq.reconstruct(x.clone()), plain.reconstruct(x.clone())) < 1e-6);
        let first = layer0(&vq);
        let mut optim = burn::optim::AdamConfig::new().init();
        let mut rng = Rng::new(11);
        let mut losses = Vec::new();
        for _ in 0..30 {
            let out = vq.forward_train(x.clone(), None, &config, true, &mut rng);
            let loss = (out.reconstruction - x.clone()).abs().mean() + out.commitment * 0.02;
            losses.push(loss.clone().into_scalar::<f32>());
            let grads = burn::optim::GradientsParams::from_grads(loss.backward(), &vq);
            vq = optim.step(3e-3, vq, grads);
            vq.update_codebooks(&out.assignments, config.ema_decay, 1, &mut rng);
        }
        assert!(losses[29] < losses[0], "{losses:?}");
        assert_eq!(layer0(&vq), first, "no layer-0 token moves");
        let (base, whole) = (plain.encode(x.clone()), vq.encode(x.clone()));
        assert!(
            gap(base[0].clone(), whole[0].clone()) > 1e-3,
            "the detail encoders learn"
        );
    }
}
