//! The planner's three LLM steps: rewrite, segment, decompose.
//!
//! Each step sends one question with a JSON schema, parses and validates the reply, retries
//! once with the validation error, and otherwise lets the built-in planner do that step (with
//! a note in the plan). The reply is data: texts are cleaned and capped, durations clamped,
//! paths checked by the sandboxed expression evaluator and never run as code.

use super::offline::{self, Embedder};
use crate::agents::llm::{
    parse_json_content, LlmClient, LlmError, Message, ReplyFormat, Transport,
};
use crate::dataset::Vocabulary;
use crate::plan::{
    clamp_seconds, clean_text, Clip, PartEdits, Plan, PlannerKind, Segment, MAX_CLIPS,
    MAX_PLAN_SECONDS, MAX_SEGMENTS,
};
use crate::posture::script::PostureScript;
use crate::posture::track::{PostureTrack, TrackKey, DEFAULT_TRANSITION_SECONDS};
use crate::skeleton::BodyPart;
use crate::trajectory::{CurveSpec, Shape, Trajectory};
use serde::Deserialize;
use serde_json::{json, Value};

/// A step of the planner, reported as it finishes.
#[derive(Clone, Debug, PartialEq)]
pub enum PlanEvent {
    /// The prompt in the model's words.
    Rewritten(String),
    /// The segments' texts and durations in seconds.
    Segmented(Vec<(String, f64)>),
    /// Segment `index` has its base motion, part edits and path.
    Decomposed(usize, Box<Segment>),
}

/// Plans `prompt` with an LLM, step by step, falling back to the built-in rules for any step
/// the LLM fails. `progress` hears each step as it ends.
pub async fn plan<T: Transport>(
    client: &LlmClient<T>,
    prompt: &str,
    vocabulary: &Vocabulary,
    embed: Option<Embedder<'_>>,
    progress: &mut dyn FnMut(&PlanEvent),
) -> Plan {
    let mut notes = Vec::new();
    let offline_plan = offline::plan_for(prompt, Some(vocabulary), embed);
    let context = vocabulary_brief(vocabulary, BRIEF_CHARS);

    // The text the later steps read: the LLM's rewrite, or the user's prompt itself when the
    // rewrite failed (the built-in rules read the prompt better than their own rewrite).
    let (rewritten, source) =
        match ask::<RewriteReply, _>(client, rewrite_messages(&context, prompt), "rewrite")
            .await
            .and_then(|r| clean_text(&r.description).map_err(StepError::Invalid))
        {
            Ok(text) => (text.clone(), text),
            Err(e) => {
                notes.push(e.note("rewrite"));
                (offline_plan.rewritten.clone(), prompt.to_string())
            }
        };
    progress(&PlanEvent::Rewritten(rewritten.clone()));

    let Timeline {
        segments: pieces,
        clips,
    } = match ask::<SegmentReply, _>(client, segment_messages(&rewritten), "segment")
        .await
        .and_then(|r| r.validate().map_err(StepError::Invalid))
    {
        Ok(timeline) => timeline,
        Err(e) => {
            notes.push(e.note("segment"));
            let built_in = offline::plan_for(&source, Some(vocabulary), embed);
            Timeline {
                segments: built_in
                    .segments
                    .into_iter()
                    .map(|s| (s.text, s.seconds))
                    .collect(),
                clips: built_in.clips,
            }
        }
    };
    progress(&PlanEvent::Segmented(pieces.clone()));

    let mut segments = Vec::new();
    for (index, (text, seconds)) in pieces.into_iter().enumerate() {
        let segment = match ask::<DecomposeReply, _>(
            client,
            decompose_messages(&context, &text),
            "decompose",
        )
        .await
        .and_then(|r| r.validate(&text, seconds).map_err(StepError::Invalid))
        {
            Ok(segment) => segment,
            Err(e) => {
                notes.push(e.note(&format!("decompose (segment {})", index + 1)));
                let mut s = offline::plan_for(&text, Some(vocabulary), embed)
                    .segments
                    .remove(0);
                s.seconds = seconds;
                s
            }
        };
        progress(&PlanEvent::Decomposed(index, Box::new(segment.clone())));
        segments.push(segment);
    }
    Plan {
        prompt: prompt.to_string(),
        rewritten,
        segments,
        clips,
        planner: PlannerKind::Llm {
            model: client.config().model.clone(),
        },
        notes,
    }
}

/// Why a step's reply was not used.
#[derive(Debug)]
enum StepError {
    /// The request itself failed (network, key, server).
    Llm(LlmError),
    /// The reply did not parse or did not pass validation, even after one retry.
    Invalid(String),
}

impl StepError {
    fn note(&self, step: &str) -> String {
        let why = match self {
            StepError::Llm(e) => e.to_string(),
            StepError::Invalid(e) => format!("its reply was unusable: {e}"),
        };
        format!("the LLM's {step} step failed ({why}); the built-in planner did that step")
    }
}

/// One question, with one retry that quotes the reply's problem.
async fn ask<R: for<'de> Deserialize<'de> + Schema, T: Transport>(
    client: &LlmClient<T>,
    mut messages: Vec<Message>,
    name: &str,
) -> Result<R, StepError> {
    let format = ReplyFormat::JsonSchema {
        name: format!("coma_{name}"),
        schema: R::schema(),
    };
    for attempt in 0..2 {
        let reply = client
            .chat(&messages, &format)
            .await
            .map_err(StepError::Llm)?;
        match parse_json_content::<R>(&reply.content).and_then(|r| r.check().map(|_| r)) {
            Ok(r) => return Ok(r),
            Err(e) if attempt == 0 => {
                let quoted: String = reply.content.chars().take(2000).collect();
                messages.push(Message::assistant(quoted));
                messages.push(Message::user(format!(
                    "That reply cannot be used: {e}. Answer again with only a JSON object that \
                     follows the schema."
                )));
            }
            Err(e) => return Err(StepError::Invalid(e)),
        }
    }
    unreachable!("the loop returns on its second attempt")
}

/// A reply type with its JSON Schema and a first check of its shape.
trait Schema {
    fn schema() -> Value;
    fn check(&self) -> Result<(), String> {
        Ok(())
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RewriteReply {
    description: String,
}

impl Schema for RewriteReply {
    fn schema() -> Value {
        json!({
            "type": "object",
            "properties": {"description": {"type": "string", "maxLength": 600}},
            "required": ["description"],
            "additionalProperties": false
        })
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SegmentReply {
    segments: Vec<SegmentPiece>,
    /// What some body parts do over a span of their own, across or within segments.
    #[serde(default)]
    clips: Vec<ClipPiece>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ClipPiece {
    parts: Vec<String>,
    text: String,
    start: f64,
    end: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SegmentPiece {
    text: String,
    seconds: f64,
}

impl Schema for SegmentReply {
    fn schema() -> Value {
        json!({
            "type": "object",
            "properties": {"segments": {
                "type": "array", "minItems": 1, "maxItems": MAX_SEGMENTS,
                "items": {
                    "type": "object",
                    "properties": {
                        "text": {"type": "string", "maxLength": 300},
                        "seconds": {"type": "number", "minimum": 2, "maximum": 9.8}
                    },
                    "required": ["text", "seconds"],
                    "additionalProperties": false
                }
            },
            "clips": {
                "type": "array", "maxItems": MAX_CLIPS,
                "items": {
                    "type": "object",
                    "properties": {
                        "parts": {
                            "type": "array", "minItems": 1, "maxItems": 3,
                            "items": {"enum": ["left_arm", "right_arm", "left_leg", "right_leg"]}
                        },
                        "text": {"type": "string", "maxLength": 300},
                        "start": {"type": "number", "minimum": 0, "maximum": MAX_PLAN_SECONDS},
                        "end": {"type": "number", "minimum": 0, "maximum": MAX_PLAN_SECONDS}
                    },
                    "required": ["parts", "text", "start", "end"],
                    "additionalProperties": false
                }
            }},
            "required": ["segments"],
            "additionalProperties": false
        })
    }

    fn check(&self) -> Result<(), String> {
        self.validate().map(|_| ())
    }
}

impl SegmentReply {
    /// The segments' texts and lengths, and the clips checked against them (see
    /// [`Clip::checked`]; clips that overlap on a part are refused, for the LLM to mend).
    fn validate(&self) -> Result<Timeline, String> {
        if self.segments.is_empty() || self.segments.len() > MAX_SEGMENTS {
            return Err(format!(
                "it has {} segments; give 1 to {MAX_SEGMENTS}",
                self.segments.len()
            ));
        }
        let segments = self
            .segments
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let seconds = clamp_seconds(s.seconds)
                    .ok_or_else(|| format!("segment {} has no valid number of seconds", i + 1))?;
                Ok((
                    clean_text(&s.text).map_err(|e| format!("segment {}: {e}", i + 1))?,
                    seconds,
                ))
            })
            .collect::<Result<Vec<_>, String>>()?;
        let seconds: f64 = segments.iter().map(|(_, s)| s).sum();
        if seconds > MAX_PLAN_SECONDS + 1e-6 {
            return Err(format!(
                "its segments last {seconds:.1} s; give at most {MAX_PLAN_SECONDS} s in all"
            ));
        }
        if self.clips.len() > MAX_CLIPS {
            return Err(format!(
                "it has {} clips; give at most {MAX_CLIPS}",
                self.clips.len()
            ));
        }
        let mut clips: Vec<Clip> = Vec::new();
        for (i, c) in self.clips.iter().enumerate() {
            let parts = c
                .parts
                .iter()
                .map(|p| {
                    BodyPart::parse(p).ok_or_else(|| {
                        format!(
                            "clip {}: \"{p}\" is not a body part (left_arm, right_arm, \
                             left_leg, right_leg)",
                            i + 1
                        )
                    })
                })
                .collect::<Result<Vec<_>, String>>()?;
            let clip = Clip {
                parts,
                text: c.text.clone(),
                start: c.start,
                end: c.end,
                postures: None,
            }
            .checked(seconds)
            .map_err(|e| format!("clip {}: {e}", i + 1))?;
            if let Some(other) = clips.iter().find(|o| o.overlaps(&clip)) {
                return Err(format!(
                    "clips \"{}\" and \"{}\" move the same body part at the same time",
                    other.text, clip.text
                ));
            }
            clips.push(clip);
        }
        Ok(Timeline { segments, clips })
    }
}

/// The segment step's answer: the whole-body track's texts and lengths, and the clips of the
/// body-part tracks.
#[derive(Clone, Debug, PartialEq)]
pub struct Timeline {
    pub segments: Vec<(String, f64)>,
    pub clips: Vec<Clip>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DecomposeReply {
    base: String,
    left_arm: Option<String>,
    right_arm: Option<String>,
    left_leg: Option<String>,
    right_leg: Option<String>,
    trajectory: Option<Value>,
    /// Key poses for what the motion model does not know (PRO-Motion's planner): posture
    /// scripts, checked like any other.
    #[serde(default)]
    key_poses: Option<Vec<Value>>,
}

/// Most key poses the LLM may write for one segment.
const MAX_LLM_KEY_POSES: usize = 4;

impl Schema for DecomposeReply {
    fn schema() -> Value {
        let part = json!({"type": ["string", "null"], "maxLength": 300});
        json!({
            "type": "object",
            "properties": {
                "base": {"type": "string", "maxLength": 300},
                "left_arm": part, "right_arm": part, "left_leg": part, "right_leg": part,
                "trajectory": trajectory_schema(),
                "key_poses": {
                    "type": ["array", "null"],
                    "maxItems": MAX_LLM_KEY_POSES,
                    "items": crate::posture::script::schema()
                }
            },
            "required": ["base", "left_arm", "right_arm", "left_leg", "right_leg", "trajectory"],
            "additionalProperties": false
        })
    }

    fn check(&self) -> Result<(), String> {
        self.key_pose_track().map(|_| ())
    }
}

impl DecomposeReply {
    /// The key poses as a whole-body posture track: each script parsed and checked (errors
    /// name the key pose and the constraint, so the retry can fix them).
    fn key_pose_track(&self) -> Result<Option<PostureTrack>, String> {
        match &self.key_poses {
            None => Ok(None),
            Some(list) if list.is_empty() => Ok(None),
            Some(list) if list.len() > MAX_LLM_KEY_POSES => Err(format!(
                "key_poses: at most {MAX_LLM_KEY_POSES} key poses, got {}",
                list.len()
            )),
            Some(list) => {
                let keys = list
                    .iter()
                    .enumerate()
                    .map(|(i, v)| {
                        PostureScript::from_value(v.clone())
                            .map(|script| TrackKey {
                                script,
                                transition: DEFAULT_TRANSITION_SECONDS,
                                turn_deg: 0.0,
                                travel: [0.0, 0.0],
                                jump_m: None,
                            })
                            .map_err(|e| format!("key_poses[{i}]: {e}"))
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                let track = PostureTrack {
                    parts: BodyPart::ALL.to_vec(),
                    keys,
                    repeat: 1,
                    lead_in: 0,
                    returns: false,
                    within: None,
                }
                .checked()
                .map_err(|e| format!("key_poses: {e}"))?;
                Ok(Some(track))
            }
        }
    }
    fn validate(&self, text: &str, seconds: f64) -> Result<Segment, String> {
        let part = |p: &Option<String>, name: &str| -> Result<Option<String>, String> {
            match p.as_deref().map(str::trim) {
                None | Some("") => Ok(None),
                Some(t) if matches!(t.to_lowercase().as_str(), "none" | "null" | "n/a" | "-") => {
                    Ok(None)
                }
                Some(t) => clean_text(t).map(Some).map_err(|e| format!("{name}: {e}")),
            }
        };
        let trajectory = match &self.trajectory {
            None | Some(Value::Null) => None,
            Some(v) => {
                Some(trajectory_from_reply(v.clone()).map_err(|e| format!("trajectory: {e}"))?)
            }
        };
        let postures = self.key_pose_track()?;
        Ok(Segment {
            text: text.to_string(),
            seconds,
            base: clean_text(&self.base).map_err(|e| format!("base: {e}"))?,
            parts: PartEdits {
                left_arm: part(&self.left_arm, "left_arm")?,
                right_arm: part(&self.right_arm, "right_arm")?,
                left_leg: part(&self.left_leg, "left_leg")?,
                right_leg: part(&self.right_leg, "right_leg")?,
            },
            trajectory,
            postures,
        })
    }
}

/// The posture-script vocabulary in a few lines for the LLM, written from the schema so that
/// it always lists the words the parser accepts.
fn posture_vocabulary() -> String {
    let schema = crate::posture::script::schema();
    let kinds = schema["properties"]["constraints"]["items"]["oneOf"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    kinds
        .iter()
        .map(|k| {
            let props = k["properties"].as_object().cloned().unwrap_or_default();
            let fields: Vec<String> = props
                .iter()
                .map(|(name, spec)| {
                    let words = match (&spec["const"], spec["enum"].as_array(), &spec["type"]) {
                        (Value::String(c), _, _) => format!("\"{c}\""),
                        (_, Some(list), _) => list
                            .iter()
                            .filter_map(Value::as_str)
                            .collect::<Vec<_>>()
                            .join("|"),
                        (_, _, Value::String(t)) => t.clone(),
                        _ => "?".into(),
                    };
                    format!("\"{name}\": {words}")
                })
                .collect();
            format!("- {{{}}}", fields.join(", "))
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The built-in shapes by their stable names ("circle_right" is clockwise).
fn shape_names() -> Vec<String> {
    Shape::ALL.iter().map(|s| s.name()).collect()
}

/// The two forms a path takes in a reply: a named shape, or a curve in `t`.
fn trajectory_schema() -> Value {
    json!({
        "anyOf": [
            {"type": "null"},
            {
                "type": "object",
                "properties": {"shape": {"type": "string", "enum": shape_names()}},
                "required": ["shape"],
                "additionalProperties": false
            },
            {
                "type": "object",
                "properties": {
                    "x": {"type": "string", "maxLength": crate::trajectory::expr::MAX_SOURCE_LEN},
                    "z": {"type": "string", "maxLength": crate::trajectory::expr::MAX_SOURCE_LEN},
                    "t0": {"type": "number"},
                    "t1": {"type": "number"}
                },
                "required": ["x", "z", "t0", "t1"],
                "additionalProperties": false
            }
        ]
    })
}

/// A path as a reply writes it: a named shape, or a curve in `t` (models write the ground
/// plane's second axis as `y` as often as `z`).
#[derive(Deserialize)]
#[serde(untagged)]
enum PathReply {
    Shape(ShapeReply),
    Curve(CurveReply),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ShapeReply {
    shape: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CurveReply {
    x: String,
    #[serde(alias = "y")]
    z: String,
    t0: f64,
    t1: f64,
}

/// A path from a reply, checked by the sandboxed evaluator: a shape name from the library,
/// or formulas that parse within the sandbox's limits and make a walkable curve. (The reply's
/// `trajectory` is read as a JSON value first, so that a malformed path gets this message
/// rather than serde's.)
fn trajectory_from_reply(value: Value) -> Result<Trajectory, String> {
    let reply: PathReply = serde_json::from_value(value).map_err(|_| {
        "expected an object with \"shape\" alone, or with \"x\", \"z\", \"t0\" and \"t1\""
            .to_string()
    })?;
    let trajectory = match reply {
        PathReply::Shape(ShapeReply { shape }) => Trajectory::Shape {
            shape: Shape::from_name(&shape).ok_or_else(|| {
                format!("unknown shape (use one of {})", shape_names().join(", "))
            })?,
        },
        PathReply::Curve(CurveReply { x, z, t0, t1 }) => {
            Trajectory::Curve(CurveSpec { x, z, t0, t1 })
        }
    };
    trajectory.validate().map_err(|e| e.to_string())?;
    Ok(trajectory)
}

/// Characters the vocabulary brief may take. Small local models have 2,048-token contexts
/// (CI's SmolLM2-135M among them): with a 2,400-character brief its server counted 2,113
/// tokens in the decompose question alone (the posture vocabulary's JSON-like lines take
/// more tokens per character than prose), so the brief keeps the actions and styles and
/// leaves the example captions and the word list to models with room for them.
pub const BRIEF_CHARS: usize = 1_000;

/// What the motion model knows, for the rewrite and decompose questions, in at most `budget`
/// characters: its actions (a left/right pair as one, `kick-{left|right}-leg`) and styles
/// always; then example captions, one per action, while they fit; then every word of its
/// captions if all of them fit.
pub fn vocabulary_brief(vocabulary: &Vocabulary, budget: usize) -> String {
    let mut actions: Vec<(String, &str)> = Vec::new();
    for (action, example) in &vocabulary.examples {
        let sided = action
            .split('-')
            .map(|w| match w {
                "left" | "right" => "{left|right}",
                w => w,
            })
            .collect::<Vec<_>>()
            .join("-");
        if !actions.iter().any(|(a, _)| *a == sided) {
            actions.push((sided, example));
        }
    }
    let names: Vec<&str> = actions.iter().map(|(a, _)| a.as_str()).collect();
    let styles: Vec<&str> = vocabulary.styles.keys().map(String::as_str).collect();
    let mut brief = format!(
        "Movements the motion model was trained on: {}.\nStyles it knows: {}.",
        names.join(", "),
        styles.join(", ")
    );
    let mut examples = Vec::new();
    let mut room = budget.saturating_sub(brief.len() + 40);
    for (_, example) in &actions {
        let line = format!("\"{example}\"");
        if line.len() + 2 > room {
            break;
        }
        room -= line.len() + 2;
        examples.push(line);
    }
    if !examples.is_empty() {
        brief += &format!("\nExample captions: {}.", examples.join("; "));
    }
    let words = vocabulary.words.join(" ");
    if brief.len() + words.len() + 30 <= budget {
        brief += &format!("\nWords of its captions: {words}.");
    }
    brief
}

fn rewrite_messages(context: &str, prompt: &str) -> Vec<Message> {
    vec![
        Message::system(format!(
            "You prepare prompts for a text-to-motion model that animates one human skeleton \
             (arms, legs, torso, and where the body goes on the ground). It only understands \
             plain physical descriptions in the words of its training captions.\n\n{context}\n\n\
             Rewrite the user's prompt as a concrete description of the body's movements, in \
             time order, using the model's words where you can. Keep style words the model \
             knows. Leave out what does not change the movement: places, names, reasons, \
             emotions it has no style for. Describe named gestures by the movement itself (a \
             military salute becomes raising the right hand to the forehead). Keep every \
             movement, path and body part the prompt asks for. Reply in JSON: \
             {{\"description\": \"...\"}}."
        )),
        Message::user(prompt.to_string()),
    ]
}

fn segment_messages(description: &str) -> Vec<Message> {
    vec![
        Message::system(format!(
            "Split a description of a human movement into 1 to {MAX_SEGMENTS} consecutive \
             segments, {MAX_PLAN_SECONDS} seconds at most in all. Each segment is one \
             complete movement that could be filmed alone; things done at the same time \
             (walking while waving) stay in one segment, and a repeated whole-body action \
             (bowing twice) is one segment per repetition. Give each segment a duration in seconds between 2 and 9.8 (a few steps of walking take \
             about 4 s, a bow about 3 s, a wave about 3 s). Write each segment's text as a \
             full sentence about \"a person\". Something some body parts do over a span \
             of its own, across segments or within one (holding a T-pose through a walk and a \
             run, waving the left hand for the last two seconds), is a clip: its parts (from \
             left_arm, right_arm, left_leg, right_leg), a caption of what they do (\"a person \
             waves the left hand\"), and its start and end in seconds from the start of the \
             first segment; clips on the same part do not overlap. Reply in JSON: \
             {{\"segments\": [{{\"text\": \"...\", \"seconds\": 4}}], \"clips\": \
             [{{\"parts\": [\"left_arm\"], \"text\": \"...\", \"start\": 2, \"end\": 6}}]}}; \
             \"clips\" may be empty."
        )),
        Message::user(description.to_string()),
    ]
}

fn decompose_messages(context: &str, segment: &str) -> Vec<Message> {
    vec![
        Message::system(format!(
            "You turn one segment of a human movement into instructions for a motion model \
             that first makes a whole-body motion and then re-animates single body parts.\n\n\
             {context}\n\nGive: \"base\", the whole-body motion as one caption in the model's \
             words (\"a person walks forward\"); for each of left_arm, right_arm, left_leg and \
             right_leg, a caption of what that part does differently from the base (\"a person \
             waves the left hand\"), or null when it just follows the base; and \"trajectory\", \
             null unless the segment asks for a path on the ground. A path is either \
             {{\"shape\": NAME}} with NAME one of {shapes}, or a curve {{\"x\": EXPR, \"z\": \
             EXPR, \"t0\": NUMBER, \"t1\": NUMBER}} on the ground (z is forward, x is the \
             person's left) where EXPR is arithmetic in t with + - * / ^, sin, cos, tan, abs, \
             sqrt, exp, log, min, max, pi and if(cond, a, b). Finally \"key_poses\": null, \
             unless the segment asks for a pose held still or a movement that is not among \
             the model's movements above (a T-pose, kneeling, sitting on the floor, a dab, a \
             superhero landing, a deep squat held); then a list of 1 to {max} key poses in time order, each {{\"name\": \
             TEXT, \"hold\": SECONDS, \"constraints\": [...]}} with constraints from this \
             closed vocabulary:\n{vocabulary}\nReply in JSON with exactly these seven keys.",
            shapes = shape_names().join(", "),
            max = MAX_LLM_KEY_POSES,
            vocabulary = posture_vocabulary()
        )),
        Message::user(segment.to_string()),
    ]
}

#[cfg(test)]
mod tests;
