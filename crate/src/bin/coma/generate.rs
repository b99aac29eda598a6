//! `coma generate`: a motion from a prompt.

use crate::common::{execute_motion, load_session, write_outputs, ModelArgs};
use anyhow::Result;
use clap::Args;
use coma::session::Command;
use std::path::PathBuf;

#[derive(Args)]
pub struct GenerateArgs {
    prompt: String,
    /// Length in seconds (0.2 s steps, at most 9.8 s).
    #[arg(long, default_value_t = 4.0)]
    seconds: f64,
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// A body part's own instruction, e.g. --part "left arm=waves the left hand".
    #[arg(long = "part")]
    parts: Vec<String>,
    /// Motion file to write (.bvh, .npy features, .json joints, .glb skinned figure).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Filmstrip PNG to write.
    #[arg(long)]
    png: Option<PathBuf>,
    /// Classifier-free guidance scale of the base transformer: 1 follows the learnt
    /// conditional distribution, more follows the text harder (default 4).
    #[arg(long)]
    guidance: Option<f32>,
    #[command(flatten)]
    model: ModelArgs,
}

pub fn run(args: GenerateArgs) -> Result<()> {
    let parts = parse_parts(&args.parts)?;
    let session = load_session(&args.model.models)?;
    let command = Command::Generate {
        prompt: args.prompt.clone(),
        seconds: args.seconds,
        seed: args.seed,
        parts,
        guidance: args.guidance,
    };
    let motion = execute_motion(&session, command)?;
    write_outputs(
        &motion.features,
        args.out.as_deref(),
        args.png.as_deref(),
        &args.prompt,
    )
}

/// `--part "left arm=…"` arguments as (part, instruction).
fn parse_parts(parts: &[String]) -> Result<Vec<(coma::skeleton::BodyPart, String)>> {
    parts
        .iter()
        .map(|p| {
            let (name, instruction) = p.split_once('=').ok_or_else(|| anyhow::anyhow!("--part '{p}': expected 'left arm=instruction'"))?;
            let part = coma::skeleton::BodyPart::parse(name)
                .ok_or_else(|| anyhow::anyhow!("--part '{p}': unknown body part '{name}' (left arm, right arm, left leg, right leg)"))?;
            Ok((part, instruction.trim().to_string()))
        })
        .collect()
}
