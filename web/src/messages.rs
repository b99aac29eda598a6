//! What the page and its inference worker say to each other. Messages cross the worker
//! boundary as JSON text, so both sides share these types and nothing else.

use coma::model::generate::MotionTokens;
use serde::{Deserialize, Serialize};

/// A body part in the user's words: "left arm", "right arm", "left leg", "right leg".
pub type PartName = String;

/// A request from the page to the worker.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Request {
    /// Fetch the models under `base` (a URL folder such as `static/models/`) and load them.
    Load { base: String },
    /// A new motion of `seconds` from `prompt`; `parts` give some body parts their own
    /// instruction.
    Generate {
        prompt: String,
        seconds: f64,
        seed: u64,
        parts: Vec<(PartName, String)>,
    },
    /// Regenerate frames `from..to` (20 fps) of every part from `text`.
    InBetween {
        tokens: MotionTokens,
        text: String,
        from: usize,
        to: usize,
        seed: u64,
    },
    /// Regenerate the named parts from `text`; the others keep doing what they do.
    EditParts {
        tokens: MotionTokens,
        text: String,
        parts: Vec<PartName>,
        seed: u64,
    },
    /// Decode tokens (from a share link) into a motion.
    Decode { tokens: MotionTokens },
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
    },
    /// The result of a Generate, InBetween, EditParts or Decode request.
    Motion { motion: Motion, millis: f64 },
    /// The request failed; the page keeps its last good state.
    Error { message: String },
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
        };
        assert_eq!(from_json::<Reply>(&to_json(&reply)).unwrap(), reply);
        assert!(from_json::<Request>("{\"type\":\"launch\"}")
            .unwrap_err()
            .starts_with("unreadable message"));
    }
}
