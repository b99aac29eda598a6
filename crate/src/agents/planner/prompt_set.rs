//! The committed prompt set (`eval/prompts.json`) and how well a planner reads its temporal
//! structure.

use crate::plan::Plan;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One prompt with what a reader sees in it.
#[derive(Clone, Debug, Deserialize)]
pub struct SetPrompt {
    pub prompt: String,
    /// Consecutive movements in the prompt.
    pub segments: usize,
    /// Arms or legs with their own instruction ("left arm").
    #[serde(default)]
    pub parts: Vec<String>,
    /// The requested root path, if any.
    #[serde(default)]
    pub path: Option<String>,
}

#[derive(Deserialize)]
struct SetFile {
    prompts: Vec<SetPrompt>,
}

/// Reads a prompt set.
pub fn load(path: &Path) -> anyhow::Result<Vec<SetPrompt>> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?;
    let set: SetFile = serde_json::from_str(&text)
        .map_err(|e| anyhow::anyhow!("{} is not a prompt set: {e}", path.display()))?;
    Ok(set.prompts)
}

/// How one prompt was planned.
#[derive(Clone, Debug, Serialize)]
pub struct PromptResult {
    pub prompt: String,
    pub expected_segments: usize,
    pub planned_segments: usize,
    pub expected_parts: Vec<String>,
    pub planned_parts: Vec<String>,
    pub expected_path: bool,
    pub planned_path: bool,
    /// Clauses the planner substituted or left out (its notes say so).
    pub unplanned: Vec<String>,
}

/// A planner over the whole set.
#[derive(Clone, Debug, Serialize)]
pub struct SetReport {
    pub prompts: usize,
    /// Fraction of prompts whose segment count matches.
    pub segment_rate: f64,
    /// Fraction whose edited parts match.
    pub parts_rate: f64,
    /// Fraction where a path was planned exactly when one was asked for.
    pub path_rate: f64,
    /// Fraction of prompts with no clause substituted or left out.
    pub planned_rate: f64,
    pub results: Vec<PromptResult>,
}

impl SetReport {
    /// A text table with the mismatches and the rates.
    pub fn table(&self) -> String {
        let mut out = String::new();
        for r in &self.results {
            let mark = if r.planned_segments == r.expected_segments {
                " "
            } else {
                "✗"
            };
            out += &format!(
                "{mark} {}/{} segments  {}\n",
                r.planned_segments, r.expected_segments, r.prompt
            );
            for u in &r.unplanned {
                out += &format!("    unplanned: {u}\n");
            }
        }
        out += &format!(
            "segment counts match in {:.0} % of {} prompts; no clause unplanned in {:.0} %; part \
             edits {:.0} %; paths {:.0} %\n",
            100.0 * self.segment_rate,
            self.prompts,
            100.0 * self.planned_rate,
            100.0 * self.parts_rate,
            100.0 * self.path_rate
        );
        out
    }
}

/// The consecutive movements of a plan: one per segment, except that a posture track played
/// several times (squats × 3, five push-ups) counts each time, as a reader counts them.
pub fn movements(plan: &Plan) -> usize {
    plan.segments
        .iter()
        .map(|s| s.postures.as_ref().map_or(1, |t| t.repeat as usize))
        .sum()
}

/// The body parts a plan edits, sorted by name.
pub fn edited_parts(plan: &Plan) -> Vec<String> {
    // Every clip of the body-part tracks: the segments' own instructions, and the plan's
    // clips, whether an instruction or a place held ("with her right arm raised above her
    // head" holds the arm up over the walk).
    let mut parts: Vec<String> = plan
        .part_clips()
        .iter()
        .flat_map(|c| c.parts.iter().map(|p| p.name().to_string()))
        .collect();
    parts.sort();
    parts.dedup();
    parts
}

/// Plans every prompt of the set at `path` with `planner` and compares.
pub fn score(path: &Path, mut planner: impl FnMut(&str) -> Plan) -> anyhow::Result<SetReport> {
    Ok(score_prompts(&load(path)?, &mut planner))
}

/// [`score`] over prompts already read.
pub fn score_prompts(prompts: &[SetPrompt], planner: &mut dyn FnMut(&str) -> Plan) -> SetReport {
    let results: Vec<PromptResult> = prompts
        .iter()
        .map(|p| {
            let plan = planner(&p.prompt);
            let mut expected_parts = p.parts.clone();
            expected_parts.sort();
            PromptResult {
                prompt: p.prompt.clone(),
                expected_segments: p.segments,
                planned_segments: movements(&plan),
                expected_parts,
                planned_parts: edited_parts(&plan),
                expected_path: p.path.is_some(),
                planned_path: plan.segments.iter().any(|s| s.trajectory.is_some()),
                unplanned: plan
                    .notes
                    .iter()
                    .filter(|n| super::offline::is_unplanned_note(n))
                    .cloned()
                    .collect(),
            }
        })
        .collect();
    let n = results.len().max(1) as f64;
    let rate =
        |f: &dyn Fn(&PromptResult) -> bool| results.iter().filter(|r| f(r)).count() as f64 / n;
    SetReport {
        prompts: results.len(),
        segment_rate: rate(&|r| r.planned_segments == r.expected_segments),
        parts_rate: rate(&|r| r.planned_parts == r.expected_parts),
        path_rate: rate(&|r| r.planned_path == r.expected_path),
        planned_rate: rate(&|r| r.unplanned.is_empty()),
        results,
    }
}
