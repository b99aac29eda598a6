//! `coma vq-error`: how closely VQ-VAE weights reconstruct the motions of a split.

use anyhow::{bail, Result};
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct VqErrorArgs {
    /// Weights: a run's vq.bpk or checkpoint/model.bpk.
    #[arg(long, default_value = "static/models/vq.bpk")]
    weights: PathBuf,
    /// The run's training configuration (for the sizes).
    #[arg(long, default_value = "configs/vq.json")]
    config: PathBuf,
    #[arg(long, default_value = "data/bandai")]
    data: PathBuf,
    /// train, val or test.
    #[arg(long, default_value = "test")]
    split: String,
    /// At most this many motions.
    #[arg(long, default_value_t = 100000)]
    limit: usize,
    /// Decode from the first N residual layers only (default: all).
    #[arg(long)]
    layers: Option<usize>,
    /// Also print how predictable each residual layer's codes are (entropies in nats).
    #[arg(long)]
    codes: bool,
}

pub fn run(args: VqErrorArgs) -> Result<()> {
    use burn::config::Config;
    let split = match args.split.as_str() {
        "train" => coma::dataset::Split::Train,
        "val" => coma::dataset::Split::Val,
        "test" => coma::dataset::Split::Test,
        other => bail!("unknown split '{other}' (train, val or test)"),
    };
    let cfg = coma::train::vq::VqTrainingConfig::load(&args.config)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", args.config.display()))?;
    let device = burn::tensor::Device::flex();
    let model = coma::weights::load_file(cfg.model.init(&device), &args.weights)?;
    let set = coma::dataset::motions::MotionSet::load(&args.data, split)?;
    let layers = args.layers.unwrap_or(cfg.model.layers);
    let e = coma::train::vq::reconstruction_errors(&model, &set, &device, args.limit, layers)?;
    println!(
        "{} motions of the {:?} split, {layers} of {} layers: mean per-joint position error {:.1} mm (root path integrated), {:.1} mm (root aligned)",
        e.motions, split, cfg.model.layers, e.global_mm, e.root_aligned_mm
    );
    for source in set.sources() {
        let part = set.subset(|i| i.source.as_deref() == Some(source.as_str()));
        let e = coma::train::vq::reconstruction_errors(&model, &part, &device, args.limit, layers)?;
        println!(
            "  {source}: {} motions, {:.1} mm (root path integrated), {:.1} mm (root aligned)",
            e.motions, e.global_mm, e.root_aligned_mm
        );
    }
    if args.codes {
        println!("layer  used  H(code)  H(code | layer below)  H(code | layer 0)   (nats; ln 256 = 5.55)");
        for l in coma::train::vq::code_statistics(&model, &set, &device, args.limit) {
            println!(
                "{:>5} {:>5} {:>8.2} {:>22.2} {:>18.2}",
                l.layer, l.used, l.entropy, l.given_previous, l.given_first
            );
        }
    }
    Ok(())
}
