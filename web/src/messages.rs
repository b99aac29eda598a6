//! What the page and its inference worker say to each other. Messages cross the worker
//! boundary as JSON text; besides loading, the page sends the engine's own [`Command`]s and
//! the worker answers with the engine's [`Progress`] and [`Outcome`], so both sides share the
//! library's types and nothing else.

use coma::dataset::DataTerms;
use coma::session::{Command, Outcome, Progress};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

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
    /// Carry out an engine command; `llm` (the Settings panel's endpoint) plans and judges
    /// where it is given.
    Execute {
        command: Box<Command>,
        #[serde(default)]
        llm: Option<LlmSettings>,
    },
}

/// An OpenAI-compatible endpoint, as the Settings panel keeps it. The key crosses to the
/// worker inside a [`Request::Execute`] and goes nowhere else: Debug hides it, and nothing that
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

/// A reply from the worker.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Reply {
    /// The worker's wasm is running and takes requests.
    Ready,
    /// Progress of loading the models: `stage` in words, `done` of `total` files.
    Loading {
        stage: String,
        done: u64,
        total: u64,
    },
    /// The models are loaded.
    Loaded {
        model_id: String,
        backend: Backend,
        /// Why WebGPU is not used, when it is not (and why one worker, when the CPU backend
        /// runs on one).
        note: Option<String>,
        /// Workers generating on the CPU backend: 2 with the guidance partner (two cores),
        /// else 1; 1 on WebGPU too.
        #[serde(default = "one")]
        workers: u32,
        bytes: u64,
        millis: f64,
        /// What did not load and what the page does without it (no evaluator: no review; no
        /// vocabulary: the built-in planner only).
        #[serde(default)]
        missing: Vec<String>,
        /// The motion data the weights were trained on, per source, with the terms the
        /// weights inherit (from `vocabulary.json`; empty when it did not load).
        #[serde(default)]
        training_data: BTreeMap<String, DataTerms>,
    },
    /// The command in flight reports progress.
    Progress { progress: Progress },
    /// The command is done, in `millis` milliseconds.
    Done { outcome: Outcome, millis: f64 },
    /// The request failed; the page keeps its last good state.
    Error { message: String },
}

/// Serde's default for counts that older messages did not carry.
fn one() -> u32 {
    1
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
            Request::Execute {
                command: Box::new(Command::Plan {
                    prompt: "p".into(),
                    seconds: None,
                }),
                llm: Some(active),
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
        let request = Request::Execute {
            command: Box::new(Command::Generate {
                prompt: "a person walks forward".into(),
                seconds: 4.0,
                seed: 7,
                parts: vec![(coma::skeleton::BodyPart::LeftArm, "waves".into())],
                guidance: None,
            }),
            llm: None,
        };
        let text = to_json(&request);
        assert!(text.contains(r#""type":"generate""#), "{text}");
        assert!(text.contains(r#""left_arm""#), "{text}");
        assert_eq!(from_json::<Request>(&text).unwrap(), request);
        let reply = Reply::Loaded {
            model_id: "0123456789abcdef".into(),
            backend: Backend::Cpu,
            note: Some("no WebGPU adapter".into()),
            workers: 2,
            bytes: 10,
            millis: 1.5,
            missing: vec![],
            training_data: [(
                "hdm05".to_string(),
                DataTerms {
                    licence: "CC BY-SA 3.0".into(),
                    attribution: "HDM05".into(),
                },
            )]
            .into(),
        };
        assert_eq!(from_json::<Reply>(&to_json(&reply)).unwrap(), reply);
        let step = Reply::Progress {
            progress: Progress::Step {
                line: "segment 1: generated".into(),
                done: 1,
                total: 3,
            },
        };
        assert_eq!(from_json::<Reply>(&to_json(&step)).unwrap(), step);
        // Tokens are checked as the message is read.
        let decode = r#"{"type":"execute","command":{"type":"decode","tokens":[[[1,2]]]}}"#;
        let e = from_json::<Request>(decode).unwrap_err();
        assert!(e.contains("4 body parts"), "{e}");
        assert!(from_json::<Request>("{\"type\":\"launch\"}")
            .unwrap_err()
            .starts_with("unreadable message"));
    }
}
