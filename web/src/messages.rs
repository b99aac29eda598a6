//! What the page and its inference worker say to each other. Messages cross the worker
//! boundary as JSON text, so both sides share these types and nothing else.

use coma::model::generate::MotionTokens;
use coma::share::Edit;
use serde::{Deserialize, Serialize};

/// A body part in the user's words: "left arm", "right arm", "left leg", "right leg".
pub type PartName = String;

/// A request from the page to the worker.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Request {
    /// Fetch the models under `base` (a URL folder such as `static/models/`) and load them,
    /// on `backend` when one is asked for (the page's `?backend=` query), else on the best
    /// one the browser has.
    Load {
        base: String,
        #[serde(default)]
        backend: Option<Backend>,
    },
    /// The whole CoMA loop: plan `prompt` (with the LLM in `llm`, else the built-in planner),
    /// then generate, edit, review for up to `rounds` rounds and blend. `plan` (a plan's JSON,
    /// e.g. a link's) skips planning; `seconds` stretches or shrinks the plan to that length.
    Run {
        prompt: String,
        seed: u64,
        rounds: usize,
        #[serde(default)]
        seconds: Option<f64>,
        #[serde(default)]
        llm: Option<LlmSettings>,
        #[serde(default)]
        plan: Option<String>,
    },
    /// A new motion of `seconds` from `prompt`; `parts` give some body parts their own
    /// instruction.
    Generate {
        prompt: String,
        seconds: f64,
        seed: u64,
        parts: Vec<(PartName, String)>,
    },
    /// Regenerate frames `from..to` (20 fps) of every part from `text`. `plan` (JSON) lays
    /// its segments' paths on the result, as on every request that carries tokens.
    InBetween {
        tokens: MotionTokens,
        text: String,
        from: usize,
        to: usize,
        seed: u64,
        #[serde(default)]
        plan: Option<String>,
    },
    /// Regenerate the named parts from `text`; the others keep doing what they do.
    EditParts {
        tokens: MotionTokens,
        text: String,
        parts: Vec<PartName>,
        seed: u64,
        #[serde(default)]
        plan: Option<String>,
    },
    /// Decode tokens (from a share link) into a motion.
    Decode {
        tokens: MotionTokens,
        #[serde(default)]
        plan: Option<String>,
    },
}

/// An OpenAI-compatible endpoint, as the Settings panel keeps it. The key crosses to the
/// worker inside a [`Request::Run`] and goes nowhere else: Debug hides it, and nothing that
/// is shared or exported holds these settings.
#[derive(Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct LlmSettings {
    pub base_url: String,
    pub model: String,
    #[serde(default)]
    pub api_key: String,
    #[serde(default)]
    pub vision_model: String,
}

impl LlmSettings {
    /// The settings when they name an endpoint and a model; `None` means no LLM (nothing is
    /// sent anywhere).
    pub fn active(&self) -> Option<LlmSettings> {
        let trimmed = LlmSettings {
            base_url: self.base_url.trim().to_string(),
            model: self.model.trim().to_string(),
            api_key: self.api_key.trim().to_string(),
            vision_model: self.vision_model.trim().to_string(),
        };
        (!trimmed.base_url.is_empty() && !trimmed.model.is_empty()).then_some(trimmed)
    }
}

impl std::fmt::Debug for LlmSettings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LlmSettings")
            .field("base_url", &self.base_url)
            .field("model", &self.model)
            .field("api_key", &if self.api_key.is_empty() { "" } else { "***" })
            .field("vision_model", &self.vision_model)
            .finish()
    }
}

/// Which compute backend the worker runs the models on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Backend {
    WebGpu,
    /// The pure-Rust CPU backend, where WebGPU is missing.
    Cpu,
}

/// A generated or decoded motion.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Motion {
    pub tokens: MotionTokens,
    /// Joint positions per frame (20 fps, metres, Y up), 22 joints.
    pub joints: Vec<[[f32; 3]; 22]>,
    /// HumanML3D features per frame (not normalised), for the NPY export.
    pub features: Vec<Vec<f32>>,
}

/// A reply from the worker.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Reply {
    /// The worker's wasm is running and takes requests.
    Ready,
    /// Progress of the current request: `stage` in words, `done` of `total` units.
    Progress {
        stage: String,
        done: u64,
        total: u64,
    },
    /// The models are loaded.
    Loaded {
        model_id: String,
        backend: Backend,
        /// Why WebGPU is not used, when it is not.
        note: Option<String>,
        bytes: u64,
        millis: f64,
        /// What did not load and what the page does without it (no evaluator: no review; no
        /// vocabulary: the built-in planner only).
        #[serde(default)]
        missing: Vec<String>,
    },
    /// The result of a Generate, InBetween, EditParts or Decode request.
    Motion {
        motion: Motion,
        millis: f64,
        /// Paths of the plan that could not be laid (the motion keeps its own root there).
        #[serde(default)]
        notes: Vec<String>,
    },
    /// A Run has its plan (the [`coma::agents::plan::Plan`] as JSON); the motion follows.
    Plan { plan: String },
    /// A step of a Run ended: one line for the user, `done` of about `total` steps.
    Step { line: String, done: u64, total: u64 },
    /// A Run's result: the motion, the plan it followed, every step as a link records it,
    /// the planner's and the run's notes, and how the review scored each segment.
    Run {
        motion: Motion,
        plan: String,
        history: Vec<Edit>,
        notes: Vec<String>,
        scores: Vec<SegmentScores>,
        millis: f64,
    },
    /// The request failed; the page keeps its last good state.
    Error { message: String },
}

/// How the reviewer scored one segment: the evaluator's 0–100 similarity of its text with its
/// motion before and after review (none without an evaluator), and the rounds it took.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SegmentScores {
    pub before: Option<f64>,
    pub after: Option<f64>,
    pub rounds: usize,
    /// Rounds whose corrections were kept.
    pub kept: usize,
}

/// Encodes a message for `postMessage`.
pub fn to_json<T: Serialize>(message: &T) -> String {
    serde_json::to_string(message).expect("messages serialise")
}

/// Decodes a message, with a readable error for anything else.
pub fn from_json<T: for<'de> Deserialize<'de>>(text: &str) -> Result<T, String> {
    serde_json::from_str(text).map_err(|e| format!("unreadable message: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn llm_settings_hide_the_key_and_need_an_endpoint_and_a_model() {
        let settings = LlmSettings {
            base_url: " http://127.0.0.1:11434/v1 ".into(),
            model: "qwen2.5:7b".into(),
            api_key: "sk-very-secret".into(),
            vision_model: String::new(),
        };
        let shown = format!("{settings:?}");
        assert!(
            !shown.contains("sk-very") && shown.contains("***"),
            "{shown}"
        );
        let active = settings.active().unwrap();
        assert_eq!(active.base_url, "http://127.0.0.1:11434/v1");
        let shown = format!(
            "{:?}",
            Request::Run {
                prompt: "p".into(),
                seed: 0,
                rounds: 0,
                seconds: None,
                llm: Some(active),
                plan: None,
            }
        );
        assert!(!shown.contains("sk-very"), "{shown}");
        assert_eq!(LlmSettings::default().active(), None);
        let no_model = LlmSettings {
            model: " ".into(),
            ..settings
        };
        assert_eq!(no_model.active(), None);
    }

    #[test]
    fn messages_round_trip_as_json() {
        let request = Request::Generate {
            prompt: "a person walks forward".into(),
            seconds: 4.0,
            seed: 7,
            parts: vec![("left arm".into(), "waves".into())],
        };
        let text = to_json(&request);
        assert!(text.contains(r#""type":"generate""#), "{text}");
        assert_eq!(from_json::<Request>(&text).unwrap(), request);
        let reply = Reply::Loaded {
            model_id: "0123456789abcdef".into(),
            backend: Backend::Cpu,
            note: Some("no WebGPU adapter".into()),
            bytes: 10,
            millis: 1.5,
            missing: vec![],
        };
        assert_eq!(from_json::<Reply>(&to_json(&reply)).unwrap(), reply);
        let run = Request::Run {
            prompt: "a person bows".into(),
            seed: 1,
            rounds: 2,
            seconds: None,
            llm: None,
            plan: None,
        };
        assert_eq!(from_json::<Request>(&to_json(&run)).unwrap(), run);
        // The page's older requests, without a plan, still read.
        let decode = r#"{"type":"decode","tokens":[[[1,2]]]}"#;
        assert!(matches!(
            from_json::<Request>(decode).unwrap(),
            Request::Decode { plan: None, .. }
        ));
        assert!(from_json::<Request>("{\"type\":\"launch\"}")
            .unwrap_err()
            .starts_with("unreadable message"));
    }
}
