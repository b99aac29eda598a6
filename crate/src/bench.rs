//! `coma bench`: how long SPAM takes to load, to generate a 196-frame motion (text encoding,
//! base tokens, residual tokens, decoding, measured separately), and how many samples per
//! second each network trains at, on this machine's CPU. With a configuration of another size
//! (such as the paper's), the same measurement runs on random weights.

use crate::executor::block_on;
use crate::features::FEATURE_DIM;
use crate::model::generate::SamplingOptions;
use crate::model::transformer::{PARTS, TEXT_DIM};
use crate::model::{Spam, SpamConfig};
use crate::rng::Rng;
use crate::text::minilm::SentenceEncoder;
use anyhow::Result;
use burn::optim::{AdamWConfig, GradientsParams};
use burn::prelude::*;
use burn::tensor::{Distribution, Int, TensorData};
use std::path::Path;
use std::time::Instant;

/// One measured figure.
#[derive(Clone, Debug)]
pub struct BenchRow {
    pub what: String,
    pub value: f64,
    pub unit: &'static str,
}

fn seconds_of<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let start = Instant::now();
    let out = f();
    (out, start.elapsed().as_secs_f64())
}

/// What to measure besides loading and one generation.
#[derive(Clone, Copy, Debug)]
pub struct BenchOptions {
    /// Timed training steps per network (0 skips training).
    pub train_steps: usize,
    /// Times the base generation runs (the same seed each time); the median and the best are
    /// reported, with achieved GFLOP/s.
    pub repeats: usize,
}

/// Runs every measurement. `models` holds the default weights; with `config`, random weights
/// of that size are measured instead.
pub fn run_bench(
    models: &Path,
    config: Option<&SpamConfig>,
    options: BenchOptions,
) -> Result<Vec<BenchRow>> {
    let device = Device::flex();
    let mut rows = Vec::new();
    let row = |what: &str, value: f64, unit: &'static str| BenchRow {
        what: what.into(),
        value,
        unit,
    };
    let (spam, load) = match config {
        Some(c) => seconds_of(|| Spam::random(&c.vq, &c.base, c.residual.as_ref(), &device)),
        None => {
            let (loaded, t) = seconds_of(|| Spam::load(models, &device));
            (loaded?.0, t)
        }
    };
    rows.push(row("load SPAM weights", load * 1e3, "ms"));
    rows.push(row(
        "parameters: VQ-VAE (encoders, quantizers, decoder)",
        spam.vq.num_params() as f64 / 1e6,
        "M",
    ));
    rows.push(row(
        "parameters: base transformer",
        spam.base.num_params() as f64 / 1e6,
        "M",
    ));
    if let Some(residual) = &spam.residual {
        rows.push(row(
            "parameters: residual transformer",
            residual.network.num_params() as f64 / 1e6,
            "M",
        ));
    }
    let (text, load_text) = seconds_of(|| SentenceEncoder::from_dir(models, &device));
    let text = text?;
    rows.push(row("load sentence encoder", load_text * 1e3, "ms"));

    let prompt = "a person walks forward waving the left hand";
    let (embedding, t) = seconds_of(|| text.encode(&[prompt]));
    rows.push(row("encode the prompt", t * 1e3, "ms"));
    let condition: [[f32; TEXT_DIM]; PARTS] = [embedding[0]; PARTS];
    let sampling = SamplingOptions::default();
    let n = 49;
    let fixed = vec![vec![None; n]; PARTS];
    let mut times = Vec::new();
    let mut base = Vec::new();
    for _ in 0..options.repeats.max(1) {
        let mut rng = Rng::new(0);
        let (b, t) =
            seconds_of(|| block_on(spam.decode_base(&condition, &fixed, &sampling, &mut rng)));
        base = b;
        times.push(t);
    }
    times.sort_by(f64::total_cmp);
    let median = times[times.len() / 2];
    let iterations = sampling.iterations as f64;
    let gflop = iterations * spam.base_config.forward_flops(2, n) / 1e9;
    rows.push(row(
        &format!(
            "base tokens, 196 frames (10 guided iterations), median of {}",
            times.len()
        ),
        median * 1e3,
        "ms",
    ));
    if times.len() > 1 {
        rows.push(row("base tokens, 196 frames, best", times[0] * 1e3, "ms"));
    }
    rows.push(row(
        "matrix products of the base generation",
        gflop,
        "GFLOP",
    ));
    rows.push(row(
        &format!(
            "achieved at the median, {} threads",
            rayon::current_num_threads()
        ),
        gflop / median,
        "GFLOP/s",
    ));
    let mut rng = Rng::new(0);
    let (tokens, t) =
        seconds_of(|| block_on(spam.decode_residual(&condition, base, None, &sampling, &mut rng)));
    if spam.residual.is_some() {
        rows.push(row("residual tokens, 196 frames", t * 1e3, "ms"));
    }
    let (_, t) = seconds_of(|| block_on(spam.decode(&tokens)));
    rows.push(row("decode tokens to features", t * 1e3, "ms"));

    if options.train_steps == 0 {
        return Ok(rows);
    }
    let train_steps = options.train_steps;
    let sizes = config.cloned().unwrap_or_else(|| {
        SpamConfig::new(spam.vq_config.clone(), spam.base_config.clone())
            .with_residual(spam.residual.as_ref().map(|r| r.config.clone()))
    });
    rows.push(row(
        "train VQ-VAE (batch 64 × 64 frames)",
        train_vq_rate(&sizes, train_steps),
        "samples/s",
    ));
    let (b, r) = train_transformer_rates(&sizes, train_steps);
    rows.push(row(
        "train base transformer (batch 64 × 196 frames)",
        b,
        "samples/s",
    ));
    if let Some(r) = r {
        rows.push(row(
            "train residual transformer (batch 64 × 196 frames)",
            r,
            "samples/s",
        ));
    }
    Ok(rows)
}

/// Samples per second of VQ-VAE training steps on random data (after one warm-up step).
fn train_vq_rate(config: &SpamConfig, steps: usize) -> f64 {
    let device = Device::flex().autodiff();
    let mut model = config.vq.init(&device);
    let mut optim = AdamWConfig::new().init();
    let mut rng = Rng::new(1);
    let mut elapsed = 0.0;
    for i in 0..=steps {
        let x = Tensor::<3>::random(
            [64, 64, FEATURE_DIM],
            Distribution::Normal(0.0, 1.0),
            &device,
        );
        let start = Instant::now();
        let out = model.forward_train(x.clone(), None, &config.vq, false, &mut rng);
        let loss = (out.reconstruction - x).abs().mean() + out.commitment * 0.02;
        let grads = GradientsParams::from_grads(loss.backward(), &model);
        model = optim.step(1e-4, model, grads);
        model.update_codebooks(&out.assignments, config.vq.ema_decay, 0, &mut rng);
        if i > 0 {
            elapsed += start.elapsed().as_secs_f64();
        }
    }
    64.0 * steps as f64 / elapsed
}

/// Samples per second of base and (when the sizes have one) residual training steps on
/// random tokens.
fn train_transformer_rates(config: &SpamConfig, steps: usize) -> (f64, Option<f64>) {
    let device = Device::flex().autodiff();
    let (b, n) = (64, 49);
    let k = config.base.codebook_size as i32;
    let tokens = |layers: usize| {
        let v: Vec<i32> = (0..b * PARTS * layers * n)
            .map(|i| (i as i32 * 7919) % k)
            .collect();
        v
    };
    let text = || {
        Tensor::<3>::random(
            [b, PARTS, TEXT_DIM],
            Distribution::Normal(0.0, 0.05),
            &device,
        )
    };
    let keep = || Tensor::<2>::ones([b, PARTS], &device);
    let pad = || Tensor::<2, Int>::zeros([b, n], &device).equal_elem(1);
    let targets = Tensor::<1, Int>::from_data(TensorData::new(tokens(1), [b * PARTS * n]), &device);
    let ce = |logits: Tensor<4>| {
        let [bb, p, nn, kk] = logits.dims();
        burn::nn::loss::CrossEntropyLossConfig::new()
            .init(&device)
            .forward(logits.reshape([bb * p * nn, kk]), targets.clone())
    };
    let mut base = crate::model::transformer::BaseTransformer::new(&config.base, &device);
    let mut residual = config
        .residual
        .as_ref()
        .map(|c| crate::model::transformer::ResidualTransformer::new(c, &device));
    let mut optim = AdamWConfig::new().init();
    let mut optim_r = AdamWConfig::new().init();
    let (mut tb, mut tr) = (0.0, 0.0);
    for i in 0..=steps {
        let input = Tensor::<3, Int>::from_data(TensorData::new(tokens(1), [b, PARTS, n]), &device);
        let start = Instant::now();
        let loss = ce(base.forward(input, text(), keep(), pad()));
        let grads = GradientsParams::from_grads(loss.backward(), &base);
        base = optim.step(1e-4, base, grads);
        if i > 0 {
            tb += start.elapsed().as_secs_f64();
        }
        let Some(net) = residual.take() else {
            continue;
        };
        let lower =
            Tensor::<4, Int>::from_data(TensorData::new(tokens(2), [b, PARTS, 2, n]), &device);
        let start = Instant::now();
        let loss = ce(net.forward(lower, 2, text(), keep(), pad()));
        let grads = GradientsParams::from_grads(loss.backward(), &net);
        residual = Some(optim_r.step(1e-4, net, grads));
        if i > 0 {
            tr += start.elapsed().as_secs_f64();
        }
    }
    let rate = |t: f64| b as f64 * steps as f64 / t;
    (rate(tb), residual.map(|_| rate(tr)))
}

/// The rows as a Markdown table.
pub fn table(rows: &[BenchRow]) -> String {
    let mut out = String::from("| measurement | value |\n|---|---|\n");
    for r in rows {
        out.push_str(&format!("| {} | {:.1} {} |\n", r.what, r.value, r.unit));
    }
    out
}
