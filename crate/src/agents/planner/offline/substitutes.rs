//! Substitutes for a clause no rule reads: the nearest training action or library entry by
//! meaning, taken only at the calibrated threshold of "the same movement" and never with the
//! side the clause does not name.

use super::super::lexicon::{self, Action, Repertoire, Side};
use super::super::meaning::Matcher;
use super::{is_filler, side_word, NOT_MOVEMENT, TRAINING_ACTIONS};
use crate::posture::library::Library;

/// A clause of no known movement mapped onto the nearest training action by similarity.
pub(super) fn nearest_action(
    words: &[&str],
    matcher: Option<&Matcher>,
    known: Repertoire,
) -> Option<(Action, f32)> {
    let matcher = matcher?;
    if words.is_empty()
        || !words
            .iter()
            .any(|w| lexicon::is_finite_verb(w) || w.len() > 3)
    {
        return None;
    }
    if words
        .iter()
        .all(|w| NOT_MOVEMENT.contains(w) || is_filler(w))
    {
        return None;
    }
    let clause = format!("a person {}", lexicon::without_subject(words).join(" "));
    // A substitute must mean the same movement, as the calibrated judgement of
    // (`planner::meaning`) has it (sides aside, never the opposite direction or gait), and keep the
    // side the clause names.
    let side = words
        .iter()
        .find_map(|w| side_word(w).filter(|s| *s != Side::Both));
    // The sided front kicks, where the model knows them, stand for the Bandai kick (as
    // `dataset_action` reads "kicks").
    let sided_kicks = known.knows(Action::FrontKick(Side::Right));
    TRAINING_ACTIONS
        .iter()
        .filter(|a| !(sided_kicks && **a == Action::Kick))
        .chain(lexicon::DATASET_ACTIONS.iter().filter(|a| known.knows(**a)))
        .map(|a| match side {
            Some(side) => a.with_side(side),
            None => *a,
        })
        .filter(|a| match side {
            Some(side) => !names_other_side(&a.caption(), side),
            // A side the clause does not name is a movement it does not ask for.
            None => !names_a_side(&a.caption()),
        })
        .filter_map(|a| matcher.same(&clause, &a.caption()).map(|s| (a, s)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// A clause of no known movement mapped onto the posture or movement of the library whose
/// name means the same movement ((`planner::meaning`)), with the similarity: "sits" is "sit on a
/// chair".
pub(super) fn nearest_library_entry(
    words: &[&str],
    matcher: Option<&Matcher>,
) -> Option<(String, f32)> {
    let matcher = matcher?;
    if words.is_empty()
        || words
            .iter()
            .all(|w| NOT_MOVEMENT.contains(w) || is_filler(w))
    {
        return None;
    }
    let clause = format!("a person {}", lexicon::without_subject(words).join(" "));
    Library::builtin()
        .all()
        .filter_map(|n| matcher.same(&clause, n.name()).map(|s| (n.name(), s)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(name, s)| (name.to_string(), s))
}

/// Whether a caption names a left or right side.
fn names_a_side(caption: &str) -> bool {
    caption.split(' ').any(|w| w == "left" || w == "right")
}

/// Whether a caption names the side opposite to `side` and not `side` itself.
fn names_other_side(caption: &str, side: Side) -> bool {
    let words: Vec<&str> = caption.split(' ').collect();
    let (own, other) = match side {
        Side::Left => ("left", "right"),
        Side::Right => ("right", "left"),
        Side::Both => return false,
    };
    words.contains(&other) && !words.contains(&own)
}
