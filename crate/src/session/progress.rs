//! The lines the engine reports while it works, and how many steps a run takes, so the page's
//! Steps panel and progress bar and the command line's log say the same thing.

use super::command::Progress;
use crate::agents::pipeline::{self, RunEvent};
use crate::agents::planner::llm::PlanEvent;
use crate::plan::Plan;

/// Counts the steps of one command and reports each as a [`Progress::Step`].
pub(super) struct Steps<'a> {
    done: u64,
    total: u64,
    report: &'a mut dyn FnMut(Progress),
}

impl<'a> Steps<'a> {
    pub fn new(report: &'a mut dyn FnMut(Progress)) -> Steps<'a> {
        Steps {
            done: 0,
            total: 0,
            report,
        }
    }

    /// Steps reported so far.
    pub fn done(&self) -> u64 {
        self.done
    }

    /// Raises the expected total to `more` steps after the ones done so far.
    pub fn expect(&mut self, more: u64) {
        self.total = self.done + more;
    }

    /// Reports one step.
    pub fn step(&mut self, line: String) {
        self.done += 1;
        self.total = self.total.max(self.done);
        (self.report)(Progress::Step {
            line,
            done: self.done,
            total: self.total,
        });
    }

    /// Reports anything else (the plan).
    pub fn report(&mut self, progress: Progress) {
        (self.report)(progress);
    }
}

/// The planner's steps as the LLM planner reports them, for a plan made in one go (the
/// built-in planner, a given plan), so both show the same lines.
pub fn plan_events(plan: &Plan) -> Vec<PlanEvent> {
    let mut events = vec![
        PlanEvent::Rewritten(plan.rewritten.clone()),
        PlanEvent::Segmented(
            plan.segments
                .iter()
                .map(|s| (s.text.clone(), s.seconds))
                .collect(),
        ),
    ];
    events.extend(
        plan.segments
            .iter()
            .enumerate()
            .map(|(i, s)| PlanEvent::Decomposed(i, Box::new(s.clone()))),
    );
    events
}

/// One progress line for a planner step.
pub fn plan_event_line(event: &PlanEvent) -> String {
    match event {
        PlanEvent::Rewritten(text) => format!("plan: \"{text}\""),
        PlanEvent::Segmented(pieces) => {
            let list: Vec<String> = pieces
                .iter()
                .map(|(text, seconds)| format!("\"{text}\" ({seconds:.1} s)"))
                .collect();
            format!("plan: {} segment(s): {}", pieces.len(), list.join(", "))
        }
        PlanEvent::Decomposed(index, segment) => {
            let mut line = format!("plan: segment {}: base \"{}\"", index + 1, segment.base);
            for (part, text) in segment.parts.edits() {
                line.push_str(&format!(", {} ← \"{text}\"", part.name()));
            }
            if let Some(path) = &segment.trajectory {
                line.push_str(&format!(", path: {}", path.describe()));
            }
            line
        }
    }
}

/// One progress line for a step of the loop.
pub fn run_event_line(event: &RunEvent) -> String {
    pipeline::describe_event(event)
}

/// Steps a run of `plan` reports at most: per segment its generation, one edit per distinct
/// part instruction and `rounds` reviews, then the blend, then one per clip that generates
/// motion.
pub fn run_steps(plan: &Plan, rounds: usize) -> u64 {
    let per_segment: usize = plan
        .segments
        .iter()
        .map(|s| {
            let mut texts: Vec<String> = s.parts.edits().into_iter().map(|(_, t)| t).collect();
            texts.sort();
            texts.dedup();
            1 + texts.len() + if s.is_posture_segment() { 0 } else { rounds }
        })
        .sum();
    let clips = plan.clips.iter().filter(|c| c.postures.is_none()).count();
    (per_segment + usize::from(plan.segments.len() > 1) + clips) as u64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::agents::planner::offline;

    #[test]
    fn every_planner_step_has_a_line() {
        let plan = offline::plan(
            "A person walks forward waving the left hand, then turns right and bows",
            None,
        );
        let lines: Vec<String> = plan_events(&plan).iter().map(plan_event_line).collect();
        assert_eq!(lines.len(), 2 + 3);
        assert!(lines[1].starts_with("plan: 3 segment(s)"), "{}", lines[1]);
        assert!(lines[2].contains("left arm ← "), "{}", lines[2]);
        // Generate, one left-arm edit, two reviews; the turn on the spot (key poses, not
        // reviewed); the bow (generate, two reviews); blend.
        assert_eq!(run_steps(&plan, 2), 4 + 1 + 3 + 1);
        assert_eq!(run_steps(&offline::plan("a person bows", None), 0), 1);
    }

    #[test]
    fn steps_count_up_and_never_report_fewer_total_than_done() {
        let mut seen = Vec::new();
        let mut report = |p: Progress| seen.push(p);
        let mut steps = Steps::new(&mut report);
        steps.expect(2);
        steps.step("a".into());
        steps.step("b".into());
        steps.step("c".into());
        assert_eq!(steps.done(), 3);
        let last = seen.last().unwrap().clone();
        assert_eq!(
            last,
            Progress::Step {
                line: "c".into(),
                done: 3,
                total: 3
            }
        );
    }
}
