//! Words of a prompt that say where, when or why a person moves, not how: "at the airport",
//! "during the national anthem", "to protest a verdict", "feeling tired after the marathon".
//! The motion model has nothing to make of them, and a planner that maps them onto the
//! nearest movement adds one nobody asked for; the built-in planner drops them with a note
//! that names them and says what they are.

use super::super::lexicon::{self, Repertoire};
use super::super::postures;
use super::{movements, path, Reader};

/// What a piece of context says instead of a movement.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Context {
    /// Where or when ("at the birthday party", "in the rain", "during the anthem").
    Setting,
    /// Why ("to greet the guests", "because he sees his friend").
    Reason,
    /// What the person feels or notices ("feeling tired", "hearing a loud noise").
    State,
}

impl Context {
    /// The note's words for it.
    pub(super) fn describe(self) -> &'static str {
        match self {
            Context::Setting => "says where or when, not how the body moves",
            Context::Reason => "says why, not how the body moves",
            Context::State => "says what the person feels or notices, not how the body moves",
        }
    }
}

/// Prepositions that open a setting at the start of a clause.
const SETTING_WORDS: &[&str] = &[
    "at", "in", "on", "during", "inside", "outside", "under", "near", "beside",
];

/// Participles of verbs that are no movement: a clause opened by one says what the person
/// feels, notices or has been through.
const STATE_PARTICIPLES: &[&str] = &[
    "feeling",
    "hearing",
    "seeing",
    "noticing",
    "realizing",
    "realising",
    "losing",
    "winning",
    "being",
    "thinking",
    "remembering",
    "watching",
    "sensing",
    "wanting",
];

/// Words after "to" that make it a destination or a change ("to the door", "to a run", "to
/// one knee", "to the left"), not a purpose.
fn is_destination_word(word: &str) -> bool {
    lexicon::is_subject_word(word)
        || lexicon::number(word).is_some()
        || matches!(
            word,
            "his"
                | "her"
                | "their"
                | "its"
                | "my"
                | "your"
                | "one"
                | "both"
                | "each"
                | "left"
                | "right"
                | "front"
                | "side"
                | "sides"
                | "back"
                | "ground"
                | "floor"
                | "standing"
                | "stand"
                | "sit"
                | "kneel"
                | "rest"
                | "halt"
                | "stop"
                | "him"
                | "them"
                | "me"
                | "us"
                | "itself"
                | "himself"
                | "herself"
                | "themselves"
        )
}

/// Verbs after "to" that are the movement itself ("crouches to set something down",
/// "lowers the body to lie flat", "stops to wave with his right hand"), as the training
/// captions say it, not a reason for it.
const MOVEMENT_INFINITIVES: &[&str] = &[
    "lie", "lay", "set", "put", "place", "pick", "sit", "kneel", "squat", "crouch", "touch",
    "reach", "bend", "lean", "step", "walk", "run", "jump", "turn", "spin", "look", "bow", "wave",
    "clap", "point", "salute", "kick", "punch", "stretch", "dance", "throw", "catch", "raise",
    "lift", "hop", "skip", "crawl", "climb", "nod",
];

/// Limb nouns after "to": the body part a movement goes to ("elbow to knee").
const LIMBS: &[&str] = &[
    "knee",
    "knees",
    "toe",
    "toes",
    "foot",
    "feet",
    "chest",
    "head",
    "hip",
    "hips",
    "shoulder",
    "shoulders",
    "waist",
    "elbow",
    "ear",
    "mouth",
    "face",
];

/// Whether `words[i]` is "to" opening a purpose ("to greet", "in order to"), not a
/// destination, a body part or a movement.
fn purpose_at(words: &[&str], i: usize) -> bool {
    words[i] == "to"
        && words.get(i + 1).is_some_and(|next| {
            !is_destination_word(next)
                && !MOVEMENT_INFINITIVES.contains(next)
                && !LIMBS.contains(next)
                && !next.ends_with("ing")
                && !next.ends_with("ed")
                // A plural noun ("signals to cars"): a verb's bare form seldom ends in one s.
                && (!next.ends_with('s') || next.ends_with("ss"))
                && !matches!(*next, "music" | "rhythm" | "himself" | "herself")
        })
}

/// What a whole clause is, when it is context and no movement.
pub(super) fn whole_clause(words: &[&str], names_movement: bool) -> Option<Context> {
    let first = *words.first()?;
    if purpose_at(words, 0) || matches!(words, ["in", "order", "to", ..] | ["so", "as", "to", ..]) {
        // "To celebrate the goal, …": whatever its verb, a clause that opens with a purpose
        // gives the reason for the clause it is attached to.
        return Some(Context::Reason);
    }
    if first == "because" || (first == "since" && words.len() > 2) {
        return Some(Context::Reason);
    }
    if STATE_PARTICIPLES.contains(&first) {
        return Some(Context::State);
    }
    if SETTING_WORDS.contains(&first) && !names_movement {
        return Some(Context::Setting);
    }
    None
}

/// Whether the words that open a sentence, up to its first comma, are context ("in the
/// rain", "to warm up", "hearing a loud noise"): a setting, a purpose, a reason or a state,
/// at most six words.
pub(super) fn opens_context(words: &[&str]) -> bool {
    words.len() <= 6 && whole_clause(words, false).is_some()
}

/// Where a purpose or a reason starts inside a clause that moves ("bows to greet the
/// guests", "waves because he sees his friend"), if one does, after the first word.
pub(super) fn reason_tail(words: &[&str]) -> Option<usize> {
    (1..words.len()).find(|&i| {
        purpose_at(words, i)
            || words[i] == "because"
            || (words[i] == "in" && words[i + 1..].starts_with(&["order", "to"]))
    })
}

/// The clauses with the context dropped (this module's readings): whole clauses that say where, when,
/// why or what the person feels, the reasons at the end of a clause ("bows to greet the
/// guests"), and a clause of no movement and no verb beside a dropped one ("feeling tired
/// after the marathon" is cut at "after"); each named in a note.
pub(super) fn without_context<'a>(
    clauses: &'a [Vec<String>],
    known: Repertoire,
    notes: &mut Vec<String>,
) -> Vec<Vec<&'a str>> {
    let clauses: Vec<Vec<&str>> = clauses
        .iter()
        .map(|c| c.iter().map(String::as_str).collect())
        .collect();
    let moves: Vec<bool> = clauses
        .iter()
        .map(|words| {
            movements(words, None, Reader::alone(known)).is_some()
                || postures::names_posture(words)
                || postures::names_movement(words)
                || path(words).is_some()
        })
        .collect();
    let kinds: Vec<Option<Context>> = clauses
        .iter()
        .zip(&moves)
        .map(|(words, moves)| whole_clause(words, *moves))
        .collect();
    // "a woman hurries forward" has a verb the rules may not know: the word after a subject.
    let has_subject = |words: &[&str]| {
        let rest = lexicon::without_subject(words).len();
        rest > 0
            && words[..words.len() - rest].iter().any(|w| {
                lexicon::is_subject_noun(w)
                    || matches!(
                        *w,
                        "he" | "she" | "they" | "someone" | "somebody" | "person"
                    )
            })
    };
    let verbless = |k: usize| {
        !moves[k]
            && !has_subject(&clauses[k])
            && !clauses[k]
                .iter()
                .any(|w| lexicon::is_finite_verb(w) || postures::is_posture_verb(w))
    };
    let mut out = Vec::new();
    for (k, words) in clauses.iter().enumerate() {
        let beside = |j: Option<usize>| j.and_then(|j| kinds.get(j).copied().flatten());
        let kind = kinds[k].or_else(|| {
            verbless(k)
                .then(|| beside(k.checked_sub(1)).or(beside(Some(k + 1))))
                .flatten()
        });
        if let Some(context) = kind {
            notes.push(format!(
                "\"{}\" {}; dropped",
                words.join(" "),
                context.describe()
            ));
            continue;
        }
        // "waves the arms to direct traffic" names an action of the data, not a reason.
        let names_action = |to: usize| {
            (to + 1..(to + 3).min(words.len())).any(|k| lexicon::dataset_action(words, k).is_some())
        };
        match reason_tail(words).filter(|&i| !names_action(i)) {
            Some(i) => {
                notes.push(format!(
                    "\"{}\" {}; dropped",
                    words[i..].join(" "),
                    Context::Reason.describe()
                ));
                out.push(words[..i].to_vec());
            }
            None => out.push(words.clone()),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(text: &str) -> Vec<&str> {
        text.split(' ').collect()
    }

    #[test]
    fn settings_reasons_and_states_are_context_and_destinations_are_not() {
        let whole = |t: &str, moves| whole_clause(&words(t), moves);
        assert_eq!(
            whole("at the birthday party", false),
            Some(Context::Setting)
        );
        assert_eq!(whole("in the rain", false), Some(Context::Setting));
        assert_eq!(whole("in a circle", true), None);
        assert_eq!(whole("to celebrate the goal", false), Some(Context::Reason));
        assert_eq!(whole("to show the way", true), Some(Context::Reason));
        assert_eq!(
            whole("feeling tired after the marathon", false),
            Some(Context::State)
        );
        assert_eq!(whole("a man bows", true), None);
        let tail = |t: &str| reason_tail(&words(t));
        assert_eq!(tail("a man stomps his feet to protest a verdict"), Some(5));
        assert_eq!(tail("a woman jogs along the beach to stay fit"), Some(6));
        assert_eq!(tail("a man waves because he sees his friend"), Some(3));
        for moving in [
            "a person walks to the door",
            "picks up speed from a walk to a run",
            "drops to one knee",
            "turns to the left",
            "turns to face the crowd",
            "sits down to rest",
            "comes to a stop",
            "a person does elbow to knee exercises",
            "the person crouches to set something down with the left hand",
            "a person lowers the body to lie flat on the floor",
            "a person signals to cars with the arms like a traffic officer",
            "someone dances to music",
        ] {
            assert_eq!(tail(moving), None, "{moving}");
        }
    }
}
