//! `coma data`: the training dataset.

use anyhow::Result;
use clap::{Args, Subcommand};
use std::path::PathBuf;

#[derive(Args)]
pub struct DataArgs {
    #[command(subcommand)]
    command: DataCommand,
}

#[derive(Subcommand)]
enum DataCommand {
    /// Convert the Bandai-Namco archive into a HumanML3D-layout dataset.
    Build {
        /// bandai-namco-bvh.tar.xz, or the folder it was extracted into.
        #[arg(long)]
        bandai: PathBuf,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// Use only this many clips, spread over the set (quick builds).
        #[arg(long)]
        limit: Option<usize>,
    },
}

pub fn run(args: DataArgs) -> Result<()> {
    match args.command {
        DataCommand::Build { bandai, out, limit } => {
            let options = coma::dataset::BuildOptions {
                source: bandai,
                out: out.clone(),
                limit,
            };
            let summary = coma::dataset::build(&options, &|line| eprintln!("{line}"))?;
            println!(
                "{}: {} clips ({} source clips, mirrors included), {} frames, {:.2} hours at 20 fps, {} captions; splits {:?}",
                out.display(),
                summary.clips,
                summary.source_clips,
                summary.frames,
                summary.hours,
                summary.captions,
                summary.clips_per_split
            );
        }
    }
    Ok(())
}
