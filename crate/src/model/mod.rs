//! SPAM, the body-part-aware motion generator: the residual VQ-VAE ([`vq`]), the masked
//! transformers that generate its tokens from text ([`transformer`]), sampling
//! ([`generate`]) and editing ([`edit`]).

pub mod edit;
pub mod generate;
pub mod transformer;
pub mod vq;

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

impl Spam {
    /// Loads `spam.json`, `vq.bpk`, `base.bpk`, `residual.bpk` and the feature statistics
    /// `mean.npy`/`std.npy` from a folder (the default model lives in `static/models`).
    pub fn load(
        dir: &std::path::Path,
        device: &Device,
    ) -> Result<(Spam, crate::features::Normalizer), SpamLoadError> {
        let config_path = dir.join("spam.json");
        let config = SpamConfig::load(&config_path).map_err(|e| load_error(&config_path, e))?;
        let mut spam = Spam::random(&config.vq, &config.base, &config.residual, device);
        let file = |name: &str| dir.join(name);
        spam.vq = spam
            .vq
            .try_load_file(file("vq.bpk"))
            .map_err(|e| load_error(&file("vq.bpk"), format!("{e:?}")))?;
        spam.base = spam
            .base
            .try_load_file(file("base.bpk"))
            .map_err(|e| load_error(&file("base.bpk"), format!("{e:?}")))?;
        spam.residual = spam
            .residual
            .try_load_file(file("residual.bpk"))
            .map_err(|e| load_error(&file("residual.bpk"), format!("{e:?}")))?;
        let normalizer = crate::features::Normalizer::read(file("mean.npy"), file("std.npy"))
            .map_err(|e| load_error(&file("mean.npy"), e))?;
        Ok((spam, normalizer))
    }
}
