//! A held pose of the torso read from the words ("leans to the left", "bends forward",
//! "stretches into a side bend to the right", "twists the upper body to the left", "looks
//! over the right shoulder"): the standing body with the trunk leaning or turned, as
//! pose-code constraints the posture solver meets (the lean and twist codes of CoMo's
//! vocabulary). The model has no torso of its own to edit (its parts are the four limbs), so
//! the pose is a key pose of the whole body, standing; the built-in planner makes it the
//! clause's segment when the clause names nothing else.

use crate::posecodes::{Lean, PelvisLevel, Twist};
use crate::posture::library::NamedPosture;
use crate::posture::script::{Constraint, PostureScript};
use crate::skeleton::{BodyPart, Side};

/// Seconds the pose is held once reached.
const HOLD_SECONDS: f64 = 1.0;

/// Verbs of a lean or a bend of the trunk.
const LEANING: &[&str] = &[
    "lean", "leans", "leaning", "bend", "bends", "bending", "tilt", "tilts", "tilting", "sway",
    "sways", "swaying",
];

/// Verbs of a turn of the trunk.
const TURNING: &[&str] = &[
    "twist", "twists", "twisting", "rotate", "rotates", "rotating",
];

/// Verbs of a look, which turns the upper body toward where the eyes go: the skeleton's head
/// is one joint, so a look is seen by the shoulders turning ("looks over the right shoulder",
/// "looks to the left").
const LOOKING: &[&str] = &[
    "look", "looks", "looking", "glance", "glances", "glancing", "peek", "peeks", "peeking",
];

/// Words that say the whole trunk goes, not a limb: "bends **down** to pick up" is a
/// movement of the model, "leans **on** the wall" none of the torso.
const ELSEWHERE: &[&str] = &[
    "down", "on", "against", "arm", "arms", "hand", "hands", "leg", "legs", "knee", "knees",
    "head", "foot", "feet",
];

/// The torso pose a clause asks for, if it asks only that: the lean or twist and its name
/// ("leaning to the left"); `None` when the words name no way for the trunk to go.
pub(super) fn torso_pose(words: &[&str]) -> Option<NamedPosture> {
    let has = |list: &[&str]| words.iter().any(|w| list.contains(w));
    // "bends forward to touch his toes": the purpose is a posture or a movement of its own.
    let purpose = words
        .windows(2)
        .any(|w| w[0] == "to" && !matches!(w[1], "the" | "his" | "her" | "their" | "one"));
    if purpose {
        return None;
    }
    let side = words.iter().find_map(|w| Side::of_word(w));
    let forward = has(&["forward", "forwards", "front"]);
    let backward = has(&["backward", "backwards", "back"]);
    let shoulder = words
        .windows(2)
        .any(|w| matches!(w[1], "shoulder") && Side::of_word(w[0]).is_some());
    // "turns his head to the left": the head's turn, seen as a look is.
    let head_turn = has(&["turn", "turns", "turning"]) && has(&["head"]);
    if words
        .iter()
        .any(|w| ELSEWHERE.contains(w) && !(head_turn && *w == "head"))
    {
        return None;
    }
    let (lean, twist, name) = if has(LEANING) {
        match (side, forward, backward) {
            (Some(s), false, false) => (
                lean_to(s),
                Twist::None,
                format!("leaning to the {}", s.name()),
            ),
            (None, true, false) => (Lean::Forward, Twist::None, "leaning forward".to_string()),
            (None, false, true) => (Lean::Backward, Twist::None, "leaning backward".to_string()),
            _ => return None,
        }
    } else if has(&["side"]) && has(&["bend", "bends", "stretch", "stretches"]) {
        let s = side?;
        (
            lean_to(s),
            Twist::None,
            format!("leaning to the {}", s.name()),
        )
    } else if has(TURNING) || has(LOOKING) || head_turn {
        let trunk = shoulder || has(&["torso", "trunk", "waist", "body", "upper"]);
        if has(TURNING) && !trunk {
            return None;
        }
        // "looks to the left" goes that way; "looks at the left door" names a thing.
        let s = if trunk {
            side?
        } else {
            // "looks to the left", "looks left".
            words
                .windows(3)
                .find(|w| matches!(w[0], "to" | "toward" | "towards") && w[1] == "the")
                .and_then(|w| Side::of_word(w[2]))
                .or_else(|| {
                    words
                        .windows(2)
                        .find(|w| LOOKING.contains(&w[0]))
                        .and_then(|w| Side::of_word(w[1]))
                })?
        };
        let twist = match s {
            Side::Left => Twist::Left,
            Side::Right => Twist::Right,
        };
        // Named as the words see it, so a reader of the plan knows the clause in it.
        let name = if head_turn {
            format!("head turned to the {}", s.name())
        } else if has(LOOKING) && shoulder {
            format!("looking over the {} shoulder", s.name())
        } else if has(LOOKING) {
            format!("looking to the {}", s.name())
        } else {
            format!("torso turned to the {}", s.name())
        };
        (Lean::Upright, twist, name)
    } else {
        return None;
    };
    let script = PostureScript {
        name: Some(name.clone()),
        hold: HOLD_SECONDS,
        constraints: vec![
            Constraint::Level {
                is: PelvisLevel::Standing,
            },
            Constraint::Lean { is: lean },
            Constraint::Twist { is: twist },
        ],
    }
    .check()
    .ok()?;
    Some(NamedPosture {
        name,
        synonyms: Vec::new(),
        parts: BodyPart::ALL.to_vec(),
        script,
    })
}

fn lean_to(side: Side) -> Lean {
    match side {
        Side::Left => Lean::Left,
        Side::Right => Lean::Right,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::posture::solver::solve;

    fn pose(text: &str) -> Option<NamedPosture> {
        torso_pose(&text.split(' ').collect::<Vec<_>>())
    }

    #[test]
    fn the_trunk_leans_or_turns_the_way_the_words_say_and_the_solver_meets_it() {
        for (text, name) in [
            ("leans to the left", "leaning to the left"),
            ("she leans to the right", "leaning to the right"),
            (
                "stretches into a side bend to the right",
                "leaning to the right",
            ),
            ("leaning backward", "leaning backward"),
            ("bends forward", "leaning forward"),
            (
                "looks over the right shoulder",
                "looking over the right shoulder",
            ),
            ("looks to the right", "looking to the right"),
            ("glances left", "looking to the left"),
            ("turns his head to the left", "head turned to the left"),
            (
                "twists the upper body to the left",
                "torso turned to the left",
            ),
        ] {
            let p = pose(text).unwrap_or_else(|| panic!("{text}: no pose"));
            assert_eq!(p.name, name, "{text}");
            let solved = solve(&p.script, None);
            assert!(solved.unmet.is_empty(), "{text}: {:?}", solved.unmet);
        }
    }

    #[test]
    fn other_movements_are_no_torso_pose() {
        for text in [
            "bends down to pick up a box",
            "bends forward to touch his toes",
            "stretches her left arm to the side",
            "looks at his left hand",
            "looks up",
            "twists his left wrist",
            "leans on the wall",
            "walks forward",
            "leans",
        ] {
            assert!(pose(text).is_none(), "{text}");
        }
    }
}
