//! Training: run bookkeeping (checkpoints, logs, plots) and the training
//! loops of the motion model.

pub mod evaluator;
pub mod launch;
pub mod run;
pub mod tokens;
pub mod transformer;
pub mod vq;

/// The autodiff device that training runs on: `flex` (pure Rust, always available) or `tch`
/// (libtorch, about twice as fast on a CPU; only in builds with the `tch` feature).
pub fn training_device(name: &str) -> anyhow::Result<burn::tensor::Device> {
    match name {
        "flex" => Ok(burn::tensor::Device::flex().autodiff()),
        #[cfg(feature = "tch")]
        // burn marks its libtorch device deprecated in favour of CubeCL backends, which cannot
        // build on this machine; libtorch is still the fastest CPU trainer here.
        #[allow(deprecated)]
        "tch" => Ok(burn::tensor::Device::libtorch().autodiff()),
        #[cfg(not(feature = "tch"))]
        "tch" => anyhow::bail!("this build has no libtorch backend: build with `--features tch` (see crate/Cargo.toml)"),
        other => anyhow::bail!("unknown device '{other}' (flex or tch)"),
    }
}

/// Action shares as a log line, largest first: `walk 41.2 %, run 9.0 %, …`.
pub fn format_shares(shares: &std::collections::BTreeMap<String, f64>) -> String {
    let mut sorted: Vec<(&String, &f64)> = shares.iter().collect();
    sorted.sort_by(|a, b| b.1.total_cmp(a.1).then(a.0.cmp(b.0)));
    sorted
        .iter()
        .map(|(label, share)| format!("{label} {:.1} %", *share * 100.0))
        .collect::<Vec<_>>()
        .join(", ")
}
