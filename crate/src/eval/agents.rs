//! The agents measured: how well the built-in planner reads the prompt set's temporal
//! structure, what the review loop does to text–motion similarity, and how closely a planned
//! circle is walked.

use crate::agents::llm::UreqTransport;
use crate::agents::planner::timeline_set::{self, TimelineFigures};
use crate::agents::planner::{meaning, offline, prompt_set};
use crate::executor::block_on;
use crate::session::{Command, Llm, Outcome, RunOutcome, Session};
use crate::trajectory::{circle_report, root_path, CircleReport};
use serde::Serialize;

/// The built-in planner on the prompt set.
#[derive(Clone, Debug, Serialize)]
pub struct PlannerFigures {
    pub prompts: usize,
    pub segment_rate: f64,
    pub parts_rate: f64,
    pub path_rate: f64,
}

/// The evaluator's 0–100 similarity of each segment's text with its motion, before the review
/// loop and after it, over every segment of the prompt set.
#[derive(Clone, Debug, Serialize)]
pub struct ReviewFigures {
    pub prompts: usize,
    pub segments: usize,
    /// Review rounds allowed per segment (K).
    pub rounds: usize,
    pub mean_before: f64,
    pub mean_after: f64,
    /// Segments whose similarity rose.
    pub improved: usize,
    /// Review rounds whose corrections were kept, over all segments.
    pub kept_rounds: usize,
}

/// Everything measured of the agents.
#[derive(Clone, Debug, Default, Serialize)]
pub struct AgentFigures {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub planner: Option<PlannerFigures>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub review: Option<ReviewFigures>,
    /// The built-in planner on the timeline prompt set, clause by clause.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub timeline: Option<(String, TimelineFigures)>,
    /// "a person walks in a circle clockwise", planned, generated and laid on its path.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub circle: Option<CircleReport>,
}

/// The built-in planner over `prompts` for the model whose training vocabulary is
/// `vocabulary` (the actions it lists are planned with the model), with `embed` mapping
/// unknown movements.
pub fn planner_figures(
    prompts: &[prompt_set::SetPrompt],
    vocabulary: Option<&crate::dataset::Vocabulary>,
    embed: Option<offline::Embedder>,
) -> PlannerFigures {
    let report =
        prompt_set::score_prompts(prompts, &mut |p| offline::plan_for(p, vocabulary, embed));
    PlannerFigures {
        prompts: report.prompts,
        segment_rate: report.segment_rate,
        parts_rate: report.parts_rate,
        path_rate: report.path_rate,
    }
}

/// The built-in planner on the timeline prompt set at `path`, with the session's vocabulary
/// and sentence encoder (which the clause scorer needs to match by meaning).
pub fn timeline_figures(
    session: &Session,
    path: &std::path::Path,
) -> anyhow::Result<TimelineFigures> {
    let set = timeline_set::load(path)?;
    let embed = |s: &str| session.model().text.encode(&[s])[0].to_vec();
    let similarity = meaning::embedding_similarity(&embed);
    let matcher = meaning::Matcher::new(&similarity, meaning::SAME_MOVEMENT_MIN_SIMILARITY);
    let report = timeline_set::score(
        &set,
        &mut |p| offline::plan_for(p, session.vocabulary(), Some(&embed)),
        &matcher,
    );
    Ok(report.figures)
}

/// One run of the engine with no LLM (built-in planner, evaluator as judge).
fn run(session: &Session, prompt: &str, rounds: usize, seed: u64) -> anyhow::Result<RunOutcome> {
    let command = Command::Run {
        prompt: prompt.to_string(),
        seed,
        rounds,
        seconds: None,
        plan: None,
    };
    match block_on(session.execute(command, &Llm::<UreqTransport>::Off, &mut |_| {}))? {
        Outcome::Run(run) => Ok(*run),
        _ => anyhow::bail!("the engine answered a run with something else"),
    }
}

/// Runs the whole loop (built-in planner, evaluator as judge) on every prompt and compares
/// each segment's similarity before and after review.
pub fn review_figures(
    session: &Session,
    prompts: &[prompt_set::SetPrompt],
    rounds: usize,
    seed: u64,
    log: &dyn Fn(&str),
) -> anyhow::Result<ReviewFigures> {
    let (mut before, mut after, mut improved, mut kept) = (Vec::new(), Vec::new(), 0, 0);
    for (i, p) in prompts.iter().enumerate() {
        let run = run(session, &p.prompt, rounds, seed + i as u64)?;
        for s in &run.segments {
            if let (Some(b), Some(a)) = (s.score_before, s.score_after) {
                before.push(b);
                after.push(a);
                improved += (a > b) as usize;
            }
            kept += s.rounds.iter().filter(|r| r.accepted).count();
        }
        log(&format!("review loop: {}/{} prompts", i + 1, prompts.len()));
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    Ok(ReviewFigures {
        prompts: prompts.len(),
        segments: before.len(),
        rounds,
        mean_before: mean(&before),
        mean_after: mean(&after),
        improved,
        kept_rounds: kept,
    })
}

/// Plans and generates "a person walks in a circle clockwise" and measures the root path.
pub fn circle_probe(session: &Session, seed: u64) -> anyhow::Result<Option<CircleReport>> {
    let run = run(session, "a person walks in a circle clockwise", 0, seed)?;
    Ok(run
        .path_notes
        .is_empty()
        .then(|| circle_report(&root_path(&run.motion.features), true)))
}

impl AgentFigures {
    /// Rows for EVAL.md's probe table, then a section on the planner and the review loop.
    pub fn markdown(&self) -> String {
        let mut md = String::new();
        match &self.circle {
            Some(c) => md.push_str(&format!(
                "| \"walk in a circle clockwise\": turned clockwise / total turn | {} / {:.0}° |\n\
                 | \"walk in a circle clockwise\": closure error | {:.3} m |\n\
                 | \"walk in a circle clockwise\": mean distance to the circle | {:.3} m (radius {:.2} m) |\n",
                if c.turned_clockwise { "yes" } else { "no" },
                c.total_turn_deg,
                c.closure_error_m,
                c.mean_radius_error_m,
                c.radius_m
            )),
            None => md.push_str("| trajectory (circle) | not measured (needs SPAM) |\n"),
        }
        md.push_str("\n## Agents\n\n");
        if let Some((set, t)) = &self.timeline {
            md.push_str(&t.markdown(set));
        }
        if let Some(p) = &self.planner {
            md.push_str(&format!(
                "Built-in planner on the {} prompts of `eval/prompts.json`: segment counts match \
                 the prompts' temporal structure in **{:.0} %**, edited body parts in {:.0} %, \
                 requested paths in {:.0} %. The set and the planner's rules were written by the \
                 same team, so this shows the rules cover the set, not how they generalise.\n\n",
                p.prompts,
                100.0 * p.segment_rate,
                100.0 * p.parts_rate,
                100.0 * p.path_rate
            ));
        }
        match &self.review {
            Some(r) => md.push_str(&format!(
                "Review loop (built-in planner, evaluator as judge, K = {}) over {} segments of \
                 the {} prompts: evaluator text–motion similarity **{:.1}** before review, \
                 **{:.1}** after; {} segments improved, {} review rounds kept. The offline judge \
                 keeps a correction only when the evaluator does not score it lower, so the \
                 loop cannot lower this figure; it shows how much it raises it.\n",
                r.rounds,
                r.segments,
                r.prompts,
                r.mean_before,
                r.mean_after,
                r.improved,
                r.kept_rounds
            )),
            None => md.push_str("Review loop: not measured (needs SPAM).\n"),
        }
        md
    }
}
