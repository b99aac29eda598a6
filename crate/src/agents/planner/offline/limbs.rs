//! A phrase about an arm that the rules read no movement in ("spins with **his right arm
//! upwards**") placed on that arm's track by meaning: the gesture of the model's lexicon or
//! the arm posture of the library that means the same movement ([`meaning`]'s calibrated
//! judgement), on the same side. Legs have no movements of their own in the lexicon or the
//! library (their postures hold the whole stance), so a leg phrase is only named in a note.

use super::super::lexicon::{Action, Side};
use super::super::meaning::Matcher;
use super::super::postures::on_arm;
use crate::posture::library::{Library, NamedPosture};
use crate::skeleton::BodyPart;

/// What a limb phrase is placed as.
#[derive(Clone, Debug)]
pub(super) enum LimbMovement {
    /// A gesture of the lexicon, as a part edit of the model's motion.
    Gesture(Action),
    /// A posture of the library held on its arms (mirrored onto the other arm where the
    /// library has it on one arm only).
    Posture(NamedPosture),
}

impl LimbMovement {
    /// The arms it moves.
    pub(super) fn parts(&self) -> Vec<BodyPart> {
        match self {
            LimbMovement::Gesture(a) => a.arms().to_vec(),
            LimbMovement::Posture(p) => p.parts.clone(),
        }
    }

    /// Its name in the plan's words.
    pub(super) fn describe(&self) -> String {
        match self {
            LimbMovement::Gesture(a) => a.verb_phrase(),
            LimbMovement::Posture(p) => p.name.clone(),
        }
    }
}

/// The gestures a phrase may mean, before their side is set.
const GESTURES: [Action; 4] = [
    Action::Wave(Side::Right),
    Action::Raise(Side::Right),
    Action::Beckon,
    Action::Guide,
];

/// The side an arm phrase names: a side word, else both for plural arms or hands ("arms
/// flapping"), else none.
fn phrase_side(words: &[&str]) -> Option<Side> {
    if words.contains(&"both") || (words.contains(&"left") && words.contains(&"right")) {
        return Some(Side::Both);
    }
    if words.contains(&"left") {
        return Some(Side::Left);
    }
    if words.contains(&"right") {
        return Some(Side::Right);
    }
    words
        .iter()
        .any(|w| matches!(*w, "arms" | "hands" | "fists"))
        .then_some(Side::Both)
}

/// The arms a side moves.
fn arms_of(side: Side) -> Vec<BodyPart> {
    match side {
        Side::Left => vec![BodyPart::LeftArm],
        Side::Right => vec![BodyPart::RightArm],
        Side::Both => vec![BodyPart::LeftArm, BodyPart::RightArm],
    }
}

/// The gesture or arm posture an arm phrase means, with the similarity; `None` when nothing
/// means the same movement on the same arms, or the phrase names no side it can keep.
pub(super) fn nearest_arm_movement(
    phrase: &[&str],
    matcher: &Matcher,
) -> Option<(LimbMovement, f32)> {
    let side = phrase_side(phrase)?;
    let arms = arms_of(side);
    let said = format!("a person {}", phrase.join(" "));
    let gestures = GESTURES
        .iter()
        .map(|g| g.with_side(side))
        .filter(|g| g.arms() == arms.as_slice())
        .filter_map(|g| {
            matcher
                .same(&said, &g.caption())
                .map(|s| (LimbMovement::Gesture(g), s))
        });
    let one_arm = match side {
        Side::Left => Some(BodyPart::LeftArm),
        Side::Right => Some(BodyPart::RightArm),
        Side::Both => None,
    };
    let postures = Library::builtin()
        .all()
        .filter_map(|n| match n {
            crate::posture::library::Named::Posture(p) => Some(on_arm(p, one_arm)),
            _ => None,
        })
        .filter(|p| {
            let mut parts = p.parts.clone();
            parts.sort();
            parts == arms
        })
        .filter_map(|p| {
            // Matched by the library's own name: the mirrored one names its arm too.
            let name = p
                .name
                .split(" with the ")
                .next()
                .unwrap_or(&p.name)
                .to_string();
            matcher
                .same(&said, &name)
                .map(|s| (LimbMovement::Posture(p), s))
        });
    gestures.chain(postures).max_by(|a, b| a.1.total_cmp(&b.1))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Similarity by shared words, for tests without the sentence encoder.
    fn shared(a: &str, b: &str) -> f32 {
        let wa: Vec<&str> = a.split(' ').collect();
        let wb: Vec<&str> = b.split(' ').collect();
        let common = wa.iter().filter(|w| wb.contains(w)).count();
        common as f32 / wa.len().max(wb.len()) as f32
    }

    #[test]
    fn an_arm_phrase_takes_a_movement_of_its_own_side_or_none() {
        let matcher = Matcher::new(&shared, 0.5);
        let (found, _) =
            nearest_arm_movement(&["raises", "the", "left", "hand"], &matcher).unwrap();
        assert!(matches!(
            found,
            LimbMovement::Gesture(Action::Raise(Side::Left))
        ));
        assert_eq!(found.parts(), [BodyPart::LeftArm]);
        // No side, no plural: which arm is unknown.
        assert!(nearest_arm_movement(&["the", "arm", "up"], &matcher).is_none());
        // Both arms: a posture of both arms only.
        let (found, _) = nearest_arm_movement(&["arms", "crossed"], &matcher).unwrap();
        assert_eq!(found.describe(), "arms crossed");
        // The library points with the right arm only; the left arm points with its mirror.
        let (found, _) = nearest_arm_movement(&["left", "pointing", "forward"], &matcher).unwrap();
        assert_eq!(found.parts(), [BodyPart::LeftArm]);
        assert_eq!(found.describe(), "pointing forward with the left arm");
    }
}
