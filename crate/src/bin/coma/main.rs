//! The `coma` command line: data, checks, conversion, rendering and the page server.
//!
//! One file per command, each with its arguments and a `run` that validates them, calls
//! into the library and prints; this file only dispatches.

use anyhow::Result;
use clap::{Parser, Subcommand};

mod align;
mod bench;
mod common;
mod convert;
mod data;
mod edit;
mod eval;
mod export;
mod features;
mod generate;
mod plan;
mod posture;
mod probe;
mod render;
mod run;
mod serve;
mod text;
mod train;
mod traj;
mod vq_error;

#[derive(Parser)]
#[command(
    name = "coma",
    version,
    about = "CoMA in the browser: motion data, models and tools"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// HumanML3D feature tools.
    Features(features::FeaturesArgs),
    /// Training data.
    Data(data::DataArgs),
    /// Draw a motion (.npy features or joints, or .bvh) as a PNG filmstrip.
    Render(render::RenderArgs),
    /// Convert a motion between .npy (features or joints), .bvh and .json.
    Convert(convert::ConvertArgs),
    /// Train a model (resumes the run in --run when it has a checkpoint).
    Train(train::TrainArgs),
    /// Generate a motion from a prompt with the default (or given) model.
    Generate(generate::GenerateArgs),
    /// Plan a prompt (segments, base motions, part edits, paths) without generating.
    Plan(plan::PlanArgs),
    /// Key postures: solve a named posture or a script (`coma posture T-pose --png t.png`),
    /// `check` the solver, `list` the library.
    Posture(posture::PostureArgs),
    /// The whole CoMA loop: plan, generate, edit, review, blend and lay the paths.
    Run(run::RunArgs),
    /// Draw the root path a phrase or an expression curve asks for, as a PNG.
    Traj(traj::TrajArgs),
    /// Edit a saved motion (.npy features): regenerate a time range or some body parts.
    Edit(edit::EditArgs),
    /// Assemble trained runs into a model folder (the default model lives in static/models).
    Export(export::ExportArgs),
    /// Reconstruction error of VQ-VAE weights on a split (mean per-joint position error).
    VqError(vq_error::VqErrorArgs),
    /// The field's metrics on the test split (real motions, a retrieval baseline, SPAM) and
    /// the control probes; writes EVAL.md and eval.json.
    Eval(eval::EvalArgs),
    /// How well a motion fits a text: the evaluator's similarity on a 0–100 scale.
    Align(align::AlignArgs),
    /// Control probes of the model.
    Probe(probe::ProbeArgs),
    /// Measure load, generation and training speed on this machine.
    Bench(bench::BenchArgs),
    /// The sentence encoder.
    Text(text::TextArgs),
    /// Serve a folder (the built page) on localhost.
    Serve(serve::ServeArgs),
}

fn main() {
    if let Err(e) = dispatch(Cli::parse()) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn dispatch(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Features(args) => features::run(args),
        Command::Data(args) => data::run(args),
        Command::Render(args) => render::run(args),
        Command::Convert(args) => convert::run(args),
        Command::Train(args) => train::run(args),
        Command::Generate(args) => generate::run(args),
        Command::Plan(args) => plan::run(args),
        Command::Posture(args) => posture::run(args),
        Command::Run(args) => run::run(args),
        Command::Traj(args) => traj::run(args),
        Command::Edit(args) => edit::run(args),
        Command::Export(args) => export::run(args),
        Command::VqError(args) => vq_error::run(args),
        Command::Eval(args) => eval::run(args),
        Command::Align(args) => align::run(args),
        Command::Probe(args) => probe::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Text(args) => text::run(args),
        Command::Serve(args) => serve::run(args),
    }
}
