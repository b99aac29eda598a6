//! Training the text–motion evaluator (`coma train evaluator`): symmetric InfoNCE between
//! motion crops and one of their captions, with near-duplicate captions taken out of each
//! other's negatives (the dataset's captions come from labels, so many motions share a
//! sentence), validated by top-3 R-precision on the validation split.

use super::run::Run;
use crate::dataset::motions::MotionSet;
use crate::features::FeatureFrame;
use crate::metrics::r_precision;
use crate::model::evaluator::{motion_batch, Evaluator, EvaluatorConfig};
use crate::model::transformer::TEXT_DIM;
use crate::rng::Rng;
use anyhow::Result;
use burn::grad_clipping::GradientClippingConfig;
use burn::optim::{AdamWConfig, GradientsParams};
use burn::prelude::*;
use burn::tensor::activation::log_softmax;
use burn::tensor::TensorData;
use std::collections::HashMap;
use std::path::PathBuf;

/// Everything an evaluator run is configured by (saved as `config.json`).
#[derive(Config, Debug)]
pub struct EvaluatorTrainingConfig {
    pub model: EvaluatorConfig,
    #[config(default = 64)]
    pub batch_size: usize,
    #[config(default = 4000)]
    pub steps: usize,
    #[config(default = 1e-4)]
    pub learning_rate: f64,
    #[config(default = 200)]
    pub warmup_steps: usize,
    /// Temperature of the contrastive logits.
    #[config(default = 0.1)]
    pub temperature: f64,
    /// Captions at least this similar (MiniLM cosine) are not each other's negatives.
    #[config(default = 0.9)]
    pub duplicate_similarity: f64,
    #[config(default = 5.0)]
    pub checkpoint_minutes: f64,
    #[config(default = 20)]
    pub log_every: usize,
    #[config(default = 500)]
    pub eval_every: usize,
    #[config(default = 2468)]
    pub seed: u64,
}

/// Motions with the MiniLM embeddings of their distinct captions.
pub struct CaptionedMotions {
    /// Normalised features per motion.
    pub motions: Vec<Vec<FeatureFrame>>,
    /// Indices into `embeddings` of each motion's captions.
    pub captions: Vec<Vec<usize>>,
    pub embeddings: Vec<[f32; TEXT_DIM]>,
}

impl CaptionedMotions {
    /// Embeds every distinct caption of `set` once with `embed`.
    pub fn build(set: &MotionSet, embed: super::tokens::TextEmbedder) -> Result<CaptionedMotions> {
        let mut index: HashMap<&str, usize> = HashMap::new();
        let mut texts: Vec<&str> = Vec::new();
        let mut captions = Vec::with_capacity(set.items.len());
        for item in &set.items {
            captions.push(
                item.captions
                    .iter()
                    .map(|c| {
                        *index.entry(c.as_str()).or_insert_with(|| {
                            texts.push(c.as_str());
                            texts.len() - 1
                        })
                    })
                    .collect::<Vec<_>>(),
            );
        }
        let mut embeddings = Vec::with_capacity(texts.len());
        for chunk in texts.chunks(64) {
            embeddings.extend(embed(chunk)?);
        }
        let keep: Vec<usize> = (0..set.items.len())
            .filter(|&i| !captions[i].is_empty())
            .collect();
        Ok(CaptionedMotions {
            motions: keep
                .iter()
                .map(|&i| set.items[i].features.clone())
                .collect(),
            captions: keep.iter().map(|&i| captions[i].clone()).collect(),
            embeddings,
        })
    }
}

fn cosine(a: &[f32], b: &[f32]) -> f64 {
    let dot: f64 = a.iter().zip(b).map(|(x, y)| *x as f64 * *y as f64).sum();
    let na: f64 = a.iter().map(|x| (*x as f64).powi(2)).sum::<f64>().sqrt();
    let nb: f64 = b.iter().map(|x| (*x as f64).powi(2)).sum::<f64>().sqrt();
    dot / (na * nb).max(1e-12)
}

/// Options of one invocation.
pub struct EvaluatorTrainOptions {
    pub run_dir: PathBuf,
    pub minutes: Option<f64>,
    /// Weights a fresh run starts from (fine-tuning), instead of random ones.
    pub init: Option<PathBuf>,
}

fn learning_rate(config: &EvaluatorTrainingConfig, step: usize) -> f64 {
    // Cosine decay to a tenth.
    super::warmup_cosine(
        config.learning_rate,
        config.warmup_steps,
        config.steps,
        0.1,
        step,
    )
}

/// Top-3 R-precision (batches of 32) of the evaluator on motions and their first caption,
/// in a fixed shuffled order (the split lists similar clips next to each other, which would
/// make every batch a set of near-twins).
pub fn retrieval_top3(
    model: &Evaluator,
    config: &EvaluatorConfig,
    data: &CaptionedMotions,
    device: &Device,
) -> f64 {
    let mut order: Vec<usize> = (0..data.motions.len()).collect();
    Rng::new(32).shuffle(&mut order);
    let refs: Vec<&[FeatureFrame]> = order.iter().map(|&i| data.motions[i].as_slice()).collect();
    let motions = model.embed_motions(config, &refs, device);
    let sentences: Vec<[f32; TEXT_DIM]> = order
        .iter()
        .map(|&i| data.embeddings[data.captions[i][0]])
        .collect();
    let texts = model.embed_texts(&sentences, device);
    r_precision(&texts, &motions, 32)[2]
}

/// Trains (or resumes) an evaluator run.
pub fn train_evaluator(
    config: &EvaluatorTrainingConfig,
    train: &CaptionedMotions,
    val: Option<&CaptionedMotions>,
    options: &EvaluatorTrainOptions,
    device: &Device,
    progress: &dyn Fn(&str),
) -> Result<()> {
    anyhow::ensure!(
        train.motions.len() >= 2,
        "the evaluator needs at least two captioned training motions"
    );
    let (mut run, resumed) = Run::open(&options.run_dir, &["loss", "accuracy"])?;
    config
        .save(options.run_dir.join("config.json"))
        .map_err(|e| anyhow::anyhow!("saving config.json: {e}"))?;
    let mut model = run.start_from(
        config.model.init(device),
        options.init.as_deref(),
        resumed,
        progress,
    )?;
    let mut optim = AdamWConfig::new()
        .with_weight_decay(1e-4)
        .with_grad_clipping(Some(GradientClippingConfig::Norm(1.0)))
        .init();
    if resumed {
        (model, optim) = run.restore(model, optim)?;
        progress(&run.resumed_line());
    }
    let plain = device.clone().without_autodiff();
    let b = config.batch_size.min(train.motions.len());
    let max_frames = config.model.max_frames();
    let epoch_steps = (train.motions.len() as f64 / b as f64).max(1.0);
    let limits = super::run::StepLimits {
        steps: config.steps,
        log_every: config.log_every,
        epoch_steps,
        checkpoint_minutes: config.checkpoint_minutes,
        minutes: options.minutes,
    };
    while run.state.step < config.steps {
        let step = run.state.step;
        let mut rng = Rng::new(config.seed ^ (step as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
        // Motions of similar length go together (an anchor's length, down to ¾ of it).
        let anchor = train.motions[rng.below(train.motions.len())]
            .len()
            .min(max_frames);
        let mut picks: Vec<usize> = Vec::with_capacity(b);
        for _ in 0..b * 50 {
            if picks.len() == b {
                break;
            }
            let i = rng.below(train.motions.len());
            let len = train.motions[i].len().min(max_frames);
            if len <= anchor && len * 4 >= anchor * 3 && !picks.contains(&i) {
                picks.push(i);
            }
        }
        while picks.len() < b {
            let i = rng.below(train.motions.len());
            if !picks.contains(&i) {
                picks.push(i);
            }
        }
        let crops: Vec<&[FeatureFrame]> = picks.iter().map(|&i| &train.motions[i][..]).collect();
        let starts: Vec<usize> = crops
            .iter()
            .map(|m| rng.below(m.len().saturating_sub(max_frames) + 1))
            .collect();
        let captions: Vec<usize> = picks
            .iter()
            .map(|&i| train.captions[i][rng.below(train.captions[i].len())])
            .collect();
        let (x, pad) = motion_batch(&config.model, &crops, Some(&starts), device);
        let sentences: Vec<f32> = captions.iter().flat_map(|&c| train.embeddings[c]).collect();
        let text = Tensor::from_data(TensorData::new(sentences, [b, TEXT_DIM]), device);
        // Near-duplicate captions are positives of each other in truth: leave them out.
        let mut excluded = vec![0.0f32; b * b];
        for i in 0..b {
            for j in 0..b {
                if i != j
                    && (captions[i] == captions[j]
                        || cosine(
                            &train.embeddings[captions[i]],
                            &train.embeddings[captions[j]],
                        ) >= config.duplicate_similarity)
                {
                    excluded[i * b + j] = -1e4;
                }
            }
        }
        let excluded = Tensor::<2>::from_data(TensorData::new(excluded, [b, b]), device);
        let m = model.motion.forward(x, pad);
        let t = model.text.forward(text);
        let logits = m.matmul(t.transpose()) / config.temperature + excluded;
        let eye = Tensor::<2>::eye(b, device);
        let motion_to_text = (log_softmax(logits.clone(), 1) * eye.clone()).sum_dim(1);
        let text_to_motion = (log_softmax(logits.clone(), 0) * eye).sum_dim(0);
        let loss = (motion_to_text.mean() + text_to_motion.mean()).neg() / 2.0;
        let loss_value = loss.clone().into_scalar::<f32>() as f64;
        let best: Vec<i64> = logits
            .argmax(1)
            .try_into_vec_as::<i64>()
            .map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let accuracy = best
            .iter()
            .enumerate()
            .filter(|(i, j)| **j as usize == *i)
            .count() as f64
            / b as f64;
        let grads = GradientsParams::from_grads(loss.backward(), &model);
        model = optim.step(learning_rate(config, step), model, grads);
        run.record(b, &[loss_value, accuracy])?;

        let done = run.report_step(&limits, progress);
        if let Some(val) = val.filter(|_| limits.due(done, config.eval_every)) {
            let top3 = retrieval_top3(&model.valid(), &config.model, val, &plain);
            progress(&format!(
                "step {done}: validation top-3 R-precision {top3:.3}"
            ));
            super::run::append_csv(
                &options.run_dir.join("eval.csv"),
                "step,val_top3",
                &format!("{done},{top3:.4}"),
            )?;
        }
        if run.end_step(&model, &optim, &limits, "text–motion evaluator", progress)? {
            break;
        }
    }
    if run.state.step >= config.steps {
        run.save_weights(model.valid(), "evaluator.bpk", progress)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::FEATURE_DIM;

    /// Two kinds of motion (rising and falling values) with two kinds of caption: the
    /// evaluator must learn to tell them apart.
    fn toy() -> CaptionedMotions {
        let mut rng = Rng::new(3);
        let motions = (0..24)
            .map(|i| {
                let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
                (0..16 + i)
                    .map(|t| {
                        let mut f = [0.0f32; FEATURE_DIM];
                        for (k, v) in f.iter_mut().enumerate() {
                            *v = sign * (t as f32 * 0.1 + k as f32 * 0.001) + rng.normal() * 0.1;
                        }
                        f
                    })
                    .collect()
            })
            .collect();
        let mut up = [0.0f32; TEXT_DIM];
        up[0] = 1.0;
        let mut down = [0.0f32; TEXT_DIM];
        down[1] = 1.0;
        CaptionedMotions {
            motions,
            captions: (0..24).map(|i| vec![i % 2]).collect(),
            embeddings: vec![up, down],
        }
    }

    #[test]
    fn the_evaluator_learns_to_match_two_kinds_of_motion_and_resumes() {
        let data = toy();
        let model = EvaluatorConfig::new()
            .with_width(16)
            .with_depth(1)
            .with_heads(2)
            .with_ff_width(32)
            .with_text_hidden(16)
            .with_embedding(8)
            .with_max_patches(8)
            .with_dropout(0.0);
        let config = EvaluatorTrainingConfig::new(model)
            .with_batch_size(8)
            .with_steps(60)
            .with_learning_rate(3e-3)
            .with_warmup_steps(5)
            .with_log_every(30)
            .with_eval_every(60);
        let tmp = tempfile::tempdir().unwrap();
        let device = Device::flex().autodiff();
        let options = EvaluatorTrainOptions {
            run_dir: tmp.path().to_path_buf(),
            minutes: None,
            init: None,
        };
        let half = EvaluatorTrainingConfig {
            steps: 30,
            ..config.clone()
        };
        train_evaluator(&half, &data, Some(&data), &options, &device, &|_| {}).unwrap();
        let lines = std::sync::Mutex::new(Vec::new());
        train_evaluator(&config, &data, Some(&data), &options, &device, &|l| {
            lines.lock().unwrap().push(l.to_string())
        })
        .unwrap();
        let lines = lines.into_inner().unwrap();
        assert!(lines[0].starts_with("resumed at step 30"), "{lines:?}");
        let trained = config
            .model
            .init(&Device::flex())
            .try_load_file(tmp.path().join("evaluator.bpk"))
            .unwrap();
        // Each caption's embedding must sit nearer to motions of its own kind.
        let refs: Vec<&[FeatureFrame]> = data.motions.iter().map(Vec::as_slice).collect();
        let m = trained.embed_motions(&config.model, &refs, &Device::flex());
        let t = trained.embed_texts(&data.embeddings, &Device::flex());
        let right = (0..24)
            .filter(|&i| {
                let own = crate::metrics::distance(&t[i % 2], &m[i]);
                let other = crate::metrics::distance(&t[1 - i % 2], &m[i]);
                own < other
            })
            .count();
        assert!(right >= 22, "{right}/24 motions nearer their own caption");
    }
}
