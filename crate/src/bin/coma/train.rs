//! `coma train`: training the networks, resumable, and redrawing a run's loss plot.

use crate::common::RunArgs;
use anyhow::Result;
use clap::{Args, Subcommand};
use coma::train::transformer::Kind;
use std::path::PathBuf;

#[derive(Args)]
pub struct TrainArgs {
    #[command(subcommand)]
    command: TrainCommand,
}

#[derive(Subcommand)]
enum TrainCommand {
    /// The VQ-VAE.
    Vq(RunArgs),
    /// The base transformer (layer-0 tokens from text).
    Base(TransformerArgs),
    /// Redraw a run's losses.png from its log.csv.
    Plot {
        /// Run folder.
        run: PathBuf,
        /// Steps averaged per plotted point.
        #[arg(long, default_value_t = 20)]
        smooth: usize,
    },
    /// The residual transformer (layers 1.. from layer 0).
    Res(TransformerArgs),
    /// The text–motion evaluator (contrastive; measures motions, never generates).
    Evaluator {
        /// Folder with the converted sentence encoder (minilm-*).
        #[arg(long, default_value = "static/models")]
        text_model: PathBuf,
        #[command(flatten)]
        run: RunArgs,
    },
}

#[derive(Args)]
struct TransformerArgs {
    #[command(flatten)]
    run: RunArgs,
    /// Trained VQ-VAE weights that tokenize the motions.
    #[arg(long, default_value = "static/models/vq.bpk")]
    vq: PathBuf,
    /// The VQ-VAE's training configuration (for its sizes).
    #[arg(long, default_value = "configs/vq.json")]
    vq_config: PathBuf,
    /// Folder with the converted sentence encoder (minilm-*).
    #[arg(long, default_value = "static/models")]
    text_model: PathBuf,
}

pub fn run(args: TrainArgs) -> Result<()> {
    let print = |line: &str| println!("{line}");
    match args.command {
        TrainCommand::Vq(args) => {
            use coma::train::vq::{train_vq, VqTrainOptions, VqTrainingConfig};
            let (run, cfg) = args.open("vq", |c: &mut VqTrainingConfig, s| c.steps = s)?;
            let device = coma::train::training_device(&args.device)?;
            let options = VqTrainOptions {
                data: args.data,
                run_dir: run,
                minutes: args.minutes,
                init: args.init.clone(),
            };
            train_vq(&cfg, &options, &device, &print)?;
        }
        TrainCommand::Base(args) => train_transformer(Kind::Base, args)?,
        TrainCommand::Res(args) => train_transformer(Kind::Residual, args)?,
        TrainCommand::Evaluator {
            text_model,
            run: args,
        } => {
            use coma::train::evaluator::{EvaluatorTrainOptions, EvaluatorTrainingConfig};
            let (run, cfg) = args.open("evaluator", |c: &mut EvaluatorTrainingConfig, s| {
                c.steps = s
            })?;
            let options = EvaluatorTrainOptions {
                run_dir: run,
                minutes: args.minutes,
                init: args.init.clone(),
            };
            coma::train::launch::train_evaluator_on_dataset(
                &cfg,
                &args.data,
                &text_model,
                &options,
                &args.device,
                &print,
            )?;
        }
        TrainCommand::Plot { run, smooth } => {
            let series = coma::train::run::read_log(&run.join("log.csv"), smooth)?;
            let options = coma::render::plot::PlotOptions {
                title: format!("training losses: {}", run.display()),
                x_label: "step".into(),
                y_label: "loss".into(),
                log_y: true,
                ..Default::default()
            };
            coma::render::plot::write_line_plot(&run.join("losses.png"), &series, &options)?;
            println!("wrote {}", run.join("losses.png").display());
        }
    }
    Ok(())
}

/// `coma train base|res`: the run folder and configuration from the arguments, then the
/// library tokenizes the dataset and trains.
fn train_transformer(kind: Kind, args: TransformerArgs) -> Result<()> {
    use coma::train::launch::{train_transformer_on_dataset, TransformerSources};
    use coma::train::transformer::{TransformerTrainOptions, TransformerTrainingConfig};
    let name = if kind == Kind::Base { "base" } else { "res" };
    let (run, cfg) = args
        .run
        .open(name, |c: &mut TransformerTrainingConfig, s| c.steps = s)?;
    let sources = TransformerSources {
        data: &args.run.data,
        vq: &args.vq,
        vq_config: &args.vq_config,
        text_model: &args.text_model,
    };
    let options = TransformerTrainOptions {
        run_dir: run,
        minutes: args.run.minutes,
        init: args.run.init.clone(),
    };
    train_transformer_on_dataset(kind, &cfg, &sources, &options, &args.run.device, &|l| {
        println!("{l}")
    })
}
