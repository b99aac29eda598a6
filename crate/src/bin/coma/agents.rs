//! `coma plan`, `coma run` and `coma traj`: the agents from the command line.

use anyhow::{bail, Context, Result};
use clap::Args;
use coma::agents::llm::{LlmClient, LlmConfig, UreqTransport};
use coma::agents::pipeline::{self, RunOptions};
use coma::agents::plan::Plan;
use coma::agents::planner;
use coma::agents::reviewer::Scorer;
use coma::dataset::Vocabulary;
use coma::executor::block_on;
use coma::model::MotionModel;
use coma::trajectory::Trajectory;
use std::path::{Path, PathBuf};

/// Where the LLM is, if one is used.
#[derive(Args, Clone)]
pub struct LlmArgs {
    /// OpenAI-compatible base URL (e.g. http://127.0.0.1:8080/v1); without it the built-in
    /// planner and the evaluator do the work.
    #[arg(long)]
    llm: Option<String>,
    /// Model name sent to the LLM server.
    #[arg(long, default_value = "default")]
    model: String,
    /// Environment variable holding the API key (the key itself is never an argument, so it
    /// stays out of shell history and process lists).
    #[arg(long, default_value = "COMA_LLM_KEY")]
    api_key_env: String,
    /// Seconds to wait for one LLM reply.
    #[arg(long, default_value_t = 60.0)]
    timeout: f64,
    /// A vision model on the same server: during review it is shown a filmstrip of each
    /// segment and its description goes to the judge with the pose codes.
    #[arg(long, requires = "llm")]
    vision_model: Option<String>,
}

impl LlmArgs {
    fn client(&self) -> Result<Option<LlmClient<UreqTransport>>> {
        let Some(url) = &self.llm else {
            return Ok(None);
        };
        let mut config = LlmConfig::new(url.clone(), self.model.clone());
        if let Ok(key) = std::env::var(&self.api_key_env) {
            config = config.with_api_key(key);
        }
        if !(self.timeout.is_finite() && self.timeout > 0.0) {
            bail!("--timeout must be a positive number of seconds");
        }
        config.timeout = std::time::Duration::from_secs_f64(self.timeout);
        config.vision_model = self.vision_model.clone().filter(|m| !m.trim().is_empty());
        Ok(Some(LlmClient::native(config)?))
    }
}

#[derive(Args)]
pub struct PlanArgs {
    /// The prompt.
    #[arg(required_unless_present = "prompts")]
    prompt: Option<String>,
    #[command(flatten)]
    llm: LlmArgs,
    /// Print the plan as JSON.
    #[arg(long)]
    json: bool,
    /// Instead of one prompt, plan every prompt of a prompt set (eval/prompts.json) and
    /// report how often the segment count matches the prompt's temporal structure.
    #[arg(long, conflicts_with = "prompt")]
    prompts: Option<PathBuf>,
    /// Folder with vocabulary.json and the sentence encoder.
    #[arg(long, default_value = "static/models")]
    models: PathBuf,
}

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
    /// Motion files to write (.bvh, .json or .npy features); may repeat.
    #[arg(long)]
    out: Vec<PathBuf>,
    /// Filmstrip PNG of the result.
    #[arg(long)]
    png: Option<PathBuf>,
    /// Print the plan, the review rounds and the files written as JSON.
    #[arg(long)]
    json: bool,
    /// Folder of the model (SPAM, sentence encoder, evaluator, vocabulary).
    #[arg(long, default_value = "static/models")]
    models: PathBuf,
}

#[derive(Args)]
pub struct TrajArgs {
    /// A path phrase ("zigzag forward", "a circle clockwise") or a curve "x(t); z(t); t0; t1"
    /// in the sandboxed expression language.
    path: String,
    /// PNG to write.
    #[arg(long, short)]
    out: PathBuf,
    /// Length of the path in metres.
    #[arg(long, default_value_t = 6.0)]
    length: f64,
}

fn vocabulary(models: &Path) -> Result<Vocabulary> {
    let path = models.join("vocabulary.json");
    serde_json::from_str(
        &std::fs::read_to_string(&path)
            .with_context(|| format!("cannot read {}", path.display()))?,
    )
    .with_context(|| format!("{} is not a vocabulary", path.display()))
}

/// MiniLM as the planner's embedder, when its files are there.
fn encoder(models: &Path) -> Option<coma::text::minilm::SentenceEncoder> {
    coma::text::minilm::SentenceEncoder::from_dir(models, &burn::tensor::Device::flex()).ok()
}

fn make_plan(
    prompt: &str,
    llm: &Option<LlmClient<UreqTransport>>,
    vocabulary: &Vocabulary,
    embed: Option<planner::offline::Embedder>,
    verbose: bool,
) -> Plan {
    match llm {
        None => planner::offline::plan(prompt, embed),
        Some(client) => block_on(planner::llm::plan(
            client,
            prompt,
            vocabulary,
            embed,
            &mut |event| {
                if verbose {
                    eprintln!("{}", describe_event(event));
                }
            },
        )),
    }
}

fn describe_event(event: &planner::llm::PlanEvent) -> String {
    use planner::llm::PlanEvent;
    match event {
        PlanEvent::Rewritten(t) => format!("rewritten: {t}"),
        PlanEvent::Segmented(s) => format!("{} segments", s.len()),
        PlanEvent::Decomposed(i, s) => format!("segment {}: {}", i + 1, s.base),
    }
}

fn print_plan(plan: &Plan) {
    println!("rewritten: {}", plan.rewritten);
    for (i, s) in plan.segments.iter().enumerate() {
        println!("{}. {:.1} s  {}", i + 1, s.seconds, s.text);
        println!("   base: {}", s.base);
        for (part, text) in s.parts.edits() {
            println!("   {}: {text}", part.name());
        }
        if let Some(t) = &s.trajectory {
            println!("   path: {}", t.describe());
        }
    }
    for n in &plan.notes {
        println!("note: {n}");
    }
}

pub fn plan(args: PlanArgs) -> Result<()> {
    let llm = args.llm.client()?;
    let vocabulary = vocabulary(&args.models)?;
    let encoder = encoder(&args.models);
    let embed_fn = |s: &str| {
        encoder
            .as_ref()
            .map(|e| e.encode(&[s])[0].to_vec())
            .unwrap_or_default()
    };
    let embed: Option<planner::offline::Embedder> = encoder.as_ref().map(|_| &embed_fn as _);
    if let Some(set) = &args.prompts {
        let report =
            planner::prompt_set::score(set, |p| make_plan(p, &llm, &vocabulary, embed, false))?;
        if args.json {
            println!("{}", serde_json::to_string_pretty(&report)?);
        } else {
            print!("{}", report.table());
        }
        return Ok(());
    }
    let prompt = args.prompt.expect("clap requires a prompt");
    let plan = make_plan(&prompt, &llm, &vocabulary, embed, !args.json);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&plan)?);
    } else {
        print_plan(&plan);
    }
    Ok(())
}

pub fn run(args: RunArgs) -> Result<()> {
    let llm = args.llm.client()?;
    let vocabulary = vocabulary(&args.models)?;
    let model: MotionModel = crate::load_model(&args.models)?;
    let device = burn::tensor::Device::flex();
    let evaluator = coma::eval::evaluator::Evaluator::load(&args.models, &device).ok();
    let scorer = evaluator.as_ref().map(|(evaluator, config)| Scorer {
        evaluator,
        config,
        model: &model,
    });
    let embed_fn = |s: &str| model.text.encode(&[s])[0].to_vec();
    let plan = make_plan(&args.prompt, &llm, &vocabulary, Some(&embed_fn), !args.json);
    if !args.json {
        print_plan(&plan);
    }
    let quiet = args.json;
    let run = block_on(pipeline::run(
        &model,
        scorer.as_ref(),
        llm.as_ref(),
        plan,
        RunOptions {
            rounds: args.rounds,
            seed: args.seed,
        },
        &mut |event| {
            if !quiet {
                eprintln!("{}", pipeline::describe_event(&event));
            }
        },
    ));
    let (features, path_notes) =
        block_on(pipeline::motion_features(&model, &run.plan, &run.tokens));
    let mut written = Vec::new();
    for out in &args.out {
        let motion = coma::motion_file::MotionData::Features(features.clone());
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
            &coma::features::features_to_joints(&features),
            &options,
        )?;
        written.push(png.display().to_string());
    }
    let paths = pipeline::path_reports(&run.plan, &run.tokens, &features);
    if args.json {
        let mut value = serde_json::to_value(&run)?;
        value["files"] = serde_json::json!(written);
        value["paths"] = serde_json::to_value(&paths)?;
        value["frames"] = serde_json::json!(features.len());
        value["path_notes"] = serde_json::json!(path_notes);
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
        for p in &paths {
            println!("{}", p.summary());
        }
        for n in run.notes.iter().chain(&path_notes) {
            println!("note: {n}");
        }
        println!(
            "{} frames ({:.1} s); wrote {}",
            features.len(),
            features.len() as f64 / coma::features::FPS,
            if written.is_empty() {
                "nothing".to_string()
            } else {
                written.join(", ")
            }
        );
    }
    Ok(())
}

/// A path phrase, or "x(t); z(t); t0; t1".
fn trajectory_arg(text: &str) -> Result<Trajectory> {
    let pieces: Vec<&str> = text.split(';').map(str::trim).collect();
    if let [x, z, t0, t1] = pieces[..] {
        let number = |s: &str| {
            s.parse::<f64>()
                .map_err(|_| anyhow::anyhow!("'{s}' is not a number (t0 and t1 are numbers)"))
        };
        let spec = coma::trajectory::CurveSpec {
            x: x.to_string(),
            z: z.to_string(),
            t0: number(t0)?,
            t1: number(t1)?,
        };
        return Ok(Trajectory::Curve(spec));
    }
    Trajectory::from_text(text).ok_or_else(|| {
        anyhow::anyhow!(
            "no path shape in '{text}' (try \"a circle clockwise\", \"zigzag\", \"figure eight\", \
             or a curve \"sin(t); t; 0; 6.28\")"
        )
    })
}

pub fn traj(args: TrajArgs) -> Result<()> {
    if !(args.length.is_finite() && args.length > 0.0 && args.length <= 1000.0) {
        bail!("--length must be a positive number of metres, at most 1000");
    }
    let trajectory = trajectory_arg(&args.path)?;
    let path = trajectory
        .validate()
        .and_then(|p| Ok(p.scaled_to(args.length)?.resample(200)?))
        .map_err(|e| anyhow::anyhow!("{}: {e}", trajectory.describe()))?;
    let options = coma::trajectory::plot::PathPlotOptions {
        title: format!("{} ({:.1} m)", trajectory.describe(), args.length),
        ..Default::default()
    };
    let png = coma::trajectory::plot::path_png(&path.points, None, &options)?;
    std::fs::write(&args.out, png).with_context(|| format!("writing {}", args.out.display()))?;
    if let Trajectory::Shape {
        shape: coma::trajectory::Shape::Circle(side),
    } = trajectory
    {
        let c = coma::trajectory::circle_report(&path.points, side.is_clockwise());
        println!(
            "{}: turned {:.0}° {}, closure error {:.3} m, mean distance to the circle {:.3} m",
            trajectory.describe(),
            c.total_turn_deg,
            if c.turned_clockwise {
                "clockwise"
            } else {
                "counter-clockwise"
            },
            c.closure_error_m,
            c.mean_radius_error_m
        );
    }
    println!("wrote {}", args.out.display());
    Ok(())
}
