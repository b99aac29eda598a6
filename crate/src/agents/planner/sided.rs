//! Whole-body postures that use one leg unlike the other ("kneel on one knee", "stand on one
//! leg", "lunge"), put on the leg the words name: "kneels on **the left knee**", "lunges
//! forward **with the right leg**", "lifts **the right knee**". The library writes each such
//! posture for one side; which side is read from its own constraints (the knee on the ground,
//! the foot off it, the foot in front), and the posture is mirrored when the words ask for
//! the other. A hop "on the right foot" is the library's jump on that foot, the other lifted;
//! a step "with the left foot" is one step of that foot.

use crate::posecodes::{Bend, BodyPoint, Distance, PelvisLevel, Relation, Support};
use crate::posture::library::NamedPosture;
use crate::posture::script::{Constraint, Hinge, PostureScript};
use crate::posture::track::PostureTrack;
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

/// The indices of the words that name the leg ("on **the right foot**", "with **his left
/// leg**"): the side word through the noun; empty when no leg is named.
pub fn leg_words(words: &[&str]) -> std::ops::Range<usize> {
    let noun = words
        .iter()
        .position(|w| matches!(*w, "leg" | "foot" | "knee"));
    let side = noun.and_then(|n| {
        (n.saturating_sub(3)..n)
            .rev()
            .find(|&k| Side::of_word(words[k]).is_some())
    });
    match (side, noun) {
        (Some(s), Some(n)) => s..n + 1,
        _ => 0..0,
    }
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

/// The foot a clause hops on ("hops forward on the right foot", "hops on the left leg");
/// `None` unless it hops on one foot it names.
pub fn hopping_foot(words: &[&str]) -> Option<Side> {
    let hops = words
        .iter()
        .any(|w| matches!(*w, "hop" | "hops" | "hopping" | "hopped"));
    let (side, rests, _) = named_leg(words)?;
    (hops && rests).then_some(side)
}

/// A jump's key poses made on the `stands_on` foot: the other foot off the ground with its
/// knee bent throughout (take-off, flight, landing), each key named "hopping on the … foot".
pub fn on_one_foot(track: &mut PostureTrack, stands_on: Side) {
    let (free_foot, free_knee, free_point, stance_foot) = match stands_on {
        Side::Left => (
            Support::RightFoot,
            Hinge::RightKnee,
            BodyPoint::RightFoot,
            Support::LeftFoot,
        ),
        Side::Right => (
            Support::LeftFoot,
            Hinge::LeftKnee,
            BodyPoint::LeftFoot,
            Support::RightFoot,
        ),
    };
    let name = format!("hopping on the {} foot", stands_on.name());
    for key in &mut track.keys {
        // What the two-footed jump asked of the free leg (on the ground, feet apart) goes.
        key.script.constraints.retain(|c| match c {
            Constraint::Contact { point, .. } => *point != free_foot && *point != stance_foot,
            Constraint::Bend { joint, .. } => *joint != free_knee,
            Constraint::Distance { a, b, .. } => *a != free_point && *b != free_point,
            _ => true,
        });
        key.script.constraints.extend([
            Constraint::Contact {
                point: free_foot,
                on_ground: false,
            },
            Constraint::Contact {
                point: stance_foot,
                on_ground: true,
            },
            Constraint::Bend {
                joint: free_knee,
                is: Bend::PartiallyBent,
            },
        ]);
        key.script.name = Some(name.clone());
    }
}

/// How far one step carries the body, metres (about half an adult's stride).
const STEP_METRES: f64 = 0.35;

/// One step of the foot a clause names ("steps forward with the left foot", "steps back with
/// the right foot"), or one step to a side ("steps to the left", "sidesteps to the right",
/// "steps to the left with the left foot"): the body carried [`STEP_METRES`] that way and
/// standing again with both feet on the ground, the stepping foot ahead (or behind) after a
/// step forward or back. `None` unless the clause is such a step: forward or back with a foot
/// it names, or to one side.
pub fn single_step(words: &[&str]) -> Option<PostureTrack> {
    let sidestep = words
        .iter()
        .any(|w| matches!(*w, "sidestep" | "sidesteps" | "sidestepping"));
    let steps = sidestep
        || words
            .iter()
            .any(|w| matches!(*w, "step" | "steps" | "stepping"));
    let has = |list: &[&str]| words.iter().any(|w| list.contains(w));
    let forward = has(&["forward", "forwards", "ahead", "front"]);
    let back = has(&["back", "backward", "backwards", "behind"]);
    // "to the left", "to his right": the way, unless the side word names a limb.
    let way = words.iter().enumerate().find_map(|(i, w)| {
        let side = Side::of_word(w)?;
        let limb_follows = words
            .get(i + 1)
            .is_some_and(|n| matches!(*n, "leg" | "foot" | "knee" | "arm" | "hand"));
        let after_to = words[..i]
            .iter()
            .rev()
            .take(2)
            .any(|w| matches!(*w, "to" | "toward" | "towards"));
        (after_to && !limb_follows).then_some(side)
    });
    if let Some(way) = way.filter(|_| steps && !forward && !back) {
        if !sidestep && !words.iter().any(|w| matches!(*w, "step" | "steps")) {
            return None;
        }
        return side_step(way);
    }
    let (side, rests, _) = named_leg(words)?;
    if !steps || rests || forward == back {
        return None;
    }
    let (foot, way, sign) = match (side, forward) {
        (Side::Left, true) => (BodyPoint::LeftFoot, "forward", 1.0),
        (Side::Right, true) => (BodyPoint::RightFoot, "forward", 1.0),
        (Side::Left, false) => (BodyPoint::LeftFoot, "back", -1.0),
        (Side::Right, false) => (BodyPoint::RightFoot, "back", -1.0),
    };
    let name = format!("step {way} with the {} foot", side.name());
    let relation = if forward {
        Relation::InFrontOf
    } else {
        Relation::Behind
    };
    let mut constraints = standing_on_both_feet();
    constraints.push(Constraint::Relation {
        a: foot,
        b: BodyPoint::Pelvis,
        is: relation,
    });
    stepped(name, constraints, [0.0, sign * STEP_METRES])
}

/// One step to `way`: the body carried [`STEP_METRES`] to that side, standing on both feet.
fn side_step(way: Side) -> Option<PostureTrack> {
    let left = match way {
        Side::Left => STEP_METRES,
        Side::Right => -STEP_METRES,
    };
    let name = format!("side step to the {}", way.name());
    stepped(name, standing_on_both_feet(), [left, 0.0])
}

/// A standing pose with both feet on the ground, shoulder width apart.
fn standing_on_both_feet() -> Vec<Constraint> {
    vec![
        Constraint::Level {
            is: PelvisLevel::Standing,
        },
        Constraint::Contact {
            point: Support::LeftFoot,
            on_ground: true,
        },
        Constraint::Contact {
            point: Support::RightFoot,
            on_ground: true,
        },
        Constraint::Distance {
            a: BodyPoint::LeftFoot,
            b: BodyPoint::RightFoot,
            is: Distance::ShoulderWidth,
        },
    ]
}

/// A whole-body key pose named `name`, held half a second, reached by travelling `travel`
/// (`[left, forward]` metres).
fn stepped(name: String, constraints: Vec<Constraint>, travel: [f64; 2]) -> Option<PostureTrack> {
    let script = PostureScript {
        name: Some(name),
        hold: 0.5,
        constraints,
    }
    .check()
    .ok()?;
    let mut track = PostureTrack::holding(crate::skeleton::BodyPart::ALL.to_vec(), script);
    track.keys[0].travel = travel;
    Some(track)
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

    #[test]
    fn a_step_is_one_step_of_the_foot_named() {
        use crate::posture::solver::solve;
        let track = single_step(&words("steps forward with the left foot")).expect("a step");
        let key = &track.keys[0];
        assert_eq!(
            key.script.name.as_deref(),
            Some("step forward with the left foot")
        );
        assert_eq!(key.travel, [0.0, STEP_METRES]);
        assert!(solve(&key.script, None).unmet.is_empty());
        let back = single_step(&words("steps back with the right foot")).expect("a step");
        assert_eq!(back.keys[0].travel, [0.0, -STEP_METRES]);
        assert!(solve(&back.keys[0].script, None).unmet.is_empty());
        for text in [
            "steps forward",
            "steps on the left foot",
            "walks forward with the left foot",
        ] {
            assert!(single_step(&words(text)).is_none(), "{text}");
        }
    }

    #[test]
    fn a_hop_on_one_foot_lifts_the_other_and_the_solver_meets_it() {
        use crate::posture::solver::solve;
        assert_eq!(
            hopping_foot(&words("hops forward on the right foot")),
            Some(Side::Right)
        );
        assert_eq!(
            hopping_foot(&words("hops on his left leg")),
            Some(Side::Left)
        );
        assert_eq!(hopping_foot(&words("hops forward")), None);
        assert_eq!(leg_words(&words("hops forward on the right foot")), 4..6);
        assert_eq!(hopping_foot(&words("jumps on the left foot")), None);
        let jump = Library::builtin()
            .all()
            .find_map(|n| match n {
                crate::posture::library::Named::Action(a) if a.name == "jump" => Some(a),
                _ => None,
            })
            .expect("the library has a jump");
        let mut track = jump.track(None, [0.0, 1.0]);
        on_one_foot(&mut track, Side::Right);
        for key in &track.keys {
            assert_eq!(
                key.script.name.as_deref(),
                Some("hopping on the right foot")
            );
            assert_eq!(free_leg(&key.script), Some(Side::Left));
            let solved = solve(&key.script, None);
            assert!(solved.unmet.is_empty(), "{:?}", solved.unmet);
        }
    }
}
