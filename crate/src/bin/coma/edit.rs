//! `coma edit`: a saved motion with a time range or some body parts regenerated.

use crate::common::{execute_motion, load_session, write_outputs, ModelArgs};
use anyhow::{bail, Result};
use clap::Args;
use coma::motion_file::read_motion;
use coma::session::Command;
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
    let session = load_session(&model.models)?;
    let model = session.model();
    let motion = match read_motion(&input)? {
        coma::motion_file::MotionData::Features(f) => f,
        _ => bail!(
            "{}: edit needs a .npy of features (as `coma generate --out m.npy` writes)",
            input.display()
        ),
    };
    let tokens = model.spam.tokenize(&model.normalizer.normalize(&motion));
    let command = match (from, to, parts.is_empty()) {
        (Some(a), Some(b), true) => {
            let fps = coma::timing::FPS;
            if !(a.is_finite() && b.is_finite() && a >= 0.0) {
                bail!("--from and --to are seconds from the start of the motion");
            }
            Command::InBetween {
                tokens,
                text: instruction.clone(),
                from: (a * fps) as usize,
                to: (b * fps).ceil() as usize,
                seed,
                plan: None,
            }
        }
        (None, None, false) => {
            let parts = parts
                .iter()
                .map(|p| {
                    coma::skeleton::BodyPart::parse(p).ok_or_else(|| {
                        anyhow::anyhow!(
                            "unknown body part '{p}' (left arm, right arm, left leg, right leg)"
                        )
                    })
                })
                .collect::<Result<Vec<_>>>()?;
            Command::EditParts {
                tokens,
                text: instruction.clone(),
                parts,
                seed,
                plan: None,
            }
        }
        _ => bail!("give either --from and --to (in-between edit) or --parts (body-part edit)"),
    };
    let edited = execute_motion(&session, command)?;
    write_outputs(&edited.features, Some(&out), png.as_deref(), &instruction)
}
