//! `coma bench`: load, generation and training speed on this machine.

use crate::common::ModelArgs;
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct BenchArgs {
    /// Measure random weights of this size (a spam.json, e.g. configs/paper.json) instead of
    /// the default model.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Timed training steps per network (0 measures inference only).
    #[arg(long, default_value_t = 3)]
    train_steps: usize,
    /// Times the base generation runs; the median and the best are reported.
    #[arg(long, default_value_t = 1)]
    repeat: usize,
    #[command(flatten)]
    model: ModelArgs,
}

pub fn run(args: BenchArgs) -> Result<()> {
    use burn::config::Config;
    let sizes = match args.config {
        Some(path) => Some(
            coma::model::SpamConfig::load(&path)
                .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?,
        ),
        None => None,
    };
    let options = coma::bench::BenchOptions {
        train_steps: args.train_steps,
        repeats: args.repeat,
    };
    let rows = coma::bench::run_bench(&args.model.models, sizes.as_ref(), options)?;
    print!("{}", coma::bench::table(&rows));
    Ok(())
}
