//! What the engine is asked and what it answers, as types that cross the worker boundary and
//! the command line unchanged: a [`Command`] in, [`Progress`] while it works, an [`Outcome`]
//! or a [`SessionError`] out.

use crate::agents::llm::{LlmClient, Transport};
use crate::agents::pipeline::{PathReport, SegmentRun};
use crate::features::{FeatureFrame, Features, FEATURE_DIM};
use crate::model::tokens::MotionTokens;
use crate::plan::Plan;
use crate::share::{Edit, SegmentScores};
use crate::skeleton::BodyPart;
use serde::{Deserialize, Serialize};

/// One request to the engine.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Command {
    /// Plan `prompt` only: segments, durations, base motions, part edits and paths.
    /// `seconds` stretches or shrinks the plan to that length.
    Plan {
        prompt: String,
        #[serde(default)]
        seconds: Option<f64>,
    },
    /// The whole CoMA loop: plan `prompt` (or follow `plan`, e.g. a link's), then generate,
    /// edit the parts, review up to `rounds` rounds per segment, blend and lay the paths.
    Run {
        prompt: String,
        seed: u64,
        rounds: usize,
        #[serde(default)]
        seconds: Option<f64>,
        #[serde(default)]
        plan: Option<Plan>,
    },
    /// A new motion of `seconds` (2 to 9.8) from `prompt`, without the agents; `parts` give
    /// some body parts their own instruction.
    Generate {
        prompt: String,
        seconds: f64,
        seed: u64,
        #[serde(default)]
        parts: Vec<(BodyPart, String)>,
        /// The base transformer's classifier-free guidance scale, 0 or more (default 4): 1
        /// follows the learnt conditional distribution, more follows the text harder.
        #[serde(default)]
        guidance: Option<f32>,
    },
    /// Frames `from..to` (20 fps) of every part regenerated from `text`. `plan` lays its
    /// segments' paths on the result, as on every command that carries tokens. Body-part
    /// clips laid as layers on `tokens` stay layers outside the range; inside it, what the
    /// text made is the base.
    InBetween {
        tokens: MotionTokens,
        text: String,
        from: usize,
        to: usize,
        seed: u64,
        #[serde(default)]
        plan: Option<Plan>,
    },
    /// The named parts regenerated from `text`; the others keep doing what they do, and so do
    /// the clips laid as layers on them. The named parts' clips become part of the base.
    EditParts {
        tokens: MotionTokens,
        text: String,
        parts: Vec<BodyPart>,
        seed: u64,
        #[serde(default)]
        plan: Option<Plan>,
    },
    /// The motion of `tokens`, made under `before`, changed to follow `plan`, which differs
    /// from it in its body-part clips only (one moved, added, reworded or deleted): only the
    /// spans of the clips that changed are regenerated. Clips are layers over the base
    /// (whole-body) motion: a clip taken off gives back the base exactly, and the frames
    /// outside the changed spans stay as they were.
    EditClips {
        tokens: MotionTokens,
        before: Plan,
        plan: Plan,
        seed: u64,
    },
    /// The motion of tokens, e.g. a share link's, with its plan's paths laid on the root.
    Decode {
        tokens: MotionTokens,
        #[serde(default)]
        plan: Option<Plan>,
    },
}

/// A motion as the engine hands it out: its tokens, and what they decode to at 20 fps.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Motion {
    /// The final tokens, with the base motion's codes under the body-part clips laid as
    /// layers ([`MotionTokens::base_patches`]): the next command takes them as they are.
    pub tokens: MotionTokens,
    /// Joint positions per frame: 22 joints, metres, Y up, starting at the origin facing +Z,
    /// every bone of the reference skeleton's length (see [`crate::skeleton::fixed_bones`]).
    pub joints: Vec<[[f32; 3]; 22]>,
    /// HumanML3D features per frame (not normalised), with the plan's paths laid on the root;
    /// they describe exactly `joints`.
    #[serde(with = "feature_rows")]
    pub features: Features,
}

/// What a [`Command::Run`] made: the motion, the plan it followed, every step as a share link
/// records it, how the review went per segment, how the paths were walked, and the notes (the
/// planner's and the reviewer's, then the paths that could not be laid).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunOutcome {
    pub motion: Motion,
    pub plan: Plan,
    pub history: Vec<Edit>,
    pub segments: Vec<SegmentRun>,
    pub paths: Vec<PathReport>,
    /// What the planner and the reviewer changed, dropped or could not do.
    pub notes: Vec<String>,
    /// Paths of the plan that could not be laid (the motion keeps its own root there).
    pub path_notes: Vec<String>,
}

impl RunOutcome {
    /// Every note, the paths' last.
    pub fn all_notes(&self) -> Vec<String> {
        self.notes.iter().chain(&self.path_notes).cloned().collect()
    }

    /// How the review scored each segment, as the page shows and a link records it.
    pub fn scores(&self) -> Vec<SegmentScores> {
        self.segments
            .iter()
            .map(|s| SegmentScores {
                before: s.score_before,
                after: s.score_after,
                rounds: s.rounds.len(),
                kept: s.rounds.iter().filter(|r| r.accepted).count(),
            })
            .collect()
    }
}

/// The engine's answer to a [`Command`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Outcome {
    /// The answer to [`Command::Plan`].
    Plan { plan: Plan },
    /// The answer to [`Command::Run`].
    Run(Box<RunOutcome>),
    /// The answer to the commands that make or change tokens without the agents; the notes
    /// say which paths of the plan could not be laid.
    Motion { motion: Motion, notes: Vec<String> },
}

/// What the engine reports while it works.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Progress {
    /// A step ended: one line for the user, `done` of about `total` steps (reviews stop early
    /// when there is nothing to correct, so `total` is an upper bound).
    Step { line: String, done: u64, total: u64 },
    /// The run has its plan (the page shows it before the motion exists).
    Planned { plan: Plan },
}

/// Why a command could not be carried out, in words for the user; the caller keeps its last
/// good state.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct SessionError(pub String);

impl From<String> for SessionError {
    fn from(message: String) -> Self {
        SessionError(message)
    }
}

impl From<&str> for SessionError {
    fn from(message: &str) -> Self {
        SessionError(message.to_string())
    }
}

/// The language model a command may use.
pub enum Llm<'a, T: Transport> {
    /// None configured: the built-in planner plans and the evaluator judges.
    Off,
    /// This client plans and judges.
    On(&'a LlmClient<T>),
    /// One was configured but cannot be used (why): the built-in planner plans, with a note.
    Unusable(String),
}

impl<T: Transport> Llm<'_, T> {
    /// The client, when there is one to use.
    pub fn client(&self) -> Option<&LlmClient<T>> {
        match self {
            Llm::On(client) => Some(client),
            _ => None,
        }
    }
}

/// Feature rows (263 floats each, more than serde's arrays take) as lists of numbers.
mod feature_rows {
    use super::{FeatureFrame, FEATURE_DIM};
    use serde::{de::Error, Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(rows: &[FeatureFrame], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(rows.iter().map(|r| r.as_slice()))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<FeatureFrame>, D::Error> {
        Vec::<Vec<f32>>::deserialize(d)?
            .into_iter()
            .map(|row| {
                FeatureFrame::try_from(row.as_slice()).map_err(|_| {
                    D::Error::custom(format!(
                        "a feature row of {} numbers ({FEATURE_DIM} expected)",
                        row.len()
                    ))
                })
            })
            .collect()
    }
}
