//! SPAM, the body-part-aware motion generator: the residual VQ-VAE ([`vq`]), the masked
//! transformers that generate its tokens from text ([`transformer`]), sampling
//! ([`generate`]) and editing ([`edit`]).

pub mod edit;
pub mod generate;
pub mod motion_model;
pub mod transformer;
pub mod vq;

pub use motion_model::MotionModel;
use transformer::{BaseTransformer, ResidualTransformer, TransformerConfig};
use vq::{MotionVq, VqConfig};

use burn::prelude::*;

/// The three networks of SPAM on one device, ready to generate.
#[derive(Debug)]
pub struct Spam {
    pub vq: MotionVq,
    pub vq_config: VqConfig,
    pub base: BaseTransformer,
    pub residual: ResidualTransformer,
    pub base_config: TransformerConfig,
    pub residual_config: TransformerConfig,
    pub device: Device,
}

impl Spam {
    /// SPAM with random weights (tests, benchmarks at a given size).
    pub fn random(
        vq: &VqConfig,
        base: &TransformerConfig,
        residual: &TransformerConfig,
        device: &Device,
    ) -> Spam {
        Spam {
            vq: vq.init(device),
            vq_config: vq.clone(),
            base: BaseTransformer::new(base, device),
            residual: ResidualTransformer::new(residual, device),
            base_config: base.clone(),
            residual_config: residual.clone(),
            device: device.clone(),
        }
    }
}

/// Sizes of the three networks, stored beside their weights as `spam.json`.
#[derive(Config, Debug)]
pub struct SpamConfig {
    pub vq: VqConfig,
    pub base: TransformerConfig,
    pub residual: TransformerConfig,
}

/// The weight files of a SPAM model folder, in the order its id hashes them.
pub const WEIGHT_FILES: [&str; 6] = [
    "spam.json",
    "vq.bpk",
    "base.bpk",
    "residual.bpk",
    "mean.npy",
    "std.npy",
];

/// A model's id: the first 16 hex digits of the SHA-256 of its weight files, in
/// [`WEIGHT_FILES`] order. Share links name the model they were made with by this id.
pub fn model_id(files: &[&[u8]]) -> String {
    use sha2::{Digest, Sha256};
    let mut hash = Sha256::new();
    for f in files {
        hash.update((f.len() as u64).to_le_bytes());
        hash.update(f);
    }
    hash.finalize()[..8]
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The id of the model in a folder (see [`model_id`]).
pub fn model_id_of_dir(dir: &std::path::Path, files: &[&str]) -> std::io::Result<String> {
    let bytes = files
        .iter()
        .map(|f| std::fs::read(dir.join(f)))
        .collect::<std::io::Result<Vec<_>>>()?;
    let refs: Vec<&[u8]> = bytes.iter().map(Vec::as_slice).collect();
    Ok(model_id(&refs))
}

/// Why SPAM could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum SpamLoadError {
    #[error("{file}: {message}")]
    File { file: String, message: String },
}

fn load_error(file: &std::path::Path, message: impl std::fmt::Display) -> SpamLoadError {
    SpamLoadError::File {
        file: file.display().to_string(),
        message: message.to_string(),
    }
}

/// The contents of a SPAM model folder's files (see [`WEIGHT_FILES`]).
pub struct SpamFiles<'a> {
    pub config: &'a str,
    pub vq: &'a [u8],
    pub base: &'a [u8],
    pub residual: &'a [u8],
    pub mean: &'a [u8],
    pub std: &'a [u8],
}

impl Spam {
    /// SPAM and its feature statistics from the contents of its files (no file system, so it
    /// works in the page).
    pub fn from_bytes(
        files: &SpamFiles,
        device: &Device,
    ) -> Result<(Spam, crate::features::Normalizer), SpamLoadError> {
        let error = |file: &str, message: String| SpamLoadError::File {
            file: file.to_string(),
            message,
        };
        let config: SpamConfig =
            serde_json::from_str(files.config).map_err(|e| error("spam.json", e.to_string()))?;
        let mut spam = Spam::random(&config.vq, &config.base, &config.residual, device);
        let record = |name: &str, bytes: &[u8]| {
            burn::store::ModuleRecord::from_bytes(burn::tensor::Bytes::from_bytes_vec(
                bytes.to_vec(),
            ))
            .map_err(|e| error(name, format!("{e:?}")))
        };
        spam.vq = spam
            .vq
            .try_load_record(record("vq.bpk", files.vq)?)
            .map_err(|e| error("vq.bpk", format!("{e:?}")))?;
        spam.base = spam
            .base
            .try_load_record(record("base.bpk", files.base)?)
            .map_err(|e| error("base.bpk", format!("{e:?}")))?;
        spam.residual = spam
            .residual
            .try_load_record(record("residual.bpk", files.residual)?)
            .map_err(|e| error("residual.bpk", format!("{e:?}")))?;
        let normalizer = crate::features::Normalizer::from_npy_bytes(files.mean, files.std)
            .map_err(|e| error("mean.npy/std.npy", e.to_string()))?;
        Ok((spam, normalizer))
    }

    /// Loads `spam.json`, `vq.bpk`, `base.bpk`, `residual.bpk` and the feature statistics
    /// `mean.npy`/`std.npy` from a folder (the default model lives in `static/models`).
    pub fn load(
        dir: &std::path::Path,
        device: &Device,
    ) -> Result<(Spam, crate::features::Normalizer), SpamLoadError> {
        let read =
            |name: &str| std::fs::read(dir.join(name)).map_err(|e| load_error(&dir.join(name), e));
        let bytes: Vec<Vec<u8>> = WEIGHT_FILES
            .iter()
            .map(|f| read(f))
            .collect::<Result<_, _>>()?;
        let config =
            std::str::from_utf8(&bytes[0]).map_err(|e| load_error(&dir.join("spam.json"), e))?;
        Spam::from_bytes(
            &SpamFiles {
                config,
                vq: &bytes[1],
                base: &bytes[2],
                residual: &bytes[3],
                mean: &bytes[4],
                std: &bytes[5],
            },
            device,
        )
        .map_err(
            |SpamLoadError::File { file, message }| SpamLoadError::File {
                file: dir.join(file).display().to_string(),
                message,
            },
        )
    }
}
