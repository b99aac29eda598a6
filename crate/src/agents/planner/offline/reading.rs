//! Reading a clause's words: the movements it names (the model's actions, gestures beside
//! them, what it moves on to), how often, how long, along which path, in whose style, and
//! the segment of the model's motion they make.

use super::super::lexicon::Side;
use super::*;
use crate::trajectory::{Shape, Trajectory};

/// A clause with the words that name the person read as one name: a word between the
/// article and the noun for the person that would read as a movement ("a **basketball**
/// player") says who, not what the body does, and is dropped. Other words there ("an **old**
/// man") stay: they are the person's style.
pub(super) fn with_subject_whole<'a>(words: &[&'a str], reader: Reader) -> Vec<&'a str> {
    let Some(article) = words
        .iter()
        .position(|w| matches!(*w, "a" | "an" | "the"))
        .filter(|&i| words[..i].iter().all(|w| lexicon::is_subject_word(w)))
    else {
        return words.to_vec();
    };
    let Some(noun) =
        (article + 1..(article + 4).min(words.len())).find(|&i| lexicon::is_subject_noun(words[i]))
    else {
        return words.to_vec();
    };
    words
        .iter()
        .enumerate()
        .filter(|&(i, w)| {
            !((article + 1..noun).contains(&i) && movements(&[*w], None, reader).is_some())
        })
        .map(|(_, w)| *w)
        .collect()
}

/// Whether a clause moves on from its first whole-body movement to another ("from a walk to
/// a run"): see [`moves_on`].
pub(super) fn moves_on_in_sequence(words: &[&str], found: &Movements) -> bool {
    found
        .left
        .iter()
        .any(|&(at, action)| !action.is_gesture() && accounting::in_sequence(words, found.at, at))
}

/// The segments of the whole-body movements a clause moves on to after its first ("from a
/// walk to a run"), each with the action it makes and carrying the clause's gestures; what
/// else the clause names that its movement does not make is named in a note with the reason.
pub(super) fn moves_on(
    words: &[&str],
    found: &Movements,
    style: Option<&str>,
    notes: &mut Vec<String>,
) -> Vec<(Action, Segment)> {
    let mut out = Vec::new();
    for &(at, action) in &found.left {
        if !action.is_gesture() && accounting::in_sequence(words, found.at, at) {
            let next = Movements {
                base: action,
                gestures: found.gestures.clone(),
                at,
                left: Vec::new(),
                named: Vec::new(),
            };
            out.push((action, segment(words, &next, style)));
            continue;
        }
        let why = if action.is_gesture() {
            "the arm it needs already does another movement in this clause"
        } else {
            "it happens at the same time as another whole-body movement of this clause, and \
             the body makes one at a time"
        };
        notes.push(format!(
            "\"{}\" {NOT_PLACED}: {why}",
            accounting::phrase_from(words, at)
        ));
    }
    out
}

/// What a clause asks for: a base motion and the gestures that ride on it.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Movements {
    pub(super) base: Action,
    pub(super) gestures: Vec<Action>,
    /// The index of the word that names the base.
    pub(super) at: usize,
    /// What else the clause names, with the index of its word, that the base and gestures do
    /// not make: a second whole-body movement, a gesture on an arm already busy. The
    /// planner places or names each ([`accounting`]).
    pub(super) left: Vec<(usize, Action)>,
    /// The indices of every word that named a movement, made or left.
    pub(super) named: Vec<usize>,
}

impl Movements {
    /// One action alone, named nowhere in particular (a substitute, a fallback).
    pub(super) fn only(base: Action) -> Movements {
        Movements {
            base,
            gestures: Vec::new(),
            at: 0,
            left: Vec::new(),
            named: Vec::new(),
        }
    }
}

/// What reading a clause depends on besides its words.
#[derive(Clone, Copy, Debug)]
pub(super) struct Reader<'a> {
    /// The actions of dataset v2 the model makes.
    pub(super) known: Repertoire<'a>,
    /// The clause after this one holds its pose or lands it in a named posture ("squats and
    /// holds it", "jumps up and lands in a superhero landing"), which the posture library
    /// makes.
    pub(super) pose_kept: bool,
}

impl Reader<'_> {
    /// A clause read on its own, for splitting the prompt into clauses.
    pub(super) fn alone(known: Repertoire) -> Reader {
        Reader {
            known,
            pose_kept: false,
        }
    }
}

/// How many segments a clause's movement takes: "twice", "three times"; for an action of
/// dataset v2 also a count before its noun ("three squats", "3 kicks"), at most
/// [`MAX_SEGMENTS`] (with a note when more were asked).
pub(super) fn repetitions(words: &[&str], found: &Movements, notes: &mut Vec<String>) -> usize {
    let said = lexicon::repetitions(words);
    let dataset = found.base.label().is_some();
    let asked = if said > 1 {
        said
    } else {
        // "does three squats", "throws two punches", "does squats three times".
        lexicon::count_before(words, found.at)
            .filter(|n| dataset || *n > 1)
            .or_else(|| lexicon::count_after(words, found.at))
            .unwrap_or(1)
    };
    if !dataset && said > 1 {
        return said;
    }
    if asked > MAX_SEGMENTS {
        notes.push(format!(
            "\"{}\" asks for {asked}; a plan has at most {MAX_SEGMENTS} segments, so it makes \
             {MAX_SEGMENTS}",
            words.join(" ")
        ));
    }
    asked.clamp(1, MAX_SEGMENTS)
}

/// The movements of one clause; `previous` lends its gesture to a clause with no verb ("then
/// the left hand").
pub(super) fn movements(
    words: &[&str],
    previous: Option<Action>,
    reader: Reader,
) -> Option<Movements> {
    let mut actions: Vec<(usize, Action)> = Vec::new();
    for (i, w) in words.iter().enumerate() {
        let next = &words[i + 1..];
        let prev = &words[..i];
        let prev_rev: Vec<&str> = prev.iter().rev().copied().collect();
        let Some(mut action) =
            dataset_action(words, i, reader).or_else(|| lexicon::action_word(w, next, &prev_rev))
        else {
            continue;
        };
        if *w == "sword" && actions.iter().any(|(_, a)| *a == Action::Slash) {
            continue;
        }
        action = match action {
            Action::Walk(Direction::Forward) => Action::Walk(direction(next)),
            a if a.is_gesture() => {
                a.with_side(side(words, i).unwrap_or(if lexicon::both_by_default(w) {
                    Side::Both
                } else {
                    Side::Right
                }))
            }
            a => a,
        };
        // "waves goodbye with his left hand" is a wave of that hand.
        if action == Action::Goodbye {
            if let Some(s) = side(words, i) {
                action = Action::Wave(s);
            }
        }
        if actions.iter().any(|(_, a)| same_kind(*a, action)) {
            continue;
        }
        actions.push((i, action));
    }
    if actions.is_empty() {
        let side = words.iter().find_map(|w| side_word(w))?;
        let previous = previous.filter(|a| a.is_gesture())?;
        return Some(Movements::only(previous.with_side(side)));
    }
    let named = actions.iter().map(|(i, _)| *i).collect();
    // A walk turning and walking is one turn.
    if let Some(turn) = actions.iter().position(|(_, a)| {
        matches!(
            a,
            Action::Walk(Direction::TurnLeft) | Action::Walk(Direction::TurnRight)
        )
    }) {
        let turn = actions[turn].1;
        actions.retain(|(_, a)| !matches!(a, Action::Walk(_)) || *a == turn);
    }
    let base_index = actions
        .iter()
        .position(|(_, a)| !a.is_gesture())
        .unwrap_or(0);
    let base = actions[base_index].1;
    let mut used: Vec<BodyPart> = base.arms().to_vec();
    let mut gestures = Vec::new();
    let mut left = Vec::new();
    for (k, (i, a)) in actions.iter().enumerate() {
        if k == base_index {
            continue;
        }
        if !a.is_gesture() || a.arms().iter().any(|p| used.contains(p)) {
            left.push((*i, *a));
            continue;
        }
        used.extend_from_slice(a.arms());
        gestures.push(*a);
    }
    Some(Movements {
        base,
        gestures,
        at: actions[base_index].0,
        left,
        named,
    })
}

/// The action of dataset v2 that word `i` names, where the model makes it and the posture
/// library does not keep the clause (a pose held, a movement it names otherwise such as
/// "jumping jacks", or a whole-body pose beside it).
pub(super) fn dataset_action(words: &[&str], i: usize, reader: Reader) -> Option<Action> {
    let action = lexicon::dataset_action(words, i).or_else(|| jog_circle(words, i))?;
    (reader.known.knows(action) && !postures::keeps(words, i, action, reader.pose_kept))
        .then_some(action)
}

/// A jog or run round a circle or an arc of one ("jogs in a circle to the left", "jogs
/// around, curving to the right"), the way it turns.
pub(super) fn jog_circle(words: &[&str], i: usize) -> Option<Action> {
    if lexicon::action_word(words[i], &[], &[]) != Some(Action::Run) {
        return None;
    }
    let Trajectory::Shape {
        shape: Shape::Circle(side) | Shape::Arc(side),
    } = path(words)?
    else {
        return None;
    };
    Some(Action::JogCircle(match side {
        crate::trajectory::Side::Left => Side::Left,
        crate::trajectory::Side::Right => Side::Right,
    }))
}

pub(super) fn same_kind(a: Action, b: Action) -> bool {
    std::mem::discriminant(&a) == std::mem::discriminant(&b) && a == b
        || matches!((a, b), (Action::Walk(_), Action::Walk(_)))
            && !matches!(
                b,
                Action::Walk(Direction::TurnLeft) | Action::Walk(Direction::TurnRight)
            )
}

pub(super) fn side_word(word: &str) -> Option<Side> {
    match word {
        "left" => Some(Side::Left),
        "right" => Some(Side::Right),
        "both" | "hands" | "arms" => Some(Side::Both),
        _ => None,
    }
}

/// The side a gesture at `i` names: a few words after it ("waves the left hand"), or before
/// ("with the left arm raised").
pub(super) fn side(words: &[&str], i: usize) -> Option<Side> {
    let stop = |w: &str| {
        lexicon::action_word(w, &[], &[]).is_some_and(|a| !a.is_gesture())
            || matches!(w, "while" | "then" | "and")
    };
    // Up to the end of the gesture's phrase: "waves to his friends with his left hand".
    for w in words.iter().skip(i + 1).take(8) {
        if stop(w) || lexicon::action_word(w, &[], &[]).is_some() {
            break;
        }
        if let Some(s) = side_word(w) {
            return Some(s);
        }
    }
    for w in words[..i].iter().rev().take(4) {
        if stop(w) {
            break;
        }
        if let Some(s) = side_word(w) {
            return Some(s);
        }
    }
    None
}

/// Where a walk goes, from the words after the verb up to the next movement.
pub(super) fn direction(next: &[&str]) -> Direction {
    for (k, w) in next.iter().take(4).enumerate() {
        match *w {
            "backward" | "backwards" | "back" => return Direction::Backward,
            "left" | "leftward" | "leftwards" => return Direction::Left,
            "right" | "rightward" | "rightwards" => return Direction::Right,
            "forward" | "forwards" | "ahead" | "straight" => return Direction::Forward,
            "sideways" => {
                if next[k..].iter().take(4).any(|w| *w == "right") {
                    return Direction::Right;
                }
                return Direction::Left;
            }
            w if matches!(w, "with" | "while" | "and" | "then" | ",")
                || lexicon::action_word(w, &[], &[]).is_some() =>
            {
                break
            }
            _ => {}
        }
    }
    Direction::Forward
}

/// The style the whole prompt asks for ("an angry person walks …"), as caption words.
pub(super) fn prompt_style(text: &str) -> Option<String> {
    tokens(text)
        .iter()
        .find_map(|w| lexicon::style_word(w).map(String::from))
}

/// Verbs of standing still or of no movement at all: a clause of only these is no segment.
pub(super) const NOT_MOVEMENT: &[&str] = &[
    "stop", "stops", "stopping", "stand", "stands", "standing", "still", "pause", "pauses", "wait",
    "waits", "rest", "rests", "laugh", "laughs", "laughing", "smile", "smiles", "smiling", "look",
    "looks", "looking", "talk", "talks", "talking", "freeze", "freezes",
];

pub(super) fn is_filler(word: &str) -> bool {
    lexicon::is_subject_word(word)
        || matches!(
            word,
            "man"
                | "woman"
                | "he"
                | "his"
                | "her"
                | "their"
                | "for"
                | "of"
                | "at"
                | "on"
                | "in"
                | "to"
                | "end"
                | "ceremony"
                | "moment"
                | "while"
                | "there"
                | "and"
        )
}

/// The actions the model was trained on, as candidates for unknown movements.
pub(super) const TRAINING_ACTIONS: [Action; 16] = [
    Action::Walk(Direction::Forward),
    Action::Walk(Direction::Backward),
    Action::Walk(Direction::TurnLeft),
    Action::Walk(Direction::TurnRight),
    Action::Run,
    Action::Dash,
    Action::Bow,
    Action::Kick,
    Action::Punch,
    Action::Slash,
    Action::Dance,
    Action::Beckon,
    Action::Guide,
    Action::Wave(Side::Both),
    Action::Goodbye,
    Action::Raise(Side::Both),
];

/// The segment of one clause.
pub(super) fn segment(words: &[&str], found: &Movements, style: Option<&str>) -> Segment {
    let own_style = words.iter().find_map(|w| lexicon::style_word(w));
    let style = own_style.or(style);
    let with_style = |caption: String| match style {
        Some(s) => format!("{caption} {s}"),
        None => caption,
    };
    let base = with_style(found.base.caption());
    let mut parts = PartEdits::default();
    let mut text = found.base.caption();
    for g in &found.gestures {
        for part in g.arms() {
            parts.set(*part, Some(with_style(g.caption())));
        }
        text = format!("{text} {}", g.participle());
    }
    let text = with_style(text);
    let trajectory = if found.base.is_locomotion()
        && !matches!(
            found.base,
            Action::Walk(Direction::TurnLeft | Direction::TurnRight)
        ) {
        path(words)
    } else {
        None
    };
    let usual = match &trajectory {
        Some(Trajectory::Shape { shape }) => path_seconds(*shape),
        _ => found.base.seconds(),
    };
    let seconds = duration(words).unwrap_or_else(|| {
        let tempo: f64 = words
            .iter()
            .filter_map(|w| lexicon::tempo_word(w))
            .product();
        let few = words.windows(2).any(|w| w == ["few", "steps"]);
        let long = words.windows(2).any(|w| w == ["a", "while"]);
        usual * tempo * if few { 0.75 } else { 1.0 } * if long { 1.5 } else { 1.0 }
    });
    Segment {
        text,
        seconds: clamp_seconds(seconds).unwrap_or(usual),
        base,
        parts,
        trajectory,
        postures: None,
    }
}

/// The note for a clause whose segment does not plainly mean what its words say, by the same
/// judgement the timeline set's scorer uses ([`meaning`]): the rules read the clause's verb
/// and its direction, and drop what they have no word for ("jogs **in place**", "walks **to
/// the door**"), so the person is told what stands for their words. Only the clause's head
/// is compared (up to the first phrase that rides on it: "…, holding the T-pose" is placed on
/// its own).
pub(super) fn said_otherwise(
    words: &[&str],
    made: &Segment,
    matcher: Option<&Matcher>,
) -> Option<String> {
    let matcher = matcher?;
    let head = accounting::head_phrase(&lexicon::without_subject(words));
    // The path is part of what the segment says ("walks forward" along "a circle, clockwise").
    let said = match &made.trajectory {
        Some(path) => format!("{} along {}", made.text, path.describe()),
        None => made.text.clone(),
    };
    if head.is_empty() || matcher.same(&head, &said).is_some() {
        return None;
    }
    Some(format!(
        "\"{}\" {MADE_AS}: \"{}\"",
        words.join(" "),
        made.text
    ))
}

/// "for 3 seconds", "for 2.5 s", "for five seconds".
pub(super) fn duration(words: &[&str]) -> Option<f64> {
    words.windows(3).find_map(|w| {
        let unit = matches!(w[2], "seconds" | "second" | "secs" | "sec" | "s");
        (w[0] == "for" && unit)
            .then(|| lexicon::number(w[1]))
            .flatten()
    })
}

/// The root path a clause names ("in a circle clockwise", "zigzag", "s shaped").
pub(super) fn path(words: &[&str]) -> Option<Trajectory> {
    let trajectory = Trajectory::from_text(&words.join(" "))?;
    // A turn is in the training data as a motion of its own; the planner asks for that.
    match trajectory {
        Trajectory::Shape {
            shape: Shape::Turn(_),
        } => None,
        t => Some(t),
    }
}

/// A usual length in seconds for walking a shape at about 1.2 m/s: long enough to make a
/// closed shape recognisable, within one generation.
pub(super) fn path_seconds(shape: Shape) -> f64 {
    match shape {
        Shape::Line => 4.0,
        Shape::Arc(_) | Shape::Turn(_) => 5.0,
        Shape::Zigzag(_) | Shape::SCurve(_) => 6.0,
        _ => 9.0,
    }
}
