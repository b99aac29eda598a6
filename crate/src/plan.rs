//! What the planner hands to the generator: a timeline. The whole-body track is a prompt cut
//! into consecutive segments, each with a whole-body motion, instructions per body part over
//! the whole segment and an optional root path; the body-part tracks hold [`Clip`]s, each with
//! its own start and end, which may run over several segments ("holding a T-pose" over a walk
//! and then a run) or over part of one.
//!
//! A part's instruction that covers exactly one segment stays with the segment
//! ([`Segment::parts`]): the model composes it with that segment's base motion and the reviewer
//! checks it there. [`Plan::part_clips`] reads both as one timeline.

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
/// Most clips on the body-part tracks of one plan.
pub const MAX_CLIPS: usize = 60;
/// Shortest clip, in seconds (two token steps of 4 frames at 20 fps).
pub const MIN_CLIP_SECONDS: f64 = 0.4;
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

impl Segment {
    /// Whether key poses make the whole segment (the generated motion under it is replaced, so
    /// there is nothing of the model's to review).
    pub fn is_posture_segment(&self) -> bool {
        self.postures.as_ref().is_some_and(|t| t.whole_body())
    }
}

/// One clip on the body-part tracks: what some parts do from `start` to `end` over whatever
/// the whole-body track does then. Either motion generated from `text` for those parts, or,
/// with `postures`, key poses held on them (`text` then names the posture).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Clip {
    /// The parts that follow the clip: one to three of them (all four is the whole body, whose
    /// track is the segments), in model order.
    pub parts: Vec<BodyPart>,
    /// What the parts do, in the words of the model's captions ("a person waves the left
    /// hand"), or the posture's name.
    pub text: String,
    /// Seconds from the start of the plan (20 fps; the blended motion's time).
    pub start: f64,
    pub end: f64,
    /// Key poses held on the parts over the clip instead of generated motion; the track's
    /// parts are the clip's, and its time range is the clip's (no `within`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub postures: Option<PostureTrack>,
}

impl Clip {
    /// The clip if its parts, text, times and posture track are what a clip may hold within
    /// a plan of `plan_seconds`; an end past the plan's is brought back to it.
    pub fn checked(mut self, plan_seconds: f64) -> Result<Clip, String> {
        self.parts.sort();
        self.parts.dedup();
        if self.parts.is_empty() || self.parts.len() == BodyPart::ALL.len() {
            return Err(format!(
                "a clip moves one to three body parts (the whole body is the segments' track), \
                 this one {}",
                self.parts.len()
            ));
        }
        self.text = clean_text(&self.text).map_err(|e| format!("a clip's text: {e}"))?;
        if !(self.start.is_finite() && self.end.is_finite()) || self.start < 0.0 {
            return Err(format!(
                "a clip's start and end are seconds from the plan's start, not {} and {}",
                self.start, self.end
            ));
        }
        self.end = self.end.min(plan_seconds);
        if self.end - self.start < MIN_CLIP_SECONDS - 1e-9 {
            return Err(format!(
                "a clip lasts at least {MIN_CLIP_SECONDS} s within the plan's {plan_seconds:.1} \
                 s, \"{}\" from {:.1} to {:.1} s does not",
                self.text, self.start, self.end
            ));
        }
        if let Some(track) = &mut self.postures {
            if track.parts != self.parts {
                return Err(format!(
                    "the key poses of clip \"{}\" are on other parts than the clip",
                    self.text
                ));
            }
            // The clip says when; a range of the track's own would say it twice.
            track.within = None;
        }
        Ok(self)
    }

    /// The middle of the clip, seconds from the plan's start.
    pub fn middle(&self) -> f64 {
        (self.start + self.end) / 2.0
    }

    /// Whether the clip and `other` move a part in common at a time in common.
    pub fn overlaps(&self, other: &Clip) -> bool {
        self.start < other.end
            && other.start < self.end
            && self.parts.iter().any(|p| other.parts.contains(p))
    }
}

/// Sorts clips by start time, then by their parts in model order: the order a plan keeps
/// them in, and the order they are laid in.
pub fn in_time_order(clips: &mut [Clip]) {
    clips.sort_by(|a, b| a.start.total_cmp(&b.start).then(a.parts.cmp(&b.parts)));
}

/// Who made a plan.
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
    /// The whole-body track: one to [`MAX_SEGMENTS`] consecutive segments.
    pub segments: Vec<Segment>,
    /// The body-part tracks: up to [`MAX_CLIPS`] clips, by start time, none moving a part
    /// another clip moves at the same time.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub clips: Vec<Clip>,
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
    #[serde(default)]
    clips: Vec<Clip>,
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
            clips: fields.clips,
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
        if self.clips.len() > MAX_CLIPS {
            return Err(format!(
                "a plan has at most {MAX_CLIPS} clips on its body-part tracks, this one {}",
                self.clips.len()
            ));
        }
        self.clips = std::mem::take(&mut self.clips)
            .into_iter()
            .map(|c| c.checked(seconds))
            .collect::<Result<_, _>>()?;
        in_time_order(&mut self.clips);
        for (i, a) in self.clips.iter().enumerate() {
            if let Some(b) = self.clips[i + 1..].iter().find(|b| a.overlaps(b)) {
                return Err(format!(
                    "clips \"{}\" and \"{}\" move the same body part at the same time",
                    a.text, b.text
                ));
            }
        }
        Ok(self)
    }

    /// The segment under time `t` (seconds from the plan's start; the last one past the end).
    pub fn segment_at(&self, t: f64) -> usize {
        let starts = self.segment_starts();
        starts[1..]
            .iter()
            .position(|end| t < *end)
            .unwrap_or(self.segments.len() - 1)
    }

    /// Seconds from the plan's start at which each segment starts, and the plan's end.
    pub fn segment_starts(&self) -> Vec<f64> {
        let mut t = 0.0;
        let mut out = vec![0.0];
        for s in &self.segments {
            t += s.seconds;
            out.push(t);
        }
        out
    }

    /// Every body-part instruction of the plan as a clip on the timeline: the segments' own
    /// (over the whole segment; parts with the same instruction as one clip) and the plan's
    /// clips, by start time.
    pub fn part_clips(&self) -> Vec<Clip> {
        self.lifted().clips
    }

    /// The same plan with its segments' part instructions moved onto the body-part tracks as
    /// clips over their segments, so that every instruction can be moved or deleted as a clip.
    /// An instruction a clip of the plan already overrides for part of its segment stays with
    /// the segment. The motion is the same: a segment's instruction and a clip over exactly
    /// that segment ask the same of the same frames.
    pub fn lifted(&self) -> Plan {
        let starts = self.segment_starts();
        let mut plan = self.clone();
        for (k, s) in self.segments.iter().enumerate() {
            let mut groups: Vec<(Vec<BodyPart>, String)> = Vec::new();
            for (part, text) in s.parts.edits() {
                match groups.iter_mut().find(|(_, t)| *t == text) {
                    Some((parts, _)) => parts.push(part),
                    None => groups.push((vec![part], text)),
                }
            }
            for (parts, text) in groups {
                let clip = Clip {
                    parts,
                    text,
                    start: starts[k],
                    end: starts[k + 1],
                    postures: None,
                };
                if self.clips.iter().any(|c| c.overlaps(&clip)) {
                    continue;
                }
                for part in &clip.parts {
                    plan.segments[k].parts.set(*part, None);
                }
                plan.clips.push(clip);
            }
        }
        in_time_order(&mut plan.clips);
        plan
    }

    /// Scales the segments' durations so the plan lasts about `seconds` in all (each segment
    /// still within what one generation makes), keeping their proportions: the length the
    /// user asks for overrides the planner's estimates, not its split. A length other than the
    /// one asked for (more than [`MAX_PLAN_SECONDS`], for one) leaves a note. Clips keep their
    /// place in the segments they lie on.
    pub fn fit_seconds(&mut self, seconds: f64) {
        let planned = self.seconds();
        if !seconds.is_finite() || seconds <= 0.0 || planned <= 0.0 {
            return;
        }
        let before = self.segment_starts();
        let target = seconds.min(MAX_PLAN_SECONDS);
        let factor = target / planned;
        for s in &mut self.segments {
            s.seconds = clamp_seconds(s.seconds * factor).unwrap_or(s.seconds);
        }
        // Segments clamped at a bound cannot take their share: the others scale again for
        // what is missing, until the length is met or every segment is at its bound.
        for _ in 0..self.segments.len() {
            let missing = target - self.seconds();
            let free = |s: &Segment| {
                if missing > 0.0 {
                    s.seconds < MAX_SEGMENT_SECONDS
                } else {
                    s.seconds > MIN_SEGMENT_SECONDS
                }
            };
            let adjustable: f64 = self
                .segments
                .iter()
                .filter(|s| free(s))
                .map(|s| s.seconds)
                .sum();
            if missing.abs() <= 1e-6 || adjustable <= 0.0 {
                break;
            }
            let factor = 1.0 + missing / adjustable;
            for s in self.segments.iter_mut().filter(|s| free(s)) {
                s.seconds = clamp_seconds(s.seconds * factor).unwrap_or(s.seconds);
            }
        }
        let after = self.segment_starts();
        for c in &mut self.clips {
            c.start = moved_with_segments(c.start, &before, &after);
            c.end = moved_with_segments(c.end, &before, &after);
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

/// A time `t` (seconds) at the same place within its segment after the segments, which started
/// at `before`, were made to start at `after` (both as [`Plan::segment_starts`] gives them).
fn moved_with_segments(t: f64, before: &[f64], after: &[f64]) -> f64 {
    let k = before[1..]
        .iter()
        .position(|end| t <= *end)
        .unwrap_or(before.len().saturating_sub(2));
    let (b0, b1) = (before[k], before[k + 1]);
    let (a0, a1) = (after[k], after[k + 1]);
    let within = if b1 > b0 { (t - b0) / (b1 - b0) } else { 0.0 };
    a0 + within.clamp(0.0, 1.0) * (a1 - a0)
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

    fn wave(parts: &[BodyPart], start: f64, end: f64) -> Clip {
        Clip {
            parts: parts.to_vec(),
            text: "a person waves".into(),
            start,
            end,
            postures: None,
        }
    }

    #[test]
    fn clips_are_checked_as_they_are_read_and_old_plans_have_none() {
        let plan = offline::plan("a person walks forward, then runs forward", None);
        let json = serde_json::to_string(&plan).unwrap();
        assert!(!json.contains("clips"), "{json}");
        assert!(serde_json::from_str::<Plan>(&json)
            .unwrap()
            .clips
            .is_empty());
        let seconds = plan.seconds();
        let read = |clips: Vec<Clip>| {
            let mut p = plan.clone();
            p.clips = clips;
            serde_json::from_str::<Plan>(&serde_json::to_string(&p).unwrap())
                .map_err(|e| e.to_string())
        };
        let left = BodyPart::LeftArm;
        // Read back in start order, the end brought within the plan.
        let ok = read(vec![
            wave(&[left], 2.0, seconds + 5.0),
            wave(&[BodyPart::RightArm, left][1..], 0.0, 1.0),
        ])
        .unwrap();
        assert_eq!(ok.clips[0].start, 0.0);
        assert_eq!(ok.clips[1].end, seconds);
        for (clips, says) in [
            (vec![wave(&[], 0.0, 1.0)], "one to three body parts"),
            (
                vec![wave(&BodyPart::ALL, 0.0, 1.0)],
                "one to three body parts",
            ),
            (vec![wave(&[left], 1.0, 1.2)], "at least 0.4 s"),
            (
                vec![wave(&[left], seconds, seconds + 3.0)],
                "at least 0.4 s",
            ),
            (
                vec![wave(&[left], -1.0, 1.0)],
                "seconds from the plan's start",
            ),
            (
                vec![wave(&[left], 0.0, 2.0), wave(&[left], 1.5, 3.0)],
                "the same body part at the same time",
            ),
            (
                vec![wave(&[left], 0.0, 1.0); MAX_CLIPS + 1],
                "at most 60 clips",
            ),
        ] {
            let e = read(clips).unwrap_err();
            assert!(e.contains(says), "{e}");
        }
        // Side by side on other parts, or one after the other on the same part: both fine.
        assert!(read(vec![
            wave(&[left], 0.0, 2.0),
            wave(&[BodyPart::RightArm], 1.0, 3.0),
            wave(&[left], 2.0, 3.0),
        ])
        .is_ok());
        let mut posture = wave(&[left], 0.0, 2.0);
        posture.postures = Some(crate::posture::track::PostureTrack::holding(
            vec![BodyPart::RightArm],
            crate::posture::library::Library::builtin()
                .get("T-pose")
                .unwrap()
                .script
                .clone(),
        ));
        assert!(read(vec![posture]).unwrap_err().contains("other parts"));
    }

    #[test]
    fn clips_keep_their_place_in_their_segments_when_the_plan_is_scaled() {
        let mut plan = offline::plan("a person walks forward, then runs forward", None);
        plan.segments[0].seconds = 4.0;
        plan.segments[1].seconds = 2.0;
        // From the middle of the walk to the middle of the run.
        plan.clips = vec![wave(&[BodyPart::LeftArm], 2.0, 5.0)];
        plan.segments[1].seconds = 2.0;
        plan.fit_seconds(12.0);
        assert_eq!(plan.segment_starts(), vec![0.0, 8.0, 12.0]);
        assert_eq!((plan.clips[0].start, plan.clips[0].end), (4.0, 10.0));
        assert_eq!(plan.segment_at(4.0), 0);
        assert_eq!(plan.segment_at(8.0), 1);
        assert_eq!(plan.segment_at(99.0), 1);
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
        // A segment at its longest leaves its share to the others.
        let mut capped = planned.clone();
        capped.segments[0].seconds = 9.0;
        capped.segments[1].seconds = 2.0;
        capped.segments[2].seconds = 2.0;
        capped.fit_seconds(20.0);
        assert!((capped.seconds() - 20.0).abs() < 1e-9, "{capped:?}");
        assert_eq!(capped.segments[0].seconds, MAX_SEGMENT_SECONDS);
        assert!((capped.segments[1].seconds - 5.1).abs() < 1e-9);
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
