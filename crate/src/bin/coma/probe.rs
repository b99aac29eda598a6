//! `coma probe`: control probes of the model, printed.

use crate::common::{load_model, ModelArgs};
use anyhow::Result;
use clap::{Args, Subcommand};
use coma::eval::probes::{
    action, edit_locality, left_right, left_right_legs, quantile, ActionProbe,
};
use coma::eval::probes::{LOCALITY_BASE, LOCALITY_EDIT};
use coma::model::MotionModel;
use std::path::PathBuf;

#[derive(Args)]
pub struct ProbeArgs {
    #[command(subcommand)]
    command: ProbeCommand,
}

/// Options of the action probes (`coma probe bow`, `coma probe squat`, …).
#[derive(Args)]
struct ActionArgs {
    #[arg(long, default_value_t = 20)]
    seeds: u64,
    /// Length of each generated motion in seconds (default: the median length of the
    /// training motions that show the action, as `coma eval` asks).
    #[arg(long)]
    seconds: Option<f64>,
    /// Guidance scales of the base transformer to try (repeat for a sweep).
    #[arg(long, default_values_t = [coma::model::generate::SamplingOptions::default().base_guidance])]
    guidance: Vec<f32>,
    /// Sample each code only among the K most likely (default: all).
    #[arg(long)]
    top_k: Option<usize>,
    /// Share of the retrieved training motion's tokens a motion keeps (0: text alone);
    /// without it, the model's own setting.
    #[arg(long)]
    prior_keep: Option<f32>,
    /// Softmax temperature of the sampling (0 takes the most likely code).
    #[arg(long, default_value_t = coma::model::generate::SamplingOptions::default().temperature)]
    temperature: f32,
    /// Dataset whose training motions of the action are the reference.
    #[arg(long, default_value = "data/coma")]
    data: PathBuf,
    #[command(flatten)]
    model: ModelArgs,
}

#[derive(Subcommand)]
enum ProbeCommand {
    /// Raise and wave each hand over many seeds: how often the asked wrist ends higher (with
    /// `--legs`: kick with each foot, how often the asked ankle rises higher).
    Leftright {
        #[arg(long, default_value_t = 20)]
        seeds: u64,
        /// Probe the legs (kicks) instead of the arms.
        #[arg(long)]
        legs: bool,
        #[command(flatten)]
        model: ModelArgs,
    },
    /// Edit the left arm of a walk: how much the legs move, what the arm does (seeds 0..N).
    Locality {
        #[arg(long, default_value_t = coma::eval::probes::LOCALITY_SEEDS)]
        seeds: u64,
        #[command(flatten)]
        model: ModelArgs,
    },
    /// "A person bows" over many seeds: how far the trunk leans, against the dataset's bows.
    Bow(ActionArgs),
    /// "A person waves the left hand" over many seeds: how fast the left wrist moves, against
    /// the dataset's left-hand waves.
    Wave(ActionArgs),
    /// "A person does a squat": how far the pelvis drops, against the dataset's squats.
    Squat(ActionArgs),
    /// "A person jumps with both feet": how high the pelvis rises, against the dataset's jumps.
    Jump(ActionArgs),
    /// "A person jumps forward": how far the pelvis travels per jump, against the dataset's
    /// jumps (their 90th percentile bounds it from above).
    JumpTravel(ActionArgs),
    /// "A person lies down on the floor": how much lower the pelvis ends, against the
    /// dataset's lying down.
    LieDown(ActionArgs),
    /// "A person kicks forward": how high an ankle rises, against the dataset's kicks.
    Kick(ActionArgs),
    /// "A person throws a ball": the fastest wrist speed, against the dataset's throws.
    Throw(ActionArgs),
    /// Blend two segments: speeds at the join against real motion's 99th percentile.
    Continuity {
        /// Dataset whose test motions give the reference speeds.
        #[arg(long, default_value = "data/coma")]
        data: PathBuf,
        #[arg(long, default_value_t = 0)]
        seed: u64,
        #[command(flatten)]
        model: ModelArgs,
    },
}

/// Runs a control probe and prints its figures.
pub fn run(args: ProbeArgs) -> Result<()> {
    let command = args.command;
    let models = match &command {
        ProbeCommand::Leftright { model, .. }
        | ProbeCommand::Locality { model, .. }
        | ProbeCommand::Bow(ActionArgs { model, .. })
        | ProbeCommand::Wave(ActionArgs { model, .. })
        | ProbeCommand::Squat(ActionArgs { model, .. })
        | ProbeCommand::Jump(ActionArgs { model, .. })
        | ProbeCommand::JumpTravel(ActionArgs { model, .. })
        | ProbeCommand::LieDown(ActionArgs { model, .. })
        | ProbeCommand::Kick(ActionArgs { model, .. })
        | ProbeCommand::Throw(ActionArgs { model, .. })
        | ProbeCommand::Continuity { model, .. } => model.models.clone(),
    };
    let generator = load_model(&models)?;
    match command {
        ProbeCommand::Leftright { seeds, legs, .. } => {
            let report = if legs {
                left_right_legs(&generator, seeds, 4.0)
            } else {
                left_right(&generator, seeds, 4.0)
            };
            for (prompt, good, total) in &report.prompts {
                println!("{prompt:<34} {good}/{total}");
            }
            println!("left/right correct: {:.1} %", report.rate * 100.0);
        }
        ProbeCommand::Locality { seeds, .. } => {
            let r = edit_locality(&generator, LOCALITY_BASE, LOCALITY_EDIT, 0..seeds);
            for s in &r.per_seed {
                println!(
                    "seed {}: legs {:.2} cm, left wrist {:+.1} cm",
                    s.seed, s.leg_change_cm, s.left_wrist_rise_gain_cm
                );
            }
            println!(
                "mean leg-joint change after a left-arm edit over {seeds} seeds: {:.2} cm",
                r.leg_change_cm
            );
            println!(
                "left wrist rises {:.1} cm more after the edit (mean)",
                r.left_wrist_rise_gain_cm
            );
        }
        ProbeCommand::Bow(args) => action_probe(&generator, &coma::eval::probes::BOW, args)?,
        ProbeCommand::Wave(args) => action_probe(&generator, &coma::eval::probes::LEFT_WAVE, args)?,
        ProbeCommand::Squat(args) => action_probe(&generator, &coma::eval::probes::SQUAT, args)?,
        ProbeCommand::Jump(args) => action_probe(&generator, &coma::eval::probes::JUMP, args)?,
        ProbeCommand::JumpTravel(args) => {
            action_probe(&generator, &coma::eval::probes::JUMP_TRAVEL, args)?
        }
        ProbeCommand::LieDown(args) => {
            action_probe(&generator, &coma::eval::probes::LIE_DOWN, args)?
        }
        ProbeCommand::Kick(args) => action_probe(&generator, &coma::eval::probes::KICK, args)?,
        ProbeCommand::Throw(args) => action_probe(&generator, &coma::eval::probes::THROW, args)?,
        ProbeCommand::Continuity { data, seed, .. } => {
            let set = coma::dataset::motions::MotionSet::load(&data, coma::dataset::Split::Test)?;
            let r = coma::eval::references::walk_to_bow(&generator, &set, seed);
            println!(
                "join: root {:.2} m/s (99th percentile of real motion {:.2}), fastest joint {:.2} m/s (99th percentile {:.2}): {}",
                r.join_root_speed,
                r.p99_root_speed,
                r.join_joint_speed,
                r.p99_joint_speed,
                if r.passes() { "no jump" } else { "JUMP" }
            );
        }
    }
    Ok(())
}

/// Prints how much of an action the model performs over seeds and guidance scales, against
/// the training motions that show it.
fn action_probe(generator: &MotionModel, probe: &ActionProbe, args: ActionArgs) -> Result<()> {
    let real = coma::eval::references::action_reference(&args.data, probe)?;
    let seconds = args.seconds.unwrap_or(real.seconds);
    anyhow::ensure!(
        seconds > 0.0 && seconds.is_finite(),
        "--seconds must be a positive number, not {seconds}"
    );
    let (name, unit) = (probe.measure_name, probe.unit);
    let p10 = real.p10;
    println!(
        "real {} ({} training motions): {name} median {:.2}{unit}, 10th percentile {p10:.2}{unit}, 90th percentile {:.2}{unit}",
        probe.contents.join("/"),
        real.motions,
        real.median,
        real.p90
    );
    let options = coma::model::generate::SamplingOptions {
        top_k: args.top_k,
        temperature: args.temperature,
        prior: args
            .prior_keep
            .map(|keep| coma::model::prior::PriorOptions {
                keep,
                ..Default::default()
            }),
        ..Default::default()
    };
    generator
        .spam
        .check_sampling(&options)
        .map_err(|e| anyhow::anyhow!("{}: {e}", args.model.models.display()))?;
    let sampling = match args.top_k {
        Some(k) => format!(", top-k {k}, temperature {}", args.temperature),
        None => format!(", temperature {}", args.temperature),
    };
    for r in action(
        generator,
        probe,
        args.seeds,
        seconds,
        &options,
        &args.guidance,
        p10,
    ) {
        println!(
            "\"{}\", {} s, guidance {}{sampling}: {name} median {:.2}{unit} over {} seeds, {:.0} % reach {p10:.2}{unit}",
            probe.prompt,
            seconds,
            r.guidance,
            quantile(r.values.clone(), 0.5),
            r.values.len(),
            r.reaching * 100.0
        );
    }
    Ok(())
}
