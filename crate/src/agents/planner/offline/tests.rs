use super::*;
use crate::agents::planner::prompt_set::edited_parts;

/// The committed prompt set, with what a reader sees in each prompt.
#[derive(serde::Deserialize)]
struct PromptSet {
    prompts: Vec<Expected>,
}

#[derive(serde::Deserialize)]
struct Expected {
    prompt: String,
    segments: usize,
    #[serde(default)]
    parts: Vec<String>,
}

fn prompt_set() -> PromptSet {
    serde_json::from_str(include_str!("../../../../../eval/prompts.json")).unwrap()
}

#[test]
fn the_acceptance_prompt_gives_segments_a_left_arm_edit_and_a_bow() {
    let plan = plan(
        "A person walks forward waving the left hand, then turns right and bows",
        None,
    );
    let n = plan.segments.len();
    assert!((2..=3).contains(&n), "{plan:#?}");
    let first = &plan.segments[0];
    assert_eq!(first.base, "a person walks forward");
    assert_eq!(
        first.parts.left_arm.as_deref(),
        Some("a person waves the left hand")
    );
    assert_eq!(first.parts.right_arm, None);
    assert_eq!(
        plan.segments[1].base,
        "a person walks forward, turning to the right"
    );
    assert_eq!(plan.segments[n - 1].base, "a person bows");
    assert_eq!(plan.planner, PlannerKind::Offline);
}

#[test]
fn segment_counts_match_the_prompt_set() {
    let set = prompt_set();
    assert!(set.prompts.len() >= 30);
    let mut wrong = Vec::new();
    for p in &set.prompts {
        let plan = plan(&p.prompt, None);
        if plan.segments.len() != p.segments {
            wrong.push(format!(
                "{:?}: {} segments, expected {}: {:?}",
                p.prompt,
                plan.segments.len(),
                p.segments,
                plan.segments.iter().map(|s| &s.text).collect::<Vec<_>>()
            ));
        }
    }
    let rate = 1.0 - wrong.len() as f64 / set.prompts.len() as f64;
    // The figure the CLI reports (`coma plan --prompts eval/prompts.json`) comes from the
    // same function; this bound keeps it from sliding back.
    assert!(rate >= 0.9, "rate {rate:.2}:\n{}", wrong.join("\n"));
}

#[test]
fn part_edits_match_the_prompt_set() {
    let set = prompt_set();
    let mut wrong = Vec::new();
    for p in &set.prompts {
        let plan = plan(&p.prompt, None);
        let mut expected = p.parts.clone();
        expected.sort();
        if edited_parts(&plan) != expected {
            wrong.push(format!("{:?}: {:?}", p.prompt, edited_parts(&plan)));
        }
    }
    assert!(wrong.len() <= 3, "{}", wrong.join("\n"));
}

#[test]
fn before_and_after_are_put_in_time_order() {
    let bases =
        |p: &str| -> Vec<String> { plan(p, None).segments.into_iter().map(|s| s.base).collect() };
    let wave_then_bow = vec![
        "a person waves the right hand".to_string(),
        "a person bows".to_string(),
    ];
    assert_eq!(
        bases("Before bowing, a person waves the right hand."),
        wave_then_bow
    );
    assert_eq!(
        bases("A person waves the right hand before bowing."),
        wave_then_bow
    );
    assert_eq!(
        bases("A person bows after waving the right hand."),
        wave_then_bow
    );
    assert_eq!(
        bases("After waving the right hand, a person bows."),
        wave_then_bow
    );
}

#[test]
fn while_joins_a_walk_and_a_gesture() {
    let plan = plan(
        "While walking forward, the person waves the right hand.",
        None,
    );
    assert_eq!(plan.segments.len(), 1, "{plan:#?}");
    assert_eq!(plan.segments[0].base, "a person walks forward");
    assert_eq!(
        plan.segments[0].parts.right_arm.as_deref(),
        Some("a person waves the right hand")
    );
    let and = super::plan("a person walks forward and waves both hands", None);
    assert_eq!(and.segments.len(), 1, "{and:#?}");
    assert!(and.segments[0].parts.left_arm.is_some() && and.segments[0].parts.right_arm.is_some());
}

#[test]
fn a_clause_without_a_verb_inherits_the_gesture() {
    let plan = plan(
        "Someone raises the right hand, then the left hand, then both hands.",
        None,
    );
    let bases: Vec<&str> = plan.segments.iter().map(|s| s.base.as_str()).collect();
    assert_eq!(
        bases,
        [
            "a person raises the right hand",
            "a person raises the left hand",
            "a person raises both hands"
        ]
    );
}

#[test]
fn durations_are_read_and_clamped() {
    let s = |p: &str| plan(p, None).segments[0].seconds;
    assert_eq!(s("a person waves the left hand for three seconds"), 3.0);
    assert_eq!(s("a person waves the left hand for 2.5 s"), 2.5);
    assert_eq!(s("a person dances for 30 seconds"), 9.8);
    assert_eq!(s("a person bows for 1 second"), 2.0);
    assert!(s("a person walks forward slowly") > s("a person walks forward"));
    for segment in plan("a person walks forward, then runs, then bows", None).segments {
        assert!((2.0..=9.8).contains(&segment.seconds));
    }
}

#[test]
fn repetitions_repeat_and_the_plan_stops_at_four_segments() {
    assert_eq!(plan("a person bows twice", None).segments.len(), 2);
    assert_eq!(plan("a person kicks three times", None).segments.len(), 3);
    let long = plan(
        "a person walks, then runs, then bows, then kicks, then punches, then dances",
        None,
    );
    assert_eq!(long.segments.len(), 4);
    assert!(
        long.notes.iter().any(|n| n.contains("at most 4")),
        "{:?}",
        long.notes
    );
}

#[test]
fn styles_become_caption_words() {
    let plan = plan(
        "An angry person walks forward, turns left, and kicks.",
        None,
    );
    assert_eq!(plan.segments.len(), 3);
    for s in &plan.segments {
        assert!(s.base.ends_with("angrily"), "{}", s.base);
    }
    let old = super::plan("an elderly woman walks slowly forward", None);
    assert_eq!(
        old.segments[0].base,
        "a person walks forward like an elderly person"
    );
}

#[test]
fn context_that_is_not_motion_is_dropped() {
    let plan = plan(
        "The player jogs onto the pitch at Highbury, waves both hands to the crowd, then bows politely.",
        None,
    );
    let bases: Vec<&str> = plan.segments.iter().map(|s| s.base.as_str()).collect();
    assert_eq!(
        bases,
        [
            "a person runs forward",
            "a person waves both hands",
            "a person bows"
        ]
    );
    assert!(!plan.rewritten.contains("highbury"));
}

#[test]
fn unknown_movements_go_to_the_nearest_action_with_an_embedder() {
    // A toy embedder: one dimension per word, so "spins around dancing" is nearest to
    // "a person dances" by shared words. MiniLM does this by meaning.
    let vocab = ["person", "dances", "dancing", "cartwheel", "bows", "walks"];
    let embed = |s: &str| -> Vec<f32> {
        let mut v: Vec<f32> = vocab
            .iter()
            .map(|w| s.split_whitespace().filter(|x| x == w).count() as f32)
            .collect();
        if s.contains("cartwheel") {
            v[1] += 1.0;
        }
        v
    };
    let with = plan("a ballerina does a cartwheel", Some(&embed));
    assert_eq!(with.segments[0].base, "a person dances", "{with:#?}");
    assert!(with.notes.iter().any(|n| n.contains("nearest")));
    let without = plan("a ballerina does a cartwheel", None);
    assert_eq!(without.segments.len(), 1);
    assert!(without
        .notes
        .iter()
        .any(|n| n.contains("no known movement")));
}

#[test]
fn hostile_prompts_give_a_plan_and_never_panic() {
    let long = "walk ".repeat(5000);
    let nested = "then ".repeat(3000);
    let inputs = [
        "",
        "   ",
        "\u{0}\u{1}\u{2}",
        ".,;!?",
        "then then then",
        "before after while",
        "and and and ,,, ...",
        long.as_str(),
        nested.as_str(),
        "😀 walks 😀 forward 😀",
        "WALKS FORWARD, THEN BOWS",
        "a person walks for 1e308 seconds",
        "a person walks for NaN seconds",
        "a person walks for -5 seconds",
        "<script>alert(1)</script> a person bows",
        "'; DROP TABLE motions; -- then kicks",
        "turn",
        "left right both",
        "after",
        "while",
    ];
    for input in inputs {
        let plan = plan(input, None);
        assert!(
            (1..=MAX_SEGMENTS).contains(&plan.segments.len()),
            "{input:?}: {plan:#?}"
        );
        for s in &plan.segments {
            assert!(s.seconds.is_finite() && (2.0..=9.8).contains(&s.seconds));
            assert!(s.text.chars().count() <= MAX_TEXT_CHARS);
            assert!(!s.base.contains('\u{0}'));
        }
    }
}

#[test]
fn every_word_the_planner_writes_is_in_the_training_vocabulary() {
    let vocabulary: serde_json::Value =
        serde_json::from_str(include_str!("../../../../../static/models/vocabulary.json")).unwrap();
    let words: std::collections::BTreeSet<String> = vocabulary["words"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap().to_string())
        .collect();
    let mut unknown = std::collections::BTreeSet::new();
    for p in &prompt_set().prompts {
        let plan = plan(&p.prompt, None);
        for s in &plan.segments {
            let texts =
                std::iter::once(s.base.clone()).chain(s.parts.edits().into_iter().map(|(_, t)| t));
            for t in texts {
                for w in t
                    .split(|c: char| !c.is_alphanumeric() && c != '-')
                    .filter(|w| !w.is_empty())
                {
                    if !words.contains(w) {
                        unknown.insert(w.to_string());
                    }
                }
            }
        }
    }
    assert!(unknown.is_empty(), "words the model never saw: {unknown:?}");
}

#[test]
fn a_jump_lands_in_the_posture_the_next_clause_names() {
    let jumped = plan("He jumps up and lands in a superhero landing.", None);
    assert_eq!(jumped.segments.len(), 2, "{:#?}", jumped.segments);
    let jump = jumped.segments[0]
        .postures
        .as_ref()
        .expect("the jump's key poses");
    let last = jump.keys.last().unwrap();
    assert!(
        last.jump_m.is_some(),
        "the last key is reached by the flight"
    );
    assert_eq!(last.script.name.as_deref(), Some("superhero landing"));
    let held = jumped.segments[1]
        .postures
        .as_ref()
        .expect("the landing held");
    assert_eq!(held.keys[0].script, last.script);
    // Landing with nothing named, or landing after something that is not a jump, is left as
    // it was: the jump ends standing.
    let plain = plan("A cheerleader jumps, then lands and claps.", None);
    let jump = plain.segments[0].postures.as_ref().unwrap();
    assert!(jump.keys.last().unwrap().jump_m.is_none());
    let squat = plan("He squats, then lands in a superhero landing.", None);
    assert!(squat.segments[0]
        .postures
        .as_ref()
        .unwrap()
        .keys
        .iter()
        .all(|k| k.jump_m.is_none()));
}
