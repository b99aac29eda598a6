//! Training runs started from a dataset folder (`coma train base|res|evaluator`): what the
//! networks learn from is prepared here (the motions tokenized by the trained VQ-VAE, the
//! captions embedded by the sentence encoder), then the training loops of
//! [`super::transformer`] and [`super::evaluator`] run.

use super::evaluator::{
    train_evaluator, CaptionedMotions, EvaluatorTrainOptions, EvaluatorTrainingConfig,
};
use super::run::RunState;
use super::tokens::TokenSet;
use super::transformer::{
    train_transformer, Kind, TransformerTrainOptions, TransformerTrainingConfig,
};
use super::vq::VqTrainingConfig;
use super::ReadConfig;
use crate::dataset::motions::MotionSet;
use crate::dataset::Split;
use crate::text::minilm::SentenceEncoder;
use anyhow::{Context, Result};
use burn::tensor::Device;
use std::path::Path;

/// What a transformer learns from: the dataset's training motions as the tokens of a trained
/// VQ-VAE, with their captions as sentence embeddings.
#[derive(Clone, Copy, Debug)]
pub struct TransformerSources<'a> {
    /// Dataset folder (from `coma data build`).
    pub data: &'a Path,
    /// The trained VQ-VAE's weights, which tokenize the motions.
    pub vq: &'a Path,
    /// The VQ-VAE's training configuration (for its sizes).
    pub vq_config: &'a Path,
    /// Folder with the converted sentence encoder (minilm-*), which embeds the captions.
    pub text_model: &'a Path,
}

/// Tokenizes the dataset with the trained VQ-VAE, embeds its texts, and trains (or resumes)
/// a base or residual transformer on the training device named `device` (see
/// [`super::training_device`]). A run whose checkpoint has already reached `config.steps`
/// only writes its final weights, without tokenizing. Progress lines go to `progress`.
pub fn train_transformer_on_dataset(
    kind: Kind,
    config: &TransformerTrainingConfig,
    sources: &TransformerSources,
    options: &TransformerTrainOptions,
    device: &str,
    progress: &dyn Fn(&str),
) -> Result<()> {
    let plain = Device::flex();
    let vq_cfg = VqTrainingConfig::read(sources.vq_config)?;
    let vq = crate::weights::load_file(vq_cfg.model.init(&plain), sources.vq)
        .context("cannot load the VQ-VAE")?;
    // A run whose checkpoint has reached its (possibly lowered) step count only writes its
    // final weights: no need to tokenize the dataset for that.
    let finished = RunState::of(&options.run_dir).is_some_and(|s| s.step >= config.steps);
    let tokens = if finished {
        TokenSet::default()
    } else {
        let text = SentenceEncoder::from_dir(sources.text_model, &plain)?;
        let set = MotionSet::load(sources.data, Split::Train)?;
        TokenSet::build(&set, &vq, &plain, &|t| Ok(text.encode(t)), progress)?
    };
    train_transformer(
        kind,
        config,
        &tokens,
        options,
        &super::training_device(device)?,
        progress,
    )
}

/// Embeds the captions of the dataset `data` with the sentence encoder in `text_model` and
/// trains (or resumes) the text–motion evaluator on its training split, validating on its
/// validation split when there is one, on the training device named `device` (see
/// [`super::training_device`]). Progress lines go to `progress`.
pub fn train_evaluator_on_dataset(
    config: &EvaluatorTrainingConfig,
    data: &Path,
    text_model: &Path,
    options: &EvaluatorTrainOptions,
    device: &str,
    progress: &dyn Fn(&str),
) -> Result<()> {
    let plain = Device::flex();
    let text = SentenceEncoder::from_dir(text_model, &plain)?;
    let embed = |t: &[&str]| Ok(text.encode(t));
    let load = |split| -> Result<CaptionedMotions> {
        let set = MotionSet::load(data, split)?;
        CaptionedMotions::build(&set, &embed)
    };
    let train = load(Split::Train)?;
    let val = load(Split::Val).ok();
    progress(&format!(
        "training on {} captioned motions ({} distinct captions), validating on {}",
        train.motions.len(),
        train.embeddings.len(),
        val.as_ref().map_or(0, |v| v.motions.len())
    ));
    train_evaluator(
        config,
        &train,
        val.as_ref(),
        options,
        &super::training_device(device)?,
        progress,
    )
}
