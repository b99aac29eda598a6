//! The text–motion evaluator: a contrastive pair of encoders in the style of TMR, mapping a
//! motion and a sentence into one space where matching pairs lie close. It measures
//! generated motions (FID, R-precision, MM-Dist, …) and scores how well a motion fits a
//! prompt for the reviewer; it never generates.
//!
//! ```text
//!  features [B, T, 263] (normalised, 20 fps)
//!     │ patches of 4 frames (0.2 s) ─► Linear ─► [B, T/4, W]
//!     │ [CLS] in front, + time embeddings
//!     ▼
//!  TransformerEncoder (padding masked) ─► CLS state ─► LayerNorm ─► Linear ─► unit vector [B, E]
//!
//!  MiniLM sentence embedding [B, 384] ─► Linear ─► GELU ─► Linear ─► unit vector [B, E]
//! ```
//!
//! Both sides end on the unit sphere, so cosine similarity is a dot product and the
//! Euclidean distances of the field's metrics lie in [0, 2].
//!
//! Weights (`evaluator.bpk`, with its sizes in `evaluator.json`): training saves f32 (a burn
//! `ModuleRecord`, a burnpack); `coma export evaluator` rounds every float parameter to f16,
//! or with `--bits` quantizes the matrices ([`Evaluator::to_shipped_bytes`]; the shipped file
//! is 8-bit, 2.0 MB for 2.0 M parameters), and reports what that changes on the test split
//! (`eval::agreement`). Loading takes any of them and computes in f32.

use crate::features::{FeatureFrame, FEATURE_DIM};
use crate::model::transformer::TEXT_DIM;
use burn::module::Param;
use burn::nn::transformer::{
    TransformerEncoder, TransformerEncoderConfig, TransformerEncoderInput,
};
use burn::nn::{Embedding, EmbeddingConfig, LayerNorm, LayerNormConfig, Linear, LinearConfig};
use burn::prelude::*;
use burn::tensor::activation::gelu;
use burn::tensor::{Bool, Distribution, Int, TensorData};

/// Sizes of the evaluator.
#[derive(Config, Debug)]
pub struct EvaluatorConfig {
    /// Frames per input step of the motion encoder (4 frames = 0.2 s).
    #[config(default = 4)]
    pub patch: usize,
    /// Width of the motion transformer.
    #[config(default = 192)]
    pub width: usize,
    #[config(default = 4)]
    pub depth: usize,
    #[config(default = 4)]
    pub heads: usize,
    #[config(default = 512)]
    pub ff_width: usize,
    /// Hidden width of the text projection.
    #[config(default = 512)]
    pub text_hidden: usize,
    /// Dimension of the joint embedding space.
    #[config(default = 256)]
    pub embedding: usize,
    #[config(default = 0.1)]
    pub dropout: f64,
    /// Longest motion in patches (200 frames at 4 frames a patch); longer motions are
    /// centre-cropped.
    #[config(default = 50)]
    pub max_patches: usize,
}

impl EvaluatorConfig {
    /// Longest motion the encoder reads, in frames.
    pub fn max_frames(&self) -> usize {
        self.max_patches * self.patch
    }

    pub fn init(&self, device: &Device) -> Evaluator {
        let w = self.width;
        Evaluator {
            motion: MotionEncoder {
                input: LinearConfig::new(self.patch * FEATURE_DIM, w).init(device),
                cls: Param::from_tensor(Tensor::random(
                    [w],
                    Distribution::Normal(0.0, 0.02),
                    device,
                )),
                time: EmbeddingConfig::new(self.max_patches + 1, w).init(device),
                encoder: TransformerEncoderConfig::new(w, self.ff_width, self.heads, self.depth)
                    .with_dropout(self.dropout)
                    .with_norm_first(true)
                    .init(device),
                norm: LayerNormConfig::new(w).init(device),
                output: LinearConfig::new(w, self.embedding).init(device),
                patch: self.patch,
            },
            text: TextProjection {
                hidden: LinearConfig::new(TEXT_DIM, self.text_hidden).init(device),
                output: LinearConfig::new(self.text_hidden, self.embedding).init(device),
            },
        }
    }
}

/// Scales each row to unit length.
fn unit_rows(x: Tensor<2>) -> Tensor<2> {
    let norm = x.clone().powf_scalar(2.0).sum_dim(1).sqrt().clamp_min(1e-6);
    x / norm
}

/// The motion side: normalised features to a unit embedding.
#[derive(Module, Debug)]
pub struct MotionEncoder {
    input: Linear,
    cls: Param<Tensor<1>>,
    time: Embedding,
    encoder: TransformerEncoder,
    norm: LayerNorm,
    output: Linear,
    patch: usize,
}

impl MotionEncoder {
    /// `features` `[B, T, 263]` with T a multiple of the patch length; `pad` `[B, T/patch]`
    /// true where a patch lies after the end of a shorter motion. Returns `[B, E]` unit rows.
    pub fn forward(&self, features: Tensor<3>, pad: Tensor<2, Bool>) -> Tensor<2> {
        let [b, t, f] = features.dims();
        let device = features.device();
        let s = t / self.patch;
        let x = self.input.forward(features.reshape([b, s, self.patch * f]));
        let w = x.dims()[2];
        let cls = self.cls.val().reshape([1, 1, w]).expand([b, 1, w]);
        let x = Tensor::cat(vec![cls, x], 1);
        let steps = Tensor::<1, Int>::arange(0..(s as i64 + 1), &device).reshape([1, s + 1]);
        let x = x + self.time.forward(steps);
        let cls_pad = Tensor::<2, Int>::zeros([b, 1], &device).equal_elem(1);
        let pad = Tensor::cat(vec![cls_pad, pad], 1);
        let h = self
            .encoder
            .forward(TransformerEncoderInput::new(x).mask_pad(pad));
        let first = h.narrow(1, 0, 1).reshape([b, w]);
        unit_rows(self.output.forward(self.norm.forward(first)))
    }
}

/// The text side: a MiniLM sentence embedding to a unit embedding.
#[derive(Module, Debug)]
pub struct TextProjection {
    hidden: Linear,
    output: Linear,
}

impl TextProjection {
    /// `sentences` `[B, 384]` MiniLM embeddings → `[B, E]` unit rows.
    pub fn forward(&self, sentences: Tensor<2>) -> Tensor<2> {
        unit_rows(self.output.forward(gelu(self.hidden.forward(sentences))))
    }
}

/// Both encoders.
#[derive(Module, Debug)]
pub struct Evaluator {
    pub motion: MotionEncoder,
    pub text: TextProjection,
}

/// A batch of motions as the motion encoder reads them: cropped to at most `max_frames`
/// (centred, or at `starts` when given), cut to whole patches and padded to the longest.
pub fn motion_batch(
    config: &EvaluatorConfig,
    motions: &[&[FeatureFrame]],
    starts: Option<&[usize]>,
    device: &Device,
) -> (Tensor<3>, Tensor<2, Bool>) {
    let max = config.max_frames();
    let crops: Vec<&[FeatureFrame]> = motions
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let len = m.len().min(max) / config.patch * config.patch;
            let len = len.max(config.patch.min(m.len()));
            let start = starts.map_or((m.len() - len) / 2, |s| s[i].min(m.len() - len));
            &m[start..start + len]
        })
        .collect();
    let patches: Vec<usize> = crops
        .iter()
        .map(|c| c.len().div_ceil(config.patch))
        .collect();
    let s = patches.iter().copied().max().unwrap_or(1).max(1);
    let t = s * config.patch;
    let mut data = Vec::with_capacity(motions.len() * t * FEATURE_DIM);
    let mut pad = Vec::with_capacity(motions.len() * s);
    for (crop, n) in crops.iter().zip(&patches) {
        for row in *crop {
            data.extend_from_slice(row);
        }
        // A motion shorter than one patch repeats its last frame to fill it.
        let last = crop.last().copied().unwrap_or([0.0; FEATURE_DIM]);
        for _ in crop.len()..n * config.patch {
            data.extend_from_slice(&last);
        }
        data.extend(std::iter::repeat_n(
            0.0,
            (t - n * config.patch) * FEATURE_DIM,
        ));
        pad.extend((0..s).map(|i| (i >= *n) as i32));
    }
    let b = motions.len();
    (
        Tensor::from_data(TensorData::new(data, [b, t, FEATURE_DIM]), device),
        Tensor::<2, Int>::from_data(TensorData::new(pad, [b, s]), device).equal_elem(1),
    )
}

/// Rows of a `[B, E]` tensor.
fn rows(x: Tensor<2>) -> Vec<Vec<f32>> {
    let [_, e] = x.dims();
    let flat: Vec<f32> = x.try_into_vec_as::<f32>().expect("evaluator output is f32");
    flat.chunks(e).map(<[f32]>::to_vec).collect()
}

impl Evaluator {
    /// Embeddings of motions (normalised features), in batches of similar length.
    pub fn embed_motions(
        &self,
        config: &EvaluatorConfig,
        motions: &[&[FeatureFrame]],
        device: &Device,
    ) -> Vec<Vec<f32>> {
        let mut order: Vec<usize> = (0..motions.len()).collect();
        order.sort_by_key(|&i| motions[i].len());
        let mut out = vec![Vec::new(); motions.len()];
        for chunk in order.chunks(32) {
            let batch: Vec<&[FeatureFrame]> = chunk.iter().map(|&i| motions[i]).collect();
            let (x, pad) = motion_batch(config, &batch, None, device);
            for (&i, row) in chunk.iter().zip(rows(self.motion.forward(x, pad))) {
                out[i] = row;
            }
        }
        out
    }

    /// Embeddings of MiniLM sentence embeddings.
    pub fn embed_texts(&self, sentences: &[[f32; TEXT_DIM]], device: &Device) -> Vec<Vec<f32>> {
        sentences
            .chunks(256)
            .flat_map(|chunk| {
                let flat: Vec<f32> = chunk.iter().flatten().copied().collect();
                let x = Tensor::from_data(TensorData::new(flat, [chunk.len(), TEXT_DIM]), device);
                rows(self.text.forward(x))
            })
            .collect()
    }
}

/// Why the evaluator could not be loaded.
#[derive(Debug, thiserror::Error)]
#[error("{file}: {message}")]
pub struct EvaluatorLoadError {
    pub file: String,
    pub message: String,
}

impl Evaluator {
    /// The evaluator from the contents of `evaluator.json` and `evaluator.bpk` (no file
    /// system, so it works in the page). The weights may be f32, f16 or quantized; all are widened
    /// to f32.
    pub fn from_bytes(
        config: &str,
        weights: &[u8],
        device: &Device,
    ) -> Result<(Evaluator, EvaluatorConfig), EvaluatorLoadError> {
        let error = |file: &str, message: String| EvaluatorLoadError {
            file: file.to_string(),
            message,
        };
        let config: EvaluatorConfig =
            serde_json::from_str(config).map_err(|e| error("evaluator.json", e.to_string()))?;
        let model = crate::weights::load_into(config.init(device), weights)
            .map_err(|e| error("evaluator.bpk", e))?;
        Ok((model, config))
    }

    /// Loads `evaluator.json` (its sizes) and `evaluator.bpk` from a folder (the default one
    /// lives in `static/models`).
    pub fn load(
        dir: &std::path::Path,
        device: &Device,
    ) -> Result<(Evaluator, EvaluatorConfig), EvaluatorLoadError> {
        let config_path = dir.join("evaluator.json");
        let config = EvaluatorConfig::load(&config_path).map_err(|e| EvaluatorLoadError {
            file: config_path.display().to_string(),
            message: e.to_string(),
        })?;
        let model = Self::load_weights(&config, &dir.join("evaluator.bpk"), device)?;
        Ok((model, config))
    }

    /// Loads weights of the sizes `config` from a burnpack file (f32 as training saves them,
    /// or f16 or quantized as [`Self::to_shipped_bytes`] writes them; computing is f32 either
    /// way).
    pub fn load_weights(
        config: &EvaluatorConfig,
        weights: &std::path::Path,
        device: &Device,
    ) -> Result<Evaluator, EvaluatorLoadError> {
        let error = |message: String| EvaluatorLoadError {
            file: weights.display().to_string(),
            message,
        };
        let bytes = std::fs::read(weights).map_err(|e| error(e.to_string()))?;
        crate::weights::load_into(config.init(device), &bytes).map_err(error)
    }

    /// `evaluator.bpk` for shipping: every float rounded to f16, and with `bits` the large
    /// tensors quantized (see [`crate::weights`]); without parameter ids, so the same weights
    /// always give the same bytes. [`Self::from_bytes`] and [`Self::load`] read it back as
    /// f32.
    pub fn to_shipped_bytes(&self, bits: Option<crate::quant::Bits>) -> anyhow::Result<Vec<u8>> {
        crate::weights::shipped_bytes(self, &|_| bits, &[])
    }
}

/// Cosine similarity of two unit embeddings as a 0–100 score (as CoMA's motion–text
/// alignment): 100 · max(cos, 0).
pub fn alignment_score(text: &[f32], motion: &[f32]) -> f64 {
    let cos: f64 = text
        .iter()
        .zip(motion)
        .map(|(a, b)| *a as f64 * *b as f64)
        .sum();
    100.0 * cos.clamp(0.0, 1.0)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn tiny() -> EvaluatorConfig {
        EvaluatorConfig::new()
            .with_width(16)
            .with_depth(1)
            .with_heads(2)
            .with_ff_width(32)
            .with_text_hidden(24)
            .with_embedding(8)
            .with_max_patches(6)
    }

    pub(crate) fn motion(frames: usize, value: f32) -> Vec<FeatureFrame> {
        (0..frames)
            .map(|t| [value + t as f32 * 0.01; FEATURE_DIM])
            .collect()
    }

    #[test]
    fn embeddings_are_unit_vectors_whatever_the_length() {
        let cfg = tiny();
        let device = Device::flex();
        let model = cfg.init(&device);
        let motions = [motion(3, 0.1), motion(17, 0.2), motion(40, -0.3)];
        let refs: Vec<&[FeatureFrame]> = motions.iter().map(Vec::as_slice).collect();
        let m = model.embed_motions(&cfg, &refs, &device);
        let t = model.embed_texts(&[[0.1; TEXT_DIM], [0.2; TEXT_DIM]], &device);
        assert_eq!(m.len(), 3);
        assert_eq!(t.len(), 2);
        for row in m.iter().chain(&t) {
            assert_eq!(row.len(), 8);
            let norm: f32 = row.iter().map(|x| x * x).sum::<f32>().sqrt();
            assert!((norm - 1.0).abs() < 1e-4, "{norm}");
        }
        let score = alignment_score(&t[0], &m[0]);
        assert!((0.0..=100.0).contains(&score));
        assert_eq!(alignment_score(&t[0], &t[0]).round(), 100.0);
    }

    #[test]
    fn padding_does_not_change_a_motion_embedding() {
        let cfg = tiny();
        let device = Device::flex();
        let model = cfg.init(&device);
        let short = motion(8, 0.5);
        let long = motion(24, -0.5);
        let alone = model.embed_motions(&cfg, &[&short], &device);
        let (x, pad) = motion_batch(&cfg, &[&short, &long], None, &device);
        assert_eq!(x.dims(), [2, 24, FEATURE_DIM]);
        let together = rows(model.motion.forward(x, pad));
        for (a, b) in alone[0].iter().zip(&together[0]) {
            assert!((a - b).abs() < 1e-4, "{a} vs {b}");
        }
    }

    #[test]
    fn the_evaluator_loads_from_bytes_as_from_a_folder() {
        let device = Device::flex();
        let dir = tempfile::tempdir().unwrap();
        let cfg = tiny();
        cfg.save(dir.path().join("evaluator.json")).unwrap();
        cfg.init(&device)
            .save_file(dir.path().join("evaluator.bpk"))
            .unwrap();
        let (from_dir, _) = Evaluator::load(dir.path(), &device).unwrap();
        let text = std::fs::read_to_string(dir.path().join("evaluator.json")).unwrap();
        let weights = std::fs::read(dir.path().join("evaluator.bpk")).unwrap();
        let (from_bytes, config) = Evaluator::from_bytes(&text, &weights, &device).unwrap();
        assert_eq!(config.embedding, 8);
        let sentence = [[0.3; TEXT_DIM]];
        assert_eq!(
            from_dir.embed_texts(&sentence, &device),
            from_bytes.embed_texts(&sentence, &device)
        );
        assert!(Evaluator::from_bytes("{", &weights, &device).is_err());
        assert!(Evaluator::from_bytes(&text, b"not weights", &device).is_err());
    }

    #[test]
    fn f16_weights_load_as_f32_and_agree_with_the_original() {
        let device = Device::flex();
        let cfg = tiny();
        let full = cfg.init(&device);
        let f32_bytes = full.clone().into_record().into_bytes().unwrap().to_vec();
        let f16_bytes = full.to_shipped_bytes(None).unwrap();
        assert!(
            f16_bytes.len() * 10 < f32_bytes.len() * 6,
            "{} bytes in f16, {} in f32",
            f16_bytes.len(),
            f32_bytes.len()
        );
        // The same weights give the same bytes (no parameter ids).
        assert_eq!(f16_bytes, full.to_shipped_bytes(None).unwrap());

        let text = serde_json::to_string(&cfg).unwrap();
        let (half, _) = Evaluator::from_bytes(&text, &f16_bytes, &device).unwrap();
        let dir = tempfile::tempdir().unwrap();
        cfg.save(dir.path().join("evaluator.json")).unwrap();
        std::fs::write(dir.path().join("evaluator.bpk"), &f16_bytes).unwrap();
        let (from_dir, _) = Evaluator::load(dir.path(), &device).unwrap();
        assert_eq!(
            half.text.hidden.weight.val().dtype(),
            burn::tensor::DType::F32
        );
        let sentence = [[0.3; TEXT_DIM]];
        assert_eq!(
            half.embed_texts(&sentence, &device),
            from_dir.embed_texts(&sentence, &device)
        );
    }

    #[test]
    fn long_motions_are_centre_cropped() {
        let cfg = tiny();
        let device = Device::flex();
        let long = motion(60, 0.0);
        let (x, pad) = motion_batch(&cfg, &[&long], None, &device);
        assert_eq!(x.dims(), [1, 24, FEATURE_DIM]);
        assert_eq!(pad.dims(), [1, 6]);
        let first: Vec<f32> = x
            .narrow(1, 0, 1)
            .narrow(2, 0, 1)
            .try_into_vec_as::<f32>()
            .unwrap();
        assert!(
            (first[0] - 0.18).abs() < 1e-6,
            "starts at frame 18: {}",
            first[0]
        );
    }
}
