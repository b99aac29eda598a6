use super::*;
use crate::agents::llm::script_server::{ScriptServer, ScriptedReply};
use crate::agents::llm::{Backoff, LlmConfig, UreqTransport};
use crate::executor::block_on;
use std::time::Duration;

const PROMPT: &str = "A person walks forward waving the left hand, then turns right and bows";

fn vocabulary() -> Vocabulary {
    serde_json::from_str(include_str!("../../../../../static/models/vocabulary.json")).unwrap()
}

fn client(server: &ScriptServer) -> LlmClient<UreqTransport> {
    let mut config = LlmConfig::new(server.base_url(), "scripted").with_api_key("sk-test-secret");
    config.max_retries = 1;
    config.timeout = Duration::from_secs(5);
    config.max_reply_bytes = 100 * 1024;
    config.backoff = Backoff {
        initial: Duration::from_millis(1),
        max: Duration::from_millis(2),
        retry_after_cap: Duration::from_millis(2),
    };
    LlmClient::native(config).unwrap()
}

fn good(step: &str) -> ScriptedReply {
    ScriptedReply::completion(match step {
        "rewrite" => {
            r#"{"description": "a person walks forward waving the left hand, then walks and turns right, then bows"}"#
        }
        "segment" => {
            r#"{"segments": [{"text": "a person walks forward waving the left hand", "seconds": 4.5}]}"#
        }
        _ => {
            r#"{"base": "a person walks forward", "left_arm": "a person waves the left hand", "right_arm": null, "left_leg": null, "right_leg": null, "trajectory": null}"#
        }
    })
}

fn run(server: &ScriptServer) -> (Plan, Vec<PlanEvent>) {
    let client = client(server);
    let mut events = Vec::new();
    let plan = block_on(plan(&client, PROMPT, &vocabulary(), None, &mut |e| {
        events.push(e.clone())
    }));
    (plan, events)
}

fn assert_valid(plan: &Plan, context: &str) {
    assert!(
        (1..=MAX_SEGMENTS).contains(&plan.segments.len()),
        "{context}: {plan:#?}"
    );
    for s in &plan.segments {
        assert!((2.0..=9.8).contains(&s.seconds), "{context}: {}", s.seconds);
        for t in std::iter::once(&s.base).chain(std::iter::once(&s.text)) {
            assert!(
                clean_text(t).as_deref() == Ok(t.as_str()),
                "{context}: {t:?}"
            );
        }
        for (_, t) in s.parts.edits() {
            assert!(
                clean_text(&t).as_deref() == Ok(t.as_str()),
                "{context}: {t:?}"
            );
        }
        if let Some(t) = &s.trajectory {
            t.validate().unwrap_or_else(|e| panic!("{context}: {e}"));
        }
    }
    assert!(!plan.rewritten.is_empty());
}

#[test]
fn a_well_behaved_llm_plans_every_step() {
    let server =
        ScriptServer::start([good("rewrite"), good("segment"), good("decompose")]).unwrap();
    let (plan, events) = run(&server);
    assert!(plan.notes.is_empty(), "{:?}", plan.notes);
    assert_eq!(
        plan.planner,
        PlannerKind::Llm {
            model: "scripted".into()
        }
    );
    assert_eq!(plan.segments.len(), 1);
    assert_eq!(plan.segments[0].seconds, 4.5);
    assert_eq!(
        plan.segments[0].parts.left_arm.as_deref(),
        Some("a person waves the left hand")
    );
    assert_eq!(events.len(), 3);
    let requests = server.requests();
    assert_eq!(requests.len(), 3);
    // Every question asks for its schema, and the key goes in the header only.
    for r in &requests {
        let body = r.json();
        assert_eq!(body["response_format"]["type"], "json_schema", "{body}");
        assert_eq!(r.header("authorization"), Some("Bearer sk-test-secret"));
        assert!(!body.to_string().contains("sk-test-secret"));
    }
    // The rewrite question tells the model's actions, a left/right pair as one.
    assert!(requests[0]
        .json()
        .to_string()
        .contains("raise-up-{left|right}-hand"));
}

#[test]
fn one_bad_reply_is_retried_with_its_error() {
    let server = ScriptServer::start([
        ScriptedReply::completion("I think the person walks."),
        good("rewrite"),
        good("segment"),
        good("decompose"),
    ])
    .unwrap();
    let (plan, _) = run(&server);
    assert!(plan.notes.is_empty(), "{:?}", plan.notes);
    let retry = server.requests()[1].json();
    let messages = retry["messages"].as_array().unwrap();
    let last = messages.last().unwrap()["content"].to_string();
    assert!(last.contains("cannot be used"), "{last}");
}

#[test]
fn no_server_at_all_gives_the_offline_plan_with_a_note() {
    let port = {
        let l = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        l.local_addr().unwrap().port()
    };
    let mut config = LlmConfig::new(format!("http://127.0.0.1:{port}/v1"), "absent");
    config.max_retries = 0;
    let client = LlmClient::native(config).unwrap();
    let plan = block_on(plan(&client, PROMPT, &vocabulary(), None, &mut |_| {}));
    let offline = offline::plan(PROMPT, None);
    assert_eq!(plan.segments, offline.segments);
    assert!(
        plan.notes.iter().any(|n| n.contains("could not reach")),
        "{:?}",
        plan.notes
    );
}

/// One line of the hostile fixture: a reply aimed at one step.
#[derive(serde::Deserialize)]
struct Hostile {
    step: String,
    why: String,
}

#[test]
fn every_hostile_reply_is_handled_with_a_note_and_a_fallback() {
    let text = include_str!("../../../../tests/fixtures/llm/planner_hostile.jsonl");
    let mut count = 0;
    let mut failures = Vec::new();
    for line in text.lines().filter(|l| !l.trim().is_empty()) {
        let hostile: Hostile = serde_json::from_str(line).unwrap();
        let reply = ScriptedReply::from_json_lines(line).unwrap().remove(0);
        // Good replies before the step under test; the hostile one for it and every later
        // request, so whatever the planner asks next, it meets the same reply.
        let before: &[&str] = match hostile.step.as_str() {
            "rewrite" => &[],
            "segment" => &["rewrite"],
            _ => &["rewrite", "segment"],
        };
        let mut replies: Vec<ScriptedReply> = before.iter().map(|s| good(s)).collect();
        replies.extend(std::iter::repeat_n(reply, 16));
        let server = ScriptServer::start(replies).unwrap();
        let (plan, _) = run(&server);
        let context = format!("{} ({})", hostile.why, hostile.step);
        assert_valid(&plan, &context);
        // A reply with one good JSON object and junk after it is read as that object:
        // the step then succeeds, with data that passed validation.
        let lenient = hostile.why == "trailing garbage";
        if !lenient
            && !plan
                .notes
                .iter()
                .any(|n| n.contains(&format!("LLM's {}", hostile.step)))
        {
            failures.push(format!("{context}: no fallback note in {:?}", plan.notes));
        }
        for note in &plan.notes {
            assert!(
                note.chars().count() < 1200,
                "{context}: a note of {} chars",
                note.len()
            );
            assert!(!note.contains("sk-test-secret"));
        }
        if hostile.step == "decompose" {
            // The offline planner took over the segment: no path came from the reply.
            if plan.segments[0].trajectory.is_some() {
                failures.push(format!("{context}: kept a path from the reply"));
            }
        }
        count += 1;
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(count >= 100, "only {count} hostile replies");
}

#[test]
fn a_valid_curve_from_the_llm_is_kept_as_data() {
    let server = ScriptServer::start([
        good("rewrite"),
        good("segment"),
        ScriptedReply::completion(
            r#"{"base": "a person walks forward", "left_arm": null, "right_arm": null, "left_leg": null, "right_leg": null,
                "trajectory": {"x": "sin(2*pi*t)", "z": "2*t", "t0": 0, "t1": 1}}"#,
        ),
    ])
    .unwrap();
    let (plan, _) = run(&server);
    assert!(plan.notes.is_empty(), "{:?}", plan.notes);
    let t = plan.segments[0].trajectory.as_ref().expect("a path");
    t.validate().unwrap();
}

#[test]
fn key_poses_from_the_llm_are_checked_and_a_bad_one_is_retried_with_its_error() {
    let with_poses = |constraint: &str| {
        ScriptedReply::completion(&format!(
            r#"{{"base": "a person stands still", "left_arm": null, "right_arm": null, "left_leg": null, "right_leg": null, "trajectory": null, "key_poses": [{{"name": "T-pose", "hold": 1.0, "constraints": [{{"kind": "level", "is": "standing"}}, {constraint}]}}]}}"#
        ))
    };
    let server = ScriptServer::start([
        good("rewrite"),
        good("segment"),
        with_poses(r#"{"kind": "bend", "joint": "left_elbow", "is": "bent"}"#),
        with_poses(r#"{"kind": "orientation", "limb": "left_upper_arm", "is": "horizontal"}"#),
    ])
    .unwrap();
    let (plan, _) = run(&server);
    assert!(plan.notes.is_empty(), "{:?}", plan.notes);
    let track = plan.segments[0].postures.as_ref().expect("a posture track");
    assert!(track.whole_body());
    assert_eq!(track.keys[0].script.name.as_deref(), Some("T-pose"));
    let retry = server.requests()[3].json();
    let last = retry["messages"].as_array().unwrap().last().unwrap()["content"].to_string();
    assert!(
        last.contains("key_poses[0]") && last.contains("bent"),
        "the retry names the wrong constraint: {last}"
    );
}

#[test]
fn the_questions_fit_a_small_model_s_context_with_the_shipped_vocabulary() {
    let vocabulary = vocabulary();
    let brief = vocabulary_brief(&vocabulary, BRIEF_CHARS);
    assert!(brief.len() <= BRIEF_CHARS, "{} characters", brief.len());
    assert!(brief.contains("kick-{left|right}-leg"), "{brief}");
    assert!(
        brief.contains("squat") && brief.contains("lie-down"),
        "{brief}"
    );
    let longest = |messages: Vec<Message>| {
        messages
            .iter()
            .flat_map(|m| &m.content)
            .map(|c| match c {
                crate::agents::llm::ContentPart::Text(t) => t.len(),
                crate::agents::llm::ContentPart::ImageUrl(u) => u.len(),
            })
            .sum::<usize>()
    };
    let segment = "a person walks forward waving the left hand while turning right slowly";
    for (question, chars) in [
        ("rewrite", longest(rewrite_messages(&brief, PROMPT))),
        ("segment", longest(segment_messages(PROMPT))),
        ("decompose", longest(decompose_messages(&brief, segment))),
    ] {
        assert!(
            // A decompose question 1,400 characters longer counted 2,113 tokens.
            chars <= 5_200,
            "the {question} question takes {chars} characters"
        );
    }
}

#[test]
fn a_small_budget_keeps_the_actions_and_drops_the_examples_first() {
    let vocabulary = vocabulary();
    let full = vocabulary_brief(&vocabulary, 100_000);
    assert!(full.contains("Words of its captions:") && full.contains("Example captions:"));
    let small = vocabulary_brief(&vocabulary, 0);
    assert!(small.contains("Movements the motion model was trained on: "));
    assert!(!small.contains("Example captions") && !small.contains("Words of"));
    for action in vocabulary
        .actions
        .keys()
        .filter(|a| !a.contains("left") && !a.contains("right"))
    {
        assert!(small.contains(action.as_str()), "{action} missing");
    }
}

#[test]
fn the_llm_writes_clips_of_its_own_and_overlapping_ones_go_back_with_the_error() {
    let walk_run = r#"{"segments": [{"text": "a person walks forward", "seconds": 4},
        {"text": "a person runs forward", "seconds": 4}], "clips": [CLIPS]}"#;
    let t_pose = r#"{"parts": ["left_arm", "right_arm"], "text": "a person holds the arms out to the sides", "start": 1, "end": 8}"#;
    let wave =
        r#"{"parts": ["left_arm"], "text": "a person waves the left hand", "start": 6, "end": 12}"#;
    let decompose = |base: &str| {
        ScriptedReply::completion(&format!(
            r#"{{"base": "{base}", "left_arm": null, "right_arm": null, "left_leg": null, "right_leg": null, "trajectory": null}}"#
        ))
    };
    let server = ScriptServer::start([
        good("rewrite"),
        ScriptedReply::completion(&walk_run.replace("CLIPS", &format!("{t_pose}, {wave}"))),
        ScriptedReply::completion(&walk_run.replace("CLIPS", t_pose)),
        decompose("a person walks forward"),
        decompose("a person runs forward"),
    ])
    .unwrap();
    let (plan, _) = run(&server);
    assert!(plan.notes.is_empty(), "{:?}", plan.notes);
    let retry = server.requests()[2].json().to_string();
    assert!(
        retry.contains("move the same body part at the same time"),
        "{retry}"
    );
    assert_eq!(plan.clips.len(), 1);
    let clip = &plan.clips[0];
    assert_eq!(clip.parts, [BodyPart::LeftArm, BodyPart::RightArm]);
    assert_eq!((clip.start, clip.end), (1.0, 8.0));
    assert!(plan.clone().checked().is_ok());
    // The segment question asks for clips in its schema.
    assert!(server.requests()[1]
        .json()
        .to_string()
        .contains("\"clips\""));
}
