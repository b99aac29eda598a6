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

/// Learning rate of optimizer step `step` (from 0) of `steps`: a linear warm-up over
/// `warmup_steps`, times a cosine that falls from 1 at the first step to `floor` at the last
/// (`floor` 1 keeps the rate constant after the warm-up).
pub fn warmup_cosine(base: f64, warmup_steps: usize, steps: usize, floor: f64, step: usize) -> f64 {
    let warm = ((step + 1) as f64 / warmup_steps.max(1) as f64).min(1.0);
    let progress = (step as f64 / steps.max(1) as f64).min(1.0);
    let cosine = 0.5 * (1.0 + (std::f64::consts::PI * progress).cos());
    base * warm * (floor + (1.0 - floor) * cosine)
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

/// A training configuration as a run folder or `configs/` holds it.
pub trait ReadConfig: burn::config::Config {
    /// Reads the configuration at `path`.
    fn read(path: &std::path::Path) -> anyhow::Result<Self>;
}

/// Reads a training configuration, taking each field the file lacks from `defaults` (the
/// code's own defaults, given the file's contents for what has none): a run written before a
/// field existed still loads, and means what it meant when the field's default keeps the old
/// behaviour.
pub fn read_with_defaults<C: burn::config::Config>(
    path: &std::path::Path,
    defaults: impl FnOnce(&serde_json::Value) -> anyhow::Result<C>,
) -> anyhow::Result<C> {
    use anyhow::Context;
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut value: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{} is not JSON", path.display()))?;
    let filled = serde_json::to_value(defaults(&value)?)?;
    if let (Some(fields), serde_json::Value::Object(all)) = (value.as_object_mut(), filled) {
        for (key, default) in all {
            fields.entry(key).or_insert(default);
        }
    }
    serde_json::from_value(value)
        .with_context(|| format!("{} is not a valid configuration", path.display()))
}

/// Configurations that have added no field since runs were first written: read as they are.
macro_rules! read_as_written {
    ($($config:ty),*) => {$(
        impl ReadConfig for $config {
            fn read(path: &std::path::Path) -> anyhow::Result<Self> {
                <$config as burn::config::Config>::load(path)
                    .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))
            }
        }
    )*};
}
read_as_written!(evaluator::EvaluatorTrainingConfig);

#[cfg(test)]
mod tests {
    use super::{warmup_cosine, ReadConfig};

    /// Every training configuration in `configs/` and every run's `config.json` reads, as
    /// the command that resumes or repeats it reads them: a field added to a configuration
    /// must not stop older runs from resuming.
    #[test]
    fn every_committed_training_configuration_reads() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        // Each with the name that says which network it trains: the file's in `configs/`,
        // the run folder's in `runs/`.
        let mut paths: Vec<(String, std::path::PathBuf)> = std::fs::read_dir(root.join("configs"))
            .unwrap()
            .map(|e| (e.as_ref().unwrap().file_name(), e.unwrap().path()))
            .map(|(name, path)| (name.to_string_lossy().into_owned(), path))
            .collect();
        for run in std::fs::read_dir(root.join("runs")).unwrap() {
            let run = run.unwrap();
            let config = run.path().join("config.json");
            if config.exists() {
                paths.push((run.file_name().to_string_lossy().into_owned(), config));
            }
        }
        let mut read = 0;
        for (name, path) in &paths {
            let result = if name.starts_with("vq") {
                super::vq::VqTrainingConfig::read(path).map(|_| ())
            } else if name.starts_with("evaluator") {
                super::evaluator::EvaluatorTrainingConfig::read(path).map(|_| ())
            } else if name.starts_with("base") || name.starts_with("res") {
                super::transformer::TransformerTrainingConfig::read(path).map(|_| ())
            } else {
                // The network sizes (spam.json, paper.json), not a training configuration.
                continue;
            };
            result.unwrap_or_else(|e| panic!("{}: {e:#}", path.display()));
            read += 1;
        }
        assert!(read >= 20, "only {read} configurations found");
        let res2 = super::transformer::TransformerTrainingConfig::read(
            &root.join("runs/res2/config.json"),
        );
        assert_eq!(
            res2.unwrap().final_rate,
            1.0,
            "a run from before the anneal keeps a constant rate"
        );
        let anneal = super::transformer::TransformerTrainingConfig::read(
            &root.join("configs/base-anneal.json"),
        );
        assert_eq!(anneal.unwrap().final_rate, 0.05);
    }

    #[test]
    fn learning_rate_warms_up_then_falls_to_its_floor() {
        let rate = |step| warmup_cosine(2e-4, 10, 110, 0.1, step);
        assert!((rate(0) - 2e-5).abs() < 1e-12, "a tenth of the warm-up");
        assert!(
            (rate(9)
                - 2e-4 * (0.1 + 0.9 * 0.5 * (1.0 + (9.0f64 / 110.0 * std::f64::consts::PI).cos())))
            .abs()
                < 1e-12
        );
        assert!(
            (rate(55) - 2e-4 * 0.55).abs() < 1e-12,
            "halfway down the cosine"
        );
        assert!((rate(110) - 2e-5).abs() < 1e-12, "the floor at the end");
        assert!(
            (1..110).all(|s| s < 10 || rate(s) < rate(s - 1)),
            "falls after the warm-up"
        );
        // A floor of 1 is the constant rate the first runs trained with.
        assert!((20..100).all(|s| (warmup_cosine(3e-4, 10, 100, 1.0, s) - 3e-4).abs() < 1e-15));
    }
}
