//! The engine: one place that runs the product's pipeline for the page's worker, the command
//! line and the evaluation. A [`Session`] holds the loaded models (SPAM with its sentence
//! encoder, the evaluator, the training vocabulary); it takes a typed [`Command`], reports
//! [`Progress`] while it works, and answers with a typed [`Outcome`]. It decides every
//! fallback once (no vocabulary, no LLM, an LLM that fails: see [`planning`]) and fits the
//! plan to the length asked for, so the page and the command line agree.
//!
//! ```text
//!  page ─ Request ─► worker ─ Command ─► Session ─► planner ─► pipeline (SPAM, reviewer) ─┐
//!  CLI  ─ args ────────────── Command ─►   │                                               │
//!  eval ───────────────────── Command ─►   └──────────── Outcome (plan, tokens, motion) ◄──┘
//! ```
//!
//! Everything is async because the model's reads from a browser's WebGPU device are; natively
//! the futures complete at once and [`crate::executor::block_on`] drives them.

pub mod command;
pub mod planning;
pub mod progress;

pub use command::{Command, Llm, Motion, Outcome, Progress, RunOutcome, SessionError};
pub use planning::{plan_prompt, PlanningContext};

use crate::agents::llm::Transport;
use crate::agents::pipeline::{self, RunOptions};
use crate::agents::reviewer::Scorer;
use crate::dataset::Vocabulary;
use crate::features::{
    features_to_joints, reference_fit, with_joint_rotations, with_reference_bones,
    with_reference_bones_fitted, FeatureFrame, Features, VELOCITIES,
};
use crate::feet::plant_feet;
use crate::model::evaluator::{Evaluator, EvaluatorConfig};
use crate::model::layers;
use crate::model::motion_model::sampling;
use crate::model::tokens::MotionTokens;
use crate::model::MotionModel;
use crate::plan::Plan;
use crate::skeleton::{lowest_joint, BodyPart, SkeletonFit};
use crate::timing::{frames_for_seconds, seconds};
use progress::{run_event_line, run_steps, Steps};

/// The vocabulary's file name beside the weights.
pub const VOCABULARY_FILE: &str = "vocabulary.json";

/// The loaded models and what they answer.
pub struct Session {
    model: MotionModel,
    evaluator: Option<(Evaluator, EvaluatorConfig)>,
    vocabulary: Option<Vocabulary>,
}

impl Session {
    /// A session of `model` with the evaluator and the vocabulary where they loaded. Returns
    /// the session and, for what did not load, a line saying what works without it (no
    /// evaluator: motions are not reviewed; no vocabulary: the built-in planner plans even
    /// with an LLM set).
    pub fn new(
        model: MotionModel,
        evaluator: Result<(Evaluator, EvaluatorConfig), String>,
        vocabulary: Result<Vocabulary, String>,
    ) -> (Session, Vec<String>) {
        let mut missing = Vec::new();
        let evaluator = evaluator
            .map_err(|e| missing.push(format!("the evaluator ({e}): motions are not reviewed")))
            .ok();
        let vocabulary = vocabulary
            .map_err(|e| {
                missing.push(format!(
                    "the model's vocabulary ({e}): the built-in planner plans even with an LLM set"
                ))
            })
            .ok();
        let session = Session {
            model,
            evaluator,
            vocabulary,
        };
        (session, missing)
    }

    /// The session of the model in a folder (the default one is `static/models`): SPAM and
    /// the sentence encoder must load; the evaluator and the vocabulary may be missing.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn load(
        dir: &std::path::Path,
        device: &burn::tensor::Device,
    ) -> Result<(Session, Vec<String>), SessionError> {
        let model = MotionModel::load(dir, device).map_err(|e| {
            SessionError(format!("the model in {} does not load: {e}", dir.display()))
        })?;
        let evaluator =
            Evaluator::load(dir, &burn::tensor::Device::flex()).map_err(|e| e.to_string());
        let vocabulary = read_vocabulary(&dir.join(VOCABULARY_FILE));
        Ok(Session::new(model, evaluator, vocabulary))
    }

    /// The motion model.
    pub fn model(&self) -> &MotionModel {
        &self.model
    }

    /// The training vocabulary, where it loaded.
    pub fn vocabulary(&self) -> Option<&Vocabulary> {
        self.vocabulary.as_ref()
    }

    /// The evaluator as the reviewer's judge, where it loaded.
    pub fn scorer(&self) -> Option<Scorer<'_>> {
        self.evaluator.as_ref().map(|(evaluator, config)| Scorer {
            evaluator,
            config,
            model: &self.model,
        })
    }

    /// MiniLM's embedding of one sentence.
    fn embed(&self, text: &str) -> Vec<f32> {
        self.model.text.encode(&[text])[0].to_vec()
    }

    /// Carries out `command`, reporting progress; `llm` plans and judges where it is on.
    pub async fn execute<T: Transport>(
        &self,
        command: Command,
        llm: &Llm<'_, T>,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<Outcome, SessionError> {
        match command {
            Command::Plan { prompt, seconds } => {
                let mut steps = Steps::new(progress);
                let plan = self.plan(&prompt, None, seconds, llm, &mut steps).await?;
                steps.report(Progress::Planned { plan: plan.clone() });
                Ok(Outcome::Plan { plan })
            }
            Command::Run {
                prompt,
                seed,
                rounds,
                seconds,
                plan,
            } => {
                let run = self
                    .run(
                        &prompt,
                        plan,
                        seconds,
                        RunOptions { rounds, seed },
                        llm,
                        progress,
                    )
                    .await?;
                Ok(Outcome::Run(Box::new(run)))
            }
            Command::Generate {
                prompt,
                seconds,
                seed,
                parts,
                guidance,
            } => {
                if prompt.trim().is_empty() {
                    return Err("type what the person should do first".into());
                }
                let mut options = sampling(seed);
                match guidance {
                    Some(g) if g.is_finite() && g >= 0.0 => options.base_guidance = g,
                    Some(g) => {
                        return Err(format!("the guidance must be 0 or more, not {g}").into())
                    }
                    None => {}
                }
                let frames = frames_for_seconds(seconds);
                let tokens = self
                    .model
                    .generate_with(&prompt, &parts, frames, &options)
                    .await;
                self.motion_outcome(tokens, None).await
            }
            Command::InBetween {
                tokens,
                text,
                from,
                to,
                seed,
                plan,
            } => {
                self.fits(&tokens)?;
                let frames = tokens.frames();
                if from >= to || from >= frames {
                    return Err(format!(
                        "choose a time range inside the motion (0 to {:.1} s)",
                        seconds(frames)
                    )
                    .into());
                }
                // Every part through all layers over the range: clips there are overwritten,
                // the ones elsewhere stay layers.
                let edited = self
                    .model
                    .inbetween(&tokens, &text, from, to.min(frames), seed)
                    .await
                    .keeping_layers_of(&tokens);
                self.motion_outcome(edited, plan.as_ref()).await
            }
            Command::EditParts {
                tokens,
                text,
                parts,
                seed,
                plan,
            } => {
                self.fits(&tokens)?;
                if parts.is_empty() {
                    return Err("choose at least one body part to edit".into());
                }
                let edited = self
                    .edit_parts(&tokens, &text, &parts, seed)
                    .await
                    .keeping_layers_of(&tokens);
                self.motion_outcome(edited, plan.as_ref()).await
            }
            Command::EditClips {
                tokens,
                before,
                plan,
                seed,
            } => {
                self.fits(&tokens)?;
                let (tokens, _) =
                    pipeline::edit_clips(&self.model, &before, &plan, tokens, seed).await?;
                self.motion_outcome(tokens, Some(&plan)).await
            }
            Command::Decode { tokens, plan } => {
                self.fits(&tokens)?;
                self.motion_outcome(tokens, plan.as_ref()).await
            }
        }
    }

    /// The plan of `prompt` (or `given`) with this session's vocabulary and sentence encoder.
    async fn plan<T: Transport>(
        &self,
        prompt: &str,
        given: Option<Plan>,
        seconds: Option<f64>,
        llm: &Llm<'_, T>,
        steps: &mut Steps<'_>,
    ) -> Result<Plan, SessionError> {
        let embed = |s: &str| self.embed(s);
        let context = PlanningContext {
            vocabulary: self.vocabulary.as_ref(),
            embed: Some(&embed),
        };
        planning::plan_with(prompt, given, seconds, llm, &context, steps).await
    }

    /// Plans (unless a plan is given), then runs the loop and decodes the motion.
    async fn run<T: Transport>(
        &self,
        prompt: &str,
        given: Option<Plan>,
        seconds: Option<f64>,
        options: RunOptions,
        llm: &Llm<'_, T>,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<RunOutcome, SessionError> {
        let mut steps = Steps::new(progress);
        let plan = self.plan(prompt, given, seconds, llm, &mut steps).await?;
        steps.report(Progress::Planned { plan: plan.clone() });
        steps.expect(run_steps(&plan, options.rounds));
        let scorer = self.scorer();
        let run = pipeline::run(
            &self.model,
            scorer.as_ref(),
            llm.client(),
            plan,
            options,
            &mut |event| steps.step(run_event_line(&event)),
        )
        .await;
        let (motion, path_notes) = self.motion(run.tokens, Some(&run.plan)).await;
        let paths = pipeline::path_reports(&run.plan, &motion.tokens, &motion.features);
        let notes = run.plan.notes.iter().chain(&run.notes).cloned().collect();
        Ok(RunOutcome {
            motion,
            plan: run.plan,
            history: run.history,
            segments: run.segments,
            paths,
            notes,
            path_notes,
        })
    }

    /// The chosen parts regenerated from `text`, the rest conditioned on a description of
    /// what the whole motion does now.
    async fn edit_parts(
        &self,
        tokens: &MotionTokens,
        text: &str,
        parts: &[BodyPart],
        seed: u64,
    ) -> MotionTokens {
        let rest = crate::posecodes::describe_motion(&self.model.joints(tokens).await);
        self.model
            .edit_parts(tokens, text, parts, &rest, seed)
            .await
    }

    /// Tokens from outside must fit the loaded model.
    fn fits(&self, tokens: &MotionTokens) -> Result<(), SessionError> {
        let vq = &self.model.spam.vq_config;
        tokens
            .fits(vq.layers, vq.codebook_size)
            .map_err(|e| SessionError(e.to_string()))
    }

    async fn motion_outcome(
        &self,
        tokens: MotionTokens,
        plan: Option<&Plan>,
    ) -> Result<Outcome, SessionError> {
        let (motion, notes) = self.motion(tokens, plan).await;
        Ok(Outcome::Motion { motion, notes })
    }

    /// The motion of `tokens` with the paths of `plan` laid on its root, finished (see
    /// [`finished`]); the notes say which paths could not be laid and which key poses could
    /// not be met in full.
    ///
    /// Body-part clips laid as layers on the tokens are composed over the base motion
    /// ([`crate::model::layers`]) where the tokens turn into features, and once more at
    /// the end: the base motion is finished on its own (skeleton, key postures, planted feet)
    /// and the clips' parts are taken over their spans from the motion finished with them.
    /// Fitting the skeleton, laying key poses and planting the feet read the whole motion (a
    /// mean shape of the hips and collars, the floor, where the feet carry the body), so a
    /// clip would otherwise still move frames outside its span, a leg's clip most; this way
    /// the frames outside the clips' spans are the base motion's exactly, whatever the clip.
    async fn motion(&self, tokens: MotionTokens, plan: Option<&Plan>) -> (Motion, Vec<String>) {
        let (features, base, notes) = match plan {
            Some(plan) => pipeline::motion_features_and_base(&self.model, plan, &tokens).await,
            None => {
                let (features, base) = self.model.features_and_base(&tokens).await;
                (features, base, Vec::new())
            }
        };
        // One skeleton for both, the base's: its triangles and floor do not follow a clip.
        let fit = reference_fit(base.as_deref().unwrap_or(&features));
        let (features, posture_notes) = finished(&features, &fit, &tokens, plan);
        let features = match base {
            None => features,
            Some(base) => {
                let (base, _) = finished(&base, &fit, &tokens, plan);
                let weights = layers::layer_weights(&tokens);
                let mut composed = layers::compose(&base, &features, &weights);
                // Joint by joint, easing between two poses shortens bones: the frames under a
                // clip once more on the one skeleton, no lower than the finished base stands
                // (and the velocities of the frame before, which lead into them). The others
                // are the base's as they are.
                let mut fit = fit;
                fit.floor = lowest_joint(&features_to_joints(&base));
                let fixed = with_reference_bones_fitted(&composed, &fit);
                let under = |t: usize| weights.get(t).is_some_and(|w| w.iter().any(|&x| x > 0.0));
                for (t, row) in composed.iter_mut().enumerate() {
                    if under(t) {
                        *row = fixed[t];
                    } else if under(t + 1) {
                        row[VELOCITIES].copy_from_slice(&fixed[t][VELOCITIES]);
                    }
                }
                composed
            }
        };
        let joints = features_to_joints(&features)
            .iter()
            .map(|p| p.map(|j| j.map(|v| v as f32)))
            .collect();
        let motion = Motion {
            tokens,
            joints,
            features,
        };
        (motion, notes.into_iter().chain(posture_notes).collect())
    }
}

/// Features with their paths laid (not normalised, 20 fps) as the engine hands them out: on
/// the reference skeleton of `fit`, the plan's key postures laid, the feet planted; with the
/// notes of the key poses that could not be met in full.
///
/// Every motion the engine answers with is finished here: its rotations become those of its
/// joints ([`with_joint_rotations`]), and it gets the one skeleton ([`with_reference_bones`]):
/// the model predicts each joint on its own, so its bones stretch; fixed once in the
/// features, the joints shown, the BVH, the JSON and both NPY exports all describe the same
/// motion on the same bones. Here too its feet are planted ([`plant_feet`]), whatever made
/// it.
fn finished(
    features: &[FeatureFrame],
    fit: &SkeletonFit,
    tokens: &MotionTokens,
    plan: Option<&Plan>,
) -> (Features, Vec<String>) {
    let features = with_reference_bones_fitted(&with_joint_rotations(features), fit);
    let (features, notes) = match plan {
        Some(plan)
            if plan.segments.iter().any(|s| s.postures.is_some())
                || plan.clips.iter().any(|c| c.postures.is_some()) =>
        {
            let (laid, notes) = pipeline::lay_postures(plan, tokens, &features);
            // Key poses keep the bone lengths but shape the hips and collars their own
            // way, which a rigid skeleton (the BVH's) cannot follow: once more on the
            // one skeleton, so posture-built motions leave here as every other does.
            (with_reference_bones(&laid), notes)
        }
        _ => (features, Vec::new()),
    };
    // Feet planted last, on whatever was laid, so every motion leaves with them.
    let paths = plan.map_or_else(Vec::new, |plan| pipeline::path_ranges(plan, tokens));
    (plant_feet(&features, &paths), notes)
}

/// Decoded features (not normalised) as the engine hands them out when no plan lays paths or
/// key postures on them: on the reference skeleton, feet planted. The evaluation measures
/// SPAM's motions through it, so it measures what a user sees.
pub fn finish(features: &[FeatureFrame]) -> Features {
    plant_feet(&with_reference_bones(&with_joint_rotations(features)), &[])
}

/// The training vocabulary from its file.
#[cfg(not(target_arch = "wasm32"))]
pub fn read_vocabulary(path: &std::path::Path) -> Result<Vocabulary, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    serde_json::from_str(&text).map_err(|e| format!("{} does not read: {e}", path.display()))
}
