//! What a clause places beside or instead of the model's movement: limb places held over
//! its segments, the body standing while limbs hold them, places kept or lowered by a clause
//! that points back at them, and why a segment cannot take a pose on some limbs.

use super::*;
use crate::posture::library::Library;
use crate::posture::track::DEFAULT_TRANSITION_SECONDS;

/// Whether a segment gets the body up to standing (the library's "stand up").
pub(super) fn gets_up(segment: &Segment) -> bool {
    segment.postures.as_ref().is_some_and(|t| {
        t.keys
            .iter()
            .any(|k| k.script.name.as_deref() == Some("stand up"))
    }) || postures::stands_up(&segment.text.split(' ').collect::<Vec<_>>())
}

/// The limb places held over the clause that ends where the clause at `clause_start` begins.
pub(super) fn held_just_before(
    held: &[(std::ops::Range<usize>, NamedPosture)],
    clause_start: usize,
) -> impl Iterator<Item = &NamedPosture> {
    held.iter()
        .filter(move |(span, _)| span.end == clause_start && !span.is_empty())
        .map(|(_, p)| p)
}

/// The limb places a clause that holds what came before keeps: those held over the clause
/// just before (`held`, ending at `clause_start`), else the arms the segment before raised,
/// up; `None` when there are none.
pub(super) fn kept_places(
    held: &[(std::ops::Range<usize>, NamedPosture)],
    clause_start: usize,
    before: Option<&Segment>,
) -> Option<Vec<NamedPosture>> {
    let kept: Vec<NamedPosture> = held_just_before(held, clause_start).cloned().collect();
    if !kept.is_empty() {
        return Some(kept);
    }
    let which = match anaphora::raised_arms(before?).as_slice() {
        [BodyPart::LeftArm] => "left arm up",
        [BodyPart::RightArm] => "right arm up",
        [] => return None,
        _ => "both arms up",
    };
    let words: Vec<&str> = which.split(' ').collect();
    limb_poses::limb_pose(&words).map(|p| vec![p])
}

/// The segment of a clause that lowers the arms the segment before raised ("raises her right
/// arm and then lowers it"): the arms go down to the library's standing posture while the
/// body stands; `None` when the clause is no such thing or nothing before was raised.
pub(super) fn lowered_back(
    words: &[&str],
    before: Option<&Segment>,
    held_before: &[BodyPart],
) -> Option<Segment> {
    if !anaphora::lowers_back(words) {
        return None;
    }
    let before = before?;
    let mut arms = anaphora::raised_arms(before);
    if arms.is_empty() {
        // "waves with the left hand, lowers it": the arm the movement before used.
        arms = anaphora::moved_arms(before);
    }
    let is_arm = |p: &&BodyPart| matches!(p, BodyPart::LeftArm | BodyPart::RightArm);
    if arms.is_empty() {
        // "raises both hands, holds them up, then lets them drop": the arms held just before.
        arms = held_before.iter().filter(is_arm).copied().collect();
    }
    let stand = Library::builtin().get("stand")?;
    let legs: Vec<BodyPart> = held_before.iter().filter(|p| !is_arm(p)).copied().collect();
    let (parts, which, name) = match (arms.as_slice(), legs.as_slice()) {
        ([BodyPart::LeftArm], _) => (arms, "lowers the left arm", anaphora::ARMS_DOWN),
        ([BodyPart::RightArm], _) => (arms, "lowers the right arm", anaphora::ARMS_DOWN),
        ([], []) => return None,
        // "lifts the right knee, holds it, then puts it down": the foot back on the ground.
        ([], [BodyPart::LeftLeg]) => (legs, "puts the left foot down", "left foot down"),
        ([], [BodyPart::RightLeg]) => (legs, "puts the right foot down", "right foot down"),
        ([], _) => (legs, "puts both feet down", "feet down"),
        _ => (arms, "lowers both arms", anaphora::ARMS_DOWN),
    };
    let mut script = stand.script.clone();
    script.name = Some(name.into());
    let arms = parts;
    Some(Segment {
        text: format!("a person {which}"),
        seconds: 2.0,
        base: "a person stands still".into(),
        parts: PartEdits::default(),
        trajectory: None,
        postures: Some(PostureTrack::holding(arms, script)),
    })
}

/// The hand's place in a clause that touches a body point with it or holds a thing ("touches
/// the right knee with the left hand", "taps his head with his left hand", "holding a phone
/// to the right ear"): the point comes before the hand that goes there, across the "with"
/// that parts the clause's phrases, or no hand is named at all, so it is read from the verb
/// on.
pub(super) fn touch_pose(words: &[&str]) -> Option<NamedPosture> {
    let at = words
        .iter()
        .position(|w| limb_poses::TOUCHING.contains(w) || limb_poses::HOLDING.contains(w))?;
    limb_poses::limb_pose(&words[at..])
}

/// Places each phrase of a clause about a limb in which the rules read no movement on the
/// clause's segments (`made`): a place the limb holds ("with his right arm upwards",
/// [`limb_poses`]) is returned, to be held on the limb's track over those segments; an arm
/// phrase that says no place is the gesture or arm posture it means ([`limbs`]), where those
/// arms are free. What cannot be placed is named in a note (`named`: the words that named a
/// movement).
pub(super) fn place_limb_phrases(
    words: &[&str],
    named: &[usize],
    matcher: Option<&Matcher>,
    made: &mut [Segment],
    notes: &mut Vec<String>,
) -> Vec<NamedPosture> {
    let mut held: Vec<NamedPosture> = Vec::new();
    // "walking, taps his head with his left hand": the hand's words ("with his left hand")
    // say only which hand, the place is before them.
    if let Some(pose) = touch_pose(words).filter(|p| !made_already(made, p)) {
        hold_place(pose, &words.join(" "), made, &mut held, notes);
    }
    for (phrase, limb) in accounting::limb_phrases_without_movement(words, named) {
        let phrase_words: Vec<&str> = phrase.split(' ').collect();
        if let Some(pose) = limb_poses::limb_pose(&phrase_words) {
            if !held.iter().any(|h| h.name == pose.name) && !made_already(made, &pose) {
                hold_place(pose, &phrase, made, &mut held, notes);
            }
            continue;
        }
        let found = matcher
            .filter(|_| limb == "arm")
            .and_then(|m| limbs::nearest_arm_movement(&phrase_words, m));
        let Some((movement, similarity)) = found
            .filter(|(m, _)| !made.is_empty() && made.iter().all(|s| arms_free(s, &m.parts())))
        else {
            notes.push(format!(
                "\"{phrase}\" {NOT_PLACED}: the built-in planner has no rule for this \
                 movement of the {limb}"
            ));
            continue;
        };
        for segment in made.iter_mut() {
            match &movement {
                limbs::LimbMovement::Gesture(g) => {
                    for part in g.arms() {
                        segment.parts.set(*part, Some(g.caption()));
                    }
                }
                limbs::LimbMovement::Posture(p) => {
                    segment.postures =
                        Some(PostureTrack::holding(p.parts.clone(), p.script.clone()));
                }
            }
        }
        notes.push(format!(
            "\"{phrase}\" {SUBSTITUTED} on its own; used \"{}\" on the same arms \
             (similarity {similarity:.2})",
            movement.describe()
        ));
    }
    held
}

/// Whether the clause's own segments already hold `pose` ("…, holding the T-pose": the
/// posture the clause names is on its segments).
pub(super) fn made_already(made: &[Segment], pose: &NamedPosture) -> bool {
    made.iter().any(|s| {
        s.postures.as_ref().is_some_and(|t| {
            t.keys
                .iter()
                .any(|k| k.script.name.as_deref() == Some(pose.name.as_str()))
        })
    })
}

/// Holds `pose` (a limb's place a phrase says) over the clause's segments, unless the
/// clause's movement or another of its phrases moves that limb, which a note then says.
pub(super) fn hold_place(
    pose: NamedPosture,
    phrase: &str,
    made: &[Segment],
    held: &mut Vec<NamedPosture>,
    notes: &mut Vec<String>,
) {
    let taken = held
        .iter()
        .any(|h| h.parts.iter().any(|p| pose.parts.contains(p)));
    match made
        .iter()
        .find_map(|s| busy(s, &pose.parts))
        .or_else(|| (made.is_empty() || taken).then_some("another phrase of the clause moves it"))
    {
        None => held.push(pose),
        Some(why) => notes.push(format!("\"{phrase}\" {NOT_PLACED}: {why}")),
    }
}

/// A clause that only says where limbs are ([`limb_poses`]): the body stands, on one leg if
/// the clause says so (the segment's own posture), and the other places are held on their
/// limbs over it. `None` when no limb phrase of the clause reads as a place.
pub(super) fn standing_poses(words: &[&str]) -> Option<(Segment, Vec<NamedPosture>)> {
    let mut poses: Vec<NamedPosture> = Vec::new();
    for (phrase, _) in accounting::limb_phrases_without_movement(words, &[]) {
        let phrase: Vec<&str> = phrase.split(' ').collect();
        if let Some(pose) = limb_poses::limb_pose(&phrase) {
            poses.push(pose);
        }
    }
    if poses.is_empty() {
        poses.extend(touch_pose(words));
    }
    if poses.is_empty() {
        return None;
    }
    let legs = [BodyPart::LeftLeg, BodyPart::RightLeg];
    let stance = poses
        .iter()
        .position(|p| legs.iter().all(|l| p.parts.contains(l)))
        .map(|k| poses.remove(k));
    // Each limb held once: the first place a phrase gives it.
    let mut kept: Vec<NamedPosture> = Vec::new();
    for pose in poses {
        if kept
            .iter()
            .all(|k| k.parts.iter().all(|p| !pose.parts.contains(p)))
        {
            kept.push(pose);
        }
    }
    let (text, postures) = match &stance {
        Some(s) => (
            format!("a person {}", s.name.replacen("standing", "stands", 1)),
            Some(PostureTrack::holding(s.parts.clone(), s.script.clone())),
        ),
        None => ("a person stands still".to_string(), None),
    };
    Some((standing_segment(text, postures), kept))
}

/// A segment over the model's standing, made by key poses the rules write (`postures`, if
/// any): as long as the poses take at their own pace with the way into them, 2 s at least.
pub(super) fn standing_segment(text: String, postures: Option<PostureTrack>) -> Segment {
    let seconds = postures
        .as_ref()
        .and_then(|t| clamp_seconds(t.natural_seconds() + DEFAULT_TRANSITION_SECONDS))
        .unwrap_or(2.0)
        .max(2.0);
    Segment {
        text,
        seconds,
        base: "a person stands still".into(),
        parts: PartEdits::default(),
        trajectory: None,
        postures,
    }
}

/// Why a segment cannot have a pose held on `parts` over it, if it cannot: an instruction or
/// a held posture of its own moves them, or (for a leg) the body travels or jumps on its legs.
/// A posture of the whole body (a spin of key poses) carries a held arm.
pub(super) fn busy(segment: &Segment, parts: &[BodyPart]) -> Option<&'static str> {
    if parts.iter().any(|p| segment.parts.get(*p).is_some()) {
        return Some("another instruction of the clause moves that limb");
    }
    let legs = parts
        .iter()
        .any(|p| matches!(p, BodyPart::LeftLeg | BodyPart::RightLeg));
    match &segment.postures {
        Some(track) if track.whole_body() && legs => {
            Some("a posture of the whole body already holds the legs")
        }
        Some(track) if !track.whole_body() && track.parts.iter().any(|p| parts.contains(p)) => {
            Some("a posture of the clause already holds that limb")
        }
        _ if legs && !stands(segment) => {
            Some("the legs carry the movement of the clause and cannot also hold a pose")
        }
        _ => None,
    }
}

/// Whether a segment's base motion stands in place (the legs are free to hold a pose).
pub(super) fn stands(segment: &Segment) -> bool {
    let base = segment.base.as_str();
    base.contains("stands") && !base.contains("up")
}

/// Whether a segment leaves `arms` to a movement of their own: no instruction and no posture
/// on them.
pub(super) fn arms_free(segment: &Segment, arms: &[BodyPart]) -> bool {
    arms.iter().all(|a| segment.parts.get(*a).is_none()) && segment.postures.is_none()
}
