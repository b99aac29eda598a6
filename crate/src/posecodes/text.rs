//! Sentences from motion descriptors.

use super::frame::floor_height;
use super::motion::{
    describe_window_with_floor, ArmHeight, ArmMotion, LegDirection, LegMotion, Level,
    MotionDescriptor, Pace, Reach, Torso, Travel,
};
use crate::skeleton::{BodyPart, Pose};
use std::ops::Range;

/// Long motions are described in windows of about this many frames (2 s at 20 fps); a motion
/// up to one and a half windows long is described as a whole.
pub const WINDOW_FRAMES: usize = 40;
/// A facing change smaller than this (degrees) is not mentioned.
pub const TURN_MIN_DEG: f64 = 30.0;

/// At most this many successive phrases per body part, so a caption stays one short sentence.
const MAX_PART_PHRASES: usize = 3;
/// At most this many successive phrases for the whole body.
const MAX_BODY_PHRASES: usize = 4;
/// A knee bent below this (degrees) during a bow counts as bending with it.
const BENT_KNEE_DEG: f64 = 150.0;
/// A foot on the ground for less than this fraction of a window is held up.
const HELD_UP_FRACTION: f64 = 0.3;
/// A foot that is down for less than this fraction of a window has stepped.
const STEPPED_FRACTION: f64 = 0.9;

/// One short sentence per body part, in [`BodyPart::ALL`] order, for poses at 20 fps
/// (e.g. "the left arm is raised above the head and waves", "the right leg stands still").
/// Motions longer than 3 s are read in windows of about 2 s and the part's successive actions
/// are joined with "then" (at most three, none repeated). Each sentence names only its own
/// part, so mirroring a motion swaps the left and right sentences.
pub fn part_sentences(poses: &[Pose]) -> [(BodyPart, String); 4] {
    let windows = analyse(poses);
    BodyPart::ALL.map(|part| {
        let phrases = part_phrases(part, &windows);
        let text = format!("the {} {}", part.name(), join_phrases(&phrases, false));
        (part, text)
    })
}

/// A whole-body description of poses at 20 fps for a reviewer: first the global movement
/// ("A person walks forward slowly, turning left by about 90 degrees."), read in windows of
/// about 2 s for motions longer than 3 s, then a sentence for each body part doing something
/// notable (a raised or waving arm, a kick, a kneel), with "both arms"/"both legs" when the
/// two sides do the same.
pub fn describe_motion(poses: &[Pose]) -> String {
    let windows = analyse(poses);
    let floor = floor_height(poses);

    // Consecutive windows doing the same thing form one segment, re-measured as a whole so a
    // turn spread over several windows is reported once with its full angle.
    let mut segments: Vec<(BodyAction, Range<usize>)> = Vec::new();
    for (range, d) in &windows {
        let action = BodyAction::of(d);
        match segments.last_mut() {
            Some((last, r)) if last.continues_as(action) => r.end = range.end,
            _ => segments.push((action, range.clone())),
        }
    }
    let phrases: Vec<String> = segments
        .into_iter()
        .map(|(action, range)| action.phrase(&describe_window_with_floor(&poses[range], floor)))
        .collect();
    let phrases = distinct(phrases, MAX_BODY_PHRASES);
    let mut out = format!("A person {}.", phrases.join(", then "));

    let lists = BodyPart::ALL.map(|part| part_phrases(part, &windows));
    for (left, right, limb) in [(0, 1, "arms"), (2, 3, "legs")] {
        let notable = |i: usize| lists[i].iter().any(|a| a.notable());
        if notable(left) && lists[left] == lists[right] {
            out.push_str(&format!(
                " Both {limb} {}.",
                join_phrases(&lists[left], true)
            ));
            continue;
        }
        for i in [left, right] {
            if notable(i) {
                let name = BodyPart::ALL[i].name();
                out.push_str(&format!(" The {name} {}.", join_phrases(&lists[i], false)));
            }
        }
    }
    out
}

/// Window ranges of a motion of `n` frames. Neighbouring windows share their boundary frame so
/// that turning and travel between windows are not lost.
fn windows(n: usize) -> Vec<Range<usize>> {
    if n < 2 {
        return std::iter::once(0..n).collect();
    }
    let steps = n - 1;
    let count = ((steps as f64 / WINDOW_FRAMES as f64).round() as usize).max(1);
    (0..count)
        .map(|k| (k * steps / count)..((k + 1) * steps / count + 1))
        .collect()
}

fn analyse(poses: &[Pose]) -> Vec<(Range<usize>, MotionDescriptor)> {
    let floor = floor_height(poses);
    windows(poses.len())
        .into_iter()
        .map(|r| {
            let d = describe_window_with_floor(&poses[r.clone()], floor);
            (r, d)
        })
        .collect()
}

fn part_phrases(part: BodyPart, windows: &[(Range<usize>, MotionDescriptor)]) -> Vec<PartAction> {
    let actions = windows
        .iter()
        .map(|(_, d)| match part {
            BodyPart::LeftArm => PartAction::Arm(ArmAction::of(&d.left_arm)),
            BodyPart::RightArm => PartAction::Arm(ArmAction::of(&d.right_arm)),
            BodyPart::LeftLeg => PartAction::Leg(LegAction::of(d, &d.left_leg)),
            BodyPart::RightLeg => PartAction::Leg(LegAction::of(d, &d.right_leg)),
        })
        .collect();
    distinct(merge_travel(actions), MAX_PART_PHRASES)
}

/// Consecutive windows travelling the same way become one phrase at the faster pace: a window
/// boundary in the middle of speeding up should not read as two separate walks.
fn merge_travel(actions: Vec<PartAction>) -> Vec<PartAction> {
    let mut out: Vec<PartAction> = Vec::new();
    for action in actions {
        if let (
            Some(PartAction::Leg(LegAction::Travels(prev_pace, prev_dir))),
            PartAction::Leg(LegAction::Travels(pace, dir)),
        ) = (out.last_mut(), action)
        {
            if *prev_dir == dir {
                *prev_pace = (*prev_pace).max(pace);
                continue;
            }
        }
        out.push(action);
    }
    out
}

/// The items in order with repeats dropped (saying a thing once is enough for a caption),
/// at most `max` of them.
fn distinct<T: PartialEq>(items: Vec<T>, max: usize) -> Vec<T> {
    let mut out: Vec<T> = Vec::new();
    for item in items {
        if out.len() < max && !out.contains(&item) {
            out.push(item);
        }
    }
    out
}

fn join_phrases(actions: &[PartAction], plural: bool) -> String {
    let phrases: Vec<String> = actions.iter().map(|a| a.phrase(plural)).collect();
    phrases.join(", then ")
}

/// A verb in the third person singular, or plural for "both arms".
fn verb(base: &str, plural: bool) -> String {
    if plural {
        base.to_string()
    } else {
        format!("{base}s")
    }
}

/// "walks forward slowly", "steps to the left", "run backward".
fn locomotion(pace: Pace, travel: Travel, plural: bool) -> String {
    let base = match (pace, travel) {
        (Pace::Running, _) => "run",
        (_, Travel::Forward | Travel::Backward) => "walk",
        (_, Travel::Left | Travel::Right) => "step",
    };
    let v = verb(base, plural);
    let dir = travel.as_str();
    match (pace, travel) {
        (Pace::Slow, Travel::Left | Travel::Right) => format!("{v} slowly {dir}"),
        (Pace::Slow, _) => format!("{v} {dir} slowly"),
        _ => format!("{v} {dir}"),
    }
}

/// "left by about 90 degrees": the angle rounded to 15° so small measurement differences do not
/// change the words.
fn turn_words(deg: f64) -> String {
    let side = if deg > 0.0 { "left" } else { "right" };
    let about = ((deg.abs() / 15.0).round() * 15.0).max(15.0);
    format!("{side} by about {about:.0} degrees")
}

/// What one arm does in a window.
#[derive(Clone, Copy, Debug, PartialEq)]
enum ArmAction {
    Waves { above_head: bool },
    RaisedAboveHead,
    NearHead,
    ReachesForward,
    StretchedSideways,
    RaisedToShoulder,
    AcrossBody,
    Swings,
    MovesInFront,
    Moves,
    HeldInFront,
    Hangs,
}

impl ArmAction {
    fn of(m: &ArmMotion) -> ArmAction {
        if m.waves {
            return ArmAction::Waves {
                above_head: m.height == ArmHeight::AboveHead,
            };
        }
        match m.height {
            ArmHeight::AboveHead => return ArmAction::RaisedAboveHead,
            _ if m.near_head => return ArmAction::NearHead,
            ArmHeight::ShoulderHeight => {
                return match m.reach {
                    Some(Reach::Forward) => ArmAction::ReachesForward,
                    Some(Reach::Sideways) => ArmAction::StretchedSideways,
                    None => ArmAction::RaisedToShoulder,
                }
            }
            ArmHeight::Low => {}
        }
        let in_front = m.in_front_fraction > 0.5;
        if m.crosses_midline {
            ArmAction::AcrossBody
        } else if m.swings {
            ArmAction::Swings
        } else if m.activity_mps >= super::motion::ACTIVE_MIN_MPS {
            if in_front {
                ArmAction::MovesInFront
            } else {
                ArmAction::Moves
            }
        } else if in_front && m.min_elbow_deg < super::frame::SLIGHTLY_BENT_MIN_DEG {
            ArmAction::HeldInFront
        } else {
            ArmAction::Hangs
        }
    }

    fn phrase(self, plural: bool) -> String {
        let (is, s, es) = if plural {
            ("are", "", "")
        } else {
            ("is", "s", "es")
        };
        match self {
            ArmAction::Waves { above_head: true } => {
                format!("{is} raised above the head and wave{s}")
            }
            ArmAction::Waves { above_head: false } => format!("{is} raised and wave{s}"),
            ArmAction::RaisedAboveHead => format!("{is} raised above the head"),
            ArmAction::NearHead => format!("{is} brought up to the head"),
            ArmAction::ReachesForward => format!("reach{es} forward at shoulder height"),
            ArmAction::StretchedSideways => {
                let sides = if plural { "sides" } else { "side" };
                format!("{is} stretched out to the {sides}")
            }
            ArmAction::RaisedToShoulder => format!("{is} raised to shoulder height"),
            ArmAction::AcrossBody => {
                format!("reach{es} across the body")
            }
            ArmAction::Swings => format!("{} back and forth", verb("swing", plural)),
            ArmAction::MovesInFront => format!("{} in front of the body", verb("move", plural)),
            ArmAction::Moves => {
                let sides = if plural { "sides" } else { "side" };
                format!("{} at the {sides}", verb("move", plural))
            }
            ArmAction::HeldInFront => format!("{is} held bent in front of the body"),
            ArmAction::Hangs => {
                let sides = if plural { "sides" } else { "side" };
                format!("{} at the {sides}", verb("hang", plural))
            }
        }
    }
}

/// What one leg does in a window.
#[derive(Clone, Copy, Debug, PartialEq)]
enum LegAction {
    Jumps { repeated: bool },
    Travels(Pace, Travel),
    Kneels,
    Kicks(LegDirection),
    Lifted(LegDirection),
    LiftsKnee,
    Level(Level, bool),
    Bows { bent: bool },
    Turns { left: bool, steps: bool },
    HeldUp,
    StepsInPlace,
    Stands,
}

impl LegAction {
    fn of(d: &MotionDescriptor, m: &LegMotion) -> LegAction {
        let bent = m.min_knee_deg < BENT_KNEE_DEG;
        // An empty window has no contacts to read; say nothing happens rather than "held up".
        if d.frames == 0 {
            LegAction::Stands
        } else if d.jumps > 0 {
            LegAction::Jumps {
                repeated: d.jumps > 1,
            }
        } else if d.pace >= Pace::Walking {
            LegAction::Travels(d.pace, d.travel.unwrap_or(Travel::Forward))
        } else if m.kneels {
            LegAction::Kneels
        } else if let Some(dir) = m.lift {
            if m.kicks {
                LegAction::Kicks(dir)
            } else {
                LegAction::Lifted(dir)
            }
        } else if m.knee_lift {
            LegAction::LiftsKnee
        } else if d.level != Level::Steady {
            LegAction::Level(d.level, bent)
        } else if d.torso == Torso::Bows {
            LegAction::Bows { bent }
        } else if d.pace == Pace::Slow {
            LegAction::Travels(d.pace, d.travel.unwrap_or(Travel::Forward))
        } else if d.turn_deg.abs() >= TURN_MIN_DEG {
            LegAction::Turns {
                left: d.turn_deg > 0.0,
                steps: m.ground_fraction < STEPPED_FRACTION,
            }
        } else if m.ground_fraction < HELD_UP_FRACTION {
            LegAction::HeldUp
        } else if m.ground_fraction < STEPPED_FRACTION && m.activity_mps >= 0.2 {
            LegAction::StepsInPlace
        } else {
            LegAction::Stands
        }
    }

    fn phrase(self, plural: bool) -> String {
        let is = if plural { "are" } else { "is" };
        match self {
            LegAction::Jumps { repeated } => {
                let how = if repeated { " again and again" } else { "" };
                format!("{} off the ground{how}", verb("jump", plural))
            }
            LegAction::Travels(pace, travel) => locomotion(pace, travel, plural),
            LegAction::Kneels => format!("{} on the ground", verb("kneel", plural)),
            LegAction::Kicks(dir) => format!("{} {}", verb("kick", plural), dir.as_str()),
            LegAction::Lifted(dir) => format!("{is} lifted {}", dir.as_str()),
            LegAction::LiftsKnee => {
                let knee = if plural { "knees" } else { "knee" };
                format!("{} the {knee} high", verb("lift", plural))
            }
            LegAction::Level(level, bent) => match level {
                Level::Lowers => format!("{} as the body lowers", verb("bend", plural)),
                Level::Rises => format!("{} as the body rises", verb("straighten", plural)),
                Level::Dips => format!(
                    "{} deeply and {} again",
                    verb("bend", plural),
                    verb("straighten", plural)
                ),
                Level::StaysLow if bent => format!("{} bent low", verb("stay", plural)),
                Level::StaysLow | Level::Steady => format!("{} low", verb("stay", plural)),
            },
            LegAction::Bows { bent: true } => format!("{} as the body bows", verb("bend", plural)),
            LegAction::Bows { bent: false } => {
                format!("{} straight as the body bows", verb("stay", plural))
            }
            LegAction::Turns { left, steps } => {
                let side = if left { "left" } else { "right" };
                let v = if steps {
                    format!("{} around", verb("step", plural))
                } else {
                    verb("pivot", plural)
                };
                format!("{v} as the body turns {side}")
            }
            LegAction::HeldUp => format!("{is} held off the ground"),
            LegAction::StepsInPlace => format!("{} in place", verb("step", plural)),
            LegAction::Stands => format!("{} still", verb("stand", plural)),
        }
    }
}

/// What one part does in a window.
#[derive(Clone, Copy, Debug, PartialEq)]
enum PartAction {
    Arm(ArmAction),
    Leg(LegAction),
}

impl PartAction {
    fn phrase(self, plural: bool) -> String {
        match self {
            PartAction::Arm(a) => a.phrase(plural),
            PartAction::Leg(l) => l.phrase(plural),
        }
    }

    /// Worth a sentence of its own in a whole-body description: not the resting state, and
    /// not something the global movement already says.
    fn notable(self) -> bool {
        match self {
            PartAction::Arm(a) => !matches!(a, ArmAction::Hangs | ArmAction::Swings),
            PartAction::Leg(l) => matches!(
                l,
                LegAction::Kneels
                    | LegAction::Kicks(_)
                    | LegAction::Lifted(_)
                    | LegAction::LiftsKnee
                    | LegAction::HeldUp
                    | LegAction::StepsInPlace
            ),
        }
    }
}

/// What the whole body does in a window.
#[derive(Clone, Copy, Debug, PartialEq)]
enum BodyAction {
    Jumps(Option<Travel>),
    Travels(Pace, Travel),
    Kneels,
    Level(Level),
    Torso(Torso),
    Turns,
    Stands,
}

impl BodyAction {
    fn of(d: &MotionDescriptor) -> BodyAction {
        // Strides reach as far as kicks and dip the pelvis, so brisk travel outranks everything
        // but jumps; slow drift of the pelvis is often a side effect of sitting or bowing.
        if d.jumps > 0 {
            BodyAction::Jumps(d.travel)
        } else if d.pace >= Pace::Walking {
            BodyAction::Travels(d.pace, d.travel.unwrap_or(Travel::Forward))
        } else if d.left_leg.kneels || d.right_leg.kneels {
            BodyAction::Kneels
        } else if d.level != Level::Steady {
            BodyAction::Level(d.level)
        } else if d.torso != Torso::Upright {
            BodyAction::Torso(d.torso)
        } else if d.pace == Pace::Slow {
            BodyAction::Travels(d.pace, d.travel.unwrap_or(Travel::Forward))
        } else if d.turn_deg.abs() >= TURN_MIN_DEG {
            BodyAction::Turns
        } else {
            BodyAction::Stands
        }
    }

    /// Whether a window doing `next` extends a segment doing `self`. Travel the same way is one
    /// segment whatever the pace, which is then measured over the whole segment.
    fn continues_as(self, next: BodyAction) -> bool {
        match (self, next) {
            (BodyAction::Travels(_, a), BodyAction::Travels(_, b)) => a == b,
            _ => self == next,
        }
    }

    /// The phrase for a segment, with its pace, turn and jump count measured over the segment.
    fn phrase(self, d: &MotionDescriptor) -> String {
        let main = match self {
            BodyAction::Jumps(travel) => {
                let dir = travel.map_or("in place", Travel::as_str);
                let times = match d.jumps {
                    0 | 1 => String::new(),
                    2 => " twice".to_string(),
                    k => format!(" {k} times"),
                };
                format!("jumps {dir}{times}")
            }
            BodyAction::Travels(pace, travel) => {
                let pace = if d.pace >= Pace::Slow { d.pace } else { pace };
                locomotion(pace, travel, false)
            }
            BodyAction::Kneels => "kneels".to_string(),
            BodyAction::Level(level) => level.as_str().to_string(),
            BodyAction::Torso(torso) => torso.as_str().to_string(),
            BodyAction::Turns => return format!("turns {}", turn_words(d.turn_deg)),
            BodyAction::Stands => "stands still".to_string(),
        };
        if d.turn_deg.abs() >= TURN_MIN_DEG {
            format!("{main}, turning {}", turn_words(d.turn_deg))
        } else {
            main
        }
    }
}

#[cfg(test)]
mod unit {
    use super::*;

    #[test]
    fn windows_cover_the_motion_and_share_boundaries() {
        for n in [0, 1, 50] {
            let w = windows(n);
            assert_eq!(w.len(), 1);
            assert_eq!(w[0], 0..n);
        }
        let w = windows(121);
        assert_eq!(w, [0..41, 40..81, 80..121]);
    }

    #[test]
    fn turn_words_round_and_sign() {
        assert_eq!(turn_words(87.0), "left by about 90 degrees");
        assert_eq!(turn_words(-181.0), "right by about 180 degrees");
    }

    #[test]
    fn verbs_agree_with_the_subject() {
        assert_eq!(ArmAction::Hangs.phrase(false), "hangs at the side");
        assert_eq!(ArmAction::Hangs.phrase(true), "hang at the sides");
        assert_eq!(
            ArmAction::Waves { above_head: true }.phrase(true),
            "are raised above the head and wave"
        );
        assert_eq!(
            locomotion(Pace::Slow, Travel::Forward, false),
            "walks forward slowly"
        );
        assert_eq!(
            locomotion(Pace::Running, Travel::Left, true),
            "run to the left"
        );
    }
}
