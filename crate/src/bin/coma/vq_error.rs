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
    #[arg(long, default_value = "data/coma")]
    data: PathBuf,
    /// train, val or test.
    #[arg(long, default_value = "test")]
    split: String,
    /// At most this many motions.
    #[arg(long, default_value_t = 100000)]
    limit: usize,
    /// Decode from the first N residual layers only (default: all); 0 decodes the encoder's
    /// output unquantized, the bound that more residual layers approach.
    #[arg(long)]
    layers: Option<usize>,
    /// Only the motions of this source (bandai, hdm05, cmu, deepmimic): a source's training
    /// clips against its test clips without measuring the whole training split.
    #[arg(long)]
    source: Option<String>,
    /// Only the motions whose item name contains this (e.g. `_mm_` for one HDM05 actor's
    /// clips and their mirrors).
    #[arg(long)]
    name_contains: Option<String>,
    /// Also print the errors of each source's actions (their content labels).
    #[arg(long)]
    by_action: bool,
    /// Also print how predictable each residual layer's codes are (entropies in nats).
    #[arg(long)]
    codes: bool,
    /// Also print the share of layer-0 codes that these weights give the same as other
    /// weights of the same sizes, with or without detail encoders (e.g. the run a fine-tune
    /// started from).
    #[arg(long)]
    base_codes_of: Option<PathBuf>,
}

pub fn run(args: VqErrorArgs) -> Result<()> {
    let split: coma::dataset::Split = args.split.parse().map_err(anyhow::Error::msg)?;
    let cfg = <coma::train::vq::VqTrainingConfig as coma::train::ReadConfig>::read(&args.config)?;
    let device = burn::tensor::Device::flex();
    let model = coma::weights::load_file(cfg.init_model(&device), &args.weights)?;
    let mut set = coma::dataset::motions::MotionSet::load(&args.data, split)?;
    if let Some(source) = &args.source {
        set = set.subset(|i| i.source.as_deref() == Some(source.as_str()));
        if set.items.is_empty() {
            bail!("the {split:?} split has no motions of the source '{source}'");
        }
    }
    if let Some(part) = &args.name_contains {
        set = set.subset(|i| i.name.contains(part.as_str()));
        if set.items.is_empty() {
            bail!("no motion of the {split:?} split has '{part}' in its name");
        }
    }
    let layers = args.layers.unwrap_or(cfg.model.layers);
    if layers > cfg.model.layers {
        bail!(
            "--layers {layers}: the model has {} residual layers",
            cfg.model.layers
        );
    }
    let by_action = args.by_action;
    let (e, groups) = coma::train::vq::reconstruction_errors_by(
        &model,
        &set,
        &device,
        args.limit,
        layers,
        |item| {
            let source = item.source.clone()?;
            Some(match (by_action, &item.content) {
                (true, Some(action)) => format!("{source}\t{action}"),
                _ => source,
            })
        },
    )?;
    println!(
        "{} motions of the {:?} split, {}: mean per-joint position error {:.1} mm (root path integrated), {:.1} mm (root aligned), {:.1} mm (posture: pelvis-relative, in the body's facing frame)",
        e.motions,
        split,
        match layers {
            0 => "unquantized".to_string(),
            n => format!("{n} of {} layers", cfg.model.layers),
        },
        e.global_mm,
        e.root_aligned_mm,
        e.posture_mm
    );
    // Per source, then (with --by-action) its actions under it.
    let mut sources: std::collections::BTreeMap<&str, coma::train::vq::ReconstructionError> =
        Default::default();
    for (key, g) in &groups {
        let source = key.split('\t').next().unwrap_or(key);
        let slot = sources.entry(source).or_default();
        *slot = slot.pool(*g);
    }
    for (source, s) in &sources {
        println!(
            "  {source}: {} motions, {:.1} mm (root path integrated), {:.1} mm (root aligned), {:.1} mm (posture)",
            s.motions, s.global_mm, s.root_aligned_mm, s.posture_mm
        );
        for (key, g) in groups
            .iter()
            .filter(|(k, _)| k.starts_with(&format!("{source}\t")))
        {
            println!(
                "    {:<32} {:>4} motions  {:>6.1} {:>6.1} {:>6.1}",
                key.split('\t').nth(1).unwrap_or(""),
                g.motions,
                g.global_mm,
                g.root_aligned_mm,
                g.posture_mm
            );
        }
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
    if let Some(path) = &args.base_codes_of {
        // The other weights may lack detail encoders (the run these were added to).
        let other = coma::weights::load_file(cfg.init_model(&device), path)
            .or_else(|_| coma::weights::load_file(cfg.model.init(&device), path))?;
        let share = coma::train::vq::base_code_agreement(&model, &other, &set, &device, args.limit);
        println!(
            "layer-0 codes the same as {}'s: {:.1} %",
            path.display(),
            100.0 * share
        );
    }
    Ok(())
}
