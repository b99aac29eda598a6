use super::*;
use crate::agents::planner::meaning::{calibrate, opposite_directions, LabelledPair};
use crate::plan::{PartEdits, PlannerKind, Segment};
use crate::posture::library::Library;
use crate::posture::track::PostureTrack;

/// A stand-in for MiniLM in tests: the share of the shorter text's content words (crudely
/// stemmed) found in the other, so that these tests check the scorer's logic and not the
/// model.
fn shared_words(a: &str, b: &str) -> f32 {
    const FILLER: [&str; 8] = ["a", "the", "person", "his", "her", "with", "hand", "arm"];
    let content = |t: &str| -> Vec<String> {
        words(t)
            .into_iter()
            .filter(|w| !FILLER.contains(&w.as_str()))
            .map(|w| {
                let w = w.trim_end_matches("ing").trim_end_matches('s');
                w.trim_end_matches('e').to_string()
            })
            .collect()
    };
    let (x, y) = (content(a), content(b));
    let common = x.iter().filter(|w| y.contains(w)).count();
    let shorter = x.len().min(y.len());
    if shorter == 0 {
        0.0
    } else {
        common as f32 / shorter as f32
    }
}

fn matcher() -> Matcher<'static> {
    Matcher::new(&shared_words, 0.5)
}

const SET: &str = r#"{"about": "test", "prompts": [
  {"id": "walk-wave-bow", "prompt": "A man walks forward while waving his left hand, then bows twice.", "clauses": [
    {"text": "walks forward", "track": "body", "order": 1, "side": null},
    {"text": "waving his left hand", "track": "left arm", "order": 1, "side": "left"},
    {"text": "bows twice", "track": "body", "order": 2, "side": null, "count": 2}
  ]}
]}"#;

fn prompt() -> SetPrompt {
    parse(SET).unwrap().prompts.remove(0)
}

fn segment(base: &str, parts: &[(BodyPart, &str)]) -> Segment {
    let mut edits = PartEdits::default();
    for (p, t) in parts {
        edits.set(*p, Some(t.to_string()));
    }
    Segment {
        text: base.into(),
        seconds: 3.0,
        base: base.into(),
        parts: edits,
        trajectory: None,
        postures: None,
    }
}

fn plan(segments: Vec<Segment>, notes: &[&str]) -> Plan {
    Plan {
        prompt: String::new(),
        rewritten: String::new(),
        segments,
        clips: Vec::new(),
        planner: PlannerKind::Offline,
        notes: notes.iter().map(|n| n.to_string()).collect(),
    }
}

fn walk_waving(part: BodyPart) -> Segment {
    segment(
        "a person walks forward",
        &[(part, "a person waves the left hand")],
    )
}

fn bow() -> Segment {
    segment("a person bows", &[])
}

#[test]
fn a_correct_plan_places_every_clause() {
    let p = plan(vec![walk_waving(BodyPart::LeftArm), bow(), bow()], &[]);
    let out = score_prompt(&prompt(), &p, &matcher());
    assert!(out.all_correct(), "{out:#?}");
    // The two bows are one clause said twice.
    assert_eq!(out.clauses[2].placed_as.len(), 2, "{out:#?}");
}

#[test]
fn a_dropped_clause_is_silently_lost_unless_a_note_names_it() {
    let p = plan(
        vec![segment("a person walks forward", &[]), bow(), bow()],
        &[],
    );
    let out = score_prompt(&prompt(), &p, &matcher());
    assert!(out.clauses[1].lost(), "{out:#?}");
    assert!(out.clauses[0].correct && out.clauses[2].correct, "{out:#?}");
    let noted = plan(
        vec![segment("a person walks forward", &[]), bow(), bow()],
        &["\"waving his left hand\" names no movement the model makes; left out"],
    );
    let out = score_prompt(&prompt(), &noted, &matcher());
    assert!(
        !out.clauses[1].lost() && !out.clauses[1].correct,
        "{out:#?}"
    );
    assert!(matches!(out.clauses[1].misses[0], Miss::OnlyInANote { .. }));
}

#[test]
fn a_gesture_on_the_other_arm_is_a_side_swap() {
    let p = plan(vec![walk_waving(BodyPart::RightArm), bow(), bow()], &[]);
    let out = score_prompt(&prompt(), &p, &matcher());
    let wave = &out.clauses[1];
    assert!(wave.side_swap() && !wave.correct, "{out:#?}");
    assert!(
        wave.misses.iter().any(|m| matches!(m, Miss::Track { .. })),
        "{wave:#?}"
    );
    assert!(out.clauses[0].correct && out.clauses[2].correct);
}

#[test]
fn clauses_out_of_order_are_misplaced() {
    let p = plan(vec![bow(), bow(), walk_waving(BodyPart::LeftArm)], &[]);
    let out = score_prompt(&prompt(), &p, &matcher());
    // The bows come before the walk and the wave they should follow: blaming the one clause
    // explains both conflicts.
    assert!(out.clauses[0].correct && out.clauses[1].correct, "{out:#?}");
    assert_eq!(
        out.clauses[2].misses,
        vec![Miss::NotAfter { other: 0 }, Miss::NotAfter { other: 1 }]
    );
    // Moved between them, the wave alone is out of place.
    let p = plan(
        vec![
            segment("a person walks forward", &[]),
            segment("a person waves the left hand", &[]),
            bow(),
            bow(),
            segment("a person waves the left hand", &[]),
        ],
        &[],
    );
    let out = score_prompt(&prompt(), &p, &matcher());
    assert!(out.clauses[0].correct && out.clauses[2].correct, "{out:#?}");
    assert!(!out.clauses[1].correct, "{out:#?}");
}

#[test]
fn a_gesture_after_the_walk_does_not_overlap_it() {
    let p = plan(
        vec![
            segment("a person walks forward", &[]),
            segment("a person waves the left hand", &[]),
            bow(),
            bow(),
        ],
        &[],
    );
    let out = score_prompt(&prompt(), &p, &matcher());
    let wave = &out.clauses[1];
    // A whole-body clip of the gesture, while a walk is meant to go on beside it.
    assert!(
        wave.misses.contains(&Miss::NoOverlap { other: 0 }),
        "{wave:#?}"
    );
    assert!(wave.misses.iter().any(|m| matches!(m, Miss::Track { .. })));
}

#[test]
fn counts_are_checked() {
    let once = plan(vec![walk_waving(BodyPart::LeftArm), bow()], &[]);
    let out = score_prompt(&prompt(), &once, &matcher());
    assert_eq!(
        out.clauses[2].misses,
        vec![Miss::Count {
            expected: 2,
            got: 1
        }]
    );
    let thrice = plan(
        vec![walk_waving(BodyPart::LeftArm), bow(), bow(), bow()],
        &[],
    );
    let out = score_prompt(&prompt(), &thrice, &matcher());
    assert_eq!(
        out.clauses[2].misses,
        vec![Miss::Count {
            expected: 2,
            got: 3
        }]
    );
    let said = plan(
        vec![
            walk_waving(BodyPart::LeftArm),
            segment("a person bows twice", &[]),
        ],
        &[],
    );
    assert!(score_prompt(&prompt(), &said, &matcher()).all_correct());
}

#[test]
fn an_arm_clause_alone_may_be_a_whole_body_clip() {
    let set = parse(
        r#"{"about": "", "prompts": [{"id": "up-down", "prompt": "She raises her right arm, then lowers it.", "clauses": [
            {"text": "raises her right arm", "track": "right arm", "order": 1, "side": "right"},
            {"text": "lowers it", "track": "right arm", "order": 2, "side": "right", "refers_to": 0, "means": "lowers the right arm"}
        ]}]}"#,
    )
    .unwrap();
    let right = plan(
        vec![
            segment("a person raises the right hand", &[]),
            segment("a person lowers the right arm", &[]),
        ],
        &[],
    );
    assert!(score_prompt(&set.prompts[0], &right, &matcher()).all_correct());
    // "lowers it" read as the opposite movement is no match at all, however many words the
    // texts share.
    let wrong = plan(
        vec![
            segment("a person raises the right hand", &[]),
            segment("a person raises the right arm up high", &[]),
        ],
        &[],
    );
    let out = score_prompt(&set.prompts[0], &wrong, &matcher());
    assert!(out.clauses[1].lost(), "{out:#?}");
}

#[test]
fn a_posture_held_over_a_walk_and_a_run_rides_over_both() {
    let set = parse(
        r#"{"about": "", "prompts": [{"id": "t-pose", "prompt": "A woman picks up speed from a walk to a run, holding the T-pose.", "clauses": [
            {"text": "from a walk", "track": "body", "order": 1},
            {"text": "to a run", "track": "body", "order": 2},
            {"text": "holding the T-pose", "track": "both arms", "order": 1, "over": [0, 1]}
        ]}]}"#,
    )
    .unwrap();
    let t_pose = Library::builtin().get("T-pose").unwrap();
    let arms = vec![BodyPart::LeftArm, BodyPart::RightArm];
    let held = |base: &str| Segment {
        postures: Some(PostureTrack::holding(arms.clone(), t_pose.script.clone())),
        ..segment(base, &[])
    };
    let riding = plan(
        vec![
            held("a person walks forward"),
            held("a person runs forward"),
        ],
        &[],
    );
    let out = score_prompt(&set.prompts[0], &riding, &matcher());
    assert!(out.all_correct(), "{out:#?}");
    // The issue's plan: a walk, then a standing T-pose, and the run gone.
    let whole = Segment {
        postures: Some(PostureTrack::holding(
            BodyPart::ALL.to_vec(),
            t_pose.script.clone(),
        )),
        ..segment("a person stands still", &[])
    };
    let issue = plan(vec![segment("a person walks forward", &[]), whole], &[]);
    let out = score_prompt(&set.prompts[0], &issue, &matcher());
    assert!(out.clauses[0].correct, "{out:#?}");
    assert!(out.clauses[1].lost(), "{out:#?}");
    let pose = &out.clauses[2].misses;
    assert!(
        pose.iter().any(|m| matches!(m, Miss::Track { .. })),
        "{pose:?}"
    );
    assert!(pose.contains(&Miss::NoOverlap { other: 0 }), "{pose:?}");
}

#[test]
fn context_is_right_only_when_dropped_with_a_note() {
    let set = parse(
        r#"{"about": "", "prompts": [{"id": "verdict", "prompt": "A man stomps his feet to protest a verdict.", "clauses": [
            {"text": "stomps his feet", "track": "body", "order": 1},
            {"text": "to protest a verdict", "track": "none", "note": "a reason"}
        ]}]}"#,
    )
    .unwrap();
    let stomp = || segment("a person stomps the feet", &[]);
    let noted = plan(
        vec![stomp()],
        &["\"to protest a verdict\" names no movement the model makes; left out"],
    );
    assert!(score_prompt(&set.prompts[0], &noted, &matcher()).all_correct());
    let silent = plan(vec![stomp()], &[]);
    let out = score_prompt(&set.prompts[0], &silent, &matcher());
    assert!(out.clauses[1].lost(), "{out:#?}");
    let acted = plan(
        vec![stomp(), segment("a person protests a verdict", &[])],
        &[],
    );
    let out = score_prompt(&set.prompts[0], &acted, &matcher());
    assert_eq!(out.clauses[1].misses, vec![Miss::ContextPlaced]);
    assert!(out.extra.is_empty(), "{out:#?}");
    // A movement nobody asked for is listed as such.
    let substituted = plan(vec![stomp(), segment("a person kicks", &[])], &[]);
    let out = score_prompt(&set.prompts[0], &substituted, &matcher());
    assert_eq!(out.extra, vec!["[3.0–6.0 s body] a person kicks"]);
    // Context the planner replaced by a movement, as its note says, is not dropped.
    let replaced = plan(
        vec![stomp(), segment("a person kicks", &[])],
        &["\"to protest a verdict\" is not a movement the model knows; used the nearest one, \"kicks\""],
    );
    let out = score_prompt(&set.prompts[0], &replaced, &matcher());
    assert_eq!(out.clauses[1].misses, vec![Miss::ContextPlaced]);
    assert!(out.extra.is_empty(), "{out:#?}");
}

#[test]
fn paths_and_turning_sides_are_read_from_the_plan() {
    use crate::trajectory::{Shape, Side as PathSide, Trajectory};
    let set = parse(
        r#"{"about": "", "prompts": [{"id": "circle", "prompt": "Someone runs in a circle to the right.", "clauses": [
            {"text": "runs in a circle to the right", "track": "body", "order": 1, "side": "right", "path": "circle"}
        ]}]}"#,
    )
    .unwrap();
    let run = |trajectory: Option<Trajectory>| Segment {
        trajectory,
        ..segment("a person runs forward", &[])
    };
    let circle = |side| Trajectory::Shape {
        shape: Shape::Circle(side),
    };
    let right = plan(vec![run(Some(circle(PathSide::Right)))], &[]);
    assert!(score_prompt(&set.prompts[0], &right, &matcher()).all_correct());
    let left = plan(vec![run(Some(circle(PathSide::Left)))], &[]);
    let out = score_prompt(&set.prompts[0], &left, &matcher());
    assert!(out.clauses[0].side_swap(), "{out:#?}");
    let straight = plan(vec![run(None)], &[]);
    let out = score_prompt(&set.prompts[0], &straight, &matcher());
    assert!(out.clauses[0]
        .misses
        .iter()
        .any(|m| matches!(m, Miss::Path { got: None, .. })));
}

#[test]
fn the_report_counts_over_the_set() {
    let set = parse(SET).unwrap();
    let mut plans = vec![plan(vec![walk_waving(BodyPart::RightArm), bow()], &[])].into_iter();
    let report = score(&set, &mut |_| plans.next().unwrap(), &matcher());
    let f = &report.figures;
    assert_eq!((f.prompts, f.clauses), (1, 3));
    assert_eq!(f.correct, 1);
    assert_eq!(f.side_swaps, 1);
    assert_eq!(f.silently_lost, 0);
    assert_eq!(f.prompts_correct, 0);
    let table = report.table();
    assert!(table.contains("✗ walk-wave-bow"), "{table}");
    assert!(table.contains("side swapped: left expected"), "{table}");
    assert!(
        table.contains("clauses placed correctly: 1/3 (33.3 %)"),
        "{table}"
    );
}

#[test]
fn bad_files_say_what_is_wrong_and_where() {
    let bad = |from: &str, to: &str| parse(&SET.replacen(from, to, 1)).unwrap_err();
    let e = bad("\"waving his left hand\"", "\"waving her left hand\"");
    assert!(
        e.contains(
            "\"walk-wave-bow\", clause 1 (\"waving her left hand\"): its text is not in the prompt"
        ),
        "{e}"
    );
    let e = bad("\"order\": 2,", "");
    assert!(e.contains("clause 2") && e.contains("`order`"), "{e}");
    let e = bad("\"track\": \"left arm\"", "\"track\": \"left hand\"");
    assert!(
        e.contains("not a timeline prompt set") && e.contains("left hand"),
        "{e}"
    );
    let e = bad("\"count\": 2", "\"count\": 2, \"over\": [7]");
    assert!(e.contains("`over` names clause 7"), "{e}");
    let e = bad("\"side\": \"left\"", "\"side\": \"right\"");
    assert!(e.contains("side \"right\" on the left arm track"), "{e}");
    let e = bad("\"count\": 2", "\"count\": 2, \"path\": \"loop\"");
    assert!(e.contains("unknown path \"loop\""), "{e}");
    let e = bad(
        "\"count\": 2",
        "\"count\": 2, \"speed\": \"fast\", \"sped\": 1",
    );
    assert!(e.contains("unknown field `sped`"), "{e}");
    let e = parse("{\"about\": \"\", \"prompts\": []}").unwrap_err();
    assert!(e.contains("no prompts"), "{e}");
    let missing = load(Path::new("/nonexistent/set.json"))
        .unwrap_err()
        .to_string();
    assert!(
        missing.contains("cannot read /nonexistent/set.json"),
        "{missing}"
    );
}

#[test]
fn the_committed_set_is_valid() {
    let set =
        load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../eval/timeline_prompts.json")).unwrap();
    assert!(set.prompts.len() >= 100);
    assert!(set.about.contains("written by hand"));
}

#[test]
fn opposite_directions_are_never_the_same_movement() {
    assert!(opposite_directions("lowers it", "a person reaches up high"));
    assert!(opposite_directions(
        "walks backwards",
        "a person walks forward"
    ));
    assert!(opposite_directions("sits down", "stand up"));
    assert!(!opposite_directions("sits down", "sit on a chair"));
    assert!(!opposite_directions(
        "jumps up and down",
        "a person jumps up"
    ));
    assert!(!opposite_directions(
        "turns around and walks back",
        "a person walks forward"
    ));
}

#[test]
fn calibration_picks_the_middle_of_the_widest_best_gap() {
    let pairs: Vec<LabelledPair> = [
        ("a", 0.9, true),
        ("b", 0.8, true),
        ("c", 0.65, true),
        ("d", 0.5, false),
        ("e", 0.2, false),
        ("f", 0.7, false),
    ]
    .iter()
    .map(|(c, _, same)| LabelledPair {
        clause: c.to_string(),
        plan: "x".into(),
        same: *same,
    })
    .collect();
    let score = |c: &str, _: &str| match c {
        "a" => 0.9,
        "b" => 0.8,
        "c" => 0.65,
        "d" => 0.5,
        "e" => 0.2,
        _ => 0.7,
    };
    let cal = calibrate(&pairs, &score);
    // 5 of 6 right from just above 0.5 to 0.65 and from just above 0.7 to 0.8; smoothed, the
    // first range is the wider plateau, and the threshold its middle.
    assert!((cal.accuracy - 5.0 / 6.0).abs() < 1e-9, "{cal:?}");
    assert!((cal.smoothed_accuracy - 5.0 / 6.0).abs() < 1e-9, "{cal:?}");
    assert!(cal.lowest > 0.51 && cal.lowest < 0.53, "{cal:?}");
    assert!(cal.highest > 0.62 && cal.highest < 0.64, "{cal:?}");
    assert!((cal.threshold - 0.575).abs() < 0.002, "{cal:?}");
    assert_eq!(cal.false_same.len(), 1);
    assert_eq!(cal.false_same[0].0, "f");
}

#[test]
fn a_substitute_in_a_note_does_not_account_for_a_clause() {
    let bows = &prompt().clauses[2];
    let substituted = "\"claps\" is not a movement the model knows; used the nearest one, \"bows\"";
    let bow = plan_elements(&plan(vec![bow()], &[]));
    let text = "A man walks forward while waving his left hand, then bows twice.";
    // The plan holds the bow: the note names what it used for another clause.
    assert!(!note_names(substituted, bows, text, &bow, &matcher()));
    // A movement the plan left out, in the note's own words, names the clause.
    let left_out = "a plan has at most 4 segments; left out: a person bows";
    assert!(note_names(left_out, bows, text, &[], &matcher()));
    // A quote of the prompt names the clauses whose words it covers, in part or whole.
    let quoted = "\"then bows\" names no movement the model makes; left out";
    assert!(note_names(quoted, bows, text, &bow, &matcher()));
    let elsewhere = "\"walks forward\" names no movement the model makes; left out";
    assert!(!note_names(elsewhere, bows, text, &bow, &matcher()));
}

#[test]
fn arms_held_through_a_movement_of_key_poses_are_on_the_arms() {
    let p = crate::agents::planner::offline::plan(
        "Someone jogs in place with both arms stretched out to the sides.",
        None,
    );
    let elements = plan_elements(&p);
    let arms: Vec<&Element> = elements
        .iter()
        .filter(|e| e.on == On::Parts(vec![BodyPart::LeftArm, BodyPart::RightArm]))
        .collect();
    assert_eq!(arms.len(), 1, "{elements:?}");
    assert_eq!(arms[0].text, "T-pose");
    let body: Vec<&Element> = elements.iter().filter(|e| e.on == On::Body).collect();
    assert_eq!(body.len(), 1, "{elements:?}");
    assert_eq!(body[0].text, "jog in place");
    assert_eq!((arms[0].start, arms[0].end), (body[0].start, body[0].end));
    // Key poses that hold nothing in common, or a leg's, are left as they are.
    assert_eq!(held_arms(&["crouch".into(), "stand".into()]), None);
    assert_eq!(held_arms(&["step forward with the left foot".into()]), None);
}

#[test]
fn tracks_of_library_movements_are_named_by_them() {
    let jump = Library::builtin()
        .actions
        .iter()
        .find(|a| a.name == "jump")
        .unwrap();
    let p = plan(
        vec![Segment {
            postures: Some(jump.track(Some(2), [0.0, 0.0])),
            ..segment("a person stands still", &[])
        }],
        &[],
    );
    let elements = plan_elements(&p);
    assert_eq!(elements.len(), 1, "{elements:?}");
    assert_eq!((elements[0].text.as_str(), elements[0].count), ("jump", 2));
    assert_eq!(elements[0].on, On::Body);
}

#[test]
fn a_walk_over_two_segments_is_one_walk_and_arm_postures_walk_no_path() {
    use crate::trajectory::{Shape, Side as PathSide, Trajectory};
    let p = plan(
        vec![
            segment("a person walks forward", &[]),
            walk_waving(BodyPart::LeftArm),
            bow(),
            bow(),
        ],
        &[],
    );
    let out = score_prompt(&prompt(), &p, &matcher());
    assert!(out.clauses[0].correct, "{out:#?}");
    let t_pose = Library::builtin().get("T-pose").unwrap();
    let circling = Segment {
        trajectory: Some(Trajectory::Shape {
            shape: Shape::Circle(PathSide::Left),
        }),
        postures: Some(PostureTrack::holding(
            vec![BodyPart::LeftArm, BodyPart::RightArm],
            t_pose.script.clone(),
        )),
        ..segment("a person walks forward", &[])
    };
    let elements = plan_elements(&plan(vec![circling], &[]));
    assert!(
        elements[0].path.is_some() && elements[1].path.is_none(),
        "{elements:?}"
    );
}
