//! `coma edit`: a saved motion with a time range or some body parts regenerated.

use crate::common::{load_model, write_outputs, ModelArgs};
use anyhow::{bail, Result};
use clap::Args;
use coma::executor::block_on;
use coma::motion_file::read_motion;
use std::path::PathBuf;

#[derive(Args)]
pub struct EditArgs {
    /// Motion to edit (.npy features from `coma generate` or the dataset).
    input: PathBuf,
    /// What the edited range or parts should do.
    #[arg(long)]
    text: String,
    /// Start of the range to regenerate, seconds (in-between edit).
    #[arg(long)]
    from: Option<f64>,
    /// End of the range, seconds.
    #[arg(long)]
    to: Option<f64>,
    /// Body parts to regenerate (body-part edit), e.g. --parts "left arm".
    #[arg(long = "parts")]
    parts: Vec<String>,
    #[arg(long, default_value_t = 0)]
    seed: u64,
    #[arg(long)]
    out: PathBuf,
    #[arg(long)]
    png: Option<PathBuf>,
    #[command(flatten)]
    model: ModelArgs,
}

pub fn run(args: EditArgs) -> Result<()> {
    let EditArgs {
        input,
        text: instruction,
        from,
        to,
        parts,
        seed,
        out,
        png,
        model,
    } = args;
    let model = load_model(&model.models)?;
    let motion = match read_motion(&input)? {
        coma::motion_file::MotionData::Features(f) => f,
        _ => bail!(
            "{}: edit needs a .npy of features (as `coma generate --out m.npy` writes)",
            input.display()
        ),
    };
    let tokens = model.spam.tokenize(&model.normalizer.normalize(&motion));
    let edited = match (from, to, parts.is_empty()) {
        (Some(a), Some(b), true) => {
            let fps = coma::timing::FPS;
            block_on(model.inbetween(
                &tokens,
                &instruction,
                (a * fps) as usize,
                (b * fps).ceil() as usize,
                seed,
            ))
        }
        (None, None, false) => {
            let chosen = parts
                .iter()
                .map(|p| {
                    coma::skeleton::BodyPart::parse(p).ok_or_else(|| {
                        anyhow::anyhow!(
                            "unknown body part '{p}' (left arm, right arm, left leg, right leg)"
                        )
                    })
                })
                .collect::<Result<Vec<_>>>()?;
            // The other parts keep doing what the motion does, as the describer puts it.
            let rest =
                coma::posecodes::describe_motion(&coma::features::features_to_joints(&motion));
            block_on(model.edit_parts(&tokens, &instruction, &chosen, &rest, seed))
        }
        _ => bail!("give either --from and --to (in-between edit) or --parts (body-part edit)"),
    };
    let features = block_on(model.features(&edited));
    write_outputs(&features, Some(&out), png.as_deref(), &instruction)
}
