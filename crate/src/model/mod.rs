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
            base: BaseTransformer::new(base, device),
            residual: ResidualTransformer::new(residual, device),
            base_config: base.clone(),
            residual_config: residual.clone(),
            device: device.clone(),
        }
    }
}
