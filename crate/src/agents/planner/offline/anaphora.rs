//! Clauses that point back at the movement before them: "raises her right arm and then
//! **lowers it**", "lifts both hands, then **puts them down**". Read alone they name no
//! movement (and the nearest one by meaning may be the opposite); read against the segment
//! before, they bring down the arms it raised.

use crate::plan::Segment;
use crate::skeleton::BodyPart;

/// Whether a clause lowers something it points back at ("lowers it", "puts them back down",
/// "brings the arm down", "drops the hands"), naming no other movement.
pub(super) fn lowers_back(words: &[&str]) -> bool {
    let lowering = words
        .iter()
        .any(|w| matches!(*w, "lower" | "lowers" | "lowering"))
        || words.contains(&"down")
            && words.iter().any(|w| {
                matches!(
                    *w,
                    "put" | "puts" | "bring" | "brings" | "take" | "takes" | "drop" | "drops"
                )
            });
    let pointer = words.iter().any(|w| {
        matches!(
            *w,
            "it" | "them" | "arm" | "arms" | "hand" | "hands" | "fist" | "fists"
        )
    });
    lowering && pointer
}

/// The arms the segment raises: an arm whose instruction raises or reaches up, else the arms
/// its base motion raises, by the side it names ("a person raises the right hand").
pub(super) fn raised_arms(segment: &Segment) -> Vec<BodyPart> {
    let raises = |text: &str| {
        [
            "raise",
            "reaches up",
            "lifts",
            "stretching arms up",
            "hands up",
        ]
        .iter()
        .any(|w| text.contains(w))
    };
    let edited: Vec<BodyPart> = [BodyPart::LeftArm, BodyPart::RightArm]
        .into_iter()
        .filter(|p| segment.parts.get(*p).is_some_and(raises))
        .collect();
    if !edited.is_empty() {
        return edited;
    }
    if !raises(&segment.base)
        && !segment.postures.as_ref().is_some_and(|t| {
            t.keys
                .iter()
                .any(|k| k.script.name.as_deref().is_some_and(raises))
        })
    {
        return Vec::new();
    }
    let text = format!("{} {}", segment.base, segment.text);
    let words: Vec<&str> = text.split(' ').collect();
    match (words.contains(&"left"), words.contains(&"right")) {
        (true, false) => vec![BodyPart::LeftArm],
        (false, true) => vec![BodyPart::RightArm],
        _ => vec![BodyPart::LeftArm, BodyPart::RightArm],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::agents::planner::offline::plan;

    #[test]
    fn lowering_what_was_raised_points_back_at_its_arms() {
        assert!(lowers_back(&["then", "lowers", "it"]));
        assert!(lowers_back(&["puts", "them", "back", "down"]));
        assert!(!lowers_back(&[
            "lowers", "the", "body", "to", "the", "floor"
        ]));
        let raised = plan("a person raises the left hand", None);
        assert_eq!(raised_arms(&raised.segments[0]), [BodyPart::LeftArm]);
        let walk = plan("a person walks forward", None);
        assert!(raised_arms(&walk.segments[0]).is_empty());
    }
}
