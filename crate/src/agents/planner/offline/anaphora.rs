//! Clauses that point back at the movement before them: "raises her right arm and then
//! **lowers it**", "lifts both hands, then **puts them down**". Read alone they name no
//! movement (and the nearest one by meaning may be the opposite); read against the segment
//! before, they bring down the arms it raised. A clause that only points back ("does it
//! again", "then with the right", "the other one") makes that movement once more, on the side
//! it names.

use super::super::lexicon::Side;
use crate::plan::Segment;
use crate::posture::library::NamedPosture;
use crate::skeleton::BodyPart;

/// Whether a clause lowers something it points back at ("lowers it", "puts them back down",
/// "brings the arm down", "drops the hands"), naming no other movement.
pub(super) fn lowers_back(words: &[&str]) -> bool {
    let has = |list: &[&str]| words.iter().any(|w| list.contains(w));
    let lowering = has(&["lower", "lowers", "lowering"])
        || words.contains(&"down")
            && has(&[
                "put", "puts", "bring", "brings", "take", "takes", "drop", "drops",
            ])
        // "lets them drop", "lets the arms fall", "drops the hands".
        || has(&["let", "lets", "letting"]) && has(&["drop", "fall", "hang", "sink"])
        || has(&["drop", "drops", "dropping"]);
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

/// The arms the segment moves on their own, when none is raised: the arms with an
/// instruction of their own or held in a posture of the arms, else the side its base motion
/// names for a hand or an arm ("a person waves the left hand").
pub(super) fn moved_arms(segment: &Segment) -> Vec<BodyPart> {
    let arms = [BodyPart::LeftArm, BodyPart::RightArm];
    let edited: Vec<BodyPart> = arms
        .into_iter()
        .filter(|p| segment.parts.get(*p).is_some())
        .collect();
    if !edited.is_empty() {
        return edited;
    }
    if let Some(track) = &segment.postures {
        if track.parts.iter().all(|p| arms.contains(p)) {
            return track.parts.clone();
        }
    }
    let words: Vec<&str> = segment.base.split(' ').collect();
    if !words
        .iter()
        .any(|w| matches!(*w, "hand" | "hands" | "arm" | "arms"))
    {
        return Vec::new();
    }
    match (words.contains(&"left"), words.contains(&"right")) {
        (true, false) => vec![BodyPart::LeftArm],
        (false, true) => vec![BodyPart::RightArm],
        _ => arms.to_vec(),
    }
}

/// Whether a segment only brings arms down (made by the built-in planner for "lowers it"):
/// "does it again" after it means the movement before the lowering.
pub(super) fn is_lowering(segment: &Segment) -> bool {
    segment.postures.as_ref().is_some_and(|t| {
        t.keys
            .iter()
            .all(|k| k.script.name.as_deref() == Some(ARMS_DOWN))
    })
}

/// The name of the key pose that brings the arms down.
pub(super) const ARMS_DOWN: &str = "arms down";

/// What a clause that only points back asks of the movement before it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Again {
    /// The same movement once more ("does it again", "repeats it").
    Same,
    /// The same movement with the other side ("then with the other hand", "the other one").
    Other,
    /// The same movement on a side it names ("then with the right", "the left one too").
    On(Side),
}

/// Words an elliptical clause may hold besides its side ("then with the right one too").
const FILLER: &[&str] = &[
    "with", "the", "his", "her", "their", "its", "then", "and", "one", "hand", "arm", "foot",
    "leg", "fist", "side", "too", "also", "now", "same", "on", "using", "a", "person", "he", "she",
    "they", "someone", "it", "again", "does", "do", "did", "repeats", "repeat", "same", "thing",
    "once", "more", "over", "this", "time", "switches", "switch", "to", "twice", "thrice", "times",
    "two", "three", "four",
];

/// Whether a clause only points back at the movement before ("does it again", "with the
/// right", "then the other one"), and how; `None` when it names anything else.
pub(super) fn again(words: &[&str]) -> Option<Again> {
    if words.is_empty() || words.iter().any(|w| !FILLER.contains(w) && !is_side(w)) {
        return None;
    }
    let repeats = words
        .iter()
        .any(|w| matches!(*w, "again" | "repeats" | "repeat" | "same"))
        || words.windows(2).any(|w| w == ["once", "more"]);
    let side = words.iter().find_map(|w| match *w {
        "left" => Some(Again::On(Side::Left)),
        "right" => Some(Again::On(Side::Right)),
        "other" => Some(Again::Other),
        _ => None,
    });
    match side {
        Some(s) => Some(s),
        None if repeats => Some(Again::Same),
        None => None,
    }
}

fn is_side(word: &str) -> bool {
    matches!(word, "left" | "right" | "other")
}

/// The side a segment moves one limb of, by its words and parts; `None` for both or none.
fn side_of(segment: &Segment) -> Option<Side> {
    let mut texts = vec![segment.base.clone()];
    texts.extend(segment.parts.edits().into_iter().map(|(_, t)| t));
    if let Some(track) = &segment.postures {
        texts.extend(track.keys.iter().filter_map(|k| k.script.name.clone()));
    }
    let all = texts.join(" ");
    let has = |side: &str| all.split(' ').any(|w| w == side);
    match (has("left"), has("right")) {
        (true, false) => Some(Side::Left),
        (false, true) => Some(Side::Right),
        _ => None,
    }
}

/// `segment` made once more as `again` asks; `None` when a side is asked of a movement that
/// has none.
pub(super) fn repeated(segment: &Segment, again: Again) -> Option<Segment> {
    let own = side_of(segment);
    let mirror = match (again, own) {
        (Again::Same, _) => false,
        (Again::Other, Some(_)) => true,
        (Again::On(want), Some(own)) => want != own,
        (Again::Other | Again::On(_), None) => return None,
    };
    Some(if mirror {
        mirrored(segment)
    } else {
        segment.clone()
    })
}

/// Text with its sides swapped ("left arm up" is "right arm up").
fn swap(text: &str) -> String {
    text.split(' ')
        .map(|w| match w {
            "left" => "right",
            "right" => "left",
            other => other,
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// Limb places held over the clause before, made once more as `again` asks ("stretches her
/// left arm to the side, and then the right one"); `None` when a side is asked of places
/// that have none (both arms, or limbs of both sides).
pub(super) fn repeated_poses(poses: &[NamedPosture], again: Again) -> Option<Vec<NamedPosture>> {
    let side = |p: &BodyPart| match p {
        BodyPart::LeftArm | BodyPart::LeftLeg => Side::Left,
        BodyPart::RightArm | BodyPart::RightLeg => Side::Right,
    };
    let sides: Vec<Side> = poses
        .iter()
        .flat_map(|p| p.parts.iter().map(side))
        .collect();
    let own = match sides.split_first() {
        Some((first, rest)) if rest.iter().all(|s| s == first) => Some(*first),
        _ => None,
    };
    let mirror = match (again, own) {
        (Again::Same, _) => false,
        (Again::Other, Some(_)) => true,
        (Again::On(want), Some(own)) => want != own,
        (Again::Other | Again::On(_), None) => return None,
    };
    Some(
        poses
            .iter()
            .map(|p| {
                if !mirror {
                    return p.clone();
                }
                let mut script = p.script.mirrored();
                script.name = script.name.as_deref().map(swap);
                NamedPosture {
                    name: swap(&p.name),
                    synonyms: Vec::new(),
                    parts: p.parts.iter().map(|b| b.mirrored()).collect(),
                    script,
                }
            })
            .collect(),
    )
}

/// Words a clause that only keeps the place the clause before reached may hold besides its
/// verb and what it points at ("holds it there for a moment", "keeps them up").
const HOLDING_ON: &[&str] = &[
    "it", "them", "there", "up", "in", "place", "the", "air", "for", "a", "an", "moment", "while",
    "few", "seconds", "second", "briefly", "then", "and", "still", "steady", "that", "position",
    "pose", "he", "she", "they", "someone", "person", "again", "long", "as",
];

/// Whether a clause only keeps where the clause before put a limb ("holds it", "holds it
/// there", "holds them up for a moment", "keeps it up"): a holding verb, a word pointing
/// back, and nothing else that moves.
pub(super) fn holds_back(words: &[&str]) -> bool {
    let verb = words
        .iter()
        .any(|w| matches!(*w, "hold" | "holds" | "holding" | "keep" | "keeps"));
    let points = words
        .iter()
        .any(|w| matches!(*w, "it" | "them" | "there" | "pose" | "position"));
    verb && points
        && words.iter().all(|w| {
            matches!(*w, "hold" | "holds" | "holding" | "keep" | "keeps")
                || HOLDING_ON.contains(w)
                || super::super::lexicon::is_subject_noun(w)
        })
}

/// The name of a limb's place kept by a clause of its own ("right leg lifted, knee up,
/// held"): the place goes on, as a clip of its own.
pub(super) fn held_name(name: &str) -> String {
    format!("{name}, held")
}

/// Words of a clause that goes back the way it came and says nothing more ("back to the
/// centre", "jumps back to where they started", "steps back to the middle").
const GOING_BACK: &[&str] = &[
    "back", "then", "and", "to", "the", "a", "his", "her", "their", "where", "he", "she", "they",
    "it", "someone", "person", "centre", "center", "middle", "start", "started", "began", "place",
    "position", "original", "spot", "again", "step", "steps", "walk", "walks", "jump", "jumps",
    "hop", "hops", "move", "moves", "go", "goes", "come", "comes", "shuffle", "shuffles", "slide",
    "slides",
];

/// Whether a clause only goes back the way the body came ("then back to the centre"); see
/// [`back_across`].
pub(super) fn goes_back(words: &[&str]) -> bool {
    words.contains(&"back")
        && words
            .iter()
            .all(|w| GOING_BACK.contains(w) || super::super::lexicon::is_subject_noun(w))
}

/// The side a segment carries the body to, by its key poses' travel or its words ("walks to
/// the left", "side step to the right"); `None` when it goes no way sideways.
fn lateral_way(segment: &Segment) -> Option<Side> {
    if let Some(track) = &segment.postures {
        let left: f64 = track.keys.iter().map(|k| k.travel[0]).sum();
        if left.abs() > 1e-6 {
            return Some(if left > 0.0 { Side::Left } else { Side::Right });
        }
    }
    // "to the left", but not "turning to the left" (a turn, not a way sideways).
    let goes = |text: &str, side: &str| {
        text.contains(&format!("to the {side}"))
            && !text.contains(&format!("turning to the {side}"))
            && !text.contains(&format!("turns to the {side}"))
    };
    let said = |side: &str| goes(&segment.base, side) || goes(&segment.text, side);
    match (said("left"), said("right")) {
        (true, false) => Some(Side::Left),
        (false, true) => Some(Side::Right),
        _ => None,
    }
}

/// The clause "back" after a movement to one side: the same movement to the other side, so
/// the body ends where it started ("steps to the left, then back to the centre": a step to
/// the right). `None` when the movement before went no way sideways.
pub(super) fn back_across(before: &Segment) -> Option<Segment> {
    lateral_way(before)?;
    let mut back = mirrored(before);
    if let Some(track) = &mut back.postures {
        for key in &mut track.keys {
            key.script.name = key
                .script
                .name
                .as_deref()
                .map(|n| n.replacen("side step to", "step back to", 1));
        }
    }
    Some(back)
}

/// A segment with its left and right swapped: the words, the part instructions and the key
/// poses.
fn mirrored(segment: &Segment) -> Segment {
    let mut out = segment.clone();
    out.text = swap(&segment.text);
    out.base = swap(&segment.base);
    let mut parts = crate::plan::PartEdits::default();
    for (part, text) in segment.parts.edits() {
        parts.set(part.mirrored(), Some(swap(&text)));
    }
    out.parts = parts;
    if let Some(track) = &mut out.postures {
        track.parts = track.parts.iter().map(|p| p.mirrored()).collect();
        for key in &mut track.keys {
            key.script = key.script.mirrored();
            key.script.name = key.script.name.as_deref().map(swap);
            key.turn_deg = -key.turn_deg;
            key.travel[0] = -key.travel[0];
        }
    }
    out
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

    fn words(text: &str) -> Vec<&str> {
        text.split(' ').collect()
    }

    #[test]
    fn a_clause_that_points_back_repeats_the_movement_on_the_side_it_names() {
        assert_eq!(again(&words("does it again")), Some(Again::Same));
        assert_eq!(
            again(&words("then with the right")),
            Some(Again::On(Side::Right))
        );
        assert_eq!(again(&words("the other one")), Some(Again::Other));
        assert_eq!(
            again(&words("does it again with the right")),
            Some(Again::On(Side::Right))
        );
        assert_eq!(again(&words("walks again")), None);
        assert_eq!(
            again(&words("with the right hand")),
            Some(Again::On(Side::Right))
        );
        let wave = Segment {
            text: "a person waves the left hand".into(),
            seconds: 3.0,
            base: "a person waves the left hand".into(),
            parts: Default::default(),
            trajectory: None,
            postures: None,
        };
        let right = repeated(&wave, Again::On(Side::Right)).unwrap();
        assert_eq!(right.base, "a person waves the right hand");
        assert_eq!(repeated(&wave, Again::On(Side::Left)).unwrap(), wave);
        assert_eq!(repeated(&wave, Again::Other).unwrap(), right);
        let bow = Segment {
            base: "a person bows".into(),
            ..wave.clone()
        };
        assert_eq!(repeated(&bow, Again::Other), None);
    }
}
