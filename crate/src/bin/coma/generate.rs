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
    /// Folder for a before/after look at the feet: filmstrips and joints of the motion as
    /// decoded and as the engine hands it out (feet planted), and their figures printed.
    #[arg(long)]
    compare_feet: Option<PathBuf>,
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
    if let Some(dir) = &args.compare_feet {
        compare_feet(&session, &motion, dir, &args.prompt)?;
    }
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

/// Writes `before.png` and `after.png` into `dir`, with their joints as `before.npy` and
/// `after.npy` ((T, 22, 3), metres): the motion as SPAM decoded it (on the reference skeleton)
/// and as the engine returned it; prints both motions' foot figures.
fn compare_feet(
    session: &coma::session::Session,
    motion: &coma::session::Motion,
    dir: &std::path::Path,
    prompt: &str,
) -> Result<()> {
    use coma::features::{features_to_joints, with_reference_bones};
    use coma::posture::measure::{floating_share, floor_penetration, foot_skating};
    use coma::render::{write_filmstrip, FilmstripOptions, View};
    let decoded = coma::executor::block_on(session.model().features(&motion.tokens));
    let before = features_to_joints(&with_reference_bones(&decoded));
    let after = features_to_joints(&motion.features);
    std::fs::create_dir_all(dir)?;
    for (name, poses) in [("before", &before), ("after", &after)] {
        println!(
            "{name}: foot skating {:.3}, floating frames {:.3}, deepest under the floor {:.3} m",
            foot_skating(poses),
            floating_share(poses),
            floor_penetration(poses)
        );
        let options = FilmstripOptions {
            frames: 12,
            columns: 6,
            cell_size: 200,
            title: Some(format!("{prompt}: {name} planting the feet")),
            view: View::Side,
        };
        write_filmstrip(&dir.join(format!("{name}.png")), poses, &options)?;
        coma::features::joints_to_npy(poses).write_f32(dir.join(format!("{name}.npy")))?;
    }
    Ok(())
}
