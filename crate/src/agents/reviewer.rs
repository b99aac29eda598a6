//! The reviewer: describes a generated segment, compares it with what the segment asked for,
//! body part by body part, and returns correction instructions (or none).
//!
//! - Describer: pose codes ([`crate::posecodes`]), always available; optionally a vision
//!   model that looks at a filmstrip of the colour-coded skeleton.
//! - Judge: the configured LLM, or without one the motion evaluator's text–motion
//!   similarity for each part's instruction against [`OFFLINE_THRESHOLD`].

use crate::agents::llm::{
    parse_json_content, ChatOptions, LlmClient, Message, ReplyFormat, Transport,
};
use crate::features::FeatureFrame;
use crate::model::evaluator::{alignment_score, Evaluator, EvaluatorConfig};
use crate::model::MotionModel;
use crate::plan::{clean_text, Segment};
use crate::posecodes;
use crate::render::{filmstrip_png, FilmstripOptions};
use crate::skeleton::{BodyPart, Pose};
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The body regions a review speaks of: the arms one by one, the legs together (they carry
/// the walk, so they are corrected as one).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Region {
    LeftArm,
    RightArm,
    LowerBody,
}

impl Region {
    /// All regions, in the order they are reviewed.
    pub const ALL: [Region; 3] = [Region::LeftArm, Region::RightArm, Region::LowerBody];

    /// The region in the user's words ("left arm", "lower body").
    pub fn name(self) -> &'static str {
        match self {
            Region::LeftArm => "left arm",
            Region::RightArm => "right arm",
            Region::LowerBody => "lower body",
        }
    }

    /// The model's body parts of the region.
    pub fn parts(self) -> &'static [BodyPart] {
        match self {
            Region::LeftArm => &[BodyPart::LeftArm],
            Region::RightArm => &[BodyPart::RightArm],
            Region::LowerBody => &[BodyPart::LeftLeg, BodyPart::RightLeg],
        }
    }

    /// What the segment asks of the region: its own edit, or the base motion.
    pub fn asked(self, segment: &Segment) -> String {
        let own = self.parts().iter().find_map(|p| segment.parts.get(*p));
        own.unwrap_or(&segment.base).to_string()
    }
}

/// A correction: regenerate the region's parts from `instruction`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Correction {
    pub region: Region,
    pub instruction: String,
}

/// Who judged.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum JudgeKind {
    /// The evaluator's similarity against [`OFFLINE_THRESHOLD`].
    Evaluator,
    /// An LLM, by model id.
    Llm { model: String },
}

/// One review of one segment.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Review {
    /// What the motion looks like, in words (pose codes, or the vision model's words).
    pub description: String,
    /// The evaluator's 0–100 similarity of each region's instruction with the motion, where
    /// an evaluator was at hand.
    pub scores: Vec<(Region, f64)>,
    /// What to regenerate; empty when the segment is done.
    pub corrections: Vec<Correction>,
    pub judge: JudgeKind,
    /// Why the LLM judge was not used, when it failed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// Similarity (0–100) under which the offline judge asks for a region to be regenerated.
/// EVAL.md's MM-Dist (the mean distance d between unit embeddings, so cos ≈ 1 − d²/2) puts
/// real test motions at about 92 against their own captions and the retrieval baseline (a
/// training motion of a near caption) at about 85; a region under 80 looks less like its
/// text than a near miss does.
pub const OFFLINE_THRESHOLD: f64 = 80.0;

/// The local description of a motion: a whole-body sentence and one per body part.
pub fn describe(poses: &[Pose]) -> String {
    let whole = posecodes::describe_motion(poses);
    let parts: Vec<String> = posecodes::part_sentences(poses)
        .into_iter()
        .map(|(_, s)| s)
        .collect();
    format!("{whole} In detail: {}.", parts.join("; "))
}

/// The motion evaluator with what it needs to score text against motion.
pub struct Scorer<'a> {
    pub evaluator: &'a Evaluator,
    pub config: &'a EvaluatorConfig,
    pub model: &'a MotionModel,
}

impl Scorer<'_> {
    /// 0–100 similarity of each text with one motion (normalised features, 20 fps).
    pub fn scores(&self, texts: &[String], normalized: &[FeatureFrame]) -> Vec<f64> {
        let device = self.model.text.device();
        let motion = &self
            .evaluator
            .embed_motions(self.config, &[normalized], device)[0];
        let sentences: Vec<_> = texts
            .iter()
            .map(|t| self.model.text.encode(&[t.as_str()])[0])
            .collect();
        self.evaluator
            .embed_texts(&sentences, device)
            .iter()
            .map(|t| alignment_score(t, motion))
            .collect()
    }

    /// 0–100 similarity of a segment's whole text with its motion.
    pub fn segment_score(&self, segment: &Segment, normalized: &[FeatureFrame]) -> f64 {
        self.scores(std::slice::from_ref(&segment.text), normalized)[0]
    }
}

/// The offline judge: every region whose instruction scores under [`OFFLINE_THRESHOLD`] is
/// regenerated from that instruction.
pub fn judge_offline(
    segment: &Segment,
    poses: &[Pose],
    normalized: &[FeatureFrame],
    scorer: &Scorer,
) -> Review {
    let asked: Vec<String> = Region::ALL.iter().map(|r| r.asked(segment)).collect();
    let scores = scorer.scores(&asked, normalized);
    let corrections = Region::ALL
        .iter()
        .zip(asked.iter().zip(&scores))
        .filter(|(_, (_, s))| **s < OFFLINE_THRESHOLD)
        .map(|(region, (text, _))| Correction {
            region: *region,
            instruction: text.clone(),
        })
        .collect();
    Review {
        description: describe(poses),
        scores: Region::ALL.iter().copied().zip(scores).collect(),
        corrections,
        judge: JudgeKind::Evaluator,
        note: None,
    }
}

/// What the LLM judge replies: one instruction per region, or null.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JudgeReply {
    left_arm: Option<String>,
    right_arm: Option<String>,
    lower_body: Option<String>,
}

fn judge_schema() -> serde_json::Value {
    let part = json!({"type": ["string", "null"], "maxLength": 300});
    json!({
        "type": "object",
        "properties": {"left_arm": part, "right_arm": part, "lower_body": part},
        "required": ["left_arm", "right_arm", "lower_body"],
        "additionalProperties": false
    })
}

fn judge_messages(segment: &Segment, description: &str) -> Vec<Message> {
    let asked: Vec<String> = Region::ALL
        .iter()
        .map(|r| format!("{}: {}", r.name(), r.asked(segment)))
        .collect();
    vec![
        Message::system(
            "You check an animation against its instructions. You get what the segment should \
             show, per body region, and a description of what the generated motion does. For \
             each region (left_arm, right_arm, lower_body) that clearly fails its instruction, \
             write a short corrective instruction as a caption about \"a person\" (\"a person \
             raises the left hand high\"); use null for a region that is fine or that the \
             description does not mention. Reply in JSON with exactly those three keys.",
        ),
        Message::user(format!(
            "Segment: {}\nInstructions per region:\n{}\nWhat the motion does: {description}",
            segment.text,
            asked.join("\n")
        )),
    ]
}

/// The LLM judge; on any failure the offline review stands, with a note saying why.
async fn judge_llm<T: Transport>(
    client: &LlmClient<T>,
    segment: &Segment,
    offline: Review,
) -> Review {
    let format = ReplyFormat::JsonSchema {
        name: "coma_review".into(),
        schema: judge_schema(),
    };
    let messages = judge_messages(segment, &offline.description);
    let reply = match client.chat(&messages, &format).await {
        Ok(r) => r,
        Err(e) => {
            return Review {
                note: Some(format!("the LLM judge failed ({e}); the evaluator judged")),
                ..offline
            }
        }
    };
    let parsed = parse_json_content::<JudgeReply>(&reply.content).and_then(|r| {
        let mut corrections = Vec::new();
        for (region, text) in [
            (Region::LeftArm, r.left_arm),
            (Region::RightArm, r.right_arm),
            (Region::LowerBody, r.lower_body),
        ] {
            let Some(text) = text.filter(|t| !t.trim().is_empty()) else {
                continue;
            };
            if matches!(
                text.trim().to_lowercase().as_str(),
                "none" | "null" | "ok" | "fine"
            ) {
                continue;
            }
            corrections.push(Correction {
                region,
                instruction: clean_text(&text)?,
            });
        }
        Ok(corrections)
    });
    match parsed {
        Ok(corrections) => Review {
            corrections,
            judge: JudgeKind::Llm {
                model: client.config().model.clone(),
            },
            ..offline
        },
        Err(e) => Review {
            note: Some(format!(
                "the LLM judge's reply was unusable ({e}); the evaluator judged"
            )),
            ..offline
        },
    }
}

/// The LLM's review of a segment: when the configuration names a vision model, it first looks
/// at a filmstrip of `poses` (metres, Y up, 20 fps) and its words join the pose codes; then the
/// LLM judges. Whatever fails leaves a note and the rest of the review stands.
pub async fn review_llm<T: Transport>(
    client: &LlmClient<T>,
    segment: &Segment,
    poses: &[Pose],
    offline: Review,
) -> Review {
    let mut offline = offline;
    let mut vision_note = None;
    if client.config().vision_model.is_some() {
        match describe_with_vision(client, poses).await {
            Ok(words) => {
                offline.description = format!(
                    "{}\nA vision model looking at a filmstrip of it says: {words}",
                    offline.description
                )
            }
            Err(e) => {
                vision_note = Some(format!(
                    "the vision describer failed ({e}); the pose codes described"
                ))
            }
        }
    }
    let mut review = judge_llm(client, segment, offline).await;
    review.note = match (vision_note, review.note.take()) {
        (Some(a), Some(b)) => Some(format!("{a}; {b}")),
        (a, b) => a.or(b),
    };
    review
}

/// Frames shown to a vision model: enough to see the movement, few enough to stay cheap.
pub const VISION_FRAMES: usize = 8;

/// Asks the configured vision model to describe a filmstrip of the motion (metres, Y up,
/// 20 fps); the reason when it cannot.
pub async fn describe_with_vision<T: Transport>(
    client: &LlmClient<T>,
    poses: &[Pose],
) -> Result<String, String> {
    let options = FilmstripOptions {
        frames: VISION_FRAMES,
        ..FilmstripOptions::default()
    };
    let png = filmstrip_png(poses, &options).map_err(|e| e.to_string())?;
    let messages = [
        Message::system(
            "You describe the movement of a stick figure in a filmstrip (time runs left to \
             right, top to bottom). The left arm is drawn in one colour, the right arm in \
             another, the legs in two more. Describe in two or three plain sentences what \
             the body does: where it goes, and what each arm and the legs do.",
        ),
        Message::user_with_pngs("Describe this motion.", [png.as_slice()]),
    ];
    let reply = client
        .chat_with(&messages, &ReplyFormat::Text, &ChatOptions::vision())
        .await
        .map_err(|e| e.to_string())?;
    clean_text(&reply.content.chars().take(1200).collect::<String>())
}

#[cfg(all(test, feature = "native"))]
mod tests {
    use super::*;
    use crate::agents::llm::script_server::{ScriptServer, ScriptedReply};
    use crate::agents::llm::LlmConfig;
    use crate::executor::block_on;
    use crate::plan::PartEdits;

    fn segment() -> Segment {
        Segment {
            text: "a person walks forward waving the left hand".into(),
            seconds: 4.0,
            base: "a person walks forward".into(),
            parts: PartEdits {
                left_arm: Some("a person waves the left hand".into()),
                ..Default::default()
            },
            trajectory: None,
            postures: None,
        }
    }

    fn offline_review() -> Review {
        Review {
            description: "A person walks forward.".into(),
            scores: vec![(Region::LeftArm, 50.0)],
            corrections: vec![Correction {
                region: Region::LeftArm,
                instruction: "a person waves the left hand".into(),
            }],
            judge: JudgeKind::Evaluator,
            note: None,
        }
    }

    /// A client of `server` for the model "judge", with `vision_model` if given, no retries.
    fn client(
        server: &ScriptServer,
        vision_model: Option<&str>,
    ) -> LlmClient<crate::agents::llm::UreqTransport> {
        let mut config = LlmConfig::new(server.base_url(), "judge");
        config.max_retries = 0;
        config.vision_model = vision_model.map(str::to_string);
        LlmClient::native(config).unwrap()
    }

    fn judge(reply: ScriptedReply) -> (Review, ScriptServer) {
        let server = ScriptServer::start([reply]).unwrap();
        let client = client(&server, None);
        (
            block_on(judge_llm(&client, &segment(), offline_review())),
            server,
        )
    }

    #[test]
    fn each_region_asks_its_own_edit_or_the_base() {
        let s = segment();
        assert_eq!(Region::LeftArm.asked(&s), "a person waves the left hand");
        assert_eq!(Region::RightArm.asked(&s), "a person walks forward");
        assert_eq!(Region::LowerBody.asked(&s), "a person walks forward");
        assert_eq!(
            Region::LowerBody.parts(),
            &[BodyPart::LeftLeg, BodyPart::RightLeg]
        );
    }

    #[test]
    fn the_llm_judge_gives_corrections_per_region() {
        let (review, server) = judge(ScriptedReply::completion(
            r#"{"left_arm": "a person raises the left hand higher", "right_arm": null, "lower_body": "none"}"#,
        ));
        assert_eq!(
            review.judge,
            JudgeKind::Llm {
                model: "judge".into()
            }
        );
        assert_eq!(
            review.corrections,
            vec![Correction {
                region: Region::LeftArm,
                instruction: "a person raises the left hand higher".into()
            }]
        );
        let asked = server.requests()[0].json().to_string();
        assert!(asked.contains("A person walks forward."), "{asked}");
        assert!(asked.contains("coma_review"), "{asked}");
    }

    #[test]
    fn a_failing_llm_judge_leaves_the_offline_review_with_a_note() {
        for reply in [
            ScriptedReply::completion("looks fine to me"),
            ScriptedReply::completion(r#"{"left_arm": 5, "right_arm": null, "lower_body": null}"#),
            ScriptedReply::completion(
                r#"{"left_arm": "ok", "right_arm": null, "lower_body": null, "eval": "rm -rf /"}"#,
            ),
            ScriptedReply::error(500, "down"),
            ScriptedReply::error(401, "bad key"),
        ] {
            let (review, _) = judge(reply);
            assert_eq!(review.judge, JudgeKind::Evaluator);
            assert_eq!(review.corrections, offline_review().corrections);
            assert!(review
                .note
                .as_deref()
                .unwrap_or("")
                .contains("evaluator judged"));
        }
    }

    fn walking_poses() -> Vec<Pose> {
        let mut pose = [[0.0; 3]; crate::skeleton::NUM_JOINTS];
        for (j, p) in pose.iter_mut().enumerate() {
            *p = [0.1 * (j % 3) as f64, 1.0 - 0.05 * j as f64, 0.0];
        }
        (0..40)
            .map(|t| {
                let mut p = pose;
                for joint in p.iter_mut() {
                    joint[2] += 0.03 * t as f64;
                }
                p
            })
            .collect()
    }

    /// The LLM review of a walking segment by a server replaying `replies`.
    fn review_with(
        replies: impl IntoIterator<Item = ScriptedReply>,
        vision_model: Option<&str>,
    ) -> (Review, ScriptServer) {
        let server = ScriptServer::start(replies).unwrap();
        let client = client(&server, vision_model);
        let review = block_on(review_llm(
            &client,
            &segment(),
            &walking_poses(),
            offline_review(),
        ));
        (review, server)
    }

    #[test]
    fn a_vision_model_looks_before_the_judge_reads() {
        let (review, server) = review_with(
            [
                ScriptedReply::completion(
                    "The figure strides forward, its left arm swinging high.",
                ),
                ScriptedReply::completion(
                    r#"{"left_arm": null, "right_arm": null, "lower_body": null}"#,
                ),
            ],
            Some("eyes"),
        );
        assert_eq!(review.note, None);
        assert!(review.corrections.is_empty());
        assert!(review.description.starts_with("A person walks forward."));
        assert!(review.description.contains("left arm swinging high"));
        let requests = server.requests();
        assert_eq!(requests.len(), 2);
        let looked = requests[0].json();
        assert_eq!(looked["model"], "eyes");
        assert!(looked
            .to_string()
            .contains("data:image/png;base64,iVBORw0KGgo"));
        let judged = requests[1].json();
        assert_eq!(judged["model"], "judge");
        assert!(judged.to_string().contains("left arm swinging high"));
    }

    #[test]
    fn a_failing_vision_model_leaves_the_pose_codes_to_the_judge() {
        let (review, _) = review_with(
            [
                ScriptedReply::error(500, "no eyes today"),
                ScriptedReply::completion(
                    r#"{"left_arm": "a person waves the left hand", "right_arm": null, "lower_body": null}"#,
                ),
            ],
            Some("eyes"),
        );
        let note = review.note.unwrap_or_default();
        assert!(note.contains("vision describer failed"), "{note}");
        assert_eq!(review.description, offline_review().description);
        assert_eq!(
            review.judge,
            JudgeKind::Llm {
                model: "judge".into()
            }
        );
        assert_eq!(review.corrections.len(), 1);
    }

    #[test]
    fn without_a_vision_model_nothing_is_shown_a_picture() {
        let (_, server) = review_with(
            [ScriptedReply::completion(
                r#"{"left_arm": null, "right_arm": null, "lower_body": null}"#,
            )],
            None,
        );
        let requests = server.requests();
        assert_eq!(requests.len(), 1);
        assert!(!requests[0].json().to_string().contains("image_url"));
    }

    #[test]
    fn the_description_names_the_movement() {
        // Standing still: the rest pose (offsets summed down the tree), unchanged for 2 s.
        use crate::skeleton::{NUM_JOINTS, PARENTS, RAW_OFFSETS};
        let mut pose = [[0.0; 3]; NUM_JOINTS];
        pose[0] = [0.0, 1.0, 0.0];
        for j in 1..NUM_JOINTS {
            let parent = pose[PARENTS[j].unwrap()];
            pose[j] = crate::geom::add(parent, RAW_OFFSETS[j]);
        }
        let poses = vec![pose; 40];
        let text = describe(&poses);
        assert!(text.contains("In detail:"), "{text}");
        assert!(
            text.contains("left arm") && text.contains("right leg"),
            "{text}"
        );
    }
}
