//! `coma convert`: a motion from one file format into another.

use anyhow::Result;
use clap::Args;
use coma::gltf::JointNames;
use coma::motion_file::{read_motion, write_motion_with, WriteOptions};
use std::path::PathBuf;

#[derive(Args)]
pub struct ConvertArgs {
    /// Motion file (.npy or .bvh).
    input: PathBuf,
    /// Output file (.bvh, .glb, .json or .npy).
    output: PathBuf,
    /// Write HumanML3D features rather than joints when the output is .npy.
    #[arg(long)]
    features: bool,
    /// Name the joints as Mixamo's rig does (`mixamorig:Hips`, …) when the output is .glb.
    #[arg(long)]
    mixamo: bool,
}

pub fn run(args: ConvertArgs) -> Result<()> {
    let motion = read_motion(&args.input)?;
    let options = WriteOptions {
        as_features: args.features,
        joint_names: if args.mixamo {
            JointNames::Mixamo
        } else {
            JointNames::Smpl
        },
    };
    write_motion_with(&args.output, &motion, options)?;
    println!("wrote {}", args.output.display());
    Ok(())
}
