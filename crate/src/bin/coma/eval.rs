//! `coma eval`: the field's metrics, the control probes and the agents' figures, written to
//! EVAL.md and eval.json.

use crate::common::ModelArgs;
use anyhow::{Context, Result};
use clap::Args;
use coma::eval::run::{evaluate, AgentEvalOptions, EvalOptions};
use coma::model::generate::SamplingOptions;
use coma::model::prior::PriorOptions;
use std::path::PathBuf;

#[derive(Args)]
pub struct EvalArgs {
    /// Folder with evaluator.json and evaluator.bpk.
    #[arg(long, default_value = "static/models")]
    evaluator: PathBuf,
    #[arg(long, default_value = "data/coma")]
    data: PathBuf,
    /// The split measured: test for the report, val to choose sampling options without
    /// looking at the test motions.
    #[arg(long, default_value = "test")]
    split: coma::dataset::Split,
    /// Guidance scale of the base transformer in the spam row (the review loop and the probes
    /// sample as the engine does).
    #[arg(long, default_value_t = SamplingOptions::default().base_guidance)]
    guidance: f32,
    /// Softmax temperature of SPAM's sampling in the spam row (0 takes the most
    /// likely code).
    #[arg(long, default_value_t = SamplingOptions::default().temperature)]
    temperature: f32,
    /// Softmax temperature of the residual layers' codes in the spam row (0 takes the most
    /// likely code).
    #[arg(long, default_value_t = SamplingOptions::default().residual_temperature)]
    residual_temperature: f32,
    /// Sample each code only among the K most likely in the spam row (default: all).
    #[arg(long)]
    top_k: Option<usize>,
    /// Share of the retrieved training motion's tokens that the spam row's motions keep
    /// (0 generates from the text alone); without it, the model's own setting (spam.json).
    #[arg(long)]
    prior_keep: Option<f32>,
    /// Least caption similarity for the retrieval prior to apply in the spam row, with
    /// --prior-keep.
    #[arg(long, default_value_t = PriorOptions::default().min_similarity, requires = "prior_keep")]
    prior_min_similarity: f32,
    /// Repetitions (each with fresh captions and seeds).
    #[arg(long, default_value_t = 10)]
    repeats: usize,
    /// Test motions per repetition (whole batches of 32).
    #[arg(long, default_value_t = 1024)]
    motions: usize,
    /// Captions × samples for SPAM's multimodality.
    #[arg(long, default_value_t = 32)]
    multimodality_texts: usize,
    #[arg(long, default_value_t = 10)]
    multimodality_samples: usize,
    /// Seeds per prompt of the left/right probe.
    #[arg(long, default_value_t = 20)]
    probe_seeds: u64,
    /// Leave SPAM out (real and retrieval rows only).
    #[arg(long)]
    no_spam: bool,
    /// Prompt set for the planner and the review loop.
    #[arg(long, default_value = "eval/prompts.json")]
    prompts: PathBuf,
    /// Timeline prompt set for the planner, scored clause by clause.
    #[arg(long, default_value = "eval/timeline_prompts.json")]
    timeline_prompts: PathBuf,
    /// Review rounds (K) of the review loop's measurements (the spam_review row and the
    /// prompt set); 0 skips them.
    #[arg(long, default_value_t = 2)]
    review_rounds: usize,
    /// Repetitions the spam_review row is measured on (the first ones; all if absent): a
    /// reviewed motion costs several generations.
    #[arg(long)]
    review_repeats: Option<usize>,
    #[arg(long, default_value = "EVAL.md")]
    markdown: PathBuf,
    #[arg(long, default_value = "eval.json")]
    json: PathBuf,
    #[command(flatten)]
    model: ModelArgs,
}

pub fn run(args: EvalArgs) -> Result<()> {
    let command = std::env::args()
        .skip(1)
        .fold("coma".to_string(), |acc, a| acc + " " + &a);
    let options = EvalOptions {
        evaluator: &args.evaluator,
        data: &args.data,
        split: args.split,
        sampling: SamplingOptions {
            base_guidance: args.guidance,
            temperature: args.temperature,
            residual_temperature: args.residual_temperature,
            top_k: args.top_k,
            prior: args.prior_keep.map(|keep| PriorOptions {
                keep,
                min_similarity: args.prior_min_similarity,
                ..Default::default()
            }),
            ..Default::default()
        },
        spam: (!args.no_spam).then_some(args.model.models.as_path()),
        protocol: coma::eval::protocol::ProtocolOptions {
            repeats: args.repeats,
            motions: args.motions,
            multimodality_texts: args.multimodality_texts,
            multimodality_samples: args.multimodality_samples,
            ..Default::default()
        },
        probe_seeds: args.probe_seeds,
        agents: AgentEvalOptions {
            prompts: args.prompts,
            timeline_prompts: args.timeline_prompts,
            review_rounds: args.review_rounds,
            review_repeats: args.review_repeats.unwrap_or(args.repeats),
        },
        command,
    };
    let report = evaluate(&options, &|l| eprintln!("{l}"))?;
    let (markdown, json) = (&args.markdown, &args.json);
    std::fs::write(markdown, report.markdown())
        .with_context(|| format!("writing {}", markdown.display()))?;
    std::fs::write(json, report.json()).with_context(|| format!("writing {}", json.display()))?;
    print!("{}", report.markdown());
    Ok(())
}
