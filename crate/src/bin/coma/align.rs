//! `coma align`: how well a motion fits a text, by the evaluator.

use anyhow::Result;
use clap::Args;
use coma::motion_file::read_motion;
use std::path::PathBuf;

#[derive(Args)]
pub struct AlignArgs {
    text: String,
    /// Motion file (.npy features or joints, or .bvh).
    motion: PathBuf,
    /// Folder with evaluator.json, evaluator.bpk, the sentence encoder and mean/std.npy.
    #[arg(long, default_value = "static/models")]
    models: PathBuf,
}

pub fn run(args: AlignArgs) -> Result<()> {
    let AlignArgs {
        text: prompt,
        motion,
        models,
    } = args;
    let device = burn::tensor::Device::flex();
    let (evaluator, config) = coma::model::evaluator::Evaluator::load(&models, &device)?;
    let text = coma::text::minilm::SentenceEncoder::from_dir(&models, &device)?;
    let normalizer =
        coma::features::Normalizer::read(models.join("mean.npy"), models.join("std.npy"))?;
    let features = match read_motion(&motion)? {
        coma::motion_file::MotionData::Features(f) => f,
        coma::motion_file::MotionData::Joints(j) => {
            coma::features::joints_to_features(&j, &coma::skeleton::Offsets::reference())?.0
        }
    };
    let m = evaluator.embed_motions(&config, &[&normalizer.normalize(&features)], &device);
    let t = evaluator.embed_texts(&text.encode(&[prompt.as_str()]), &device);
    println!(
        "{:.1}",
        coma::model::evaluator::alignment_score(&t[0], &m[0])
    );
    Ok(())
}
