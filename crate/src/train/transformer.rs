//! Training the base and residual transformers (`coma train base|res`): masked-token
//! prediction with a cosine masking schedule (base) or next-layer prediction (residual), label
//! smoothing, text dropout for classifier-free guidance, resumable checkpoints.

use super::run::Run;
use super::tokens::{BatchDraw, TokenBatch, TokenSet};
use crate::model::generate::mask_schedule;
use crate::model::transformer::{BaseTransformer, ResidualTransformer, TransformerConfig, PARTS};
use crate::rng::Rng;
use anyhow::Result;
use burn::grad_clipping::GradientClippingConfig;
use burn::optim::{AdamWConfig, GradientsParams};
use burn::prelude::*;
use burn::tensor::activation::log_softmax;
use burn::tensor::{Int, TensorData};
use std::path::PathBuf;

/// Which transformer a run trains.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Base,
    Residual,
}

/// Everything a transformer training run is configured by (saved as `config.json`).
#[derive(Config, Debug)]
pub struct TransformerTrainingConfig {
    pub model: TransformerConfig,
    #[config(default = 64)]
    pub batch_size: usize,
    #[config(default = 5000)]
    pub steps: usize,
    #[config(default = 2e-4)]
    pub learning_rate: f64,
    #[config(default = 1000)]
    pub warmup_steps: usize,
    /// Share of the learning rate left at the last step, reached along a cosine (1 keeps it
    /// constant after the warm-up, as the first runs trained).
    #[config(default = 1.0)]
    pub final_rate: f64,
    /// Probability that a part is conditioned on its own sentence rather than the caption.
    #[config(default = 0.3)]
    pub part_text: f64,
    /// Probability that a motion's text is dropped (for classifier-free guidance).
    #[config(default = 0.1)]
    pub drop_text: f64,
    #[config(default = 0.1)]
    pub label_smoothing: f64,
    #[config(default = 5.0)]
    pub checkpoint_minutes: f64,
    #[config(default = 20)]
    pub log_every: usize,
    #[config(default = 4321)]
    pub seed: u64,
    /// How strongly rare actions are drawn more often (see `TokenSet::draw_weights`: 0 draws
    /// every motion equally often, 1 every action), from step `balance_from` on.
    #[config(default = 0.0)]
    pub balance: f64,
    #[config(default = 0)]
    pub balance_from: usize,
}

impl super::ReadConfig for TransformerTrainingConfig {
    /// Fields added since a run was written (`final_rate`) take their defaults, which keep
    /// the run as it trained: a run resumes with the schedule it started with.
    fn read(path: &std::path::Path) -> anyhow::Result<Self> {
        use anyhow::Context;
        super::read_with_defaults(path, |file| {
            let model = serde_json::from_value(file.get("model").cloned().unwrap_or_default())
                .with_context(|| format!("{} has no valid \"model\"", path.display()))?;
            Ok(TransformerTrainingConfig::new(model))
        })
    }
}

/// Inputs and targets of one step.
struct Step {
    inputs: Tensor<3, Int>,
    lower: Option<(Tensor<4, Int>, usize)>,
    targets: Tensor<1, Int>,
    /// 1 where a position counts in the loss.
    weights: Tensor<1>,
}

/// Base: masks a cosine-scheduled fraction of each motion's layer-0 tokens (80 % become the
/// mask id, 10 % a random code, 10 % stay), targets are the masked positions.
fn base_step(
    batch: &TokenBatch,
    config: &TransformerConfig,
    rng: &mut Rng,
    device: &Device,
) -> Step {
    let (b, layers, n) = batch.dims;
    let k = config.codebook_size;
    let mut inputs = Vec::with_capacity(b * PARTS * n);
    let mut targets = Vec::with_capacity(b * PARTS * n);
    let mut weights = Vec::with_capacity(b * PARTS * n);
    for (i, len) in batch.lengths.iter().enumerate() {
        let real = PARTS * len;
        let ratio = mask_schedule(rng.uniform() as f64);
        let count = ((ratio * real as f64).ceil() as usize).clamp(1, real);
        let mut order: Vec<usize> = (0..real).collect();
        rng.shuffle(&mut order);
        let mut masked = vec![false; real];
        for o in order.into_iter().take(count) {
            masked[o] = true;
        }
        for p in 0..PARTS {
            let row =
                &batch.tokens[((i * PARTS + p) * layers) * n..((i * PARTS + p) * layers) * n + n];
            for (s, token) in row.iter().enumerate() {
                let is_masked = s < *len && masked[p * len + s];
                let input = if !is_masked {
                    *token
                } else {
                    match rng.uniform() {
                        u if u < 0.8 => config.mask_id() as i32,
                        u if u < 0.9 => rng.below(k) as i32,
                        _ => *token,
                    }
                };
                inputs.push(input);
                targets.push(if is_masked { *token } else { 0 });
                weights.push(is_masked as u8 as f32);
            }
        }
    }
    Step {
        inputs: Tensor::from_data(TensorData::new(inputs, [b, PARTS, n]), device),
        lower: None,
        targets: Tensor::from_data(TensorData::new(targets, [b * PARTS * n]), device),
        weights: Tensor::from_data(TensorData::new(weights, [b * PARTS * n]), device),
    }
}

/// Residual: a random layer `j ≥ 1` is the target everywhere the motion is real.
fn residual_step(batch: &TokenBatch, rng: &mut Rng, device: &Device) -> Step {
    let (b, layers, n) = batch.dims;
    let j = 1 + rng.below(layers - 1);
    let mut lower = Vec::with_capacity(b * PARTS * j * n);
    let mut targets = Vec::with_capacity(b * PARTS * n);
    let mut weights = Vec::with_capacity(b * PARTS * n);
    for (i, len) in batch.lengths.iter().enumerate() {
        for p in 0..PARTS {
            let base = (i * PARTS + p) * layers * n;
            lower.extend_from_slice(&batch.tokens[base..base + j * n]);
            let row = &batch.tokens[base + j * n..base + (j + 1) * n];
            targets.extend(
                row.iter()
                    .enumerate()
                    .map(|(s, t)| if s < *len { *t } else { 0 }),
            );
            weights.extend((0..n).map(|s| (s < *len) as u8 as f32));
        }
    }
    Step {
        inputs: Tensor::from_data(
            TensorData::new(vec![0i32; b * PARTS * n], [b, PARTS, n]),
            device,
        ),
        lower: Some((
            Tensor::from_data(TensorData::new(lower, [b, PARTS, j, n]), device),
            j,
        )),
        targets: Tensor::from_data(TensorData::new(targets, [b * PARTS * n]), device),
        weights: Tensor::from_data(TensorData::new(weights, [b * PARTS * n]), device),
    }
}

/// Label-smoothed cross entropy over weighted positions, and the accuracy there.
fn loss_and_accuracy(logits: Tensor<4>, step: &Step, smoothing: f64) -> (Tensor<1>, f64) {
    let [b, p, n, k] = logits.dims();
    let logp = log_softmax(logits.reshape([b * p * n, k]), 1);
    let picked = logp
        .clone()
        .gather(1, step.targets.clone().reshape([b * p * n, 1]))
        .reshape([b * p * n]);
    let uniform = logp.clone().mean_dim(1).reshape([b * p * n]);
    let per_position = (picked * (1.0 - smoothing) + uniform * smoothing).neg();
    let count = step.weights.clone().sum().clamp_min(1.0);
    let loss = (per_position * step.weights.clone()).sum() / count.clone();
    let predicted = logp.argmax(1).reshape([b * p * n]);
    let hits = predicted.equal(step.targets.clone()).float() * step.weights.clone();
    let accuracy =
        hits.sum().into_scalar::<f32>() as f64 / count.into_scalar::<f32>().max(1.0) as f64;
    (loss, accuracy)
}

/// Options of one invocation.
pub struct TransformerTrainOptions {
    pub run_dir: PathBuf,
    pub minutes: Option<f64>,
    /// Weights a fresh run starts from (fine-tuning), instead of random ones.
    pub init: Option<PathBuf>,
}

/// The two kinds of model behind one interface for the loop.
#[derive(Module, Debug)]
enum Model {
    Base(BaseTransformer),
    Residual(ResidualTransformer),
}

/// Trains (or resumes) a base or residual transformer run on a token set.
pub fn train_transformer(
    kind: Kind,
    config: &TransformerTrainingConfig,
    data: &TokenSet,
    options: &TransformerTrainOptions,
    device: &Device,
    progress: &dyn Fn(&str),
) -> Result<()> {
    let (mut run, resumed) = Run::open(&options.run_dir, &["loss", "accuracy"])?;
    config
        .save(options.run_dir.join("config.json"))
        .map_err(|e| anyhow::anyhow!("saving config.json: {e}"))?;
    let init = options.init.as_deref();
    let fresh = || match kind {
        Kind::Base => Model::Base(BaseTransformer::new(&config.model, device)),
        Kind::Residual => Model::Residual(ResidualTransformer::new(&config.model, device)),
    };
    let started = match fresh() {
        Model::Base(m) => run.start_from(m, init, resumed, progress).map(Model::Base),
        Model::Residual(m) => run
            .start_from(m, init, resumed, progress)
            .map(Model::Residual),
    };
    let mut model = match (started, init) {
        (Ok(model), _) => model,
        // A checkpoint's model.bpk holds the network inside the loop's wrapper.
        (Err(bare), Some(path)) => match crate::weights::load_file(fresh(), path) {
            Ok(model) => {
                progress(&format!(
                    "starting from the checkpoint weights in {}",
                    path.display()
                ));
                model
            }
            Err(_) => return Err(bare),
        },
        (Err(bare), None) => return Err(bare),
    };
    let mut optim = AdamWConfig::new()
        .with_weight_decay(1e-5)
        .with_grad_clipping(Some(GradientClippingConfig::Norm(1.0)))
        .init();
    if resumed {
        (model, optim) = run.restore(model, optim)?;
        progress(&run.resumed_line());
    }
    let epoch_steps = (data.items.len() as f64 / config.batch_size as f64).max(1.0);
    let limits = super::run::StepLimits {
        steps: config.steps,
        log_every: config.log_every,
        epoch_steps,
        checkpoint_minutes: config.checkpoint_minutes,
        minutes: options.minutes,
    };
    let weights = (config.balance != 0.0).then(|| data.draw_weights(config.balance));
    progress(&format!(
        "share of draws per action{}: {}",
        if config.balance_from > 0 && weights.is_some() {
            format!(" from step {}", config.balance_from)
        } else {
            String::new()
        },
        super::format_shares(&data.action_shares(weights.as_deref()))
    ));
    while run.state.step < config.steps {
        let step = run.state.step;
        let mut rng = Rng::new(config.seed ^ (step as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
        let draw = BatchDraw {
            batch: config.batch_size,
            part_text: config.part_text as f32,
            drop_text: config.drop_text as f32,
            weights: weights.as_deref().filter(|_| step >= config.balance_from),
        };
        let batch = data.batch(&config.model, &mut rng, &draw, device);
        let inputs = match kind {
            Kind::Base => base_step(&batch, &config.model, &mut rng, device),
            Kind::Residual => residual_step(&batch, &mut rng, device),
        };
        let logits = match (&model, &inputs.lower) {
            (Model::Base(m), _) => m.forward(
                inputs.inputs.clone(),
                batch.text.clone(),
                batch.keep_text.clone(),
                batch.pad.clone(),
            ),
            (Model::Residual(m), Some((lower, j))) => m.forward(
                lower.clone(),
                *j,
                batch.text.clone(),
                batch.keep_text.clone(),
                batch.pad.clone(),
            ),
            (Model::Residual(_), None) => unreachable!("residual steps carry their lower layers"),
        };
        let (loss, accuracy) = loss_and_accuracy(logits, &inputs, config.label_smoothing);
        let loss_value = loss.clone().into_scalar::<f32>() as f64;
        let lr = super::warmup_cosine(
            config.learning_rate,
            config.warmup_steps,
            config.steps,
            config.final_rate,
            step,
        );
        let grads = GradientsParams::from_grads(loss.backward(), &model);
        model = optim.step(lr, model, grads);
        run.record(config.batch_size, &[loss_value, accuracy])?;

        run.report_step(&limits, progress);
        let title = if kind == Kind::Base {
            "base transformer"
        } else {
            "residual transformer"
        };
        if run.end_step(&model, &optim, &limits, title, progress)? {
            break;
        }
    }
    if run.state.step >= config.steps {
        match model.valid() {
            Model::Base(m) => run.save_weights(m, "base.bpk", progress),
            Model::Residual(m) => run.save_weights(m, "residual.bpk", progress),
        }?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::transformer::TEXT_DIM;
    use crate::train::tokens::TokenItem;

    fn tiny_set() -> TokenSet {
        let mut rng = Rng::new(9);
        let items = (0..12)
            .map(|i| {
                let n = 3 + i % 5;
                TokenItem {
                    tokens: (0..PARTS)
                        .map(|_| {
                            (0..3)
                                .map(|_| (0..n).map(|_| rng.below(16) as u32).collect())
                                .collect()
                        })
                        .collect(),
                    captions: vec![i % 3],
                    parts: [Some(3), None, None, Some(4)],
                    // Nine walks and three bows.
                    content: Some(if i % 4 == 0 { "bow" } else { "walk" }.to_string()),
                }
            })
            .collect();
        let texts: Vec<String> = (0..5).map(|i| format!("text {i}")).collect();
        let embeddings = (0..5).map(|i| [i as f32 * 0.1; TEXT_DIM]).collect();
        TokenSet {
            items,
            texts,
            embeddings,
        }
    }

    fn config() -> TransformerTrainingConfig {
        let model = TransformerConfig::new()
            .with_width(16)
            .with_depth(1)
            .with_heads(2)
            .with_ff_width(32)
            .with_codebook_size(16)
            .with_vq_layers(3)
            .with_max_steps(8);
        TransformerTrainingConfig::new(model)
            .with_batch_size(4)
            .with_steps(3)
            .with_warmup_steps(1)
            .with_log_every(1)
    }

    #[test]
    fn balancing_draws_rare_actions_as_often_as_frequent_ones() {
        let set = tiny_set();
        assert_eq!(set.draw_weights(0.0), vec![1.0; 12]);
        let full = set.draw_weights(1.0);
        let share = |w: &[f64], content: &str| {
            let of: f64 = set
                .items
                .iter()
                .zip(w)
                .filter(|(i, _)| i.content.as_deref() == Some(content))
                .map(|(_, w)| w)
                .sum();
            of / w.iter().sum::<f64>()
        };
        assert!((share(&full, "bow") - 0.5).abs() < 1e-12);
        let half = set.draw_weights(0.5);
        let bows = share(&half, "bow");
        assert!(
            bows > 0.25 && bows < 0.5,
            "between uniform and balanced: {bows}"
        );
        // Drawn batches follow the weights: every item a bow when only bows weigh.
        let only_bows: Vec<f64> = set
            .items
            .iter()
            .map(|i| (i.content.as_deref() == Some("bow")) as u8 as f64)
            .collect();
        let mut rng = Rng::new(2);
        let device = Device::flex();
        for _ in 0..5 {
            let draw = BatchDraw {
                batch: 4,
                part_text: 0.0,
                drop_text: 0.0,
                weights: Some(&only_bows),
            };
            let batch = set.batch(&config().model, &mut rng, &draw, &device);
            for len in &batch.lengths {
                assert!(
                    [3, 6, 7].contains(len),
                    "bows are items 0, 4, 8: lengths 3, 7, 6"
                );
            }
        }
    }

    #[test]
    fn batches_pad_similar_lengths_and_masking_targets_only_masked_tokens() {
        let set = tiny_set();
        let cfg = config();
        let device = Device::flex();
        let mut rng = Rng::new(1);
        let draw = BatchDraw {
            batch: 4,
            part_text: 0.3,
            drop_text: 0.1,
            weights: None,
        };
        let batch = set.batch(&cfg.model, &mut rng, &draw, &device);
        let (b, layers, n) = batch.dims;
        assert_eq!((b, layers), (4, 3));
        assert_eq!(n, *batch.lengths.iter().max().unwrap());
        assert_eq!(batch.tokens.len(), b * PARTS * layers * n);
        let step = base_step(&batch, &cfg.model, &mut rng, &device);
        let weights: Vec<f32> = step.weights.try_into_vec_as::<f32>().unwrap();
        let inputs: Vec<i64> = step.inputs.try_into_vec_as::<i64>().unwrap();
        assert!(weights.contains(&1.0));
        // Unmasked positions keep their token; padding is never a target.
        for (i, w) in weights.iter().enumerate() {
            let (item, s) = (i / (PARTS * n), i % n);
            if s >= batch.lengths[item] {
                assert_eq!(*w, 0.0);
                assert_eq!(inputs[i], cfg.model.pad_id() as i64);
            }
        }
    }

    #[test]
    fn base_and_residual_runs_train_and_save_weights() {
        let set = tiny_set();
        let device = Device::flex().autodiff();
        for kind in [Kind::Base, Kind::Residual] {
            let tmp = tempfile::tempdir().unwrap();
            let options = TransformerTrainOptions {
                run_dir: tmp.path().to_path_buf(),
                minutes: None,
                init: None,
            };
            let lines = std::sync::Mutex::new(Vec::new());
            train_transformer(kind, &config(), &set, &options, &device, &|l| {
                lines.lock().unwrap().push(l.to_string())
            })
            .unwrap();
            let name = if kind == Kind::Base {
                "base.bpk"
            } else {
                "residual.bpk"
            };
            assert!(tmp.path().join(name).exists());
            assert!(lines
                .into_inner()
                .unwrap()
                .iter()
                .any(|l| l.contains("accuracy")));
        }
    }

    /// A fresh run may start from another run's checkpoint (`checkpoint/model.bpk`, the
    /// network inside the loop's wrapper) as well as from its final weights.
    #[test]
    fn a_run_starts_from_another_run_s_checkpoint_or_weights() {
        let set = tiny_set();
        let device = Device::flex().autodiff();
        let first = tempfile::tempdir().unwrap();
        let options = |dir: &std::path::Path, init: Option<PathBuf>| TransformerTrainOptions {
            run_dir: dir.to_path_buf(),
            minutes: None,
            init,
        };
        train_transformer(
            Kind::Base,
            &config(),
            &set,
            &options(first.path(), None),
            &device,
            &|_| {},
        )
        .unwrap();
        for (init, says) in [
            (
                "checkpoint/model.bpk",
                "starting from the checkpoint weights",
            ),
            ("base.bpk", "starting from the weights"),
        ] {
            let second = tempfile::tempdir().unwrap();
            let lines = std::sync::Mutex::new(Vec::new());
            train_transformer(
                Kind::Base,
                &config(),
                &set,
                &options(second.path(), Some(first.path().join(init))),
                &device,
                &|l| lines.lock().unwrap().push(l.to_string()),
            )
            .unwrap_or_else(|e| panic!("starting from {init}: {e:#}"));
            let lines = lines.into_inner().unwrap();
            assert!(lines.iter().any(|l| l.starts_with(says)), "{lines:?}");
        }
        // Weights of the other network are refused with the first attempt's reason.
        let third = tempfile::tempdir().unwrap();
        let error = train_transformer(
            Kind::Residual,
            &config(),
            &set,
            &options(third.path(), Some(first.path().join("base.bpk"))),
            &device,
            &|_| {},
        )
        .unwrap_err();
        assert!(format!("{error:#}").contains("base.bpk"), "{error:#}");
    }

    /// The residual transformer can learn a residual layer that is a function of the layers
    /// below: the run at chance on real tokens (loss ln 256 after 800 steps) is then the data's
    /// or the schedule's doing, not a broken forward pass or loss.
    #[test]
    fn residual_transformer_overfits_a_learnable_layer() {
        let mut rng = Rng::new(17);
        let items = (0..16)
            .map(|_| {
                let n = 8;
                TokenItem {
                    tokens: (0..PARTS)
                        .map(|p| {
                            let first: Vec<u32> = (0..n).map(|_| rng.below(16) as u32).collect();
                            (0..3u32)
                                .map(|j| {
                                    first
                                        .iter()
                                        .map(|t| (t * 5 + j * 3 + p as u32) % 16)
                                        .collect()
                                })
                                .collect()
                        })
                        .collect(),
                    captions: vec![0],
                    parts: [None; PARTS],
                    content: None,
                }
            })
            .collect();
        let set = TokenSet {
            items,
            texts: vec!["text".into()],
            embeddings: vec![[0.1; TEXT_DIM]],
        };
        let model = TransformerConfig::new()
            .with_width(32)
            .with_depth(2)
            .with_heads(2)
            .with_ff_width(64)
            .with_codebook_size(16)
            .with_vq_layers(3)
            .with_max_steps(8);
        let config = TransformerTrainingConfig::new(model)
            .with_batch_size(8)
            .with_steps(150)
            .with_learning_rate(3e-3)
            .with_warmup_steps(10)
            .with_label_smoothing(0.0)
            .with_drop_text(0.0)
            .with_log_every(50);
        let tmp = tempfile::tempdir().unwrap();
        let options = TransformerTrainOptions {
            run_dir: tmp.path().to_path_buf(),
            minutes: None,
            init: None,
        };
        let device = Device::flex().autodiff();
        train_transformer(Kind::Residual, &config, &set, &options, &device, &|_| {}).unwrap();
        let log = std::fs::read_to_string(tmp.path().join("log.csv")).unwrap();
        let last: Vec<(f64, f64)> = log
            .lines()
            .skip(1)
            .map(|l| {
                let f: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
                (f[2], f[3])
            })
            .collect();
        let tail = &last[last.len() - 10..];
        let loss = tail.iter().map(|(l, _)| l).sum::<f64>() / 10.0;
        let accuracy = tail.iter().map(|(_, a)| a).sum::<f64>() / 10.0;
        // The CPU backend's threaded sums make the loss curve vary from run to run (a CI run
        // ended at 0.529 against a bound of 0.5), so the bound sits well below chance, not at the
        // curve's edge; the accuracy says the layer was learnt.
        assert!(
            loss < 0.8 && accuracy > 0.9,
            "chance is ln 16 = 2.77: loss {loss:.3}, accuracy {accuracy:.3}"
        );
    }
}
