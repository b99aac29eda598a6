//! What the worker does around the core crate's planner and pipeline that needs no browser:
//! reading a plan from a link or a message, fitting it to the length the user asked for,
//! turning planner events into progress lines, and summing up a run's review.

use crate::messages::SegmentScores;
use coma::agents::pipeline::Run;
use coma::agents::plan::{clamp_seconds, Plan, MAX_SEGMENTS};
use coma::agents::planner::llm::PlanEvent;

/// A plan from JSON that did not come from this worker's planner (a share link, the page):
/// it must have 1 to [`MAX_SEGMENTS`] segments of finite length. Durations are clamped
/// again, since the link's author may not have.
pub fn parse_plan(json: &str) -> Result<Plan, String> {
    let mut plan: Plan =
        serde_json::from_str(json).map_err(|e| format!("the plan does not read: {e}"))?;
    if plan.segments.is_empty() || plan.segments.len() > MAX_SEGMENTS {
        return Err(format!(
            "a plan has 1 to {MAX_SEGMENTS} segments, this one {}",
            plan.segments.len()
        ));
    }
    for s in &mut plan.segments {
        s.seconds = clamp_seconds(s.seconds).ok_or("a segment has no length")?;
    }
    Ok(plan)
}

/// Scales the segments' durations so the plan lasts about `seconds` in all (each segment
/// still within what one generation makes), keeping their proportions: the user's Seconds
/// field overrides the planner's estimates, not its split.
pub fn fit_seconds(plan: &mut Plan, seconds: f64) {
    let planned = plan.seconds();
    if !seconds.is_finite() || seconds <= 0.0 || planned <= 0.0 {
        return;
    }
    let factor = seconds / planned;
    for s in &mut plan.segments {
        s.seconds = clamp_seconds(s.seconds * factor).unwrap_or(s.seconds);
    }
    // Only a length other than the one asked for is worth a note.
    let got = plan.seconds();
    if (got - seconds).abs() > 0.05 {
        plan.notes.push(format!(
            "asked for {seconds:.1} s; {} segment(s) of 2 to 9.8 s make {got:.1} s",
            plan.segments.len()
        ));
    }
}

/// The planner's steps as the LLM planner reports them, for a plan the built-in planner made
/// in one go, so both show the same lines.
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
            .map(|(i, s)| PlanEvent::Decomposed(i, s.clone())),
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

/// Steps a run of `plan` reports at most: per segment its generation, one edit per distinct
/// part instruction and `rounds` reviews, then the blend. (Reviews stop early when there is
/// nothing to correct, so the count is an upper bound for the progress bar.)
pub fn run_steps(plan: &Plan, rounds: usize) -> u64 {
    let per_segment: usize = plan
        .segments
        .iter()
        .map(|s| {
            let mut texts: Vec<String> = s.parts.edits().into_iter().map(|(_, t)| t).collect();
            texts.sort();
            texts.dedup();
            1 + texts.len() + rounds
        })
        .sum();
    (per_segment + usize::from(plan.segments.len() > 1)) as u64
}

/// How the review scored each segment of a run.
pub fn scores(run: &Run) -> Vec<SegmentScores> {
    run.segments
        .iter()
        .map(|s| SegmentScores {
            before: s.score_before,
            after: s.score_after,
            rounds: s.rounds.len(),
            kept: s.rounds.iter().filter(|r| r.accepted).count(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use coma::agents::planner::offline;

    #[test]
    fn plans_from_outside_are_checked() {
        let plan = offline::plan("a person walks forward, then bows", None);
        let json = serde_json::to_string(&plan).unwrap();
        assert_eq!(parse_plan(&json).unwrap(), plan);
        let mut long = plan.clone();
        long.segments[0].seconds = 1e9;
        assert_eq!(
            parse_plan(&serde_json::to_string(&long).unwrap())
                .unwrap()
                .segments[0]
                .seconds,
            9.8
        );
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
        ] {
            assert!(parse_plan(&bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn the_seconds_asked_for_scale_the_plan() {
        let mut one = offline::plan("a person walks forward", None);
        fit_seconds(&mut one, 9.8);
        assert_eq!(one.segments[0].seconds, 9.8);
        let mut three = offline::plan(
            "A person walks forward waving the left hand, then turns right and bows",
            None,
        );
        assert_eq!(three.segments.len(), 3);
        let before = three.notes.len();
        fit_seconds(&mut three, 9.0);
        assert!((three.seconds() - 9.0).abs() < 1e-9, "{}", three.seconds());
        assert_eq!(three.notes.len(), before);
        // Three segments cannot be shorter than 3 × 2 s; the plan says so.
        fit_seconds(&mut three, 3.0);
        assert_eq!(three.seconds(), 6.0);
        assert!(three.notes.last().unwrap().contains("make 6.0 s"));
        let planned = three.clone();
        fit_seconds(&mut three, f64::NAN);
        assert_eq!(three, planned);
    }

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
        // Generate, one left-arm edit, two reviews; two × (generate, two reviews); blend.
        assert_eq!(run_steps(&plan, 2), 4 + 3 + 3 + 1);
        assert_eq!(run_steps(&offline::plan("a person bows", None), 0), 1);
    }
}
