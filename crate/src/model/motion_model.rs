//! SPAM with its sentence encoder and feature statistics: everything that turns words into
//! motion. The command line, the probes, the evaluation and the page's worker all go through
//! it, so a prompt means the same motion everywhere.

use super::edit::{part_text, PartText};
use super::generate::{MotionTokens, SamplingOptions};
use super::layers;
use super::{Spam, SpamFiles, SpamLoadError};
use crate::features::{features_to_joints, Features, Normalizer};
use crate::skeleton::{BodyPart, Pose};
use crate::text::minilm::{MiniLmError, SentenceEncoder};
use crate::timing::{FRAMES_PER_TOKEN, MAX_FRAMES};
use burn::prelude::*;

/// Why a motion model could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum MotionModelError {
    #[error(transparent)]
    Spam(#[from] SpamLoadError),
    #[error("sentence encoder: {0}")]
    Text(#[from] MiniLmError),
    #[error("{0}")]
    Io(String),
}

/// The contents of the sentence encoder's three files.
pub struct TextFiles<'a> {
    pub vocab: &'a str,
    pub words: &'a [u8],
    pub model: &'a [u8],
}

/// The three networks of SPAM, the sentence encoder and the statistics that undo the
/// features' normalisation.
pub struct MotionModel {
    pub spam: Spam,
    pub normalizer: Normalizer,
    pub text: SentenceEncoder,
    /// The model id (see [`super::model_id`]): share links name the model by it.
    pub id: String,
}

impl MotionModel {
    /// A model from the contents of its files (no file system, so it works in the page).
    /// SPAM runs on `device`, the sentence encoder on `text_device`: the page keeps the
    /// encoder on the CPU, since the planner asks for embeddings in synchronous callbacks and
    /// one sentence is quick there.
    pub fn from_files(
        spam: &SpamFiles,
        text: &TextFiles,
        device: &Device,
        text_device: &Device,
    ) -> Result<MotionModel, MotionModelError> {
        let ((spam_model, normalizer), text) =
            Self::parts_from_files(spam, text, device, text_device)?;
        Ok(MotionModel {
            spam: spam_model,
            normalizer,
            text,
            id: spam.id(),
        })
    }

    /// The same, with the model id from `id`, awaited once the weights are loaded: the page
    /// has the browser hash [`SpamFiles::id_message`] on its own threads meanwhile.
    pub async fn from_files_hashed(
        spam: &SpamFiles<'_>,
        text: &TextFiles<'_>,
        id: impl std::future::Future<Output = String>,
        device: &Device,
        text_device: &Device,
    ) -> Result<MotionModel, MotionModelError> {
        let ((spam, normalizer), text) = Self::parts_from_files(spam, text, device, text_device)?;
        Ok(MotionModel {
            spam,
            normalizer,
            text,
            id: id.await,
        })
    }

    fn parts_from_files(
        spam: &SpamFiles,
        text: &TextFiles,
        device: &Device,
        text_device: &Device,
    ) -> Result<((Spam, Normalizer), SentenceEncoder), MotionModelError> {
        Ok((
            Spam::from_bytes(spam, device)?,
            SentenceEncoder::from_bytes(text.vocab, text.words, text.model, text_device)?,
        ))
    }

    /// The model in a folder (the default one is `static/models`).
    pub fn load(dir: &std::path::Path, device: &Device) -> Result<MotionModel, MotionModelError> {
        let (spam, normalizer, id) = Spam::load(dir, device)?;
        let text = SentenceEncoder::from_dir(dir, device)?;
        Ok(MotionModel {
            spam,
            normalizer,
            text,
            id,
        })
    }

    /// The condition of every part: `prompt`'s embedding, replaced by their own
    /// instruction's for the parts in `parts`.
    pub fn condition(&self, prompt: &str, parts: &[(BodyPart, String)]) -> PartText {
        // One sentence at a time: a batch pads, and padding may move the last bits of an
        // embedding, which would change what a seed samples.
        let embed = |t: &str| self.text.encode(&[t])[0];
        let overrides: Vec<_> = parts.iter().map(|(p, t)| (*p, embed(t))).collect();
        part_text(&embed(prompt), &overrides)
    }

    /// A new motion of about `frames` frames ([`FRAMES_PER_TOKEN`] to [`MAX_FRAMES`], in whole token steps).
    pub async fn generate(
        &self,
        prompt: &str,
        parts: &[(BodyPart, String)],
        frames: usize,
        seed: u64,
    ) -> MotionTokens {
        self.generate_with(prompt, parts, frames, &sampling(seed))
            .await
    }

    /// The same with sampling options of one's own (guidance scales, temperature).
    pub async fn generate_with(
        &self,
        prompt: &str,
        parts: &[(BodyPart, String)],
        frames: usize,
        options: &SamplingOptions,
    ) -> MotionTokens {
        self.spam
            .generate(
                &self.condition(prompt, parts),
                frames.clamp(FRAMES_PER_TOKEN, MAX_FRAMES),
                options,
            )
            .await
    }

    /// Frames `from..to` (20 fps) of every part regenerated from `text`.
    pub async fn inbetween(
        &self,
        tokens: &MotionTokens,
        text: &str,
        from: usize,
        to: usize,
        seed: u64,
    ) -> MotionTokens {
        self.spam
            .inbetween(
                tokens,
                &self.condition(text, &[]),
                from,
                to,
                &sampling(seed),
            )
            .await
    }

    /// The `parts` regenerated from `instruction`; the other parts are conditioned on
    /// `rest`, what the whole motion does (its prompt, or a description of it).
    pub async fn edit_parts(
        &self,
        tokens: &MotionTokens,
        instruction: &str,
        parts: &[BodyPart],
        rest: &str,
        seed: u64,
    ) -> MotionTokens {
        self.edit_parts_each(tokens, &each(parts, instruction), rest, seed)
            .await
    }

    /// Each part of `edits` regenerated from its own instruction, all in one generation (the
    /// text condition is per part); a part named twice takes its first instruction. The other
    /// parts keep their tokens and are conditioned on `rest`.
    pub async fn edit_parts_each(
        &self,
        tokens: &MotionTokens,
        edits: &[(BodyPart, String)],
        rest: &str,
        seed: u64,
    ) -> MotionTokens {
        let parts: Vec<BodyPart> = edits.iter().map(|(p, _)| *p).collect();
        self.spam
            .edit_parts(
                tokens,
                &self.condition(rest, edits),
                &parts,
                &sampling(seed),
            )
            .await
    }

    /// The `parts` regenerated from `instruction` over frames `frames` (20 fps) only: a clip
    /// on a body-part track. The other parts, conditioned on `rest`, and the chosen parts
    /// outside the span keep their tokens, but for [`crate::model::edit::SEAM_STEPS`] steps
    /// either side of the span's ends, where the parts move into and out of the clip.
    pub async fn edit_parts_span(
        &self,
        tokens: &MotionTokens,
        instruction: &str,
        parts: &[BodyPart],
        rest: &str,
        frames: std::ops::Range<usize>,
        seed: u64,
    ) -> MotionTokens {
        self.spam
            .edit_parts_span(
                tokens,
                &self.condition(rest, &each(parts, instruction)),
                parts,
                steps_of(frames),
                &sampling(seed),
            )
            .await
    }

    /// The `parts` regenerated over frames `frames` (20 fps) from the condition of what the
    /// rest of the body does (`rest`, and the parts' own instructions in `own`), the other
    /// parts and the frames around kept: a clip taken off.
    pub async fn regenerate_parts_span(
        &self,
        tokens: &MotionTokens,
        parts: &[BodyPart],
        rest: &str,
        own: &[(BodyPart, String)],
        frames: std::ops::Range<usize>,
        seed: u64,
    ) -> MotionTokens {
        self.spam
            .regenerate_parts_span(
                tokens,
                &self.condition(rest, own),
                parts,
                steps_of(frames),
                &sampling(seed),
            )
            .await
    }

    /// The features (not normalised, 20 fps) of tokens: their decoding, or, where body-part
    /// clips lie on them as layers, the base motion with the clips' parts laid over their
    /// spans (see [`crate::model::layers`]).
    pub async fn features(&self, tokens: &MotionTokens) -> Features {
        self.features_and_base(tokens).await.0
    }

    /// [`MotionModel::features`], and the base motion's features alone where clips lie on the
    /// tokens as layers (`None` without: the motion is its base). Decoding the base costs a
    /// second pass of the decoder, only for motions with such clips.
    pub async fn features_and_base(&self, tokens: &MotionTokens) -> (Features, Option<Features>) {
        let decoded = self.normalizer.denormalize(&self.spam.decode(tokens).await);
        if tokens.base_patches().is_empty() {
            return (decoded, None);
        }
        let base = self
            .normalizer
            .denormalize(&self.spam.decode(&tokens.base()).await);
        let composed = layers::compose(&base, &decoded, &layers::layer_weights(tokens));
        (composed, Some(base))
    }

    /// Joint positions of tokens (metres, 20 fps).
    pub async fn joints(&self, tokens: &MotionTokens) -> Vec<Pose> {
        features_to_joints(&self.features(tokens).await)
    }
}

/// The same instruction for each of `parts`.
fn each(parts: &[BodyPart], instruction: &str) -> Vec<(BodyPart, String)> {
    parts
        .iter()
        .map(|p| (*p, instruction.to_string()))
        .collect()
}

/// The token steps (of 4 frames) that cover `frames` (20 fps).
pub fn steps_of(frames: std::ops::Range<usize>) -> std::ops::Range<usize> {
    frames.start / FRAMES_PER_TOKEN..frames.end.div_ceil(FRAMES_PER_TOKEN)
}

/// Default sampling with a seed.
pub fn sampling(seed: u64) -> SamplingOptions {
    SamplingOptions {
        seed,
        ..Default::default()
    }
}
