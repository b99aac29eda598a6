//! `coma features`: HumanML3D feature tools.

use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use std::path::PathBuf;

#[derive(Args)]
pub struct FeaturesArgs {
    #[command(subcommand)]
    command: FeaturesCommand,
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

pub fn run(args: FeaturesArgs) -> Result<()> {
    match args.command {
        FeaturesCommand::Check { dir, id } => {
            let report = coma::features::check::check_reference(&dir, &id)
                .with_context(|| format!("checking {}", dir.display()))?;
            println!("{report}");
            if !report.passes() {
                bail!("features differ from the reference beyond tolerance");
            }
        }
    }
    Ok(())
}
