//! A take: one state of the page's motion (tokens, joints and features) with what made it
//! (prompt, seed, plan, the edits so far, the segments), as undo keeps it and a share link
//! carries it.

use coma::plan::Plan;
use coma::session::Motion;
use coma::share::{Edit, EditKind, LinkPlan, LinkSegment, RunRecord, SegmentScores, SharedMotion};
use coma::timing::{frames_for_seconds, seconds, FRAMES_PER_TOKEN};

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
            }
        })
        .filter(|s| s.from < s.to)
        .collect()
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

/// One line for an edit of the history, as the Steps panel lists it.
pub fn edit_line(edit: &Edit) -> String {
    let span = format!(
        "{:.1}–{:.1} s",
        seconds(edit.from_frame as usize),
        seconds(edit.to_frame as usize)
    );
    let parts: Vec<&str> = coma::skeleton::BodyPart::ALL
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
            "A person walks forward waving the left hand, then turns right and bows",
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
