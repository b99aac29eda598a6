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
    /// Convert motion capture sources into one HumanML3D-layout dataset (each source
    /// optional, at least one).
    Build {
        /// The shared data folder: takes every source below from its usual place in it
        /// (a source named on its own overrides it).
        #[arg(long)]
        shared: Option<PathBuf>,
        /// bandai-namco-bvh.tar.xz, or the folder it was extracted into.
        #[arg(long)]
        bandai: Option<PathBuf>,
        /// hdm05-subset-amc.tar.xz, or the folder it was extracted into.
        #[arg(long)]
        hdm05: Option<PathBuf>,
        /// cmu-8action-expmap.tar.xz, or the folder it was extracted into.
        #[arg(long)]
        cmu: Option<PathBuf>,
        /// The deepmimic folder (humanoid3d.txt and motions/).
        #[arg(long)]
        deepmimic: Option<PathBuf>,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// Use only this many clips of each source, spread over it (quick builds).
        #[arg(long)]
        limit: Option<usize>,
        /// HDM05 actors to hold out for testing (comma-separated, e.g. `mm,tr`) instead of
        /// the usual one: measures how well the networks carry over to unseen performers.
        #[arg(long, value_delimiter = ',')]
        hdm05_test_actors: Option<Vec<String>>,
    },
}

pub fn run(args: DataArgs) -> Result<()> {
    match args.command {
        DataCommand::Build {
            shared,
            bandai,
            hdm05,
            cmu,
            deepmimic,
            out,
            limit,
            hdm05_test_actors,
        } => {
            let usual = |given: Option<PathBuf>, place: &str| {
                given.or_else(|| {
                    shared
                        .as_ref()
                        .map(|s| s.join(place))
                        .filter(|p| p.exists())
                })
            };
            let options = coma::dataset::BuildOptions {
                bandai: usual(bandai, "bandai-namco-bvh.tar.xz"),
                hdm05: usual(hdm05, "hdm05-subset/hdm05-subset-amc.tar.xz"),
                cmu: usual(cmu, "cmu-8action-expmap/cmu-8action-expmap.tar.xz"),
                deepmimic: usual(deepmimic, "deepmimic"),
                out: out.clone(),
                limit,
                hdm05_test_actors,
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
            for (source, s) in &summary.sources {
                println!(
                    "  {source:?}: {} source clips, items per split {:?}, {} frames; {}",
                    s.source_clips, s.items, s.frames, s.licence
                );
            }
        }
    }
    Ok(())
}
