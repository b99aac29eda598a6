//! What the planner hands to the generator: a prompt cut into consecutive segments, each with
//! a whole-body motion, instructions per body part and an optional root path.

use crate::posture::track::PostureTrack;
use crate::skeleton::BodyPart;
use crate::trajectory::Trajectory;
use serde::{Deserialize, Serialize};

/// Shortest segment the model makes well, in seconds (40 frames at 20 fps).
pub const MIN_SEGMENT_SECONDS: f64 = 2.0;
/// Longest segment one generation makes, in seconds (196 frames at 20 fps).
pub const MAX_SEGMENT_SECONDS: f64 = 9.8;
/// Longest plan, in seconds (1200 frames at 20 fps): the whole-body track's segments add up
/// to at most this.
pub const MAX_PLAN_SECONDS: f64 = 60.0;
/// Most segments in one plan: [`MAX_PLAN_SECONDS`] of the shortest.
pub const MAX_SEGMENTS: usize = (MAX_PLAN_SECONDS / MIN_SEGMENT_SECONDS) as usize;
/// Longest text the planner keeps for one prompt, segment or instruction, in characters:
/// MiniLM reads 256 word pieces at most, and longer replies are a sign of a confused model.
pub const MAX_TEXT_CHARS: usize = 300;

/// One instruction per body part, in the words of the model's captions ("a person waves the
/// left hand"); `None` where the part simply follows the segment's base motion.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PartEdits {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub left_arm: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub right_arm: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub left_leg: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub right_leg: Option<String>,
}

impl PartEdits {
    /// The instruction of one part.
    pub fn get(&self, part: BodyPart) -> Option<&str> {
        match part {
            BodyPart::LeftArm => self.left_arm.as_deref(),
            BodyPart::RightArm => self.right_arm.as_deref(),
            BodyPart::LeftLeg => self.left_leg.as_deref(),
            BodyPart::RightLeg => self.right_leg.as_deref(),
        }
    }

    /// Sets (or with `None` clears) one part's instruction.
    pub fn set(&mut self, part: BodyPart, text: Option<String>) {
        let slot = match part {
            BodyPart::LeftArm => &mut self.left_arm,
            BodyPart::RightArm => &mut self.right_arm,
            BodyPart::LeftLeg => &mut self.left_leg,
            BodyPart::RightLeg => &mut self.right_leg,
        };
        *slot = text;
    }

    /// The parts that have an instruction, in model order.
    pub fn edits(&self) -> Vec<(BodyPart, String)> {
        BodyPart::ALL
            .iter()
            .filter_map(|p| self.get(*p).map(|t| (*p, t.to_string())))
            .collect()
    }

    /// True when no part has its own instruction.
    pub fn is_empty(&self) -> bool {
        self.edits().is_empty()
    }
}

/// One temporally consecutive movement of the plan.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    /// The whole segment in one sentence ("a person walks forward while waving the left hand").
    pub text: String,
    /// Length in seconds at 20 fps, within [`MIN_SEGMENT_SECONDS`]..=[`MAX_SEGMENT_SECONDS`].
    pub seconds: f64,
    /// The whole-body motion generated first ("a person walks forward").
    pub base: String,
    /// The body-part edits applied to the base motion.
    #[serde(default)]
    pub parts: PartEdits,
    /// The path the root follows on the ground, if the segment asks for one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trajectory: Option<Trajectory>,
    /// Key postures for what the motion model does not know: on all four parts they replace
    /// the generated motion over the segment; on some parts they are held over it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub postures: Option<PostureTrack>,
}

/// Who made a plan.
impl Segment {
    /// Whether key poses make the whole segment (the generated motion under it is replaced, so
    /// there is nothing of the model's to review).
    pub fn is_posture_segment(&self) -> bool {
        self.postures.as_ref().is_some_and(|t| t.whole_body())
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum PlannerKind {
    /// The deterministic built-in planner (no LLM).
    Offline,
    /// An LLM, named by its model id.
    Llm { model: String },
}

/// A prompt turned into segments. A plan that arrives from outside the planner (a share link,
/// a worker message, a file) is checked as it is read: 1 to [`MAX_SEGMENTS`] segments, each
/// of finite length, clamped into what one generation makes, [`MAX_PLAN_SECONDS`] in all.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "PlanFields")]
pub struct Plan {
    /// What the user typed.
    pub prompt: String,
    /// The prompt in words the motion model knows.
    pub rewritten: String,
    /// One to [`MAX_SEGMENTS`] consecutive segments.
    pub segments: Vec<Segment>,
    pub planner: PlannerKind,
    /// What the planner changed or dropped, and why (clamped durations, unknown words, an LLM
    /// that failed and the fallback that took over).
    #[serde(default)]
    pub notes: Vec<String>,
}

/// A plan as it is read, before [`Plan`]'s checks.
#[derive(Deserialize)]
struct PlanFields {
    prompt: String,
    rewritten: String,
    segments: Vec<Segment>,
    planner: PlannerKind,
    #[serde(default)]
    notes: Vec<String>,
}

impl TryFrom<PlanFields> for Plan {
    type Error = String;

    fn try_from(fields: PlanFields) -> Result<Plan, String> {
        Plan {
            prompt: fields.prompt,
            rewritten: fields.rewritten,
            segments: fields.segments,
            planner: fields.planner,
            notes: fields.notes,
        }
        .checked()
    }
}

impl Plan {
    /// Total length in seconds, before blending shortens the joins.
    pub fn seconds(&self) -> f64 {
        self.segments.iter().map(|s| s.seconds).sum()
    }

    /// The plan if it has 1 to [`MAX_SEGMENTS`] segments of finite length and lasts at most
    /// [`MAX_PLAN_SECONDS`], with every length clamped into what one generation makes (the
    /// plan's author may not have clamped).
    pub fn checked(mut self) -> Result<Plan, String> {
        if self.segments.is_empty() || self.segments.len() > MAX_SEGMENTS {
            return Err(format!(
                "a plan has 1 to {MAX_SEGMENTS} segments, this one {}",
                self.segments.len()
            ));
        }
        for s in &mut self.segments {
            s.seconds = clamp_seconds(s.seconds).ok_or("a segment has no length")?;
        }
        let seconds = self.seconds();
        if seconds > MAX_PLAN_SECONDS + 1e-6 {
            return Err(format!(
                "a plan lasts at most {MAX_PLAN_SECONDS} s, this one {seconds:.1} s"
            ));
        }
        Ok(self)
    }

    /// Scales the segments' durations so the plan lasts about `seconds` in all (each segment
    /// still within what one generation makes), keeping their proportions: the length the
    /// user asks for overrides the planner's estimates, not its split. A length other than the
    /// one asked for (more than [`MAX_PLAN_SECONDS`], for one) leaves a note.
    pub fn fit_seconds(&mut self, seconds: f64) {
        let planned = self.seconds();
        if !seconds.is_finite() || seconds <= 0.0 || planned <= 0.0 {
            return;
        }
        let factor = seconds.min(MAX_PLAN_SECONDS) / planned;
        for s in &mut self.segments {
            s.seconds = clamp_seconds(s.seconds * factor).unwrap_or(s.seconds);
        }
        // Clamping short segments up may overshoot the longest plan: the overshoot comes off
        // the segments that can give it, in proportion (one pass takes exactly it).
        if self.seconds() > MAX_PLAN_SECONDS + 1e-6 {
            let over = self.seconds() - MAX_PLAN_SECONDS;
            let spare: f64 = self
                .segments
                .iter()
                .map(|s| s.seconds - MIN_SEGMENT_SECONDS)
                .sum();
            let keep = 1.0 - (over / spare).min(1.0);
            for s in &mut self.segments {
                s.seconds = MIN_SEGMENT_SECONDS + (s.seconds - MIN_SEGMENT_SECONDS) * keep;
            }
        }
        let got = self.seconds();
        if seconds > MAX_PLAN_SECONDS {
            self.notes.push(format!(
                "asked for {seconds:.1} s; a plan lasts at most {MAX_PLAN_SECONDS} s, so it \
                 makes {got:.1} s"
            ));
        } else if (got - seconds).abs() > 0.05 {
            self.notes.push(format!(
                "asked for {seconds:.1} s; {} segment(s) of {MIN_SEGMENT_SECONDS} to \
                 {MAX_SEGMENT_SECONDS} s make {got:.1} s",
                self.segments.len()
            ));
        }
    }
}

/// Clamps a duration into what one generation makes; `None` for a value that is not a
/// number of seconds at all.
pub fn clamp_seconds(seconds: f64) -> Option<f64> {
    seconds
        .is_finite()
        .then(|| seconds.clamp(MIN_SEGMENT_SECONDS, MAX_SEGMENT_SECONDS))
}

/// A text fit for the motion model: printable, trimmed, single-spaced and at most
/// [`MAX_TEXT_CHARS`] characters. Returns why not otherwise.
pub fn clean_text(text: &str) -> Result<String, String> {
    if text.chars().count() > MAX_TEXT_CHARS * 4 {
        return Err(format!(
            "a text of {} characters (at most {MAX_TEXT_CHARS})",
            text.chars().count()
        ));
    }
    if let Some(c) = text.chars().find(|c| c.is_control() && !c.is_whitespace()) {
        return Err(format!(
            "a control character (U+{:04X}) in a text",
            c as u32
        ));
    }
    let cleaned = text.split_whitespace().collect::<Vec<_>>().join(" ");
    if cleaned.is_empty() {
        return Err("an empty text".into());
    }
    if cleaned.chars().count() > MAX_TEXT_CHARS {
        return Err(format!(
            "a text of {} characters (at most {MAX_TEXT_CHARS})",
            cleaned.chars().count()
        ));
    }
    Ok(cleaned)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::agents::planner::offline;

    #[test]
    fn plans_from_outside_are_checked_as_they_are_read() {
        let plan = offline::plan("a person walks forward, then bows", None);
        let json = serde_json::to_string(&plan).unwrap();
        assert_eq!(serde_json::from_str::<Plan>(&json).unwrap(), plan);
        let mut long = plan.clone();
        long.segments[0].seconds = 1e9;
        let read: Plan = serde_json::from_str(&serde_json::to_string(&long).unwrap()).unwrap();
        assert_eq!(read.segments[0].seconds, MAX_SEGMENT_SECONDS);
        let mut empty = plan.clone();
        empty.segments.clear();
        let mut many = plan.clone();
        many.segments = vec![plan.segments[0].clone(); MAX_SEGMENTS + 1];
        for bad in [
            String::new(),
            "{".into(),
            r#"{"segments":[{"text":"x","from":0,"to":4}]}"#.into(),
            serde_json::to_string(&empty).unwrap(),
            serde_json::to_string(&many).unwrap(),
            json.replace("\"seconds\":", "\"seconds\":null,\"x\":"),
        ] {
            assert!(serde_json::from_str::<Plan>(&bad).is_err(), "{bad}");
        }
        let e = serde_json::from_str::<Plan>(&serde_json::to_string(&many).unwrap())
            .unwrap_err()
            .to_string();
        assert!(e.contains("1 to 30 segments"), "{e}");
        // Seven segments of 9.8 s are 68.6 s: longer than a plan lasts.
        let mut long = plan.clone();
        long.segments = vec![plan.segments[0].clone(); 7];
        long.segments.iter_mut().for_each(|s| s.seconds = 9.8);
        let e = serde_json::from_str::<Plan>(&serde_json::to_string(&long).unwrap())
            .unwrap_err()
            .to_string();
        assert!(e.contains("at most 60 s, this one 68.6 s"), "{e}");
        long.segments.pop();
        assert!(serde_json::from_str::<Plan>(&serde_json::to_string(&long).unwrap()).is_ok());
    }

    #[test]
    fn the_seconds_asked_for_scale_the_plan() {
        let mut one = offline::plan("a person walks forward", None);
        one.fit_seconds(9.8);
        assert_eq!(one.segments[0].seconds, 9.8);
        let mut three = offline::plan(
            "A person walks forward waving the left hand, then turns right and bows",
            None,
        );
        assert_eq!(three.segments.len(), 3);
        let before = three.notes.len();
        three.fit_seconds(9.0);
        assert!((three.seconds() - 9.0).abs() < 1e-9, "{}", three.seconds());
        assert_eq!(three.notes.len(), before);
        // Three segments cannot be shorter than 3 × 2 s; the plan says so.
        three.fit_seconds(3.0);
        assert_eq!(three.seconds(), 6.0);
        assert!(three.notes.last().unwrap().contains("make 6.0 s"));
        let planned = three.clone();
        three.fit_seconds(f64::NAN);
        assert_eq!(three, planned);
        // More than a plan lasts: 60 s, with a note; every segment still one generation.
        three.fit_seconds(90.0);
        assert!((three.seconds() - 29.4).abs() < 1e-9, "{}", three.seconds());
        let mut many = planned.clone();
        many.segments = vec![planned.segments[0].clone(); 12];
        many.fit_seconds(200.0);
        assert!(
            (many.seconds() - MAX_PLAN_SECONDS).abs() < 1e-9,
            "{}",
            many.seconds()
        );
        assert!(many
            .segments
            .iter()
            .all(|s| (MIN_SEGMENT_SECONDS..=MAX_SEGMENT_SECONDS).contains(&s.seconds)));
        assert!(many
            .notes
            .last()
            .unwrap()
            .contains("at most 60 s, so it makes 60.0 s"));
    }
}
