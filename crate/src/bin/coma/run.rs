//! `coma run`: the whole CoMA loop from the command line: plan, generate, edit the parts,
//! review, blend and lay the paths.

use crate::common::{llm_of, LlmArgs};
use crate::plan::{print_plan, print_progress};
use anyhow::Result;
use clap::Args;
use coma::agents::pipeline;
use coma::executor::block_on;
use coma::session::{Command, Outcome, Progress, Session};
use std::path::PathBuf;

#[derive(Args)]
pub struct RunArgs {
    /// The prompt.
    prompt: String,
    #[command(flatten)]
    llm: LlmArgs,
    /// Review rounds per segment (K).
    #[arg(long, default_value_t = pipeline::DEFAULT_ROUNDS)]
    rounds: usize,
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Motion files to write (.bvh, .json, .glb or .npy features); may repeat.
    #[arg(long)]
    out: Vec<PathBuf>,
    /// Filmstrip PNG of the result.
    #[arg(long)]
    png: Option<PathBuf>,
    /// Stretch or shrink the plan to about this many seconds (as the page's Seconds field).
    #[arg(long)]
    seconds: Option<f64>,
    /// Print the plan, the review rounds, the paths, the files written and the motion's
    /// tokens as JSON.
    #[arg(long)]
    json: bool,
    /// Folder of the model (SPAM, sentence encoder, evaluator, vocabulary).
    #[arg(long, default_value = "static/models")]
    models: PathBuf,
}

pub fn run(args: RunArgs) -> Result<()> {
    let client = args.llm.client()?;
    let (session, missing) = Session::load(&args.models, &burn::tensor::Device::flex())?;
    for m in &missing {
        eprintln!("note: not loaded: {m}");
    }
    let verbose = !args.json;
    let command = Command::Run {
        prompt: args.prompt.clone(),
        seed: args.seed,
        rounds: args.rounds,
        seconds: args.seconds,
        plan: None,
    };
    let outcome =
        block_on(
            session.execute(command, &llm_of(&client), &mut |p| match (&p, verbose) {
                (Progress::Planned { plan }, true) => print_plan(plan),
                _ => print_progress(&p, verbose),
            }),
        )?;
    let Outcome::Run(run) = outcome else {
        anyhow::bail!("the engine answered a run with something else");
    };
    let features = &run.motion.features;
    let mut written = Vec::new();
    for out in &args.out {
        let motion = coma::motion_file::MotionData::Features(features.to_vec());
        coma::motion_file::write_motion(out, &motion, true)?;
        written.push(out.display().to_string());
    }
    if let Some(png) = &args.png {
        let options = coma::render::FilmstripOptions {
            title: Some(args.prompt.clone()),
            frames: 12,
            columns: 6,
            ..Default::default()
        };
        coma::render::write_filmstrip(
            png,
            &coma::features::features_to_joints(features),
            &options,
        )?;
        written.push(png.display().to_string());
    }
    if args.json {
        let value = serde_json::json!({
            "plan": run.plan,
            "segments": run.segments,
            "seed": args.seed,
            "notes": run.all_notes(),
            "files": written,
            "paths": run.paths,
            "frames": features.len(),
            "tokens": run.motion.tokens,
        });
        println!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        for (i, s) in run.segments.iter().enumerate() {
            if let (Some(a), Some(b)) = (s.score_before, s.score_after) {
                println!(
                    "segment {}: similarity {a:.1} before review, {b:.1} after",
                    i + 1
                );
            }
        }
        for p in &run.paths {
            println!("{}", p.summary());
        }
        // The plan's own notes were printed with the plan.
        for n in run
            .all_notes()
            .iter()
            .filter(|n| !run.plan.notes.contains(n))
        {
            println!("note: {n}");
        }
        println!(
            "{} frames ({:.1} s); wrote {}",
            features.len(),
            features.len() as f64 / coma::timing::FPS,
            if written.is_empty() {
                "nothing".to_string()
            } else {
                written.join(", ")
            }
        );
    }
    Ok(())
}
