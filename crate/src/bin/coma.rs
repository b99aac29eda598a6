//! The `coma` command line: data, checks, rendering (and later training and generation).

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use std::path::PathBuf;

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
    Features {
        #[command(subcommand)]
        command: FeaturesCommand,
    },
}

#[derive(Subcommand)]
enum FeaturesCommand {
    /// Compare our features ↔ joints code with a HumanML3D reference folder.
    Check {
        /// Folder with new_joint_vecs/, new_joints/ and skeleton_example_h3d.npy.
        dir: PathBuf,
        /// Motion id to check.
        #[arg(long, default_value = "012314")]
        id: String,
    },
}

fn main() {
    if let Err(e) = run(Cli::parse()) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Features {
            command: FeaturesCommand::Check { dir, id },
        } => {
            let report = coma::features::check::check_reference(&dir, &id)
                .with_context(|| format!("checking {}", dir.display()))?;
            println!("{report}");
            if !report.passes() {
                bail!("features differ from the reference beyond tolerance");
            }
            Ok(())
        }
    }
}
