//! `coma plan`: the plan of a prompt (segments, base motions, part edits, paths), or the
//! planner scored on a prompt set or on the timeline prompt set.

use crate::common::{llm_of, LlmArgs};
use anyhow::Result;
use clap::Args;
use coma::agents::planner;
use coma::agents::planner::{meaning, timeline_set};
use coma::executor::block_on;
use coma::plan::Plan;
use coma::session::{self, PlanningContext, Progress, VOCABULARY_FILE};
use std::path::PathBuf;
use std::time::{Duration, Instant};

#[derive(Args)]
pub struct PlanArgs {
    /// The prompt.
    #[arg(required_unless_present_any = ["prompts", "timeline_set"])]
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
    /// Instead of one prompt, plan every prompt of a timeline prompt set
    /// (eval/timeline_prompts.json) and report how many of its clauses are placed correctly
    /// (track, order, overlap, side, count), silently lost or on the swapped side, with every
    /// miss and its reason.
    #[arg(long, conflicts_with_all = ["prompt", "prompts"])]
    timeline_set: Option<PathBuf>,
    /// With --timeline-set: print the figures as the paragraph `coma eval` writes into
    /// EVAL.md's agents section.
    #[arg(long, requires = "timeline_set")]
    markdown: bool,
    /// Stretch or shrink the plan to about this many seconds (as the page's Seconds field).
    #[arg(long)]
    seconds: Option<f64>,
    /// Folder with vocabulary.json and the sentence encoder.
    #[arg(long, default_value = "static/models")]
    models: PathBuf,
}

pub fn print_plan(plan: &Plan) {
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
        if let Some(track) = &s.postures {
            println!("   {}", postures_line(track));
        }
    }
    for c in &plan.clips {
        let parts: Vec<&str> = c.parts.iter().map(|p| p.name()).collect();
        let held = match &c.postures {
            Some(track) => format!(", {}", postures_line(track)),
            None => String::new(),
        };
        println!(
            "clip {:.1}–{:.1} s  {}: {}{held}",
            c.start,
            c.end,
            parts.join(" and "),
            c.text
        );
    }
    for n in &plan.notes {
        println!("note: {n}");
    }
}

/// A posture track in one line: what it drives and its key poses' names.
fn postures_line(track: &coma::posture::track::PostureTrack) -> String {
    let names: Vec<&str> = track
        .keys
        .iter()
        .map(|k| k.script.name.as_deref().unwrap_or("posture"))
        .collect();
    let on = if track.whole_body() {
        "key poses".to_string()
    } else {
        let parts: Vec<&str> = track.parts.iter().map(|p| p.name()).collect();
        format!("key poses held on the {}", parts.join(" and "))
    };
    let times = if track.repeat > 1 {
        format!(" ×{}", track.repeat)
    } else {
        String::new()
    };
    format!("{on}: {}{times}", names.join(", "))
}

/// One progress line to stderr, when `verbose`.
pub fn print_progress(progress: &Progress, verbose: bool) {
    if let (Progress::Step { line, .. }, true) = (progress, verbose) {
        eprintln!("{line}");
    }
}

pub fn run(args: PlanArgs) -> Result<()> {
    let client = args.llm.client()?;
    let llm = llm_of(&client);
    // The engine plans without SPAM: the vocabulary and the sentence encoder are enough, and
    // the engine decides what to do without them.
    let vocabulary = session::read_vocabulary(&args.models.join(VOCABULARY_FILE));
    if let Err(e) = &vocabulary {
        eprintln!("note: {e}");
    }
    let loaded =
        coma::text::minilm::SentenceEncoder::from_dir(&args.models, &burn::tensor::Device::flex());
    let encoder = loaded.as_ref().ok();
    let embed_fn = |s: &str| {
        encoder
            .map(|e| e.encode(&[s])[0].to_vec())
            .unwrap_or_default()
    };
    let context = PlanningContext {
        vocabulary: vocabulary.as_ref().ok(),
        embed: encoder.map(|_| &embed_fn as planner::offline::Embedder),
    };
    let plan_one = |prompt: &str, verbose: bool| -> Result<Plan> {
        Ok(block_on(session::plan_prompt(
            prompt,
            args.seconds,
            &llm,
            &context,
            &mut |p| print_progress(&p, verbose),
        ))?)
    };
    if let Some(set) = &args.prompts {
        let mut failed = None;
        let report = planner::prompt_set::score(set, |p| {
            plan_one(p, false).unwrap_or_else(|e| {
                failed = Some(format!("'{p}': {e}"));
                planner::offline::plan(p, None)
            })
        })?;
        if let Some(e) = failed {
            anyhow::bail!("a prompt of the set did not plan: {e}");
        }
        if args.json {
            println!("{}", serde_json::to_string_pretty(&report)?);
        } else {
            print!("{}", report.table());
        }
        return Ok(());
    }
    if let Some(path) = &args.timeline_set {
        let set = timeline_set::load(path)?;
        if let Err(e) = &loaded {
            anyhow::bail!(
                "the timeline scorer matches clauses to the plan by meaning with the sentence \
                 encoder, which did not load from {}: {e}",
                args.models.display()
            );
        }
        let similarity = meaning::embedding_similarity(&embed_fn);
        let matcher = meaning::Matcher::new(&similarity, meaning::SAME_MOVEMENT_MIN_SIMILARITY);
        let mut failed = None;
        let mut planning = Duration::ZERO;
        let mut report = timeline_set::score(
            &set,
            &mut |p| {
                let start = Instant::now();
                let plan = plan_one(p, false).unwrap_or_else(|e| {
                    failed = Some(format!("'{p}': {e}"));
                    planner::offline::plan(p, None)
                });
                planning += start.elapsed();
                plan
            },
            &matcher,
        );
        if let Some(e) = failed {
            anyhow::bail!("a prompt of the set did not plan: {e}");
        }
        report.planner_seconds = Some(planning.as_secs_f64());
        if args.markdown {
            print!("{}", report.figures.markdown(&path.display().to_string()));
        } else if args.json {
            println!("{}", serde_json::to_string_pretty(&report)?);
        } else {
            print!("{}", report.table());
        }
        return Ok(());
    }
    let prompt = args.prompt.expect("clap requires a prompt");
    let plan = plan_one(&prompt, !args.json)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&plan)?);
    } else {
        print_plan(&plan);
    }
    Ok(())
}
