//! SPAM, the body-part-aware motion generator: the residual VQ-VAE ([`vq`]), the masked
//! transformers that generate its tokens from text ([`transformer`]), sampling
//! ([`generate`]) with classifier-free guidance ([`guidance`]) and editing ([`edit`]);
//! beside it the text–motion evaluator ([`evaluator`]), the network that measures motions
//! and judges them for the reviewer.

pub mod edit;
pub mod evaluator;
pub mod gelu;
pub mod generate;
pub mod guidance;
pub mod layers;
pub mod motion_model;
pub mod prior;
pub mod tokens;
pub mod transformer;
pub mod vq;

pub use motion_model::MotionModel;
use prior::{MotionPrior, PriorOptions};
use transformer::{BaseTransformer, ResidualTransformer, TransformerConfig};
use vq::{MotionVq, VqConfig};

use burn::prelude::*;

/// A float tensor's values on the host. Awaited, because a browser's WebGPU device can hand
/// data back only asynchronously; on the CPU backends the future is ready at once.
pub(crate) async fn read_floats<const D: usize>(tensor: Tensor<D>) -> Vec<f32> {
    tensor
        .into_data_async()
        .await
        .expect("the device returns what it computed")
        .convert::<f32>()
        .try_into_vec::<f32>()
        .expect("floats converted to f32")
}

/// The networks of SPAM on one device, ready to generate.
#[derive(Debug)]
pub struct Spam {
    pub vq: MotionVq,
    pub vq_config: VqConfig,
    pub base: BaseTransformer,
    pub base_config: TransformerConfig,
    /// Absent in a base-only model, whose motions decode from the layer-0 tokens alone
    /// (coarser: see MODEL_CARD.md for the reconstruction error of one layer).
    pub residual: Option<Residual>,
    /// Training motions that new motions start from (see [`prior`]); `None` generates from
    /// the text alone.
    pub prior: Option<Prior>,
    pub device: Device,
    /// Where guidance's unconditional pass runs besides here (the page's second worker);
    /// `None` runs both passes on this device (see [`guidance`]).
    pub partner: Option<std::rc::Rc<dyn guidance::GuidancePartner>>,
}

/// The retrieval prior and how generation uses it by default.
#[derive(Debug)]
pub struct Prior {
    pub motions: MotionPrior,
    pub options: PriorOptions,
}

/// The residual transformer and its sizes.
#[derive(Debug)]
pub struct Residual {
    pub network: ResidualTransformer,
    pub config: TransformerConfig,
}

impl Spam {
    /// SPAM with random weights (tests, benchmarks at a given size); base-only without
    /// `residual`.
    pub fn random(
        vq: &VqConfig,
        base: &TransformerConfig,
        residual: Option<&TransformerConfig>,
        device: &Device,
    ) -> Spam {
        Spam {
            vq: vq.init(device),
            vq_config: vq.clone(),
            base: BaseTransformer::new(base, device),
            base_config: base.clone(),
            residual: residual.map(|config| Residual {
                network: ResidualTransformer::new(config, device),
                config: config.clone(),
            }),
            prior: None,
            device: device.clone(),
            partner: None,
        }
    }

    /// Token layers per body part that generation produces: all of the VQ-VAE's with the
    /// residual transformer, 1 without.
    pub fn generated_layers(&self) -> usize {
        match &self.residual {
            Some(r) => r.config.vq_layers,
            None => 1,
        }
    }

    /// Refuses sampling options that ask for a retrieval prior this model does not have:
    /// generation would silently run from the text alone, and a comparison made with them
    /// would measure something other than it says.
    pub fn check_sampling(&self, options: &generate::SamplingOptions) -> Result<(), String> {
        match (&options.prior, &self.prior) {
            (Some(asked), None) if asked.keep > 0.0 => Err(format!(
                "the model has no retrieval prior (its spam.json has \"prior\": null), so keeping \
                 {} of a retrieved motion's tokens cannot apply; add one with `coma export prior`",
                asked.keep
            )),
            _ => Ok(()),
        }
    }
}

/// Sizes of SPAM's networks, stored beside their weights as `spam.json`. A model without a
/// residual transformer (`"residual": null`) is base-only; one with `prior` options has a
/// retrieval prior ([`PRIOR_FILE`]) and generates with those options by default.
#[derive(Config, Debug)]
pub struct SpamConfig {
    pub vq: VqConfig,
    pub base: TransformerConfig,
    pub residual: Option<TransformerConfig>,
    pub prior: Option<PriorOptions>,
}

impl SpamConfig {
    /// The model folder's files for these sizes, in the order its id hashes them: every one
    /// of [`WEIGHT_FILES`] but `residual.bpk` for a base-only model and `prior.bin` for one
    /// without a retrieval prior.
    pub fn weight_files(&self) -> Vec<&'static str> {
        WEIGHT_FILES
            .into_iter()
            .filter(|f| *f != RESIDUAL_FILE || self.residual.is_some())
            .filter(|f| *f != PRIOR_FILE || self.prior.is_some())
            .collect()
    }
}

/// Every weight file a SPAM model folder may hold, in the order its id hashes them.
pub const WEIGHT_FILES: [&str; 7] = [
    "spam.json",
    "vq.bpk",
    "base.bpk",
    RESIDUAL_FILE,
    "mean.npy",
    "std.npy",
    PRIOR_FILE,
];

/// The residual transformer's weights: the one file a base-only model lacks.
pub const RESIDUAL_FILE: &str = "residual.bpk";

/// The retrieval prior (see [`prior`]), in a model whose `spam.json` has `prior` options.
pub const PRIOR_FILE: &str = "prior.bin";

/// A model's id: the first 16 hex digits of the SHA-256 of its weight files, in
/// [`SpamConfig::weight_files`] order (see [`model_id_message`]). Share links name the model
/// they were made with by this id.
pub fn model_id(files: &[&[u8]]) -> String {
    use sha2::{Digest, Sha256};
    // Streamed into the hash: the joined message would copy every weight file once more.
    let mut hash = Sha256::new();
    for f in files {
        hash.update((f.len() as u64).to_le_bytes());
        hash.update(f);
    }
    model_id_from_digest(&hash.finalize())
}

/// What a model id hashes: each file's length in bytes (u64, little-endian), then its bytes.
/// The page hands it to the browser's own SHA-256, which is many times faster than one
/// compiled to wasm.
pub fn model_id_message(files: &[&[u8]]) -> Vec<u8> {
    let mut message = Vec::with_capacity(files.iter().map(|f| f.len() + 8).sum());
    for f in files {
        message.extend_from_slice(&(f.len() as u64).to_le_bytes());
        message.extend_from_slice(f);
    }
    message
}

/// A model id from the SHA-256 digest of its [`model_id_message`].
pub fn model_id_from_digest(digest: &[u8]) -> String {
    digest.iter().take(8).map(|b| format!("{b:02x}")).collect()
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
    /// `None` for a base-only model.
    pub residual: Option<&'a [u8]>,
    pub mean: &'a [u8],
    pub std: &'a [u8],
    /// `None` for a model without a retrieval prior.
    pub prior: Option<&'a [u8]>,
}

impl SpamFiles<'_> {
    /// The model id of these files (see [`model_id`]).
    pub fn id(&self) -> String {
        model_id(&self.in_id_order())
    }

    /// What their model id hashes (see [`model_id_message`]).
    pub fn id_message(&self) -> Vec<u8> {
        model_id_message(&self.in_id_order())
    }

    fn in_id_order(&self) -> Vec<&[u8]> {
        let mut files: Vec<&[u8]> = vec![self.config.as_bytes(), self.vq, self.base];
        files.extend(self.residual);
        files.extend([self.mean, self.std]);
        files.extend(self.prior);
        files
    }
}

impl Spam {
    /// SPAM and its feature statistics from the contents of its files (no file system, so it
    /// works in the page).
    pub fn from_bytes(
        files: &SpamFiles,
        device: &Device,
    ) -> Result<(Spam, crate::features::Normalizer), SpamLoadError> {
        let mut spam =
            Spam::transformers_from_bytes(files.config, files.base, files.residual, device)?;
        spam.vq =
            crate::weights::load_into(spam.vq, files.vq).map_err(|e| file_error("vq.bpk", e))?;
        let normalizer = crate::features::Normalizer::from_npy_bytes(files.mean, files.std)
            .map_err(|e| file_error("mean.npy/std.npy", e.to_string()))?;
        let options = serde_json::from_str::<SpamConfig>(files.config)
            .map_err(|e| file_error("spam.json", e.to_string()))?
            .prior;
        let prior = declared_file(PRIOR_FILE, "prior", options.is_some(), files.prior)?;
        spam.prior = match (options, prior) {
            (Some(options), Some(bytes)) => Some(Prior {
                motions: MotionPrior::from_bytes(bytes, spam.base_config.codebook_size)
                    .map_err(|e| file_error(PRIOR_FILE, e.to_string()))?,
                options,
            }),
            _ => None,
        };
        Ok((spam, normalizer))
    }

    /// SPAM with its transformers' weights from `spam.json`, `base.bpk` and `residual.bpk`
    /// (`None` for a base-only model) and the VQ-VAE left random: all a guidance partner
    /// needs (see [`guidance`]).
    pub fn transformers_from_bytes(
        config: &str,
        base: &[u8],
        residual: Option<&[u8]>,
        device: &Device,
    ) -> Result<Spam, SpamLoadError> {
        let config: SpamConfig =
            serde_json::from_str(config).map_err(|e| file_error("spam.json", e.to_string()))?;
        let mut spam = Spam::random(&config.vq, &config.base, config.residual.as_ref(), device);
        spam.base =
            crate::weights::load_into(spam.base, base).map_err(|e| file_error("base.bpk", e))?;
        let declared = spam.residual.is_some();
        if let (Some(residual), Some(bytes)) = (
            spam.residual.as_mut(),
            declared_file(RESIDUAL_FILE, "residual", declared, residual)?,
        ) {
            residual.network = crate::weights::load_into(residual.network.clone(), bytes)
                .map_err(|e| file_error(RESIDUAL_FILE, e))?;
        }
        Ok(spam)
    }

    /// Loads `spam.json`, `vq.bpk`, `base.bpk`, `residual.bpk` (unless base-only) and the
    /// feature statistics `mean.npy`/`std.npy` from a folder (the default model lives in
    /// `static/models`). Returns the model id too.
    pub fn load(
        dir: &std::path::Path,
        device: &Device,
    ) -> Result<(Spam, crate::features::Normalizer, String), SpamLoadError> {
        let read =
            |name: &str| std::fs::read(dir.join(name)).map_err(|e| load_error(&dir.join(name), e));
        let config_bytes = read("spam.json")?;
        let config = std::str::from_utf8(&config_bytes)
            .map_err(|e| load_error(&dir.join("spam.json"), e))?;
        // A damaged spam.json is reported by `from_bytes`.
        let sizes = serde_json::from_str::<SpamConfig>(config).ok();
        let residual = match &sizes {
            Some(sizes) if sizes.residual.is_none() => None,
            _ => Some(read(RESIDUAL_FILE)?),
        };
        let prior = match &sizes {
            Some(sizes) if sizes.prior.is_some() => Some(read(PRIOR_FILE)?),
            _ => None,
        };
        let (vq, base) = (read("vq.bpk")?, read("base.bpk")?);
        let (mean, std) = (read("mean.npy")?, read("std.npy")?);
        let files = SpamFiles {
            config,
            vq: &vq,
            base: &base,
            residual: residual.as_deref(),
            mean: &mean,
            std: &std,
            prior: prior.as_deref(),
        };
        let (spam, normalizer) =
            Spam::from_bytes(&files, device).map_err(|SpamLoadError::File { file, message }| {
                SpamLoadError::File {
                    file: dir.join(file).display().to_string(),
                    message,
                }
            })?;
        Ok((spam, normalizer, files.id()))
    }
}

/// An optional file of a model folder against `spam.json`'s `key`: its bytes when both have
/// it, `None` when neither does, and an error naming the file when only one does.
fn declared_file<'a>(
    file: &str,
    key: &str,
    declared: bool,
    bytes: Option<&'a [u8]>,
) -> Result<Option<&'a [u8]>, SpamLoadError> {
    match (declared, bytes) {
        (true, None) => Err(file_error(
            file,
            format!("missing, but spam.json has \"{key}\""),
        )),
        (false, Some(_)) => Err(file_error(
            file,
            format!("present, but spam.json has no \"{key}\" (\"{key}\": null)"),
        )),
        (_, bytes) => Ok(bytes),
    }
}

fn file_error(file: &str, message: String) -> SpamLoadError {
    SpamLoadError::File {
        file: file.to_string(),
        message,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_model_id_is_the_sha256_of_length_prefixed_files() {
        let files: [&[u8]; 3] = [b"{\"a\":1}", b"", &[0, 1, 2, 3, 4, 5, 6]];
        let message = model_id_message(&files);
        assert_eq!(message.len(), 3 * 8 + 7 + 7);
        assert_eq!(&message[..8], &7u64.to_le_bytes());
        // From Python's hashlib over the same bytes: what the browser's SHA-256 also gives.
        assert_eq!(model_id(&files), "240d50a1f6c97ea2");
        use sha2::{Digest, Sha256};
        assert_eq!(
            model_id_from_digest(&Sha256::digest(&message)),
            "240d50a1f6c97ea2"
        );
    }

    #[test]
    fn a_prior_loads_only_as_spam_json_declares_it() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../static/models");
        let read = |name: &str| std::fs::read(dir.join(name)).unwrap();
        let config = String::from_utf8(read("spam.json")).unwrap();
        let (vq, base, mean, std, prior) = (
            read("vq.bpk"),
            read("base.bpk"),
            read("mean.npy"),
            read("std.npy"),
            read(PRIOR_FILE),
        );
        let mut sizes: SpamConfig = serde_json::from_str(&config).unwrap();
        assert!(sizes.prior.is_some(), "the default model has a prior");
        sizes.prior = None;
        let undeclared = serde_json::to_string(&sizes).unwrap();
        let device = Device::flex();
        let load = |config: &str, prior: Option<&[u8]>| {
            let files = SpamFiles {
                config,
                vq: &vq,
                base: &base,
                residual: None,
                mean: &mean,
                std: &std,
                prior,
            };
            Spam::from_bytes(&files, &device).map(|(spam, _)| spam.prior.is_some())
        };
        assert!(load(&config, Some(&prior)).unwrap());
        assert!(!load(&undeclared, None).unwrap());
        let message = |r: Result<bool, SpamLoadError>| r.unwrap_err().to_string();
        assert_eq!(
            message(load(&config, None)),
            "prior.bin: missing, but spam.json has \"prior\""
        );
        assert!(message(load(&undeclared, Some(&prior))).starts_with("prior.bin: present"));
        let cut = message(load(&config, Some(&prior[..prior.len() / 2])));
        assert!(cut.starts_with("prior.bin: "), "{cut}");
    }

    #[test]
    fn asking_a_model_without_a_prior_to_keep_prior_tokens_is_an_error() {
        use generate::tests::{small, tiny_vq};
        let spam = Spam::random(&tiny_vq(), &small(), None, &Device::flex());
        let with_keep = |keep| generate::SamplingOptions {
            prior: Some(PriorOptions {
                keep,
                ..Default::default()
            }),
            ..Default::default()
        };
        let message = spam.check_sampling(&with_keep(0.2)).unwrap_err();
        assert!(
            message.starts_with("the model has no retrieval prior"),
            "{message}"
        );
        assert!(message.contains("coma export prior"), "{message}");
        // Turning the prior off, or leaving the model's own setting, asks for nothing absent.
        assert!(spam.check_sampling(&with_keep(0.0)).is_ok());
        assert!(spam.check_sampling(&Default::default()).is_ok());
    }
}
