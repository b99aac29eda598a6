//! Assembling trained runs into a model folder (`coma export`): SPAM's three networks and the
//! evaluator rounded to f16 or quantized (the page's weights, see [`crate::weights`]), and
//! what that changes in the motions they reconstruct, the tokens they generate and the scores
//! they give; SPAM with
//! random weights for tests of the plumbing; the training captions' vocabulary for the planner.

use crate::dataset::motions::MotionSet;
use crate::dataset::Split;
use crate::eval::agreement::{agreement, Agreement};
use crate::executor::block_on;
use crate::features::FeatureFrame;
use crate::model::evaluator::{Evaluator, EvaluatorConfig};
use crate::model::generate::SamplingOptions;
use crate::model::prior::{MotionPrior, PriorOptions};
use crate::model::transformer::PARTS;
use crate::model::{Spam, SpamConfig, SpamFiles, PRIOR_FILE, RESIDUAL_FILE};
use crate::quant::Bits;
use crate::text::minilm::SentenceEncoder;
use crate::train::evaluator::EvaluatorTrainingConfig;
use crate::train::transformer::TransformerTrainingConfig;
use crate::train::vq::{reconstruction_errors, VqTrainingConfig};
use crate::weights::shipped_bytes;
use anyhow::{Context, Result};
use burn::config::Config;
use burn::module::Module;
use burn::tensor::Device;
use std::path::{Path, PathBuf};

/// Prompts whose greedily decoded tokens [`ExportedSpam::token_rounding`] compares between the f32
/// and the shipped weights: a walk, a wave and a raise of one hand each, and a bow.
pub const ROUNDING_PROMPTS: [&str; 4] = [
    "a person walks forward",
    "a person waves the left hand",
    "a person raises the right hand",
    "a person bows",
];

/// Frames of motion (9.8 s at 20 fps) generated per prompt of [`ROUNDING_PROMPTS`].
pub const ROUNDING_FRAMES: usize = 196;

/// Test motions whose reconstruction error [`ExportedSpam::vq_rounding`] measures.
pub const ROUNDING_VQ_MOTIONS: usize = 200;

/// Captioned test motions on which [`ExportedEvaluator::rounding`] compares the scores.
pub const ROUNDING_EVALUATOR_MOTIONS: usize = 224;

/// SPAM written to a model folder in f16 or quantized, beside the f32 weights of its runs.
#[derive(Debug)]
pub struct ExportedSpam {
    /// The model folder written.
    pub dir: PathBuf,
    /// The networks' sizes, as written to `spam.json`.
    pub sizes: SpamConfig,
    /// The runs' weights as trained (f32).
    pub full: Spam,
    /// The weights as the folder holds them (f16 or quantized), loaded back from it.
    pub shipped: Spam,
    /// Bytes of the folder's weight files (see [`SpamConfig::weight_files`]).
    pub bytes: u64,
    /// The folder's model id (see [`crate::model::model_id`]), which share links name.
    pub id: String,
}

/// What shipping SPAM in f16 or quantized changes in the motions its VQ-VAE reconstructs.
#[derive(Clone, Debug)]
pub struct VqRounding {
    /// Test motions reconstructed.
    pub motions: usize,
    /// Token layers decoded (those generation produces) and the VQ-VAE's layers.
    pub layers: usize,
    pub vq_layers: usize,
    /// Mean per-joint position error of the reconstructions, root aligned, in millimetres,
    /// with the f32 and with the shipped weights.
    pub f32_mm: f64,
    pub shipped_mm: f64,
}

/// What shipping SPAM in f16 or quantized changes in the tokens it generates: of the tokens of
/// [`ROUNDING_PROMPTS`], greedily decoded, how many are the same with both weights.
#[derive(Clone, Copy, Debug)]
pub struct TokenRounding {
    pub same: usize,
    pub total: usize,
}

/// `coma export spam`: the runs' final weights (`vq.bpk`, `base.bpk`, and `residual.bpk`
/// when `res` names the residual transformer's run; without it the model is base-only)
/// rounded to f16, and with `bits` quantized, into `out` with `spam.json` and the feature statistics of `data`
/// (`Mean.npy`, `Std.npy`), then loaded back. [`ExportedSpam::vq_rounding`] and
/// [`ExportedSpam::token_rounding`] say what the rounding changes.
pub fn export_spam(
    vq: &Path,
    base: &Path,
    res: Option<&Path>,
    data: &Path,
    out: &Path,
    bits: Option<Bits>,
) -> Result<ExportedSpam> {
    let read = |p: PathBuf| std::fs::read(&p).with_context(|| p.display().to_string());
    let transformer = |run: &Path| {
        TransformerTrainingConfig::load(run.join("config.json"))
            .map(|c| c.model)
            .map_err(|e| anyhow::anyhow!("{}: {e}", run.join("config.json").display()))
    };
    let sizes = SpamConfig::new(
        <VqTrainingConfig as crate::train::ReadConfig>::read(&vq.join("config.json"))?.model,
        transformer(base)?,
    )
    .with_residual(res.map(transformer).transpose()?);
    let config = serde_json::to_string_pretty(&sizes)?;
    let (vq_bytes, base_bytes) = (read(vq.join("vq.bpk"))?, read(base.join("base.bpk"))?);
    let res_bytes = res.map(|r| read(r.join("residual.bpk"))).transpose()?;
    let (mean, std) = (read(data.join("Mean.npy"))?, read(data.join("Std.npy"))?);
    let device = Device::flex();
    let files = SpamFiles {
        config: &config,
        vq: &vq_bytes,
        base: &base_bytes,
        residual: res_bytes.as_deref(),
        mean: &mean,
        std: &std,
        prior: None,
    };
    let (full, _) = Spam::from_bytes(&files, &device)?;

    std::fs::create_dir_all(out)?;
    let write = |name: &str, bytes: &[u8]| {
        std::fs::write(out.join(name), bytes).with_context(|| out.join(name).display().to_string())
    };
    write("spam.json", config.as_bytes())?;
    write(
        "vq.bpk",
        &shipped_bytes(&full.vq, &|name| vq_bits(name, bits), &[])?,
    )?;
    write("base.bpk", &shipped_bytes(&full.base, &|_| bits, &[])?)?;
    // A stale residual file, or a prior of another VQ-VAE's tokens, would make the folder
    // fail to load; `coma export prior` adds the prior back.
    let remove = |name: &str| match std::fs::remove_file(out.join(name)) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e),
        _ => Ok(()),
    };
    match &full.residual {
        Some(r) => write(RESIDUAL_FILE, &shipped_bytes(&r.network, &|_| bits, &[])?)?,
        None => remove(RESIDUAL_FILE)?,
    }
    remove(PRIOR_FILE)?;
    write("mean.npy", &mean)?;
    write("std.npy", &std)?;
    let (shipped, _, id) = Spam::load(out, &device)?;
    let bytes: u64 = sizes
        .weight_files()
        .iter()
        .map(|f| std::fs::metadata(out.join(f)).map_or(0, |m| m.len()))
        .sum();
    Ok(ExportedSpam {
        dir: out.to_path_buf(),
        sizes,
        full,
        shipped,
        bytes,
        id,
    })
}

/// Bits of the VQ-VAE's parameter `name` when the model ships at `bits`: its encoders at 4
/// whatever `bits` says (generation, review and the page only decode; the encoders serve
/// `coma edit` on an input motion and training), the rest at `bits`.
fn vq_bits(name: &str, bits: Option<Bits>) -> Option<Bits> {
    bits.map(|b| {
        if name.starts_with("encoders.") {
            Bits::Four
        } else {
            b
        }
    })
}

impl ExportedSpam {
    /// True when the motions generated from the exported folder get their finer token layers
    /// from a residual transformer; false for a base-only model.
    pub fn has_residual(&self) -> bool {
        self.shipped.residual.is_some()
    }

    /// What the rounding changes in reconstructions: the VQ-VAE's error on
    /// [`ROUNDING_VQ_MOTIONS`] test motions of `data`, decoding the layers generation
    /// produces.
    pub fn vq_rounding(&self, data: &Path) -> Result<VqRounding> {
        let device = Device::flex();
        let test = MotionSet::load(data, Split::Test)?;
        let layers = self.shipped.generated_layers();
        let error = |spam: &Spam| {
            reconstruction_errors(&spam.vq, &test, &device, ROUNDING_VQ_MOTIONS, layers)
        };
        let (e32, shipped) = (error(&self.full)?, error(&self.shipped)?);
        Ok(VqRounding {
            motions: e32.motions,
            layers,
            vq_layers: self.sizes.vq.layers,
            f32_mm: e32.root_aligned_mm,
            shipped_mm: shipped.root_aligned_mm,
        })
    }

    /// What the rounding changes in generation: the tokens greedy decoding picks for
    /// [`ROUNDING_PROMPTS`] ([`ROUNDING_FRAMES`] frames each, texts embedded by the sentence
    /// encoder in the folder).
    pub fn token_rounding(&self) -> Result<TokenRounding> {
        let device = Device::flex();
        let text = SentenceEncoder::from_dir(&self.dir, &device)?;
        let (mut same, mut total) = (0usize, 0usize);
        for (i, prompt) in ROUNDING_PROMPTS.iter().enumerate() {
            let condition = [text.encode(&[prompt])[0]; PARTS];
            // Greedy: sampling would turn the smallest change of a probability into another
            // code, and every later step would follow it.
            let options = SamplingOptions {
                seed: i as u64,
                temperature: 0.0,
                ..Default::default()
            };
            let [a, b] = [&self.full, &self.shipped]
                .map(|spam| block_on(spam.generate(&condition, ROUNDING_FRAMES, &options)));
            for (x, y) in a
                .iter()
                .flatten()
                .flatten()
                .zip(b.iter().flatten().flatten())
            {
                same += (x == y) as usize;
                total += 1;
            }
        }
        Ok(TokenRounding { same, total })
    }
}

/// The text–motion evaluator written to a model folder in f16 or quantized, beside its
/// run's weights.
pub struct ExportedEvaluator {
    /// The model folder written.
    pub dir: PathBuf,
    /// The run's weights as trained (f32).
    pub original: Evaluator,
    /// The weights as the folder holds them (f16 or quantized), loaded back from it.
    pub shipped: Evaluator,
    pub config: EvaluatorConfig,
    /// Size of the folder's `evaluator.bpk`.
    pub bytes: usize,
}

/// What shipping the evaluator in f16 or quantized changes, when it could be measured.
#[derive(Clone, Debug)]
pub enum EvaluatorRounding {
    /// The dataset has no test split to measure on.
    NoTestSplit,
    /// The model folder has no sentence encoder to embed the captions.
    NoSentenceEncoder,
    /// The run's and the shipped evaluators' scores and retrieval on the same captioned test
    /// motions.
    Compared(Agreement),
}

/// `coma export evaluator`: the run's weights (`evaluator.bpk`, sizes from its
/// `config.json`) rounded to f16, and with `bits` quantized, into `out` as `evaluator.bpk` and `evaluator.json`, then
/// loaded back. [`ExportedEvaluator::rounding`] says what the rounding changes.
pub fn export_evaluator(run: &Path, out: &Path, bits: Option<Bits>) -> Result<ExportedEvaluator> {
    let device = Device::flex();
    let cfg = EvaluatorTrainingConfig::load(run.join("config.json"))
        .map_err(|e| anyhow::anyhow!("{}: {e}", run.join("config.json").display()))?;
    let original = Evaluator::load_weights(&cfg.model, &run.join("evaluator.bpk"), &device)?;
    std::fs::create_dir_all(out)?;
    cfg.model
        .save(out.join("evaluator.json"))
        .map_err(|e| anyhow::anyhow!("writing evaluator.json: {e}"))?;
    let weights = out.join("evaluator.bpk");
    let bytes = original.to_shipped_bytes(bits)?;
    std::fs::write(&weights, &bytes).with_context(|| weights.display().to_string())?;
    let (shipped, config) = Evaluator::load(out, &device)?;
    Ok(ExportedEvaluator {
        dir: out.to_path_buf(),
        original,
        shipped,
        config,
        bytes: bytes.len(),
    })
}

impl ExportedEvaluator {
    /// What the rounding changes on [`ROUNDING_EVALUATOR_MOTIONS`] random captioned test
    /// motions of `data`, each with a random one of its captions (when `data` has a test
    /// split and the folder a sentence encoder).
    pub fn rounding(&self, data: &Path) -> EvaluatorRounding {
        let device = Device::flex();
        let Ok(test) = MotionSet::load(data, Split::Test) else {
            return EvaluatorRounding::NoTestSplit;
        };
        let Ok(text) = SentenceEncoder::from_dir(&self.dir, &device) else {
            return EvaluatorRounding::NoSentenceEncoder;
        };
        // As one repetition of `coma eval`: motions in a random order (neighbouring test
        // motions are windows of the same take, which would crowd a batch of 32) with a
        // random caption.
        let mut rng = crate::rng::Rng::new(0);
        let mut items: Vec<_> = test
            .items
            .iter()
            .filter(|i| !i.captions.is_empty())
            .collect();
        rng.shuffle(&mut items);
        items.truncate(ROUNDING_EVALUATOR_MOTIONS);
        let motions: Vec<&[FeatureFrame]> = items.iter().map(|i| i.features.as_slice()).collect();
        let captions: Vec<&str> = items
            .iter()
            .map(|i| i.captions[rng.below(i.captions.len())].as_str())
            .collect();
        let sentences: Vec<_> = captions.chunks(64).flat_map(|c| text.encode(c)).collect();
        EvaluatorRounding::Compared(agreement(
            &self.original,
            &self.shipped,
            &self.config,
            &motions,
            &sentences,
            &device,
        ))
    }
}

/// A retrieval prior added to a model folder.
#[derive(Debug)]
pub struct ExportedPrior {
    /// Distinct training captions and training motions it holds.
    pub captions: usize,
    pub motions: usize,
    /// Bytes of `prior.bin`.
    pub bytes: u64,
    /// The folder's model id after the change (see [`crate::model::model_id`]).
    pub id: String,
}

/// `coma export prior`: the retrieval prior (see [`crate::model::prior`]) of the training
/// motions of `data` (at most `per_action` of each action), tokenized by the VQ-VAE run `vq`
/// (the f32 weights the transformers learnt from), with their captions embedded by the
/// sentence encoder in `out`, written to `out/prior.bin`; `out/spam.json` gets `options` as
/// the model's default. The folder must hold the model made from that VQ-VAE (`coma export
/// spam` first), and is loaded back.
pub fn export_prior(
    vq: &Path,
    data: &Path,
    out: &Path,
    options: PriorOptions,
    per_action: usize,
    progress: &dyn Fn(&str),
) -> Result<ExportedPrior> {
    let device = Device::flex();
    let vq_config = <VqTrainingConfig as crate::train::ReadConfig>::read(&vq.join("config.json"))?;
    let network = crate::weights::load_file(vq_config.init_model(&device), &vq.join("vq.bpk"))
        .context("cannot load the VQ-VAE")?;
    let spam_json = out.join("spam.json");
    let mut sizes = SpamConfig::load(&spam_json)
        .map_err(|e| anyhow::anyhow!("{}: {e}", spam_json.display()))?;
    anyhow::ensure!(
        sizes.vq.codebook_size == vq_config.model.codebook_size,
        "{} holds a model with {} codes per layer, the VQ-VAE {} has {}",
        out.display(),
        sizes.vq.codebook_size,
        vq.display(),
        vq_config.model.codebook_size
    );
    let text = SentenceEncoder::from_dir(out, &device)?;
    let train = MotionSet::load(data, Split::Train)?;
    // Only the kept motions are tokenized, and only their captions embedded (once each).
    let kept = kept_per_action(&train, per_action);
    progress(&format!("tokenizing {} training motions", kept.len()));
    // One key per caption with its subject said plainly: the subject words say nothing about
    // the motion, and each key is most of the file.
    let mut described: std::collections::BTreeMap<String, Vec<u32>> = Default::default();
    for (m, item) in kept.iter().map(|i| &train.items[*i]).enumerate() {
        for c in &item.captions {
            let motions = described
                .entry(crate::dataset::captions::with_plain_subject(c))
                .or_default();
            if motions.last() != Some(&(m as u32)) {
                motions.push(m as u32);
            }
        }
    }
    let texts: Vec<&str> = described.keys().map(String::as_str).collect();
    let mut embeddings = Vec::with_capacity(texts.len());
    for chunk in texts.chunks(64) {
        embeddings.extend(text.encode(chunk));
    }
    let captions: Vec<_> = embeddings
        .into_iter()
        .zip(described.into_values())
        .collect();
    let motions = kept
        .iter()
        .map(|i| {
            let tokens = network.tokenize_motion(&train.items[*i].features, &device);
            std::array::from_fn(|p| tokens[p][0].clone())
        })
        .collect();
    let prior = MotionPrior::new(&captions, motions);
    let bytes = prior.to_bytes();
    std::fs::write(out.join(PRIOR_FILE), &bytes)
        .with_context(|| out.join(PRIOR_FILE).display().to_string())?;
    sizes.prior = Some(options);
    std::fs::write(&spam_json, serde_json::to_string_pretty(&sizes)?)
        .with_context(|| spam_json.display().to_string())?;
    let (_, _, id) = Spam::load(out, &device)?;
    let (captions, motions) = prior.len();
    Ok(ExportedPrior {
        captions,
        motions,
        bytes: bytes.len() as u64,
        id,
    })
}

/// Indices of at most `per_action` items of each action (unlabelled items counted as one
/// action), drawn with a fixed seed, in their original order: every action stays, and the
/// hundreds of walks and raised hands do not fill the page's download.
fn kept_per_action(set: &MotionSet, per_action: usize) -> Vec<usize> {
    let mut by_action: std::collections::BTreeMap<Option<&str>, Vec<usize>> = Default::default();
    for (i, item) in set.items.iter().enumerate() {
        by_action
            .entry(item.content.as_deref())
            .or_default()
            .push(i);
    }
    let mut rng = crate::rng::Rng::new(0x0050_5249_4f52);
    let mut kept: Vec<usize> = by_action
        .into_values()
        .flat_map(|mut items| {
            rng.shuffle(&mut items);
            items.truncate(per_action);
            items
        })
        .collect();
    kept.sort_unstable();
    kept
}

/// `coma export random`: SPAM with random weights at `sizes` and the feature statistics of
/// `data` into `out`, loaded back to check the folder: a model that moves, but not as any
/// prompt asks, for tests of the plumbing before trained weights exist.
pub fn export_random(sizes: &SpamConfig, data: &Path, out: &Path) -> Result<()> {
    let device = Device::flex();
    let spam = Spam::random(&sizes.vq, &sizes.base, sizes.residual.as_ref(), &device);
    std::fs::create_dir_all(out)?;
    sizes
        .save(out.join("spam.json"))
        .map_err(|e| anyhow::anyhow!("writing spam.json: {e}"))?;
    let save =
        |r: Result<(), _>, name: &str| r.map_err(|e| anyhow::anyhow!("writing {name}: {e:?}"));
    save(spam.vq.clone().save_file(out.join("vq.bpk")), "vq.bpk")?;
    save(
        spam.base.clone().save_file(out.join("base.bpk")),
        "base.bpk",
    )?;
    if let Some(residual) = &spam.residual {
        save(
            residual.network.clone().save_file(out.join("residual.bpk")),
            "residual.bpk",
        )?;
    }
    for (from, to) in [("Mean.npy", "mean.npy"), ("Std.npy", "std.npy")] {
        std::fs::copy(data.join(from), out.join(to))
            .with_context(|| format!("copying {}", data.join(from).display()))?;
    }
    Spam::load(out, &device)?;
    Ok(())
}

/// `coma export vocabulary`: the words and action labels of the training captions (the
/// `vocabulary` of `data`'s `dataset.json`, with its licence and each source's terms), which
/// the planner is told to describe motions with and the page's About box credits, written to
/// `out/vocabulary.json`. Returns the number of words.
pub fn export_vocabulary(data: &Path, out: &Path) -> Result<usize> {
    let path = data.join("dataset.json");
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(&path)
            .with_context(|| format!("cannot read {}", path.display()))?,
    )?;
    let mut vocabulary = summary["vocabulary"].clone();
    anyhow::ensure!(
        vocabulary["words"].is_array(),
        "{} has no vocabulary (rebuild it with `coma data build`)",
        path.display()
    );
    vocabulary["licence"] = summary["licence"].clone();
    let terms: serde_json::Map<String, serde_json::Value> = summary["sources"]
        .as_object()
        .into_iter()
        .flatten()
        .map(|(name, source)| {
            let terms = crate::dataset::DataTerms {
                licence: source["licence"].as_str().unwrap_or_default().to_string(),
                attribution: source["attribution"]
                    .as_str()
                    .unwrap_or_default()
                    .to_string(),
            };
            (name.clone(), serde_json::json!(terms))
        })
        .collect();
    vocabulary["sources"] = serde_json::Value::Object(terms);
    std::fs::create_dir_all(out)?;
    std::fs::write(
        out.join("vocabulary.json"),
        serde_json::to_string_pretty(&vocabulary)? + "\n",
    )?;
    Ok(vocabulary["words"].as_array().map_or(0, Vec::len))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::{DataTerms, Vocabulary};

    #[test]
    fn the_vocabulary_carries_each_source_s_terms() {
        let data = tempfile::tempdir().unwrap();
        let summary = serde_json::json!({
            "licence": "CC BY-NC 4.0; CC BY-SA 3.0",
            "sources": {
                "bandai": {"licence": "CC BY-NC 4.0", "attribution": "Bandai Namco", "frames": 9},
                "hdm05": {"licence": "CC BY-SA 3.0", "attribution": "HDM05", "frames": 3},
            },
            "vocabulary": {"actions": {"squat": 4}, "styles": {}, "examples": {}, "words": ["squat"]},
        });
        std::fs::write(data.path().join("dataset.json"), summary.to_string()).unwrap();
        let out = tempfile::tempdir().unwrap();
        assert_eq!(export_vocabulary(data.path(), out.path()).unwrap(), 1);
        let text = std::fs::read_to_string(out.path().join("vocabulary.json")).unwrap();
        let vocabulary: Vocabulary = serde_json::from_str(&text).unwrap();
        assert_eq!(
            vocabulary.sources["hdm05"],
            DataTerms {
                licence: "CC BY-SA 3.0".into(),
                attribution: "HDM05".into()
            }
        );
        assert_eq!(vocabulary.sources.len(), 2);
        // A vocabulary exported before sources were listed still reads, with none.
        let old: Vocabulary =
            serde_json::from_str(r#"{"actions": {}, "styles": {}, "examples": {}, "words": []}"#)
                .unwrap();
        assert!(old.sources.is_empty());
    }
}
