//! A take: one state of the page's motion (tokens, joints and features) with what made it
//! (prompt, seed, plan, the edits so far, the segments), as undo keeps it and a share link
//! carries it.

use coma::plan::Plan;
use coma::posture::script::PostureScript;
use coma::posture::track::PostureTrack;
use coma::session::Motion;
use coma::share::{Edit, EditKind, LinkPlan, LinkSegment, RunRecord, SegmentScores, SharedMotion};
use coma::skeleton::BodyPart;
use coma::timing::{frames_for_seconds, seconds, FPS, FRAMES_PER_TOKEN};
use coma::trajectory::drawn::{thin, MIN_DRAWN_STEP_M};
use coma::trajectory::{check_drawn, path_length, MapOptions, Trajectory, MAX_DRAWN_POINTS};

/// A stretch of the motion with its own text, in frames at 20 fps, and what the plan asked
/// of it.
#[derive(Clone, Debug, PartialEq)]
pub struct Segment {
    pub text: String,
    pub from: usize,
    pub to: usize,
    /// The whole-body motion generated first ("" when the take has no plan).
    pub base: String,
    /// `(body part, instruction)` for the parts with their own edit.
    pub parts: Vec<(String, String)>,
    /// The root path, described ("a circle, clockwise").
    pub path: Option<String>,
    /// The key poses of the segment's posture track, each in words
    /// ([`PostureTrack::in_words`]); empty when the segment has none.
    pub postures: Vec<String>,
    /// The body parts the key poses drive: all four for a posture segment (the key poses are
    /// the motion), fewer when they are held on those parts over the generated motion.
    pub posture_parts: Vec<String>,
    /// Where the key poses are reached on the timeline.
    pub keys: Vec<KeyMark>,
}

/// A key pose on the timeline: the frame (20 fps, from the start of the take) at which it is
/// reached, and its name.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyMark {
    pub frame: f64,
    pub name: String,
    /// Seconds it is held once reached.
    pub hold: f64,
}

impl Segment {
    pub fn seconds(&self) -> f64 {
        seconds(self.to - self.from)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Take {
    pub motion: Motion,
    pub prompt: String,
    pub seed: u64,
    pub edits: Vec<Edit>,
    /// The plan the run followed; `None` for a take from an older link without one.
    pub plan: Option<Plan>,
    pub segments: Vec<Segment>,
    /// What the planner and the run changed, dropped or could not do.
    pub notes: Vec<String>,
    /// The review's scores per segment (cleared by an edit, which they no longer describe).
    pub scores: Vec<SegmentScores>,
    /// The lines of the run that made the take, one a step (plan, generation, edits, review
    /// rounds, blend), as the Steps panel showed them.
    pub steps: Vec<String>,
}

impl Take {
    /// A take of `motion` made by following `plan` (its segments come from the plan), or with
    /// `legacy` segments when there is no plan.
    pub fn new(
        motion: Motion,
        prompt: String,
        seed: u64,
        edits: Vec<Edit>,
        plan: Option<Plan>,
        legacy: Vec<Segment>,
    ) -> Take {
        let frames = motion.joints.len();
        let segments = match &plan {
            Some(plan) => plan_segments(plan, frames),
            None => legacy,
        };
        Take {
            motion,
            prompt,
            seed,
            edits,
            plan,
            segments,
            notes: Vec::new(),
            scores: Vec::new(),
            steps: Vec::new(),
        }
    }

    /// How the run that made the take went, as its share link keeps it, so that an opened
    /// link shows the same steps, scores and notes.
    fn record(&self) -> Option<RunRecord> {
        let record = RunRecord {
            steps: self.steps.clone(),
            scores: self.scores.clone(),
            notes: self.notes.clone(),
        };
        (!record.is_empty()).then_some(record)
    }

    /// Takes the steps, scores and notes a link recorded.
    pub fn restore_record(&mut self, record: Option<RunRecord>) {
        if let Some(record) = record {
            self.steps = record.steps;
            self.scores = record.scores;
            self.notes.extend(record.notes);
        }
    }

    /// Frames of the motion.
    pub fn frames(&self) -> usize {
        self.motion.joints.len()
    }

    /// What a share link of this take carries.
    pub fn shared(&self, model_id: [u8; 8]) -> SharedMotion {
        SharedMotion {
            model_id,
            seed: self.seed,
            prompt: self.prompt.clone(),
            plan: match &self.plan {
                Some(plan) => LinkPlan::Planned(plan.clone()),
                None => LinkPlan::Segments(link_segments(&self.segments)),
            },
            record: self.record(),
            history: self.edits.clone(),
            tokens: self.motion.tokens.clone(),
            notes: Vec::new(),
        }
    }
}

/// The plan's segments laid end to end over a motion of `frames` frames, each as long as
/// one generation of its seconds (whole token steps), as the pipeline's
/// `segment_ranges` lays them; a motion still being made (`frames` 0) gets them all.
pub fn plan_segments(plan: &Plan, frames: usize) -> Vec<Segment> {
    let lengths: Vec<usize> = plan
        .segments
        .iter()
        .map(|s| frames_for_seconds(s.seconds).div_ceil(FRAMES_PER_TOKEN) * FRAMES_PER_TOKEN)
        .collect();
    let total = if frames == 0 {
        lengths.iter().sum()
    } else {
        frames
    };
    let mut start = 0;
    plan.segments
        .iter()
        .zip(lengths)
        .map(|(s, len)| {
            let (from, to) = (start.min(total), (start + len).min(total));
            start += len;
            Segment {
                text: s.text.chars().take(500).collect(),
                from,
                to,
                base: s.base.chars().take(500).collect(),
                parts: s
                    .parts
                    .edits()
                    .into_iter()
                    .map(|(p, t)| (p.name().to_string(), t.chars().take(500).collect()))
                    .collect(),
                path: s.trajectory.as_ref().map(|t| t.describe()),
                postures: s.postures.as_ref().map_or_else(Vec::new, |t| {
                    t.in_words()
                        .into_iter()
                        .map(|l| l.chars().take(2000).collect())
                        .collect()
                }),
                posture_parts: s.postures.as_ref().map_or_else(Vec::new, |t| {
                    t.parts.iter().map(|p| p.name().to_string()).collect()
                }),
                keys: s
                    .postures
                    .as_ref()
                    .map_or_else(Vec::new, |t| key_marks(t, from..to)),
            }
        })
        .filter(|s| s.from < s.to)
        .collect()
}

/// Where the key poses of `track` are reached when it is laid over the frames `segment`, by the
/// engine's own timing ([`PostureTrack::key_times`]).
///
/// An approximation by the natural timing: the go stage also lengthens a transition that would
/// move a joint faster than it allows, and a posture segment that needs more time than its
/// frames makes the motion longer; the marks do not follow either.
pub fn key_marks(track: &PostureTrack, segment: std::ops::Range<usize>) -> Vec<KeyMark> {
    let span = track.frames_within(segment);
    if span.is_empty() || track.keys.is_empty() {
        return Vec::new();
    }
    let seconds = span.len() as f64 / FPS;
    let marks = track
        .key_times(seconds)
        .into_iter()
        .map(|(t, hold, i)| KeyMark {
            frame: span.start as f64 + (t * FPS).min(span.len() as f64),
            name: track.keys[i]
                .script
                .name
                .as_deref()
                .unwrap_or("posture")
                .chars()
                .take(60)
                .collect(),
            hold,
        })
        .collect();
    marks
}

/// The segments as an older link's plan (written for takes without a planner's plan).
fn link_segments(segments: &[Segment]) -> Vec<LinkSegment> {
    segments
        .iter()
        .map(|s| LinkSegment {
            text: s.text.clone(),
            from: s.from,
            to: s.to,
        })
        .collect()
}

/// A link's plan and the segments it shows over a motion of `frames` frames: the planner's
/// plan, else an older link's segments, else one segment over the whole motion with the
/// prompt as its text.
pub fn plan_from_link(
    plan: &LinkPlan,
    prompt: &str,
    frames: usize,
) -> (Option<Plan>, Vec<Segment>) {
    let whole = |text: &str, from, to| Segment {
        text: text.chars().take(500).collect(),
        from,
        to,
        base: String::new(),
        parts: Vec::new(),
        path: None,
        postures: Vec::new(),
        posture_parts: Vec::new(),
        keys: Vec::new(),
    };
    match plan {
        LinkPlan::Planned(plan) => {
            let segments = plan_segments(plan, frames);
            if !segments.is_empty() {
                return (Some(plan.clone()), segments);
            }
        }
        LinkPlan::Segments(segments) if segments.iter().all(|s| s.to <= frames) => {
            return (
                None,
                segments
                    .iter()
                    .map(|s| whole(&s.text, s.from, s.to))
                    .collect(),
            )
        }
        _ => {}
    }
    (None, vec![whole(prompt, 0, frames)])
}

/// A named posture laid on a take: the plan to decode the take's tokens with, and where the
/// posture went.
#[derive(Clone, Debug, PartialEq)]
pub struct PostureEdit {
    pub plan: Plan,
    /// The plan segment that holds the posture.
    pub segment: usize,
    /// The frames it covers (the asked range, cut at the end of that segment).
    pub from: usize,
    pub to: usize,
    /// Whether the asked range went past the segment's end and was cut there.
    pub cut: bool,
    /// Whether the segment already had key poses, which the posture replaces.
    pub replaced: bool,
}

/// The plan of `take` with `script` held on `parts` over the frames `from..to`: the segment
/// in which the range starts (as the engine lays the plan's segments on the take's tokens)
/// gets a posture track of that one key pose covering the range (cut at the segment's end),
/// in place of any track it had. A take without a plan (an older link) cannot take one.
pub fn with_posture(
    take: &Take,
    script: &PostureScript,
    parts: Vec<BodyPart>,
    from: usize,
    to: usize,
) -> Result<PostureEdit, String> {
    let Some(mut plan) = take.plan.clone() else {
        return Err(
            "This motion came from an older link without a plan: generate it again to add a posture."
                .into(),
        );
    };
    if parts.is_empty() {
        return Err("Tick the body parts to hold the posture on first.".into());
    }
    if from >= to {
        return Err("The range must start before it ends.".into());
    }
    let ranges = coma::agents::pipeline::segment_ranges(&plan, &take.motion.tokens);
    let Some(segment) = ranges.iter().position(|r| r.start <= from && from < r.end) else {
        return Err(format!(
            "The range starts at {:.1} s, after the motion ends ({:.1} s).",
            seconds(from),
            seconds(ranges.last().map_or(0, |r| r.end))
        ));
    };
    let range = ranges[segment].clone();
    let end = to.min(range.end);
    if end - from < 2 {
        return Err("The range is too short to hold a posture: choose at least 0.1 s.".into());
    }
    let at = |f: usize| (f - range.start) as f64 / FPS;
    let track = PostureTrack {
        within: Some([at(from), at(end)]),
        ..PostureTrack::holding(parts, script.clone())
    }
    .checked()?;
    let replaced = plan.segments[segment].postures.replace(track).is_some();
    Ok(PostureEdit {
        plan,
        segment,
        from,
        to: end,
        cut: end < to,
        replaced,
    })
}

/// A path drawn on the ground laid on a segment of a take: the plan to decode the take's
/// tokens with (the segment's trajectory is the drawn path), the history's edit, and what
/// the user is told.
#[derive(Clone, Debug, PartialEq)]
pub struct PathEdit {
    pub plan: Plan,
    /// The plan segment that walks the path.
    pub segment: usize,
    /// Its frames (20 fps, from the start of the take).
    pub from: usize,
    pub to: usize,
    /// The drawn path as the plan carries it (thinned, rounded to the millimetre).
    pub trajectory: Trajectory,
    /// Length of the drawn line, metres.
    pub drawn_m: f64,
    /// Length the engine gives the path on the segment (see
    /// [`coma::trajectory::path_length`]), metres; `None` when the take has no features to
    /// measure (the engine still scales it, the message just cannot say to what).
    pub walk_m: Option<f64>,
    /// The segment barely moves, so the path is walked at the default walking speed.
    pub default_speed: bool,
    /// The path the segment had before (which the drawn one replaces), described.
    pub replaced: Option<String>,
    /// Segments in the plan, for naming the segment only when there are several.
    pub segments: usize,
}

impl PathEdit {
    /// What happened, for the status line: the drawn length, what it was scaled to and why.
    pub fn line(&self) -> String {
        let mut line = format!("path drawn: {:.1} m", self.drawn_m);
        match self.walk_m {
            Some(walk) if self.default_speed => line.push_str(&format!(
                ", walked at an even pace over {walk:.1} m (the motion barely moves on its own)"
            )),
            Some(walk) => line.push_str(&format!(", scaled to the walk's {walk:.1} m")),
            None => line.push_str(", scaled to the distance the motion walks"),
        }
        if self.segments > 1 {
            line.push_str(&format!(" in segment {}", self.segment + 1));
        }
        if let Some(old) = &self.replaced {
            line.push_str(&format!(", in place of {old}"));
        }
        line
    }

    /// The history's record of the edit (a link carries it; the plan carries the points).
    pub fn edit(&self, seed: u64) -> Edit {
        Edit {
            kind: EditKind::Trajectory,
            text: self.trajectory.describe(),
            from_frame: self.from as u32,
            to_frame: self.to as u32,
            parts: 0,
            seed,
        }
    }
}

/// The plan of `take` with segment `segment` walking `stroke`, the points drawn on the
/// ground (`[x, z]` metres, Y up, the motion starting at the origin facing +Z): thinned to
/// at most [`MAX_DRAWN_POINTS`] points a couple of centimetres apart and checked as a plan's
/// path is. The engine lays it as it lays a typed path: from where the segment starts, turned
/// to its heading there, scaled to the distance it travels. A take without a plan (an older
/// link) cannot take one.
pub fn with_drawn_path(
    take: &Take,
    segment: usize,
    stroke: &[[f64; 2]],
) -> Result<PathEdit, String> {
    let Some(mut plan) = take.plan.clone() else {
        return Err(
            "This motion came from an older link without a plan: generate it again to draw its path."
                .into(),
        );
    };
    let ranges = coma::agents::pipeline::segment_ranges(&plan, &take.motion.tokens);
    let Some(range) = ranges.get(segment).filter(|r| !r.is_empty()).cloned() else {
        return Err(format!(
            "There is no segment {} to draw a path for.",
            segment + 1
        ));
    };
    let points = thin(stroke, MIN_DRAWN_STEP_M, MAX_DRAWN_POINTS);
    let drawn_m =
        check_drawn(&points).map_err(|e| format!("No path laid: {e}. The motion is unchanged."))?;
    let trajectory = Trajectory::Points { points };
    trajectory
        .validate()
        .map_err(|e| format!("No path laid: {e}. The motion is unchanged."))?;
    let rows = take.motion.features.get(range.clone());
    let length = rows
        .filter(|r| r.len() >= 2)
        .map(|r| path_length(r, &MapOptions::default()));
    let replaced = plan.segments[segment]
        .trajectory
        .replace(trajectory.clone())
        .map(|t| t.describe());
    Ok(PathEdit {
        segments: plan.segments.len(),
        plan,
        segment,
        from: range.start,
        to: range.end,
        trajectory,
        drawn_m,
        walk_m: length.map(|l| l.length_m),
        default_speed: length.is_some_and(|l| l.slow),
        replaced,
    })
}

/// One line for an edit of the history, as the Steps panel lists it.
pub fn edit_line(edit: &Edit) -> String {
    let span = format!(
        "{:.1}–{:.1} s",
        seconds(edit.from_frame as usize),
        seconds(edit.to_frame as usize)
    );
    let parts: Vec<&str> = BodyPart::ALL
        .iter()
        .enumerate()
        .filter(|(i, _)| edit.parts & (1 << i) != 0)
        .map(|(_, p)| p.name())
        .collect();
    let text: String = edit.text.chars().take(200).collect();
    match edit.kind {
        EditKind::Generate => format!("generate \"{text}\" ({span})"),
        EditKind::BodyParts => format!("{} ← \"{text}\" ({span})", parts.join(", ")),
        EditKind::InBetween => format!("regenerate {span} from \"{text}\""),
        EditKind::Regenerate => format!("regenerate the segment {span} from \"{text}\""),
        EditKind::Blend => format!("blend the join {span}"),
        EditKind::Trajectory => format!("path \"{text}\" ({span})"),
    }
}

/// A short stable hash of the joints (FNV-1a over the f32 bits): two pages showing the same
/// motion show the same hash.
pub fn joints_hash(joints: &[[[f32; 3]; 22]]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for v in joints.iter().flatten().flatten() {
        for b in v.to_bits().to_le_bytes() {
            h ^= b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    format!("{h:016x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn legacy(text: &str, from: usize, to: usize) -> Segment {
        Segment {
            text: text.into(),
            from,
            to,
            base: String::new(),
            parts: Vec::new(),
            path: None,
            postures: Vec::new(),
            posture_parts: Vec::new(),
            keys: Vec::new(),
        }
    }

    #[test]
    fn older_plans_round_trip_and_bad_plans_fall_back_to_one_segment() {
        let segments = vec![legacy("walk forward", 0, 80), legacy("bow", 80, 120)];
        let plan = LinkPlan::Segments(link_segments(&segments));
        assert_eq!(plan_from_link(&plan, "p", 120), (None, segments.clone()));
        // A segment beyond the motion is not believed.
        assert_eq!(
            plan_from_link(&plan, "the prompt", 100),
            (None, vec![legacy("the prompt", 0, 100)])
        );
        assert_eq!(
            plan_from_link(&LinkPlan::None, "the prompt", 60),
            (None, vec![legacy("the prompt", 0, 60)])
        );
    }

    #[test]
    fn planned_segments_lie_where_the_pipeline_puts_them() {
        let plan = coma::agents::planner::offline::plan(
            "A person walks forward waving the left hand, then walks on turning right and bows",
            None,
        );
        // 4 + 5 + 3 s of token steps, as blended.
        let tokens = coma::model::tokens::MotionTokens::new(vec![vec![vec![0; 60]; 1]; 4]).unwrap();
        let ranges = coma::agents::pipeline::segment_ranges(&plan, &tokens);
        let segments = plan_segments(&plan, 240);
        let ours: Vec<_> = segments.iter().map(|s| s.from..s.to).collect();
        assert_eq!(ours, ranges);
        assert_eq!(segments[0].parts[0].0, "left arm");
        assert_eq!(segments[1].seconds(), 5.0);
        // While the motion is being made, the plan alone places them.
        assert_eq!(plan_segments(&plan, 0), segments);
        // A shorter motion (a link's) cuts the segments that do not fit.
        assert_eq!(plan_segments(&plan, 100).len(), 2);
        let (read, again) = plan_from_link(&LinkPlan::Planned(plan.clone()), "p", 240);
        assert_eq!((read.as_ref(), again), (Some(&plan), segments));
    }

    fn t_pose() -> PostureScript {
        coma::posture::library::Library::builtin()
            .get("T-pose")
            .expect("the library has a T-pose")
            .script
            .clone()
    }

    #[test]
    fn key_marks_follow_the_scaled_transitions_and_holds() {
        let mut track = PostureTrack::holding(BodyPart::ALL.to_vec(), t_pose());
        track.keys[0].script.hold = 1.0;
        track.keys[0].transition = 0.5;
        // 4 s of frames for 1.5 s of key poses: the hold takes the spare time.
        let marks = key_marks(&track, 40..120);
        assert_eq!(marks.len(), 1);
        assert_eq!(marks[0].frame, 40.0 + 10.0);
        assert!((marks[0].hold - 3.5).abs() < 1e-9, "{marks:?}");
        assert_eq!(marks[0].name, "T-pose");
        // Too little time shortens everything alike.
        let marks = key_marks(&track, 0..15);
        assert!((marks[0].frame - 5.0).abs() < 1e-9, "{marks:?}");
        // Repetitions come back to the start between cycles; a range within the segment.
        track.repeat = 2;
        track.within = Some([1.0, 3.0]);
        let marks = key_marks(&track, 40..120);
        let frames: Vec<f64> = marks.iter().map(|m| m.frame).collect();
        // 2 s for 2 × (0.5 + 1.0) + 2 × 0.5 s back = 4 s: everything at half speed.
        assert_eq!(frames, vec![60.0 + 5.0, 60.0 + 5.0 + 10.0 + 5.0 + 5.0]);
    }

    #[test]
    fn a_named_posture_goes_into_the_segment_where_its_range_starts() {
        let plan = coma::agents::planner::offline::plan(
            "A person walks forward waving the left hand, then walks on turning right and bows",
            None,
        );
        let tokens = coma::model::tokens::MotionTokens::new(vec![vec![vec![0; 60]; 1]; 4]).unwrap();
        let motion = Motion {
            tokens,
            joints: vec![[[0.0; 3]; 22]; 240],
            features: Vec::new(),
        };
        let take = Take::new(motion, "p".into(), 0, Vec::new(), Some(plan), Vec::new());
        let arms = vec![BodyPart::LeftArm, BodyPart::RightArm];
        // Segment 2 covers 80..180: the range is cut at its end.
        let edit = with_posture(&take, &t_pose(), arms.clone(), 90, 300).unwrap();
        assert_eq!(
            (edit.segment, edit.from, edit.to, edit.cut),
            (1, 90, 180, true)
        );
        assert!(!edit.replaced);
        let track = edit.plan.segments[1].postures.as_ref().unwrap();
        assert_eq!(track.within, Some([0.5, 5.0]));
        assert_eq!(track.parts, arms);
        // The plan view and the timeline show it.
        let shown = plan_segments(&edit.plan, 240);
        assert_eq!(shown[1].posture_parts, vec!["left arm", "right arm"]);
        assert!(
            shown[1].postures[0].starts_with("key 1 (T-pose"),
            "{:?}",
            shown[1].postures
        );
        assert!(shown[1]
            .keys
            .iter()
            .all(|k| (90.0..180.0).contains(&k.frame)));
        assert!(shown[0].postures.is_empty() && shown[0].keys.is_empty());
        // Once more on the same segment: the posture replaces the one before.
        let mut again = take.clone();
        again.plan = Some(edit.plan);
        assert!(
            with_posture(&again, &t_pose(), arms.clone(), 100, 120)
                .unwrap()
                .replaced
        );
        // Ranges that cannot take a posture.
        assert!(with_posture(&take, &t_pose(), arms.clone(), 240, 260).is_err());
        assert!(with_posture(&take, &t_pose(), arms.clone(), 50, 50).is_err());
        assert!(with_posture(&take, &t_pose(), Vec::new(), 0, 50).is_err());
        let mut old = take.clone();
        old.plan = None;
        assert!(with_posture(&old, &t_pose(), arms, 0, 50).is_err());
    }

    /// A take of the three-segment plan, walking 0.05 m a frame (1 m/s).
    fn walking_take() -> Take {
        let plan = coma::agents::planner::offline::plan(
            "A person walks forward waving the left hand, then walks on turning right and bows",
            None,
        );
        let tokens = coma::model::tokens::MotionTokens::new(vec![vec![vec![0; 60]; 1]; 4]).unwrap();
        let mut row = [0f32; coma::features::FEATURE_DIM];
        row[2] = 0.05;
        let motion = Motion {
            tokens,
            joints: vec![[[0.0; 3]; 22]; 240],
            features: vec![row; 240],
        };
        Take::new(motion, "p".into(), 4, Vec::new(), Some(plan), Vec::new())
    }

    #[test]
    fn a_drawn_path_goes_into_its_segment_and_says_how_it_was_scaled() {
        let take = walking_take();
        // An L drawn every centimetre: 2 m forward, 1 m to the right.
        let mut stroke: Vec<[f64; 2]> = (0..=200).map(|i| [0.0, 0.01 * i as f64]).collect();
        stroke.extend((1..=100).map(|i| [-0.01 * i as f64, 2.0]));
        let edit = with_drawn_path(&take, 1, &stroke).unwrap();
        assert_eq!((edit.segment, edit.from, edit.to), (1, 80, 180));
        let Trajectory::Points { points } = &edit.trajectory else {
            panic!("{:?}", edit.trajectory)
        };
        assert!(points.len() < 200 && points.len() > 100, "{}", points.len());
        assert_eq!(
            edit.plan.segments[1].trajectory.as_ref(),
            Some(&edit.trajectory)
        );
        assert_eq!(
            edit.plan.segments[0],
            take.plan.as_ref().unwrap().segments[0]
        );
        assert!((edit.drawn_m - 3.0).abs() < 0.01, "{}", edit.drawn_m);
        // 99 steps of 5 cm in the segment's frames.
        assert!(
            (edit.walk_m.unwrap() - 4.95).abs() < 1e-4,
            "{:?}",
            edit.walk_m
        );
        assert!(!edit.default_speed);
        assert_eq!(
            edit.line(),
            "path drawn: 3.0 m, scaled to the walk's 5.0 m in segment 2"
        );
        let record = edit.edit(9);
        assert_eq!(record.kind, EditKind::Trajectory);
        assert_eq!(
            edit_line(&record),
            format!(
                "path \"a drawn path (3.0 m, {} points)\" (4.0–9.0 s)",
                points.len()
            )
        );
        // The plan as a link carries it reads back the same, points and all.
        let link = coma::share::decode(&coma::share::encode(
            &Take {
                plan: Some(edit.plan.clone()),
                ..take.clone()
            }
            .shared([1; 8]),
        ))
        .unwrap();
        assert_eq!(link.plan.plan(), Some(&edit.plan));
        // Drawn again on the same segment: the new path replaces the old one.
        let mut again = take.clone();
        again.plan = Some(edit.plan.clone());
        let second = with_drawn_path(&again, 1, &stroke[..150]).unwrap();
        assert_eq!(
            second.replaced.as_deref(),
            Some(edit.trajectory.describe().as_str())
        );
        assert!(second.line().contains("in place of a drawn path (3.0 m"));
    }

    #[test]
    fn strokes_that_are_no_path_leave_a_clear_message() {
        let take = walking_take();
        let short = with_drawn_path(&take, 0, &[[0.0, 0.0], [0.1, 0.1]]).unwrap_err();
        assert!(
            short.contains("too short") && short.contains("unchanged"),
            "{short}"
        );
        let click = with_drawn_path(&take, 0, &[[1.0, 1.0], [1.001, 1.0]]).unwrap_err();
        assert!(click.contains("at least 2 points"), "{click}");
        assert!(with_drawn_path(&take, 0, &[]).is_err());
        let far = with_drawn_path(&take, 0, &[[0.0, 0.0], [0.0, 500.0]]).unwrap_err();
        assert!(far.contains("beyond"), "{far}");
        assert!(with_drawn_path(&take, 7, &[[0.0, 0.0], [0.0, 1.0]])
            .unwrap_err()
            .contains("no segment 8"));
        let mut old = take.clone();
        old.plan = None;
        assert!(with_drawn_path(&old, 0, &[[0.0, 0.0], [0.0, 1.0]])
            .unwrap_err()
            .contains("older link"));
        // A motion that stands still walks the path at the default speed, and says so.
        let mut still = take.clone();
        for row in &mut still.motion.features {
            row[2] = 0.0;
        }
        let edit = with_drawn_path(&still, 0, &[[0.0, 0.0], [0.0, 1.0]]).unwrap();
        assert!(edit.default_speed);
        assert!(
            edit.line().contains("even pace over 4.7 m"),
            "{}",
            edit.line()
        );
    }

    #[test]
    fn a_link_keeps_the_run_record() {
        let motion = Motion {
            tokens: coma::model::tokens::MotionTokens::new(vec![vec![vec![7; 5]; 2]; 4]).unwrap(),
            joints: vec![[[0.0; 3]; 22]; 20],
            features: Vec::new(),
        };
        let mut take = Take::new(
            motion.clone(),
            "a person bows".into(),
            3,
            Vec::new(),
            None,
            Vec::new(),
        );
        assert_eq!(take.record(), None, "a take without a run records nothing");
        take.steps = vec![
            "segment 1: generated".into(),
            "segment 1, review round 1: kept".into(),
        ];
        take.notes = vec!["'bows' is read as 'a person bows'".into()];
        take.scores = vec![SegmentScores {
            before: Some(28.5),
            after: Some(33.0),
            rounds: 1,
            kept: 1,
        }];
        let link = coma::share::decode(&coma::share::encode(&take.shared([1; 8]))).unwrap();
        let mut opened = Take::new(
            motion.clone(),
            link.prompt,
            link.seed,
            link.history,
            None,
            Vec::new(),
        );
        opened.restore_record(link.record);
        assert_eq!(
            (&opened.steps, &opened.notes, &opened.scores),
            (&take.steps, &take.notes, &take.scores)
        );
    }

    #[test]
    fn every_edit_has_a_line() {
        let edit = |kind, parts| Edit {
            kind,
            text: "a person waves the left hand".into(),
            from_frame: 80,
            to_frame: 180,
            parts,
            seed: 1,
        };
        assert_eq!(
            edit_line(&edit(EditKind::BodyParts, 0b0101)),
            "left arm, left leg ← \"a person waves the left hand\" (4.0–9.0 s)"
        );
        assert_eq!(
            edit_line(&edit(EditKind::Blend, 0b1111)),
            "blend the join 4.0–9.0 s"
        );
    }

    #[test]
    fn the_joints_hash_sees_every_value() {
        let a = vec![[[0.0f32; 3]; 22]; 3];
        let mut b = a.clone();
        assert_eq!(joints_hash(&a), joints_hash(&b));
        b[2][21][1] = 1e-6;
        assert_ne!(joints_hash(&a), joints_hash(&b));
    }
}
