//! A held pose of an arm or a leg read from the words that say where the limb is ("his right
//! arm upwards", "the left arm extended forward", "hands on the hips", "the right leg out
//! behind her", "stands on the left leg"): the limb and its side, then the way it points or
//! the body point it touches, written as pose-code constraints ([`PostureScript`]) that the
//! posture solver meets. This is PRO-Motion's key-posture script made by rules instead of an
//! LLM, for the phrases where a limb holds a place rather than moves; the built-in planner
//! holds the pose on the limb's track over the movement the clause rides on.
//!
//! Only a place is read, never a movement: a phrase with a movement word ("his right hand
//! swinging", "arms flapping", "tapping his right foot") is no pose, and a limb without a
//! side it can keep ("the arm up") is none either.

use crate::posecodes::Support;
use crate::posecodes::{Bend, BodyPoint, Distance, Limb, Orientation, PelvisLevel, Relation};
use crate::posture::library::{Library, Named, NamedPosture};
use crate::posture::script::{Constraint, Hinge, PostureScript};
use crate::skeleton::{BodyPart, Side};

/// Seconds a read pose is held once reached when the clause does not say (the clip's span
/// holds it anyway).
const HOLD_SECONDS: f64 = 1.0;

/// The relation "further out on this side".
fn outward(side: Side) -> Relation {
    match side {
        Side::Left => Relation::LeftOf,
        Side::Right => Relation::RightOf,
    }
}

/// Which limb a noun names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Arm,
    Leg,
}

/// The limb a noun names and whether it is plural ("hands": both).
fn limb_noun(word: &str) -> Option<(Kind, bool)> {
    Some(match word {
        "arm" | "hand" | "fist" | "palm" => (Kind::Arm, false),
        "arms" | "hands" | "fists" | "palms" => (Kind::Arm, true),
        "leg" | "foot" | "knee" => (Kind::Leg, false),
        "legs" | "feet" | "knees" => (Kind::Leg, true),
        _ => return None,
    })
}

/// Words that make the phrase a movement, not a place held.
const MOVING: &[&str] = &[
    "swing",
    "swings",
    "swinging",
    "wave",
    "waves",
    "waving",
    "flap",
    "flaps",
    "flapping",
    "shake",
    "shakes",
    "shaking",
    "circle",
    "circles",
    "circling",
    "clap",
    "claps",
    "clapping",
    "punch",
    "punches",
    "punching",
    "throw",
    "throws",
    "throwing",
    "dribble",
    "dribbles",
    "dribbling",
    "kick",
    "kicks",
    "kicking",
    "stomp",
    "stomps",
    "stomping",
    "pump",
    "pumps",
    "pumping",
    "wiggle",
    "wiggles",
    "wiggling",
    "bounce",
    "bounces",
    "bouncing",
    "flail",
    "flails",
    "flailing",
    "back and forth",
    "forth",
    "alternately",
    "alternating",
];

/// Verbs of a hand going to a body point and staying on it, or coming back to it ("touches
/// the right knee", "taps his head", "scratches his head", "wipes the forehead"): the hand's
/// place is the point they name; with none they are movements ("tapping his right foot").
pub(super) const TOUCHING: &[&str] = &[
    "touch",
    "touches",
    "touching",
    "tap",
    "taps",
    "tapping",
    "pat",
    "pats",
    "patting",
    "rub",
    "rubs",
    "rubbing",
    "scratch",
    "scratches",
    "scratching",
    "wipe",
    "wipes",
    "wiping",
];

/// Where a limb is, as the words say it.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Place {
    Up,
    Forward,
    Out,
    Down,
    Behind,
    UpForward,
    UpOut,
    /// Holding a thing in front of the body: the upper arm down, the forearm level, the hand
    /// in front of the hip ("holding a cup in his right hand", "carrying a tray").
    Holding,
    /// Touching a body point (the hand's own side where the point has sides and the words
    /// name none).
    On(Target),
}

/// A body point a hand rests on.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Target {
    Head,
    Neck,
    Chest,
    Belly,
    Hip(Option<Side>),
    /// A trouser pocket: the hip's pose, said as the words say it.
    Pocket(Option<Side>),
    Knee(Option<Side>),
    Shoulder(Option<Side>),
}

impl Target {
    fn of_word(word: &str) -> Option<Target> {
        Some(match word {
            "head" | "forehead" | "face" | "mouth" | "chin" | "cheek" | "cheeks" | "ear"
            | "ears" | "nose" | "eyes" | "temple" | "temples" => Target::Head,
            "neck" | "throat" => Target::Neck,
            "chest" | "heart" | "breast" => Target::Chest,
            "belly" | "stomach" | "tummy" | "abdomen" => Target::Belly,
            "hip" | "hips" | "waist" | "thigh" | "thighs" => Target::Hip(None),
            "pocket" | "pockets" => Target::Pocket(None),
            "knee" | "knees" => Target::Knee(None),
            "shoulder" | "shoulders" => Target::Shoulder(None),
            _ => return None,
        })
    }

    /// The same point on the side given; points of no side stay as they are.
    fn on_side(self, side: Option<Side>) -> Target {
        match self {
            Target::Hip(_) => Target::Hip(side),
            Target::Pocket(_) => Target::Pocket(side),
            Target::Knee(_) => Target::Knee(side),
            Target::Shoulder(_) => Target::Shoulder(side),
            other => other,
        }
    }

    /// The side of the body it is on, where it has one and the words said it.
    fn side(self) -> Option<Side> {
        match self {
            Target::Hip(s) | Target::Pocket(s) | Target::Knee(s) | Target::Shoulder(s) => s,
            _ => None,
        }
    }

    fn words(self) -> &'static str {
        match self {
            Target::Head => "the head",
            Target::Neck => "the neck",
            Target::Chest => "the chest",
            Target::Belly => "the belly",
            Target::Hip(_) => "the hip",
            Target::Pocket(_) => "the pocket",
            Target::Knee(_) => "the knee",
            Target::Shoulder(_) => "the shoulder",
        }
    }
}

/// The pose a limb phrase holds, as a posture of its limbs named in plain words ("right arm
/// up"); `None` when the words say no place, say a movement, or name no side.
pub(super) fn limb_pose(phrase: &[&str]) -> Option<NamedPosture> {
    let text = phrase.join(" ");
    if MOVING
        .iter()
        .any(|m| phrase.contains(m) || (m.contains(' ') && text.contains(m)))
    {
        return None;
    }
    // A touch that names no point is a movement of its own ("tapping his right foot").
    if has(phrase, TOUCHING) && target(phrase).is_none() && !has(phrase, &["knee", "knees"]) {
        return None;
    }
    if let Some(pose) = holding_pose(phrase) {
        return Some(pose);
    }
    // "both arms crossed over the chest": a posture of both arms the library names is that
    // posture, not a point the words name (the hands on the chest); a way the words say
    // ("arms out to the sides") is read as it is.
    let said_way = arm_place(phrase).is_some_and(|p| !matches!(p, Place::On(_)));
    let mentions = if said_way {
        Vec::new()
    } else {
        Library::builtin().mentions(&text)
    };
    if let Some(pose) = mentions.into_iter().find_map(|(_, named)| match named {
        Named::Posture(p) if is_arms_posture(p) => Some(p.clone()),
        _ => None,
    }) {
        return Some(pose);
    }
    let nouns: Vec<(usize, Kind, bool)> = phrase
        .iter()
        .enumerate()
        .filter_map(|(i, w)| limb_noun(w).map(|(k, p)| (i, k, p)))
        .collect();
    // "touches the right knee with the left hand": the knee is where the hand goes.
    // Standing "on the left leg" or "on the right foot" is the leg's own place.
    let touched = |i: usize| {
        let stood_on = matches!(phrase[i], "leg" | "legs" | "foot" | "feet");
        phrase[i.saturating_sub(3)..i]
            .iter()
            .any(|w| onto(w) && !(stood_on && *w == "on"))
    };
    let actors: Vec<&(usize, Kind, bool)> = nouns.iter().filter(|(i, ..)| !touched(*i)).collect();
    let &&(at, kind, plural) = actors.first()?;
    // The words about this limb end where the next limb's own words begin ("…, the right
    // arm tucked behind the back").
    let end = actors.get(1).map_or(phrase.len(), |(next, ..)| {
        (0..*next)
            .rev()
            .take_while(|&k| k > at && is_limb_determiner(phrase[k]))
            .last()
            .unwrap_or(*next)
    });
    let scope = &phrase[..end];
    let before = &scope[at.saturating_sub(3)..at];
    let sides: Vec<Side> = if before.contains(&"both") || plural {
        vec![Side::Left, Side::Right]
    } else {
        vec![before.iter().rev().find_map(|w| Side::of_word(w))?]
    };
    match kind {
        Kind::Arm => arm_pose(scope, &sides),
        Kind::Leg => leg_pose(scope, at, &sides),
    }
}

/// Whether a library posture holds both arms and nothing else ("arms crossed", "hands on
/// hips").
fn is_arms_posture(p: &NamedPosture) -> bool {
    p.parts.len() == 2
        && p.parts
            .iter()
            .all(|part| matches!(part, BodyPart::LeftArm | BodyPart::RightArm))
}

/// Verbs of a hand that holds a thing.
pub(super) const HOLDING: &[&str] = &[
    "holding",
    "holds",
    "carrying",
    "carries",
    "clutching",
    "clutches",
    "gripping",
    "grips",
];

/// The thing held, as the words name it ("a cup"); "something" when they name none, or
/// more than a short noun phrase.
fn thing_named(words: &[&str]) -> String {
    if words.is_empty() || words.len() > 4 {
        "something".to_string()
    } else {
        words.join(" ")
    }
}

/// A thing held to a point of the body on a side the words name, with no hand named
/// ("holding a phone to the right ear"): the hand of that side, on that point.
fn held_to_the_body(phrase: &[&str]) -> Option<NamedPosture> {
    if phrase.iter().any(|w| limb_noun(w).is_some()) {
        return None;
    }
    let verb = phrase.iter().position(|w| HOLDING.contains(w))?;
    let (k, w) = phrase.windows(4).enumerate().find(|(_, w)| {
        matches!(w[0], "to" | "against" | "at")
            && Side::of_word(w[2]).is_some()
            && Target::of_word(w[3]).is_some()
    })?;
    let side = Side::of_word(w[2])?;
    let target = Target::of_word(w[3])?.on_side(Some(side));
    let thing = thing_named(&phrase[verb + 1..k]);
    posture(
        format!("{} hand holding {thing} to the {}", side.name(), w[3]),
        vec![arm_part(side)],
        arm_constraints(side, Place::On(target)),
    )
}

/// The pose of a hand that holds a thing ("holding a cup in his right hand", "with a cane
/// in her right hand", "carrying a tray on the left hand"): the hand the thing is in or on,
/// held in front of the body. `None` when the phrase holds nothing in a hand it names.
fn holding_pose(phrase: &[&str]) -> Option<NamedPosture> {
    let holds = has(phrase, HOLDING) || matches!(phrase, ["with", "a" | "an", ..]);
    if !holds {
        return None;
    }
    if let Some(pose) = held_to_the_body(phrase) {
        return Some(pose);
    }
    // One limb only: "carrying a tray on the left hand, the right arm tucked behind the
    // back" says the right arm's place.
    if phrase.iter().filter(|w| limb_noun(w).is_some()).count() != 1 {
        return None;
    }
    let at = phrase.iter().position(|w| matches!(*w, "hand" | "hands"))?;
    let before = &phrase[at.saturating_sub(4)..at];
    if !before.iter().any(|w| matches!(*w, "in" | "on")) {
        return None;
    }
    let sides = if phrase[at] == "hands" || before.contains(&"both") {
        vec![Side::Left, Side::Right]
    } else {
        vec![before.iter().rev().find_map(|w| Side::of_word(w))?]
    };
    let constraints = sides
        .iter()
        .flat_map(|s| arm_constraints(*s, Place::Holding))
        .collect();
    let hands = match sides.as_slice() {
        [one] => format!("{} hand", one.name()),
        _ => "both hands".to_string(),
    };
    // The thing held, as the words name it ("a cup", "a cane"), up to where the hand is.
    let verb = phrase
        .iter()
        .position(|w| HOLDING.contains(w) || *w == "with")
        .filter(|v| *v < at)?;
    let until = (verb + 1..at)
        .find(|&k| matches!(phrase[k], "in" | "on"))
        .unwrap_or(at);
    let thing = thing_named(&phrase[verb + 1..until]);
    let parts = sides.iter().map(|s| arm_part(*s)).collect();
    posture(format!("{hands} holding {thing}"), parts, constraints)
}

/// Words that open a limb's own words ("the right arm", "his left hand").
fn is_limb_determiner(word: &str) -> bool {
    matches!(
        word,
        "the" | "his" | "her" | "their" | "its" | "a" | "one" | "left" | "right" | "both" | "other"
    )
}

/// Words after which a body point is what a hand touches, not what moves.
const ONTO: &[&str] = &[
    "on", "onto", "to", "at", "against", "over", "near", "covering", "covers", "behind", "in",
    "presses", "pressing",
];

/// Whether a body point after `word` is what a hand touches: after a word of [`ONTO`] or a
/// touching verb ("taps **his head**").
fn onto(word: &str) -> bool {
    ONTO.contains(&word) || TOUCHING.contains(&word)
}

/// Whether any of `words` is in the phrase.
fn has(phrase: &[&str], words: &[&str]) -> bool {
    phrase.iter().any(|w| words.contains(w))
}

/// "by his side", "at her sides": hanging down, not out to the side.
fn at_the_side(phrase: &[&str]) -> bool {
    phrase.windows(3).any(|w| {
        matches!(w[0], "by" | "at" | "to")
            && matches!(w[1], "his" | "her" | "their" | "the" | "its")
            && matches!(w[2], "side" | "sides")
            && w[0] != "to"
    }) || phrase
        .windows(2)
        .any(|w| matches!(w[0], "by" | "at") && matches!(w[1], "side" | "sides"))
}

/// The body point a hand rests on ("on the hips", "to the right ear", "over his heart"), with
/// the side the words give it.
fn target(phrase: &[&str]) -> Option<Target> {
    let at = (0..phrase.len()).find(|&i| {
        onto(phrase[i])
            && phrase[i + 1..phrase.len().min(i + 5)]
                .iter()
                .any(|w| Target::of_word(w).is_some())
    })?;
    let rest = &phrase[at + 1..phrase.len().min(at + 5)];
    let (k, found) = rest
        .iter()
        .enumerate()
        .find_map(|(k, w)| Target::of_word(w).map(|t| (k, t)))?;
    let side = rest[..k].iter().rev().find_map(|w| Side::of_word(w));
    Some(found.on_side(side))
}

/// Where the words put an arm.
fn arm_place(phrase: &[&str]) -> Option<Place> {
    if let Some(t) = target(phrase) {
        return Some(Place::On(t));
    }
    // "behind the back", and a hand "on his back" (its own back: behind the body).
    if phrase
        .windows(2)
        .any(|w| w[0] == "behind" && matches!(w[1], "the" | "his" | "her" | "their"))
        && has(phrase, &["back"])
        || phrase.windows(3).any(|w| {
            w[0] == "on" && matches!(w[1], "the" | "his" | "her" | "their") && w[2] == "back"
        })
    {
        return Some(Place::Behind);
    }
    let up = has(
        phrase,
        &[
            "up", "upward", "upwards", "overhead", "raised", "high", "aloft", "skyward",
            "skywards", "above", "air", "sky", "ceiling", "lifted",
        ],
    );
    let forward = has(
        phrase,
        &[
            "forward", "forwards", "ahead", "front", "pointing", "points", "point",
        ],
    );
    let out = !at_the_side(phrase)
        && has(
            phrase,
            &[
                "side",
                "sides",
                "sideways",
                "outward",
                "outwards",
                "wide",
                "apart",
                "spread",
                "spreads",
                "spreading",
                "open",
            ],
        );
    let down = at_the_side(phrase)
        || has(
            phrase,
            &[
                "down",
                "downward",
                "downwards",
                "lowered",
                "hanging",
                "dangling",
                "relaxed",
            ],
        );
    let behind = has(phrase, &["behind", "backward", "backwards"]);
    let stretched = has(
        phrase,
        &[
            "extended",
            "outstretched",
            "stretched",
            "stretching",
            "stretches",
            "straight",
            "out",
        ],
    );
    Some(match (up, forward, out, down, behind) {
        (true, true, _, false, _) => Place::UpForward,
        (true, false, true, false, _) => Place::UpOut,
        (true, false, false, false, _) => Place::Up,
        (false, true, _, false, _) => Place::Forward,
        (false, false, true, false, _) => Place::Out,
        (false, false, false, true, _) => Place::Down,
        (false, false, false, false, true) => Place::Behind,
        // "the left arm extended": straight out in front ("arms outstretched" go to the
        // sides: see `arm_pose`).
        (false, false, false, false, false) if stretched => Place::Forward,
        _ => return None,
    })
}

/// The pose of one or both arms.
fn arm_pose(phrase: &[&str], sides: &[Side]) -> Option<NamedPosture> {
    let mut place = arm_place(phrase)?;
    let both = sides.len() == 2;
    // Both arms stretched with no way named spread to the sides ("arms outstretched").
    if both
        && place == Place::Forward
        && !has(
            phrase,
            &[
                "forward", "forwards", "ahead", "front", "pointing", "points", "point",
            ],
        )
    {
        place = Place::Out;
    }
    let mut constraints = Vec::new();
    for &side in sides {
        constraints.extend(arm_constraints(side, place));
    }
    if both {
        match place {
            Place::Out | Place::UpOut => constraints.push(Constraint::Distance {
                a: BodyPoint::LeftHand,
                b: BodyPoint::RightHand,
                is: Distance::Wide,
            }),
            Place::Forward => constraints.push(Constraint::Distance {
                a: BodyPoint::LeftHand,
                b: BodyPoint::RightHand,
                is: Distance::ShoulderWidth,
            }),
            _ => {}
        }
    }
    let who = match sides {
        [one] => format!("{} arm", one.name()),
        _ => "both arms".to_string(),
    };
    let hands = match sides {
        [one] => format!("{} hand", one.name()),
        _ => "hands".to_string(),
    };
    let name = match place {
        Place::Up => format!("{who} up"),
        Place::Forward => format!("{who} straight forward"),
        Place::Out => format!("{who} out to the side{}", if both { "s" } else { "" }),
        Place::Down => format!("{who} down"),
        Place::Behind => format!("{hands} behind the back"),
        Place::UpForward => format!("{who} up and forward"),
        Place::UpOut => format!(
            "{who} up and out to the side{}",
            if both { "s" } else { "" }
        ),
        Place::Holding => format!("{hands} holding something"),
        Place::On(t) => {
            let on = match t.side() {
                Some(s) => t.words().replace("the ", &format!("the {} ", s.name())),
                _ if both => format!("{}s", t.words())
                    .replace("the heads", "the head")
                    .replace("the necks", "the neck")
                    .replace("the chests", "the chest")
                    .replace("the bellys", "the belly"),
                _ => t.words().to_string(),
            };
            let at = if matches!(t, Target::Pocket(_)) {
                "in"
            } else {
                "on"
            };
            format!("{hands} {at} {on}")
        }
    };
    let parts = sides.iter().map(|s| arm_part(*s)).collect();
    posture(name, parts, constraints)
}

fn arm_part(side: Side) -> BodyPart {
    match side {
        Side::Left => BodyPart::LeftArm,
        Side::Right => BodyPart::RightArm,
    }
}

fn leg_part(side: Side) -> BodyPart {
    match side {
        Side::Left => BodyPart::LeftLeg,
        Side::Right => BodyPart::RightLeg,
    }
}

/// The constraints that put one arm in `place`.
fn arm_constraints(side: Side, place: Place) -> Vec<Constraint> {
    let (hand, shoulder, elbow, upper, fore, hip, knee, elbow_point) = match side {
        Side::Left => (
            BodyPoint::LeftHand,
            BodyPoint::LeftShoulder,
            Hinge::LeftElbow,
            Limb::LeftUpperArm,
            Limb::LeftForearm,
            BodyPoint::LeftHip,
            BodyPoint::LeftKnee,
            BodyPoint::LeftElbow,
        ),
        Side::Right => (
            BodyPoint::RightHand,
            BodyPoint::RightShoulder,
            Hinge::RightElbow,
            Limb::RightUpperArm,
            Limb::RightForearm,
            BodyPoint::RightHip,
            BodyPoint::RightKnee,
            BodyPoint::RightElbow,
        ),
    };
    let bend = |is| Constraint::Bend { joint: elbow, is };
    let orient = |limb, is| Constraint::Orientation { limb, is };
    let rel = |a, b, is| Constraint::Relation { a, b, is };
    let close = |b| Constraint::Distance {
        a: hand,
        b,
        is: Distance::Close,
    };
    match place {
        Place::Up => vec![
            bend(Bend::Straight),
            orient(upper, Orientation::Vertical),
            rel(hand, BodyPoint::Head, Relation::Above),
        ],
        Place::Forward => vec![
            bend(Bend::Straight),
            orient(upper, Orientation::Horizontal),
            orient(fore, Orientation::Horizontal),
            rel(hand, shoulder, Relation::InFrontOf),
            rel(hand, shoulder, Relation::LevelWith),
        ],
        Place::Out => vec![
            bend(Bend::Straight),
            orient(upper, Orientation::Horizontal),
            orient(fore, Orientation::Horizontal),
            rel(hand, shoulder, Relation::LevelWith),
            rel(hand, shoulder, outward(side)),
        ],
        Place::Down => vec![
            bend(Bend::Straight),
            orient(upper, Orientation::Vertical),
            rel(hand, shoulder, Relation::Below),
        ],
        Place::Behind => vec![
            bend(Bend::SlightlyBent),
            rel(hand, BodyPoint::Pelvis, Relation::Behind),
        ],
        Place::UpForward => vec![
            bend(Bend::Straight),
            orient(upper, Orientation::Diagonal),
            rel(hand, shoulder, Relation::Above),
            rel(hand, shoulder, Relation::InFrontOf),
        ],
        Place::UpOut => vec![
            bend(Bend::Straight),
            rel(elbow_point, shoulder, Relation::Above),
            rel(hand, BodyPoint::Head, Relation::Above),
            rel(hand, shoulder, outward(side)),
        ],
        Place::Holding => vec![
            bend(Bend::PartiallyBent),
            orient(upper, Orientation::Vertical),
            orient(fore, Orientation::Horizontal),
            rel(hand, hip, Relation::InFrontOf),
        ],
        Place::On(t) => {
            let point = |s: Option<Side>, left, right, own| match s {
                Some(Side::Left) => left,
                Some(Side::Right) => right,
                None => own,
            };
            match t {
                Target::Head => vec![close(BodyPoint::Head), bend(Bend::CompletelyBent)],
                Target::Neck => vec![close(BodyPoint::Neck), bend(Bend::CompletelyBent)],
                Target::Chest => vec![close(BodyPoint::Chest), bend(Bend::CompletelyBent)],
                Target::Belly => vec![
                    rel(hand, BodyPoint::Pelvis, Relation::InFrontOf),
                    rel(hand, BodyPoint::Chest, Relation::Below),
                    bend(Bend::PartiallyBent),
                ],
                Target::Hip(s) | Target::Pocket(s) => vec![
                    close(point(s, BodyPoint::LeftHip, BodyPoint::RightHip, hip)),
                    bend(Bend::PartiallyBent),
                ],
                Target::Knee(s) => vec![close(point(
                    s,
                    BodyPoint::LeftKnee,
                    BodyPoint::RightKnee,
                    knee,
                ))],
                Target::Shoulder(s) => vec![
                    close(point(
                        s,
                        BodyPoint::LeftShoulder,
                        BodyPoint::RightShoulder,
                        shoulder,
                    )),
                    bend(Bend::CompletelyBent),
                ],
            }
        }
    }
}

/// The pose of a leg (or the stance on one), with the body standing.
fn leg_pose(phrase: &[&str], at: usize, sides: &[Side]) -> Option<NamedPosture> {
    let [side] = sides else {
        return None;
    };
    let side = *side;
    let (foot, other_foot, knee_hinge, thigh, hip) = match side {
        Side::Left => (
            Support::LeftFoot,
            Support::RightFoot,
            Hinge::LeftKnee,
            Limb::LeftThigh,
            BodyPoint::LeftHip,
        ),
        Side::Right => (
            Support::RightFoot,
            Support::LeftFoot,
            Hinge::RightKnee,
            Limb::RightThigh,
            BodyPoint::RightHip,
        ),
    };
    let foot_point = match side {
        Side::Left => BodyPoint::LeftFoot,
        Side::Right => BodyPoint::RightFoot,
    };
    let standing = Constraint::Level {
        is: PelvisLevel::Standing,
    };
    let off = Constraint::Contact {
        point: foot,
        on_ground: false,
    };
    let bend = |is| Constraint::Bend {
        joint: knee_hinge,
        is,
    };
    let rel = |a, b, is| Constraint::Relation { a, b, is };
    // "stands on the left leg", "balances on her right foot": the other leg is lifted.
    let on = phrase[at.saturating_sub(3)..at].contains(&"on");
    if on
        && has(
            phrase,
            &[
                "stands",
                "stand",
                "standing",
                "balances",
                "balance",
                "balancing",
            ],
        )
    {
        let other_knee = match side.other() {
            Side::Left => Hinge::LeftKnee,
            Side::Right => Hinge::RightKnee,
        };
        return posture(
            format!("standing on the {} leg", side.name()),
            vec![BodyPart::LeftLeg, BodyPart::RightLeg],
            vec![
                standing,
                Constraint::Contact {
                    point: foot,
                    on_ground: true,
                },
                Constraint::Contact {
                    point: other_foot,
                    on_ground: false,
                },
                bend(Bend::Straight),
                Constraint::Bend {
                    joint: other_knee,
                    is: Bend::PartiallyBent,
                },
            ],
        );
    }
    let noun = phrase[at];
    let behind = has(phrase, &["behind", "back", "backward", "backwards"]);
    let forward = has(phrase, &["forward", "forwards", "front", "ahead"]);
    let out = has(phrase, &["side", "sideways", "outward", "outwards"]);
    let up = has(
        phrase,
        &[
            "up", "raised", "raises", "raise", "lifts", "lifted", "lift", "high", "air", "off",
        ],
    );
    // A straight leg lifted off the floor toward `from`'s `way`.
    let straight = |from: BodyPoint, way: Relation| {
        vec![
            off,
            bend(Bend::Straight),
            rel(foot_point, from, way),
            Constraint::Orientation {
                limb: thigh,
                is: Orientation::Diagonal,
            },
        ]
    };
    let (what, constraints) = if behind {
        (
            "lifted out behind",
            straight(BodyPoint::Pelvis, Relation::Behind),
        )
    } else if out {
        ("lifted out to the side", straight(hip, outward(side)))
    } else if forward {
        (
            "lifted straight forward",
            straight(BodyPoint::Pelvis, Relation::InFrontOf),
        )
    } else if up || noun == "knee" {
        (
            "lifted, knee up",
            vec![
                off,
                bend(Bend::CompletelyBent),
                Constraint::Orientation {
                    limb: thigh,
                    is: Orientation::Horizontal,
                },
            ],
        )
    } else {
        return None;
    };
    let mut all = vec![
        standing,
        Constraint::Contact {
            point: other_foot,
            on_ground: true,
        },
    ];
    all.extend(constraints);
    posture(
        format!("{} leg {what}", side.name()),
        vec![leg_part(side)],
        all,
    )
}

/// A named posture of `parts`, if its constraints make a script.
fn posture(
    name: String,
    parts: Vec<BodyPart>,
    constraints: Vec<Constraint>,
) -> Option<NamedPosture> {
    let script = PostureScript {
        name: Some(name.clone()),
        hold: HOLD_SECONDS,
        constraints,
    }
    .check()
    .ok()?;
    Some(NamedPosture {
        name,
        synonyms: Vec::new(),
        parts,
        script,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Option<(String, Vec<BodyPart>)> {
        let words: Vec<&str> = text.split(' ').collect();
        limb_pose(&words).map(|p| (p.name, p.parts))
    }

    #[test]
    fn a_limb_phrase_holds_the_place_its_words_say_on_its_own_side() {
        assert_eq!(
            read("having his right arm upwards"),
            Some(("right arm up".into(), vec![BodyPart::RightArm]))
        );
        assert_eq!(
            read("the left arm extended forward"),
            Some(("left arm straight forward".into(), vec![BodyPart::LeftArm]))
        );
        assert_eq!(
            read("with both arms stretched out to the sides").map(|p| p.0),
            Some("both arms out to the sides".into())
        );
        assert_eq!(
            read("arms outstretched").map(|p| p.0),
            Some("both arms out to the sides".into())
        );
        assert_eq!(
            read("keeping the right hand on the hip").map(|p| p.0),
            Some("right hand on the hip".into())
        );
        assert_eq!(
            read("the right hand on the left knee").map(|p| p.0),
            Some("right hand on the left knee".into())
        );
        assert_eq!(
            read("holding a phone to the right ear"),
            Some((
                "right hand holding a phone to the ear".into(),
                vec![BodyPart::RightArm]
            )),
            "the ear's side is the hand's"
        );
        assert_eq!(
            read("stretching the right leg out behind her"),
            Some((
                "right leg lifted out behind".into(),
                vec![BodyPart::RightLeg]
            ))
        );
        assert_eq!(
            read("touches the right knee with the left hand").map(|p| p.0),
            Some("left hand on the right knee".into())
        );
        assert_eq!(
            read("carrying a tray on the left hand the right arm tucked behind the back")
                .map(|p| p.0),
            Some("right hand behind the back".into()),
            "the hand under the tray is no place of the right arm's"
        );
        for (text, name) in [
            (
                "holding a cup in his right hand",
                "right hand holding a cup",
            ),
            ("with a cane in her right hand", "right hand holding a cane"),
            (
                "carrying a tray on the right hand",
                "right hand holding a tray",
            ),
        ] {
            assert_eq!(
                read(text),
                Some((name.into(), vec![BodyPart::RightArm])),
                "{text}"
            );
        }
        assert_eq!(
            read("taps his head with his left hand").map(|p| p.0),
            Some("left hand on the head".into())
        );
        assert_eq!(read("tapping his right foot"), None);
        assert_eq!(
            read("with his right hand on his back").map(|p| p.0),
            Some("right hand behind the back".into())
        );
        assert_eq!(
            read("stands on the left leg").map(|p| p.0),
            Some("standing on the left leg".into())
        );
        assert_eq!(
            read("lifts the left knee").map(|p| p.0),
            Some("left leg lifted, knee up".into())
        );
    }

    #[test]
    fn a_movement_or_a_limb_without_a_side_is_no_pose() {
        assert_eq!(read("his right hand swinging"), None);
        assert_eq!(read("arms flapping like wings"), None);
        assert_eq!(read("tapping his right foot"), None);
        assert_eq!(read("the arm up"), None);
        assert_eq!(read("with the right hand"), None);
    }

    #[test]
    fn every_pose_read_is_one_the_solver_meets() {
        use crate::posture::solver::solve;
        for text in [
            "his right arm upwards",
            "the left arm extended forward",
            "both arms stretched out to the sides",
            "left arm down by his side",
            "right arm raised forward",
            "both arms up and spread wide",
            "hands on the hips",
            "the right hand on the head",
            "left hand on the chest",
            "both hands behind the back",
            "the right leg out behind her",
            "lifts the left knee",
            "the left leg out to the side",
            "stands on the right leg",
            "holding a cup in his right hand",
            "carrying a box in both hands",
            "holding a phone to the right ear",
        ] {
            let words: Vec<&str> = text.split(' ').collect();
            let pose = limb_pose(&words).unwrap_or_else(|| panic!("{text}: no pose"));
            let solved = solve(&pose.script, None);
            assert!(
                solved.unmet.is_empty(),
                "{text} ({}): {:?}",
                pose.name,
                solved.unmet
            );
        }
    }
}
