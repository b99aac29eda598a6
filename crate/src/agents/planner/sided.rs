//! Whole-body postures that use one leg unlike the other ("kneel on one knee", "stand on one
//! leg", "lunge"), put on the leg the words name: "kneels on **the left knee**", "lunges
//! forward **with the right leg**", "lifts **the right knee**". The library writes each such
//! posture for one side; which side is read from its own constraints (the knee on the ground,
//! the foot off it, the foot in front), and the posture is mirrored when the words ask for
//! the other.

use crate::posecodes::{BodyPoint, Relation, Support};
use crate::posture::library::NamedPosture;
use crate::posture::script::{Constraint, PostureScript};
use crate::skeleton::{BodyPart, Side};

/// The leg a one-legged posture does not rest on: the front leg of a kneel, the lifted leg
/// of a one-leg stand, the leading leg of a lunge; `None` when both legs do the same.
fn free_leg(script: &PostureScript) -> Option<Side> {
    let contact = |point: Support| {
        script.constraints.iter().find_map(|c| match c {
            Constraint::Contact {
                point: p,
                on_ground,
            } if *p == point => Some(*on_ground),
            _ => None,
        })
    };
    let knees = (contact(Support::LeftKnee), contact(Support::RightKnee));
    match knees {
        (Some(true), Some(false) | None) => return Some(Side::Right),
        (Some(false) | None, Some(true)) => return Some(Side::Left),
        _ => {}
    }
    match (contact(Support::LeftFoot), contact(Support::RightFoot)) {
        (Some(false), Some(true)) => return Some(Side::Left),
        (Some(true), Some(false)) => return Some(Side::Right),
        _ => {}
    }
    let in_front = |foot: BodyPoint| {
        script.constraints.iter().any(|c| {
            matches!(c, Constraint::Relation { a, b: BodyPoint::Pelvis, is: Relation::InFrontOf } if *a == foot)
        })
    };
    match (
        in_front(BodyPoint::LeftFoot),
        in_front(BodyPoint::RightFoot),
    ) {
        (true, false) => Some(Side::Left),
        (false, true) => Some(Side::Right),
        _ => None,
    }
}

/// The leg the words name and whether they name the leg the body rests on ("kneels **on**
/// the left knee", "stands on the right leg") rather than the free one ("lifts the left
/// knee", "lunges with the right leg"), with the noun they use.
fn named_leg(words: &[&str]) -> Option<(Side, bool, &'static str)> {
    words.iter().enumerate().find_map(|(i, w)| {
        let noun = match *w {
            "leg" => "leg",
            "foot" => "foot",
            "knee" => "knee",
            _ => return None,
        };
        let before = &words[i.saturating_sub(3)..i];
        let side = before.iter().rev().find_map(|w| Side::of_word(w))?;
        let rests = before.iter().any(|w| matches!(*w, "on" | "onto"));
        Some((side, rests, noun))
    })
}

/// `posture` on the leg `words` name: mirrored when the library's is the other, and named
/// for that leg ("kneel on one knee, on the left knee"); itself when it is no one-legged
/// posture of the whole body or the words name no leg.
pub fn on_leg(posture: &NamedPosture, words: &[&str]) -> NamedPosture {
    let legs = [BodyPart::LeftLeg, BodyPart::RightLeg];
    if !legs.iter().all(|l| posture.parts.contains(l)) {
        return posture.clone();
    }
    let (Some(own), Some((side, rests, noun))) = (free_leg(&posture.script), named_leg(words))
    else {
        return posture.clone();
    };
    let wanted = if rests { side.other() } else { side };
    let name = if rests {
        format!("{}, on the {} {noun}", posture.name, side.name())
    } else {
        format!("{} with the {} {noun}", posture.name, side.name())
    };
    let mut script = if own == wanted {
        posture.script.clone()
    } else {
        posture.script.mirrored()
    };
    script.name = Some(name.clone());
    NamedPosture {
        name,
        synonyms: Vec::new(),
        parts: posture.parts.clone(),
        script,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::posture::library::Library;

    fn named(name: &str) -> NamedPosture {
        Library::builtin()
            .get(name)
            .unwrap_or_else(|| panic!("{name} is in the library"))
            .clone()
    }

    fn words(text: &str) -> Vec<&str> {
        text.split(' ').collect()
    }

    #[test]
    fn the_library_side_is_read_from_the_constraints() {
        assert_eq!(
            free_leg(&named("kneel on one knee").script),
            Some(Side::Left)
        );
        assert_eq!(
            free_leg(&named("stand on one leg").script),
            Some(Side::Left)
        );
        assert_eq!(free_leg(&named("lunge").script), Some(Side::Left));
        assert_eq!(free_leg(&named("squat").script), None);
    }

    #[test]
    fn the_posture_goes_on_the_leg_the_words_name() {
        let kneel = named("kneel on one knee");
        // The library kneels on the right knee: "on the left knee" is its mirror.
        let left = on_leg(&kneel, &words("she kneels on the left knee"));
        assert_eq!(left.name, "kneel on one knee, on the left knee");
        assert_eq!(free_leg(&left.script), Some(Side::Right));
        let right = on_leg(&kneel, &words("he kneels on his right knee"));
        assert_eq!(free_leg(&right.script), Some(Side::Left));
        let lunge = on_leg(&named("lunge"), &words("lunges forward with the right leg"));
        assert_eq!(lunge.name, "lunge with the right leg");
        assert_eq!(free_leg(&lunge.script), Some(Side::Right));
        let lifted = on_leg(&named("stand on one leg"), &words("lifts the left knee"));
        assert_eq!(free_leg(&lifted.script), Some(Side::Left));
        // No leg named, or a posture of both legs alike: unchanged.
        assert_eq!(on_leg(&kneel, &words("kneels down")), kneel);
        let squat = named("squat");
        assert_eq!(on_leg(&squat, &words("squats on the left leg")), squat);
    }
}
