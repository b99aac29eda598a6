//! `coma convert`: a motion from one file format into another.

use anyhow::Result;
use clap::Args;
use coma::motion_file::{read_motion, write_motion};
use std::path::PathBuf;

#[derive(Args)]
pub struct ConvertArgs {
    /// Motion file (.npy or .bvh).
    input: PathBuf,
    /// Output file (.bvh, .json or .npy).
    output: PathBuf,
    /// Write HumanML3D features rather than joints when the output is .npy.
    #[arg(long)]
    features: bool,
}

pub fn run(args: ConvertArgs) -> Result<()> {
    let motion = read_motion(&args.input)?;
    write_motion(&args.output, &motion, args.features)?;
    println!("wrote {}", args.output.display());
    Ok(())
}
