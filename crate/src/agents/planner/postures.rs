//! The built-in planner's key postures: clauses that name a posture ("strikes a T-pose",
//! "kneels on one knee") or a movement made of key poses ("jumps", "crawls forward", "does
//! five push-ups") from the posture library ([`crate::posture::library`]) become posture
//! tracks, where the motion model does not know them.
//!
//! - A clause with a walk or run and postures of the arms only keeps the model's motion and
//!   holds the postures on those arms ("walks in a zigzag holding both arms out in a T").
//! - Otherwise the postures and movements make a posture segment: one movement's keys (with
//!   the arm postures laid into each key), or one key merged from the named postures (a squat
//!   with a T-pose's arms). Gestures the model knows in the same clause ("kneels and raises the
//!   right hand") stay the model's: the track then leaves those arms to it.
//! - A clause that only asks to stay ("waits", "rests", "lies still") holds the pose before.
//! - Where the model knows a movement of dataset v2 (a squat, a jump, lying down), the model
//!   makes it, and a posture of the arms is held over it ("squats while striking a T-pose");
//!   the library keeps poses held ("holds a deep squat", "squats and holds it"), and
//!   movements and poses it names otherwise ("jumping jacks", "hops on one leg").

use super::lexicon::{self, Action};
use crate::plan::{clamp_seconds, PartEdits, Segment};
use crate::posecodes::{BodyPoint, Limb, Support};
use crate::posture::library::{Library, Named, NamedPosture};
use crate::posture::script::{Constraint, Hinge, PostureScript};
use crate::posture::track::{PostureTrack, DEFAULT_TRANSITION_SECONDS};
use crate::skeleton::BodyPart;

/// Seconds added to the segment before for a clause that only asks to stay still.
pub const HOLD_EXTRA_SECONDS: f64 = 1.5;

/// Verbs that start a clause about postures (so "and kneels" begins a new movement), beyond
/// those the model's own lexicon knows.
pub fn is_posture_verb(word: &str) -> bool {
    const VERBS: &[&str] = &[
        "squat",
        "squats",
        "crouch",
        "crouches",
        "kneel",
        "kneels",
        "sit",
        "sits",
        "lie",
        "lies",
        "lay",
        "lays",
        "crawl",
        "crawls",
        "creep",
        "creeps",
        "fall",
        "falls",
        "rise",
        "rises",
        "get",
        "gets",
        "hop",
        "hops",
        "leap",
        "leaps",
        "jump",
        "jumps",
        "spin",
        "spins",
        "twirl",
        "twirls",
        "bend",
        "bends",
        "stretch",
        "stretches",
        "flex",
        "flexes",
        "strike",
        "strikes",
        "hold",
        "holds",
        "put",
        "puts",
        "cover",
        "covers",
        "clap",
        "claps",
        "pray",
        "prays",
        "dab",
        "dabs",
        "land",
        "lands",
        "lower",
        "lowers",
        "roll",
        "rolls",
        "push",
        "pushes",
        "meditate",
        "meditates",
        "dive",
        "dives",
        "trip",
        "trips",
        "collapse",
        "collapses",
        "reach",
        "reaches",
        "uncross",
        "uncrosses",
        "cross",
        "crosses",
        "fly",
        "flies",
        "stand",
        "stands",
        "rest",
        "rests",
        "wait",
        "waits",
        "relax",
        "relaxes",
        "stay",
        "stays",
        "pose",
        "poses",
        "balance",
        "balances",
        "lunge",
        "lunges",
        "touch",
        "touches",
        "slide",
        "slides",
        "open",
        "opens",
        "spread",
        "spreads",
    ];
    VERBS.contains(&word)
}

/// Words of a plain raise or wave of a hand ("raises both arms", "waves the left hand"): the
/// model makes those itself, so a posture named by these words alone stays the model's.
const PLAIN_GESTURE_WORDS: &[&str] = &[
    "raise", "raises", "raising", "raised", "lift", "lifts", "lifting", "wave", "waves", "waving",
    "the", "a", "his", "her", "their", "its", "left", "right", "both", "one", "hand", "hands",
    "arm", "arms", "up", "high", "in", "into", "air", "overhead",
];

/// Words of holding a pose ("holds a squat", "stays in a squat", "and holds it").
const HOLD_VERBS: &[&str] = &[
    "hold",
    "holds",
    "holding",
    "held",
    "stay",
    "stays",
    "staying",
    "remain",
    "remains",
    "remaining",
    "freeze",
    "freezes",
    "frozen",
];

/// The library's names for what an action of dataset v2 also is, or passes through: a clause
/// that names the action with these ("squats", "crouches down into a squat", "jumps up",
/// "lies down", "crouches to set something down") is the model's when it knows the action;
/// any other name there ("sumo squat", "jumping jacks") is the library's.
fn library_names(action: Action) -> &'static [&'static str] {
    match action {
        Action::Squat => &["squat", "deep squat", "crouch"],
        Action::Jump | Action::JumpForward => &["jump"],
        Action::LieDown => &[
            "lie on the back",
            "kneel on both knees",
            "kneel on one knee",
        ],
        Action::ReachUp(_) => &["stretching arms up"],
        Action::PutDown(_) => &["crouch", "squat", "kneel on one knee"],
        _ => &[],
    }
}

/// Whether the words right after a library mention say it is about a limb the posture does
/// not hold: "stretching **the right leg** out" is no "stretching arms up", nor is
/// "stretches out **his right arm**".
fn names_other_limb(after: &str, one_word: bool, named: &Named) -> bool {
    let Named::Posture(posture) = named else {
        return false;
    };
    // Only the mention's own words: "kneels on one knee **while waving both hands**" is a
    // kneel with a movement of the arms beside it.
    let next: Vec<&str> = after
        .split(' ')
        .filter(|w| !w.is_empty())
        .take(4)
        .take_while(|w| {
            !matches!(*w, "while" | "whilst" | "and" | "," | "then" | "as") && !w.ends_with("ing")
        })
        .collect();
    let limb = next.iter().find_map(|w| match *w {
        "leg" | "legs" | "foot" | "feet" | "knee" | "knees" => Some(true),
        "arm" | "arms" | "hand" | "hands" => Some(false),
        _ => None,
    });
    // "stretches out his right arm": a bare verb the words after complete, about one arm;
    // the limb's own words say where it goes.
    if one_word && one_arm_after(after).is_some() {
        return true;
    }
    let holds_legs = posture
        .parts
        .iter()
        .any(|p| matches!(p, BodyPart::LeftLeg | BodyPart::RightLeg));
    let holds_arms = posture
        .parts
        .iter()
        .any(|p| matches!(p, BodyPart::LeftArm | BodyPart::RightArm));
    match limb {
        Some(true) => !holds_legs,
        Some(false) => !holds_arms,
        None => false,
    }
}

/// The one arm the words right after a mention name ("… with the left hand"), if they name
/// one arm.
fn one_arm_after(after: &str) -> Option<BodyPart> {
    // "points up at the sky with the left hand": a place may come between, not another
    // movement.
    let next: Vec<&str> = after
        .split(' ')
        .filter(|w| !w.is_empty())
        .take_while(|w| !matches!(*w, "and" | "while" | "then" | "as"))
        .take(8)
        .collect();
    let arm = next.iter().any(|w| matches!(*w, "arm" | "hand" | "fist"));
    match (arm, next.contains(&"left"), next.contains(&"right")) {
        (true, true, false) => Some(BodyPart::LeftArm),
        (true, false, true) => Some(BodyPart::RightArm),
        _ => None,
    }
}

/// A posture of both arms held by `arm` alone: its constraints on that arm (and none on the
/// other), named for it; `None` when it says nothing of that arm alone.
fn one_arm_of(posture: &NamedPosture, arm: BodyPart) -> Option<NamedPosture> {
    use crate::skeleton::joint;
    let other = match arm {
        BodyPart::LeftArm => [joint::R_SHOULDER, joint::R_ELBOW, joint::R_WRIST],
        _ => [joint::L_SHOULDER, joint::L_ELBOW, joint::L_WRIST],
    };
    let constraints: Vec<Constraint> = posture
        .script
        .constraints
        .iter()
        .filter(|c| region(c) == Region::Arms && !c.joints().iter().any(|j| other.contains(j)))
        .copied()
        .collect();
    let name = format!("{} with the {}", posture.name, arm.name());
    let script = PostureScript {
        name: Some(name.clone()),
        hold: posture.script.hold,
        constraints,
    }
    .check()
    .ok()?;
    Some(NamedPosture {
        name,
        synonyms: posture.synonyms.clone(),
        parts: vec![arm],
        script,
    })
}

/// Whether a clause only names poses that `action`, planned next, passes through
/// ("kneels and then lies down": the model's lying down kneels on the way).
pub fn leads_into(words: &[&str], action: Action) -> bool {
    let mentions = Library::builtin().mentions(&words.join(" "));
    let names = library_names(action);
    !mentions.is_empty()
        && mentions
            .iter()
            .all(|(_, n)| matches!(n, Named::Posture(_)) && names.contains(&n.name()))
}

/// Whether the posture library keeps the clause although the model knows `action`, named by
/// word `at`: the word is part of the library's name for something else ("jumping jacks",
/// "sumo squat", "creeps on hands and knees"); the clause names a whole-body pose besides
/// ("hops on one leg"); or the action's pose is held, in the clause ("holds a squat", "stays
/// in a squat", "a squat position") or, when `held_after`, by the clause after it.
pub fn keeps(words: &[&str], at: usize, action: Action, held_after: bool) -> bool {
    let same = library_names(action);
    let text = words.join(" ");
    let start: usize = words[..at].iter().map(|w| w.len() + 1).sum();
    let mentions = Library::builtin().mentions(&text);
    let other = |n: &Named| !same.contains(&n.name());
    let claimed = mentions.iter().any(|(r, n)| r.contains(&start) && other(n));
    let body_pose = mentions.iter().any(|(r, n)| {
        !r.contains(&start) && other(n) && matches!(n, Named::Posture(p) if !arms_only(p))
    });
    let held = !same.is_empty() && (held_after || held_in(words, at));
    claimed || body_pose || held
}

/// Whether the clause holds the pose of the movement at `at`: a word of holding before it,
/// or a word of a pose after it, with only articles and such between ("holds a deep
/// squat", "stays down in a squat", "squats into a squat position").
fn held_in(words: &[&str], at: usize) -> bool {
    const BETWEEN: &[&str] = &[
        "a", "an", "the", "in", "into", "down", "low", "deep", "full", "his", "her", "their",
        "its", "this", "that", "there",
    ];
    const POSE: &[&str] = &[
        "position",
        "pose",
        "posture",
        "stance",
        "still",
        "motionless",
    ];
    let before = words[..at].iter().rev().find(|w| !BETWEEN.contains(w));
    let after = words[at + 1..].iter().find(|w| !BETWEEN.contains(w));
    before.is_some_and(|w| HOLD_VERBS.contains(w)) || after.is_some_and(|w| POSE.contains(w))
}

/// Whether a clause holds the pose the clause before it ends in ("and holds it", "then stays
/// there") or lands it in a named posture ("and lands in a superhero landing").
pub fn keeps_pose_before(words: &[&str]) -> bool {
    let first = words
        .iter()
        .find(|w| !lexicon::is_subject_word(w) && !lexicon::is_subject_noun(w));
    match first {
        Some(&("land" | "lands")) => names_posture(words),
        // "holds it", "holds for 3 seconds"; not "holds a T-pose", a pose of its own.
        Some(w) => {
            HOLD_VERBS.contains(w) && Library::builtin().mentions(&words.join(" ")).is_empty()
        }
        None => false,
    }
}

/// Whether a clause only stands up ("stands back up", "gets up"), the library's movement.
pub fn stands_up(words: &[&str]) -> bool {
    let mentions = Library::builtin().mentions(&words.join(" "));
    !mentions.is_empty()
        && mentions
            .iter()
            .all(|(_, n)| matches!(n, Named::Action(_)) && n.name() == "stand up")
}

/// What a clause with no movement of its own asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stay {
    /// Nothing new: leaving one pose on the way to the next ("trips", "lands", "uncrosses
    /// them").
    Passing,
    /// Waiting as one is ("waits", "rests", "pauses"): the movement before lasts longer.
    Longer,
    /// Holding the pose as a movement of its own ("meditates for a while", "lies still").
    Hold,
}

/// A jump lands in the posture that a "lands in …" clause names ("jumps up and lands in a
/// superhero landing"): the previous segment's last flight key becomes that posture and the
/// keys after it (the way back up to standing) go, so the posture comes out of the jump
/// instead of from standing after it. The landing clause keeps its own segment, which then
/// holds the pose. Returns whether the jump was changed.
pub fn land_in(words: &[&str], previous: Option<&mut Segment>, landing: &Segment) -> bool {
    let lands = words.iter().any(|w| matches!(*w, "land" | "lands"));
    let (Some(previous), Some(pose)) = (previous, landing.postures.as_ref()) else {
        return false;
    };
    let Some(jump) = previous.postures.as_mut() else {
        return false;
    };
    let single = pose.whole_body() && pose.keys.len() == 1 && pose.repeat == 1;
    let Some(flight) = jump.keys.iter().rposition(|k| k.jump_m.is_some()) else {
        return false;
    };
    if !(lands && single && jump.whole_body() && jump.repeat == 1) {
        return false;
    }
    let mut landed = jump.clone();
    landed.keys[flight].script = pose.keys[0].script.clone();
    landed.keys.truncate(flight + 1);
    landed.returns = false;
    let Ok(landed) = landed.checked() else {
        return false;
    };
    previous.seconds =
        clamp_seconds(landed.natural_seconds() + DEFAULT_TRANSITION_SECONDS).unwrap_or(2.0);
    *jump = landed;
    true
}

/// Whether a clause with no movement only asks to stay as one is, and how.
pub fn stay(words: &[&str]) -> Option<Stay> {
    const PASSING: &[&str] = &[
        "trip",
        "trips",
        "tripping",
        "stumble",
        "stumbles",
        "stumbling",
        "slip",
        "slips",
        "slipping",
        "land",
        "lands",
        "landing",
        "uncross",
        "uncrosses",
        "release",
        "releases",
        "loses",
    ];
    const LONGER: &[&str] = &[
        "wait", "waits", "waiting", "rest", "rests", "resting", "pause", "pauses", "relax",
        "relaxes", "stop", "stops", "freeze", "freezes", "remain", "remains", "breath", "breathe",
        "breathes",
    ];
    const HOLD: &[&str] = &[
        "still",
        "meditate",
        "meditates",
        "meditating",
        "stays",
        "stay",
    ];
    let has = |list: &[&str]| words.iter().any(|w| list.contains(w));
    // "holds the pose", "holds it there": holding what there is, not an object.
    let holds_it = words.windows(2).any(|w| {
        matches!(w[0], "hold" | "holds" | "holding")
            && matches!(
                w[1],
                "it" | "them" | "that" | "this" | "there" | "still" | "steady"
            )
    }) || words.windows(3).any(|w| {
        matches!(w[0], "hold" | "holds" | "holding")
            && matches!(w[1], "the" | "that" | "this" | "his" | "her" | "their")
            && matches!(w[2], "pose" | "position" | "posture" | "stance")
    });
    if has(HOLD) || holds_it {
        Some(Stay::Hold)
    } else if has(LONGER) {
        Some(Stay::Longer)
    } else if has(PASSING) {
        Some(Stay::Passing)
    } else {
        None
    }
}

/// Whether a clause holds by name the posture `previous` ends in ("lunges with the left leg,
/// holds the lunge"): the same pose held on, not the library's posture made anew (which
/// would forget the leg the clause before named).
pub fn holds_by_name(words: &[&str], previous: &Segment) -> bool {
    let Some(name) = previous
        .postures
        .as_ref()
        .filter(|t| t.whole_body())
        .and_then(|t| t.keys.last())
        .and_then(|k| k.script.name.as_deref())
    else {
        return false;
    };
    let name_words: Vec<&str> = name.split([' ', ',']).collect();
    words.windows(3).any(|w| {
        matches!(
            w[0],
            "hold" | "holds" | "holding" | "keeps" | "keep" | "stays" | "stay"
        ) && matches!(
            w[1],
            "the" | "that" | "this" | "his" | "her" | "their" | "in"
        ) && name_words.contains(&w[2])
    })
}

/// A segment that holds the last key pose of `previous` (a posture segment) for a while.
pub fn hold_segment(words: &[&str], previous: &Segment) -> Option<Segment> {
    let track = previous.postures.as_ref().filter(|t| t.whole_body())?;
    let last = track.keys.last()?;
    let mut script = last.script.clone();
    script.hold = HOLD_EXTRA_SECONDS;
    let mut held = PostureTrack::holding(track.parts.clone(), script);
    held.keys[0].transition = 0.3;
    let subject_free = lexicon::without_subject(words);
    Some(Segment {
        text: format!("a person {}", subject_free.join(" ")),
        seconds: clamp_seconds(held.natural_seconds()).unwrap_or(2.0),
        base: previous.base.clone(),
        parts: PartEdits::default(),
        trajectory: None,
        postures: Some(held),
    })
}

/// Whether a clause names a whole-body posture of the library (a state one stays in, not a
/// movement like standing up), so that "kneels and raises the right hand" stays one movement
/// while "gets up and waves" is two.
pub fn names_posture(words: &[&str]) -> bool {
    Library::builtin()
        .mentions(&words.join(" "))
        .iter()
        .any(|(_, n)| matches!(n, Named::Posture(p) if !arms_only(p)))
}

/// Whether a clause names a movement of the key-pose library ("turns to the left", "spins").
pub fn names_movement(words: &[&str]) -> bool {
    Library::builtin()
        .mentions(&words.join(" "))
        .iter()
        .any(|(_, n)| matches!(n, Named::Action(_)))
}

/// Which part of the body a constraint is about, to merge two postures (a squat's legs with a
/// T-pose's arms).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Region {
    Arms,
    Legs,
    Torso,
    /// Hands with feet or knees (touching the toes): both at once.
    Whole,
}

fn point_region(p: BodyPoint) -> Region {
    use BodyPoint::*;
    match p {
        LeftHand | RightHand | LeftElbow | RightElbow => Region::Arms,
        LeftKnee | RightKnee | LeftFoot | RightFoot | LeftHip | RightHip => Region::Legs,
        _ => Region::Torso,
    }
}

fn region(c: &Constraint) -> Region {
    let pair = |a: BodyPoint, b: BodyPoint| match (point_region(a), point_region(b)) {
        (Region::Arms, Region::Legs) | (Region::Legs, Region::Arms) => Region::Whole,
        (Region::Arms, _) | (_, Region::Arms) => Region::Arms,
        (Region::Legs, _) | (_, Region::Legs) => Region::Legs,
        _ => Region::Torso,
    };
    match *c {
        Constraint::Bend { joint, .. } => match joint {
            Hinge::LeftElbow | Hinge::RightElbow => Region::Arms,
            Hinge::LeftKnee | Hinge::RightKnee => Region::Legs,
        },
        Constraint::Distance { a, b, .. } | Constraint::Relation { a, b, .. } => pair(a, b),
        Constraint::Orientation { limb, .. } => match limb {
            Limb::LeftUpperArm | Limb::RightUpperArm | Limb::LeftForearm | Limb::RightForearm => {
                Region::Arms
            }
            Limb::Torso => Region::Torso,
            _ => Region::Legs,
        },
        Constraint::Contact { point, .. } => match point {
            Support::LeftHand | Support::RightHand => Region::Whole,
            _ => Region::Legs,
        },
        Constraint::Lean { .. } | Constraint::Twist { .. } => Region::Torso,
        Constraint::Level { .. } => Region::Legs,
    }
}

/// `base` with its arms taken from `arms` (an arms-only posture): the base keeps its legs,
/// torso and level; the arms posture adds its arm constraints and any torso constraint the
/// base leaves open. `None` when the two contradict each other.
fn with_arms(base: &PostureScript, arms: &PostureScript) -> Option<PostureScript> {
    let mut constraints: Vec<Constraint> = base
        .constraints
        .iter()
        .filter(|c| !matches!(region(c), Region::Arms))
        .copied()
        .collect();
    let base_has_torso = base.constraints.iter().any(|c| region(c) == Region::Torso);
    for c in &arms.constraints {
        match region(c) {
            Region::Arms => constraints.push(*c),
            Region::Torso if !base_has_torso => constraints.push(*c),
            _ => {}
        }
    }
    let name = match (&base.name, &arms.name) {
        (Some(a), Some(b)) => Some(format!("{a} with {b}")),
        (a, b) => a.clone().or_else(|| b.clone()),
    };
    PostureScript {
        name,
        hold: base.hold.max(arms.hold),
        constraints,
    }
    .check()
    .ok()
}

/// The arms of a whole-body posture as a posture of their own (its name kept: the boxer's
/// guard is still "boxing stance"); `None` when it says nothing of the arms.
fn arms_of(p: &NamedPosture) -> Option<NamedPosture> {
    let constraints: Vec<Constraint> = p
        .script
        .constraints
        .iter()
        .filter(|c| region(c) == Region::Arms)
        .copied()
        .collect();
    let script = PostureScript {
        name: p.script.name.clone(),
        hold: p.script.hold,
        constraints,
    }
    .check()
    .ok()?;
    Some(NamedPosture {
        name: p.name.clone(),
        synonyms: p.synonyms.clone(),
        parts: vec![BodyPart::LeftArm, BodyPart::RightArm],
        script,
    })
}

fn arms_only(p: &NamedPosture) -> bool {
    p.parts
        .iter()
        .all(|part| matches!(part, BodyPart::LeftArm | BodyPart::RightArm))
}

/// What the planner makes of a clause that names postures.
pub struct PostureClause {
    /// The segment (with its track).
    pub segment: Segment,
    /// Notes for the plan (postures that could not be combined).
    pub notes: Vec<String>,
    /// The segment is the model's motion with postures held on some parts (a walk with the
    /// arms in a T), not a posture segment.
    pub over_model: bool,
    /// The indices of the clause's words that named what the segment makes: the library's
    /// postures and movements, and the model's actions.
    pub named: Vec<usize>,
}

/// The segment for a clause that names postures or movements of the library, or `None` when
/// it names none (or only what the model's own movement already is, such as "bows").
/// `model` is what the model's lexicon found in the clause (base and gestures);
/// `model_segment` builds the model's own segment for it.
pub fn plan_clause(
    words: &[&str],
    model: Option<(Action, &[Action])>,
    model_segment: &dyn Fn() -> Segment,
) -> Option<PostureClause> {
    let text = words.join(" ");
    let library = Library::builtin();
    let mut mentions = library.mentions(&text);
    // A whole-body movement the model knows ("bows", or a squat where it knows squats) stays
    // the model's.
    let dataset_base = model.map(|(base, _)| base).filter(|b| b.label().is_some());
    let model_words: Vec<&str> = words
        .iter()
        .enumerate()
        .filter(|(i, w)| {
            let next = &words[i + 1..];
            let prev: Vec<&str> = words[..*i].iter().rev().copied().collect();
            lexicon::action_word(w, next, &prev).is_some_and(|a| !a.is_gesture())
                || dataset_base.is_some_and(|b| {
                    lexicon::dataset_action(words, *i)
                        .is_some_and(|a| std::mem::discriminant(&a) == std::mem::discriminant(&b))
                })
        })
        .map(|(_, w)| *w)
        .collect();
    // So do the poses a movement of dataset v2 passes through ("crouches down into a squat").
    let passed = dataset_base.map_or(&[][..], library_names);
    // "jogs in place": the model's jog travels, the library's stays on the spot.
    let travels = model.is_some_and(|(base, _)| base.is_locomotion());
    let on_the_spot =
        |phrase: &str| travels && (phrase.contains("in place") || phrase.contains("on the spot"));
    mentions.retain(|(range, named)| {
        let phrase = &text[range.clone()];
        // "puts the left hand on the right knee": where the hand goes, not a kneel.
        let hand_goes = text[..range.start]
            .split_whitespace()
            .rev()
            .take(3)
            .any(|w| matches!(w, "hand" | "hands" | "palm" | "palms" | "fist" | "fingers"))
            && ["on ", "onto ", "to ", "against "]
                .iter()
                .any(|p| phrase.starts_with(p));
        if hand_goes {
            return false;
        }
        let plain_raise = phrase.split(' ').all(|w| PLAIN_GESTURE_WORDS.contains(&w));
        !plain_raise
            && (!phrase.split(' ').any(|w| model_words.contains(&w)) || on_the_spot(phrase))
            && !passed.contains(&named.name())
            && !names_other_limb(&text[range.end..], !phrase.contains(' '), named)
    });
    if mentions.is_empty() {
        return None;
    }
    let mut named = named_words(words, &mentions);
    let mut notes = Vec::new();
    // A one-arm posture goes on the arm the clause names ("points … with his left arm" is
    // the library's right-arm pointing, mirrored).
    let arm = arm_side(words);
    let postures: Vec<NamedPosture> = mentions
        .iter()
        .filter_map(|(r, n)| match n {
            Named::Posture(p) => Some(
                // "reaches up high with the left hand": the posture of both arms, on one.
                match one_arm_after(&text[r.end..]).filter(|_| p.parts.len() == 2 && arms_only(p)) {
                    Some(one) => one_arm_of(p, one).unwrap_or_else(|| on_arm(p, arm)),
                    // "kneels on the left knee": a one-legged posture on the leg named.
                    None => on_arm(&super::sided::on_leg(p, words), arm),
                },
            ),
            Named::Action(_) => None,
        })
        .collect();
    let postures: Vec<&NamedPosture> = postures.iter().collect();
    let action = mentions.iter().find_map(|(r, n)| match n {
        Named::Action(a) => Some((r.clone(), *a)),
        Named::Posture(_) => None,
    });
    let (arm_postures, body_postures): (Vec<&NamedPosture>, Vec<&NamedPosture>) =
        postures.iter().partition(|p| arms_only(p));
    let carries_arms = model.is_some_and(|(base, _)| base.frees_arms());
    // A gesture word inside a named posture ("points up with both hands", "one arm forward
    // and up") is the posture's, not a gesture of its own.
    let mut at = 0;
    let gesture_outside = words.iter().enumerate().any(|(i, w)| {
        let start = at;
        at += w.len() + 1;
        let next = &words[i + 1..];
        let prev: Vec<&str> = words[..i].iter().rev().copied().collect();
        lexicon::action_word(w, next, &prev).is_some_and(|a| a.is_gesture())
            && !mentions.iter().any(|(r, _)| r.contains(&start))
    });
    let gestures: Vec<Action> = model
        .filter(|_| gesture_outside)
        .map(|(base, gestures)| {
            std::iter::once(base)
                .filter(|b| b.is_gesture())
                .chain(gestures.iter().copied())
                .collect()
        })
        .unwrap_or_default();

    // A walk or a run keeps its legs: a posture of the whole body named beside it lends it
    // only its arms ("shuffles backward, keeping his guard up" walks in a boxer's guard).
    let lent: Vec<NamedPosture> = body_postures
        .iter()
        .filter(|_| travels && action.is_none())
        .filter_map(|p| arms_of(p))
        .collect();
    let (arm_postures, body_postures) = if lent.is_empty() {
        (arm_postures, body_postures)
    } else {
        (arm_postures.into_iter().chain(&lent).collect(), Vec::new())
    };
    // The model's walk, run or squat, with the arms held in a posture.
    if carries_arms && action.is_none() && body_postures.is_empty() {
        let mut segment = model_segment();
        let arms = merge_arms(&arm_postures, &mut notes)?;
        let parts: Vec<BodyPart> = arm_postures.iter().flat_map(|p| p.parts.clone()).collect();
        for part in &parts {
            segment.parts.set(*part, None);
        }
        segment.text = format!("{} holding {}", segment.text, describe_names(&arm_postures));
        let mut track = PostureTrack::holding(parts, arms);
        // "claps her hands four times while walking": the count is the arms' when it follows
        // their posture's own words (in "does two squats in a T-pose" it is the squats').
        let arm_count = posture_count(&text, &mentions, arms_only);
        if arm_count > 1 {
            track.repeat = arm_count as u32;
            track.returns = true;
        }
        segment.postures = Some(track);
        return Some(PostureClause {
            segment,
            notes,
            over_model: true,
            named,
        });
    }

    let count = repetitions(words, &text, action.as_ref().map(|(r, _)| r.start));
    let mut track = match &action {
        Some((_, a)) => {
            let mut track = a.track(count, direction(words));
            // "hops forward on the right foot": a jump, on that foot.
            let jumps = track.keys.iter().any(|k| k.jump_m.is_some());
            if let Some(foot) = super::sided::hopping_foot(words).filter(|_| jumps) {
                super::sided::on_one_foot(&mut track, foot);
                named.extend(super::sided::leg_words(words));
            }
            // The library turns to the left; "spins to the right" turns the other way.
            if turns_right(words) {
                for key in &mut track.keys {
                    key.turn_deg = -key.turn_deg;
                }
            }
            if let Some(arms) = merge_arms(&arm_postures, &mut notes) {
                for key in &mut track.keys {
                    match with_arms(&key.script, &arms) {
                        Some(s) => key.script = s,
                        None => notes.push(format!(
                            "{} cannot be held during {}; left out",
                            describe_names(&arm_postures),
                            a.name
                        )),
                    }
                }
            }
            track
        }
        None => {
            let mut script = match body_postures.first() {
                Some(p) => p.script.clone(),
                None => merge_arms(&arm_postures, &mut notes)?,
            };
            for extra in body_postures.iter().skip(1) {
                notes.push(format!(
                    "{} and {} in one movement: kept {}",
                    body_postures[0].name, extra.name, body_postures[0].name
                ));
            }
            if !body_postures.is_empty() {
                if let Some(arms) = merge_arms(&arm_postures, &mut notes) {
                    match with_arms(&script, &arms) {
                        Some(s) => script = s,
                        None => notes.push(format!(
                            "{} cannot be combined with {}; kept {}",
                            describe_names(&arm_postures),
                            body_postures[0].name,
                            body_postures[0].name
                        )),
                    }
                }
            }
            // A posture of the arms alone is held on the arms while the body stands (the
            // model's standing, not a statue); one of the whole body is the whole body.
            let parts = if body_postures.is_empty() {
                let mut arms: Vec<BodyPart> =
                    arm_postures.iter().flat_map(|p| p.parts.clone()).collect();
                arms.sort();
                arms.dedup();
                arms
            } else {
                BodyPart::ALL.to_vec()
            };
            let mut track = PostureTrack::holding(parts, script);
            // "raises the left arm twice while standing on one leg" stands on it once.
            let n = posture_count(&text, &mentions, |_| true);
            if n > 1 {
                track.repeat = n as u32;
                track.returns = true;
            }
            track
        }
    };
    // Gestures the model knows stay its own: the track leaves those arms to it.
    let gesture_arms: Vec<BodyPart> = gestures.iter().flat_map(|g| g.arms().to_vec()).collect();
    let mut parts = PartEdits::default();
    let mut base = "a person stands still".to_string();
    if let Some(g) = gestures.first() {
        base = g.caption();
        for g in &gestures {
            for arm in g.arms() {
                parts.set(*arm, Some(g.caption()));
            }
        }
        track.parts.retain(|p| !gesture_arms.contains(p));
    }
    let track = track.checked().ok()?;
    // The key poses, and the way out into whatever comes next.
    let seconds =
        clamp_seconds(track.natural_seconds() + DEFAULT_TRANSITION_SECONDS).unwrap_or(2.0);
    let subject_free = lexicon::without_subject(words);
    let segment = Segment {
        text: format!("a person {}", subject_free.join(" ")),
        seconds,
        base,
        parts,
        trajectory: None,
        postures: Some(track),
    };
    Some(PostureClause {
        segment,
        notes,
        over_model: false,
        named,
    })
}

/// The arm a clause names: the side word just before "arm", "hand", "fist" or "finger" ("with
/// his left arm", "the right index finger"); `None` when it names none, or both.
fn arm_side(words: &[&str]) -> Option<BodyPart> {
    let mut found = None;
    for (i, w) in words.iter().enumerate() {
        let part = match *w {
            "left" => BodyPart::LeftArm,
            "right" => BodyPart::RightArm,
            _ => continue,
        };
        let names_arm = words[i + 1..]
            .iter()
            .take(2)
            .any(|n| matches!(*n, "arm" | "hand" | "fist" | "finger" | "index"));
        if names_arm {
            if found.is_some_and(|f| f != part) {
                return None;
            }
            found = Some(part);
        }
    }
    found
}

/// `posture` on `arm`: its mirror, named for that arm, when it is a posture of the other arm
/// alone; itself otherwise.
pub fn on_arm(posture: &NamedPosture, arm: Option<BodyPart>) -> NamedPosture {
    match (arm, posture.parts.as_slice()) {
        (Some(arm), [own]) if own.mirrored() == arm => {
            let name = format!("{} with the {}", posture.name, arm.name());
            let mut script = posture.script.mirrored();
            script.name = Some(name.clone());
            NamedPosture {
                name,
                synonyms: Vec::new(),
                parts: vec![arm],
                script,
            }
        }
        // A posture of one arm says which when the clause does ("salutes with the right hand").
        (Some(arm), [own])
            if *own == arm && !posture.name.contains("left") && !posture.name.contains("right") =>
        {
            let name = format!("{} with the {}", posture.name, arm.name());
            let mut script = posture.script.clone();
            script.name = Some(name.clone());
            NamedPosture {
                name,
                synonyms: posture.synonyms.clone(),
                parts: vec![arm],
                script,
            }
        }
        _ => posture.clone(),
    }
}

/// The indices of `words` inside a library mention (byte ranges of the words joined by
/// spaces) or naming an action of the model's lexicon.
fn named_words(words: &[&str], mentions: &[(std::ops::Range<usize>, Named)]) -> Vec<usize> {
    let mut start = 0;
    let mut out = Vec::new();
    for (i, w) in words.iter().enumerate() {
        let range = start..start + w.len();
        start = range.end + 1;
        let next = &words[i + 1..];
        let prev: Vec<&str> = words[..i].iter().rev().copied().collect();
        let in_mention = mentions
            .iter()
            .any(|(r, _)| r.start < range.end && range.start < r.end);
        if in_mention || lexicon::action_word(w, next, &prev).is_some() {
            out.push(i);
        }
    }
    out
}

fn describe_names(postures: &[&NamedPosture]) -> String {
    let names: Vec<&str> = postures.iter().map(|p| p.name.as_str()).collect();
    names.join(" and ")
}

/// Arms-only postures laid into one script (the first one's arms, then the next's where they
/// do not contradict it).
fn merge_arms(postures: &[&NamedPosture], notes: &mut Vec<String>) -> Option<PostureScript> {
    let (first, rest) = postures.split_first()?;
    let mut script = first.script.clone();
    for p in rest {
        let mut constraints = script.constraints.clone();
        constraints.extend(p.script.constraints.iter().copied());
        match (PostureScript {
            name: Some(format!("{} with {}", first.name, p.name)),
            hold: script.hold.max(p.script.hold),
            constraints,
        })
        .check()
        {
            Ok(s) => script = s,
            Err(_) => notes.push(format!(
                "{} and {} ask different things of the arms; kept {}",
                first.name, p.name, first.name
            )),
        }
    }
    Some(script)
}

/// How many times a clause asks for its movement: "twice", "three times", or a number just
/// before it ("five push-ups").
fn repetitions(words: &[&str], text: &str, action_at: Option<usize>) -> Option<u32> {
    let said = lexicon::repetitions(words);
    if said > 1 {
        return Some(said as u32);
    }
    let at = action_at?;
    let before = text[..at].split(' ').rev().find(|w| !w.is_empty())?;
    lexicon::number(before).map(|n| n.round().clamp(1.0, 10.0) as u32)
}

/// How many times the clause counts a posture it names (of those `which` keeps): a count in
/// the few words right after the posture's own words ("claps her hands four times", "squats
/// twice"); 1 when none follows any.
fn posture_count(
    text: &str,
    mentions: &[(std::ops::Range<usize>, Named<'_>)],
    which: impl Fn(&NamedPosture) -> bool,
) -> usize {
    mentions
        .iter()
        .filter(|(_, n)| matches!(n, Named::Posture(p) if which(p)))
        .map(|(r, _)| {
            let after: Vec<&str> = text[r.end..].split_whitespace().take(4).collect();
            lexicon::repetitions(&after)
        })
        .max()
        .unwrap_or(1)
}

/// The way a movement travels, `[left, forward]`: forward unless the clause says otherwise,
/// and nowhere when it names no direction.
fn direction(words: &[&str]) -> [f64; 2] {
    let has = |w: &[&str]| words.iter().any(|x| w.contains(x));
    let sideways = has(&["sideways", "aside"]);
    if has(&["forward", "forwards", "ahead", "across"]) {
        [0.0, 1.0]
    } else if has(&["backward", "backwards"]) {
        [0.0, -1.0]
    } else if (sideways && has(&["left"])) || toward(words, "left") {
        [1.0, 0.0]
    } else if (sideways && has(&["right"])) || toward(words, "right") {
        [-1.0, 0.0]
    } else {
        [0.0, 0.0]
    }
}

/// Whether the words go toward `side` ("to the left", "towards his right", "leftward"), not
/// only name a limb of that side ("with the left hand").
fn toward(words: &[&str], side: &str) -> bool {
    let ward = format!("{side}ward");
    let wards = format!("{side}wards");
    words.iter().any(|w| *w == ward || *w == wards)
        || words.windows(3).any(|w| {
            matches!(w[0], "to" | "towards" | "toward")
                && matches!(w[1], "the" | "his" | "her" | "their")
                && w[2] == side
        })
        || words
            .windows(2)
            .any(|w| matches!(w[0], "to" | "towards" | "toward") && w[1] == side)
}

/// Whether a turning movement goes to the right (clockwise seen from above): the words say
/// "to the right", "clockwise" or "rightward"; the library's turns go to the left.
fn turns_right(words: &[&str]) -> bool {
    let counter = words.iter().any(|w| {
        matches!(
            *w,
            "counterclockwise" | "anticlockwise" | "counter-clockwise" | "anti-clockwise"
        )
    }) || words
        .windows(2)
        .any(|w| matches!(w[0], "counter" | "anti") && w[1] == "clockwise");
    let turn_right = words.windows(2).any(|w| {
        matches!(
            w[0],
            "turn" | "turns" | "turning" | "spin" | "spins" | "spinning" | "twirls" | "pivots"
        ) && w[1] == "right"
    });
    !counter && (toward(words, "right") || turn_right || words.contains(&"clockwise"))
}
