//! Training the VQ-VAE (`coma train vq`): random crops of the training split, smooth-L1
//! reconstruction plus position and velocity terms plus commitment, AdamW with warm-up,
//! moving-average codebooks, resumable checkpoints, and the reconstruction error in millimetres
//! on held-out motions.

use super::run::Run;
use crate::dataset::motions::{CropSpec, MotionSet};
use crate::dataset::Split;
use crate::features::{self, FeatureFrame, Normalizer, FEATURE_DIM, POSITIONS, ROOT_ROT_VEL};
use crate::geom;
use crate::model::vq::{MotionVq, VqConfig, VqTrainOutput};
use crate::rng::Rng;
use crate::timing::FRAMES_PER_TOKEN;
use anyhow::{Context, Result};
use burn::grad_clipping::GradientClippingConfig;
use burn::nn::loss::SmoothL1LossConfig;
use burn::optim::{AdamWConfig, GradientsParams};
use burn::prelude::*;
use burn::tensor::TensorData;
use std::path::PathBuf;

/// Everything a VQ training run is configured by (saved as the run's `config.json`).
#[derive(Config, Debug)]
pub struct VqTrainingConfig {
    pub model: VqConfig,
    /// Motions per step.
    #[config(default = 64)]
    pub batch_size: usize,
    /// Longest crop in frames (at 20 fps); shorter motions train in batches of their length.
    #[config(default = 64)]
    pub max_frames: usize,
    /// Chance that a crop is replayed at another speed (`features::retime`): timings the few
    /// actors of the small sources did not perform. 0 replays nothing.
    #[config(default = 0.0)]
    pub retime_chance: f64,
    /// The largest speed factor of a replayed crop (factors log-uniform in `[1/max, max]`).
    #[config(default = 1.25)]
    pub retime_max: f64,
    /// Chance that a crop is performed with another posture habit
    /// (`features::vary_posture`): stances and reaches the few actors of the small sources
    /// did not show. 0 varies nothing.
    #[config(default = 0.0)]
    pub posture_chance: f64,
    /// The largest turn of one bone in a varied crop, in degrees.
    #[config(default = 6.0)]
    pub posture_degrees: f64,
    /// How strongly crops favour rare actions (see `MotionSet::balance`: 0 draws in
    /// proportion to length, 1 gives every action the same share).
    #[config(default = 0.0)]
    pub balance: f64,
    /// Total optimizer steps.
    #[config(default = 5000)]
    pub steps: usize,
    #[config(default = 2e-4)]
    pub learning_rate: f64,
    /// Steps of linear learning-rate warm-up.
    #[config(default = 500)]
    pub warmup_steps: usize,
    /// The learning rate is divided by 10 after this fraction of the steps.
    #[config(default = 0.8)]
    pub decay_at: f64,
    /// Weight of the commitment loss (β).
    #[config(default = 0.02)]
    pub commitment: f64,
    /// Weight of the extra term on root-relative joint positions.
    #[config(default = 0.5)]
    pub position_weight: f64,
    /// Weight of the term on frame-to-frame changes of those positions.
    #[config(default = 0.5)]
    pub velocity_weight: f64,
    /// Weight of the heading term: smooth L1 (β = 0.05 rad) between the reconstructed and the
    /// true facing angle, each integrated from the root's turn per frame since the crop's
    /// start. A small error in the turn per frame costs little in the other terms but
    /// integrates into a drifting heading that turns the whole body. 0 leaves it out.
    #[config(default = 0.0)]
    pub heading_weight: f64,
    /// Above 0, trains the decoder alone for motions decoded from this many token layers:
    /// the encoder and the codebooks stay as `--init` gave them, so every token stays the
    /// same and transformers trained on them still fit. 0 trains everything.
    #[config(default = 0)]
    pub decoder_only_layers: usize,
    /// Above 0, holds the layer-0 tokens where `--init` put them while everything else
    /// learns: codebook 0 stays as it is, and the encoder is pulled, with this weight, toward
    /// the layer-0 code that `--init`'s encoder chooses for the same crop
    /// ([`MotionVq::base_code_loss`]). The residual layers carry what the encoder learns.
    /// Adam still moves a few codes whatever the weight (`runs/vq11` kept 98.3 %);
    /// `hold_base_codes` keeps every one. 0 lets layer 0 move.
    #[config(default = 0.0)]
    pub base_code_weight: f64,
    /// Holds the first encoders and codebook 0 exactly as `--init` gave them, so every
    /// layer-0 token stays; the residual codebooks, the decoder and (with `detail_encoders`)
    /// the detail encoders learn. Unlike `base_code_weight`, no token can move.
    #[config(default = false)]
    pub hold_base_codes: bool,
    /// The VQ-VAE has detail encoders ([`MotionVq::with_detail_encoders`]), added to
    /// `--init`'s weights if they have none. A training setting rather than one of `model`'s
    /// sizes: the page's models never have them, and its `spam.json` stays as it was.
    #[config(default = false)]
    pub detail_encoders: bool,
    #[config(default = 5.0)]
    pub checkpoint_minutes: f64,
    /// Steps between progress lines.
    #[config(default = 20)]
    pub log_every: usize,
    /// Steps between validation passes.
    #[config(default = 1000)]
    pub eval_every: usize,
    #[config(default = 1234)]
    pub seed: u64,
}

impl super::ReadConfig for VqTrainingConfig {
    /// Fields added since a run was written (speed replays, the heading term) take their
    /// defaults, which leave them out.
    fn read(path: &std::path::Path) -> Result<Self> {
        super::read_with_defaults(path, |file| {
            let model = serde_json::from_value(file.get("model").cloned().unwrap_or_default())
                .with_context(|| format!("{} has no valid \"model\"", path.display()))?;
            Ok(VqTrainingConfig::new(model))
        })
    }
}

impl VqTrainingConfig {
    /// A VQ-VAE of this run's sizes with random weights (with detail encoders if the run has
    /// them), for its weights to be loaded into.
    pub fn init_model(&self, device: &Device) -> MotionVq {
        let model = self.model.init(device);
        if self.detail_encoders {
            model.with_detail_encoders()
        } else {
            model
        }
    }
}

/// Learning rate of a step: linear warm-up, then constant, then a tenth.
fn learning_rate(config: &VqTrainingConfig, step: usize) -> f64 {
    let base = config.learning_rate;
    if step < config.warmup_steps {
        base * (step + 1) as f64 / config.warmup_steps as f64
    } else if (step as f64) < config.decay_at * config.steps as f64 {
        base
    } else {
        base * 0.1
    }
}

/// Flattened crops → `[B, T, 263]`.
fn batch_tensor(data: Vec<f32>, b: usize, t: usize, device: &Device) -> Tensor<3> {
    Tensor::from_data(TensorData::new(data, [b, t, FEATURE_DIM]), device)
}

/// Options of one invocation (not part of the run's configuration).
pub struct VqTrainOptions {
    pub data: PathBuf,
    pub run_dir: PathBuf,
    /// Stop after this many minutes (checkpointing first); the run resumes next time.
    pub minutes: Option<f64>,
    /// Weights a fresh run starts from (fine-tuning), instead of random ones.
    pub init: Option<PathBuf>,
}

/// Trains (or resumes) a VQ-VAE run, printing progress through `progress`.
pub fn train_vq(
    config: &VqTrainingConfig,
    options: &VqTrainOptions,
    device: &Device,
    progress: &dyn Fn(&str),
) -> Result<()> {
    let mut train = MotionSet::load(&options.data, Split::Train)?;
    train.balance(config.balance);
    // A small dataset may have no validation motions; training goes on without validation.
    let val = MotionSet::load(&options.data, Split::Val).ok();
    progress(&format!(
        "training on {} motions ({} frames), validating on {}",
        train.items.len(),
        train.frames(),
        val.as_ref()
            .map_or("nothing (empty validation split)".to_string(), |v| format!(
                "{} motions",
                v.items.len()
            ))
    ));
    let pulls_to_base_codes = config.base_code_weight > 0.0 && config.decoder_only_layers == 0;
    let mut columns = vec![
        "loss",
        "reconstruction",
        "commitment",
        "heading",
        "codes_reset",
    ];
    if pulls_to_base_codes {
        columns.extend(["base_codes", "base_codes_kept"]);
    }
    let (mut run, resumed) = Run::open(&options.run_dir, &columns)?;
    config
        .save(options.run_dir.join("config.json"))
        .context("saving config.json")?;

    let spec = CropSpec {
        retime_chance: config.retime_chance,
        retime_max: config.retime_max,
        posture_chance: config.posture_chance,
        posture_degrees: config.posture_degrees,
        ..CropSpec::plain(config.max_frames, FRAMES_PER_TOKEN)
    };
    progress(&format!(
        "share of crops per action: {}",
        super::format_shares(&train.action_shares())
    ));
    progress(&format!(
        "real crop frames per source (100 sampled batches): {}",
        super::format_shares(&train.crop_frame_shares(
            &mut Rng::new(config.seed),
            100,
            config.batch_size,
            &spec
        ))
    ));
    // The turn column in radians of heading: stored normalised, as half the angle.
    let turn_scale = 2.0 * train.normalizer.std[ROOT_ROT_VEL.start] as f64;
    let mut model = match options.init.as_deref() {
        // Detail encoders join weights that have none: copies of their first encoders.
        Some(path) if config.detail_encoders && !resumed => {
            match run.start_from(config.init_model(device), Some(path), resumed, progress) {
                Ok(model) => model,
                Err(_) => run
                    .start_from(config.model.init(device), Some(path), resumed, progress)?
                    .with_detail_encoders(),
            }
        }
        init => run.start_from(config.init_model(device), init, resumed, progress)?,
    };
    // The encoder whose layer-0 codes are held: `--init`'s, on every resumption too.
    let plain = device.clone().without_autodiff();
    let anchor = match (pulls_to_base_codes, options.init.as_deref()) {
        (false, _) => None,
        (true, None) => anyhow::bail!(
            "base_code_weight holds the layer-0 codes of the weights a run starts from: give --init"
        ),
        (true, Some(path)) => Some(
            crate::weights::load_file(config.model.init(&plain), path)
                .with_context(|| format!("loading the held codes' VQ-VAE {}", path.display()))?,
        ),
    };
    let mut optim = AdamWConfig::new()
        .with_weight_decay(0.0)
        .with_grad_clipping(Some(GradientClippingConfig::Norm(1.0)))
        .init();
    if resumed {
        (model, optim) = run.restore(model, optim)?;
        progress(&run.resumed_line());
    }

    let smooth_l1 = SmoothL1LossConfig::new().init();
    let heading_l1 = SmoothL1LossConfig::new().with_beta(0.05).init();
    let epoch_steps =
        (train.frames() as f64 / (config.batch_size * config.max_frames) as f64).max(1.0);
    let limits = super::run::StepLimits {
        steps: config.steps,
        log_every: config.log_every,
        epoch_steps,
        checkpoint_minutes: config.checkpoint_minutes,
        minutes: options.minutes,
    };
    while run.state.step < config.steps {
        let step = run.state.step;
        // Each step's randomness depends only on the seed and the step, so a resumed run
        // continues exactly as an uninterrupted one would.
        let mut rng = Rng::new(config.seed ^ (step as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
        let crops = train.sample_crops(&mut rng, config.batch_size, &spec);
        let (b, t) = (crops.batch, crops.frames);
        let x = batch_tensor(crops.data, b, t, device);
        let real_frames: Vec<usize> = crops
            .mask
            .chunks(t)
            .map(|m| m.iter().filter(|&&v| v > 0.0).count())
            .collect();
        let mask: Tensor<3> = Tensor::from_data(TensorData::new(crops.mask, [b, t, 1]), device);

        let decoder_only = config.decoder_only_layers;
        let out = if decoder_only > 0 {
            VqTrainOutput {
                reconstruction: model.forward_decoder_train(x.clone(), decoder_only),
                commitment: Tensor::zeros([1], device),
                assignments: Vec::new(),
                encodings: Vec::new(),
            }
        } else {
            model.forward_train(
                x.clone(),
                Some(&real_frames),
                &config.model,
                config.hold_base_codes,
                &mut rng,
            )
        };
        // Means over the motions' own frames: padding that holds a short clip's last frame
        // is not the clip.
        let masked_mean = |loss: Tensor<3>, mask: Tensor<3>| {
            let columns = loss.dims()[2] as f64;
            (loss * mask.clone()).sum() / (mask.sum() * columns).clamp_min(1.0)
        };
        let recon = masked_mean(
            smooth_l1.forward(out.reconstruction.clone(), x.clone()),
            mask.clone(),
        );
        let pos_pred = out.reconstruction.clone().slice(s![.., .., POSITIONS]);
        let pos_true = x.clone().slice(s![.., .., POSITIONS]);
        let positions = masked_mean(
            smooth_l1.forward(pos_pred.clone(), pos_true.clone()),
            mask.clone(),
        );
        let vel_pred =
            pos_pred.clone().slice(s![.., 1..t, ..]) - pos_pred.slice(s![.., 0..t - 1, ..]);
        let vel_true =
            pos_true.clone().slice(s![.., 1..t, ..]) - pos_true.slice(s![.., 0..t - 1, ..]);
        let pair_mask =
            mask.clone().slice(s![.., 1..t, ..]) * mask.clone().slice(s![.., 0..t - 1, ..]);
        let velocity = masked_mean(smooth_l1.forward(vel_pred, vel_true), pair_mask);
        let turn_error = (out.reconstruction.clone().slice(s![.., .., ROOT_ROT_VEL])
            - x.clone().slice(s![.., .., ROOT_ROT_VEL]))
            * mask.clone()
            * turn_scale;
        let heading = masked_mean(
            heading_l1.forward(turn_error.cumsum(1), Tensor::zeros([b, t, 1], device)),
            mask,
        );
        let mut loss = recon.clone()
            + positions * config.position_weight
            + velocity * config.velocity_weight
            + heading.clone() * config.heading_weight
            + out.commitment.clone() * config.commitment;
        let base = anchor.as_ref().map(|anchor| {
            let targets: Vec<Tensor<1, Int>> = anchor
                .tokenize(x.clone().without_autodiff())
                .into_iter()
                .map(|mut layers| {
                    let codes = layers.swap_remove(0);
                    Tensor::from_data(
                        codes.reshape([b * (t / FRAMES_PER_TOKEN)]).into_data(),
                        device,
                    )
                })
                .collect();
            model.base_code_loss(&out.encodings, &targets)
        });
        if let Some((base_loss, _)) = &base {
            loss = loss + base_loss.clone() * config.base_code_weight;
        }

        let mut values = vec![
            loss.clone().into_scalar::<f32>() as f64,
            recon.into_scalar::<f32>() as f64,
            out.commitment.clone().into_scalar::<f32>() as f64,
            heading.into_scalar::<f32>() as f64,
        ];
        let mut gradients = loss.backward();
        let grads = if decoder_only > 0 {
            GradientsParams::from_module(&mut gradients, model.decoder())
        } else {
            GradientsParams::from_grads(gradients, &model)
        };
        model = optim.step(learning_rate(config, step), model, grads);
        let reset = if decoder_only > 0 {
            0
        } else {
            model.update_codebooks(
                &out.assignments,
                config.model.ema_decay,
                (pulls_to_base_codes || config.hold_base_codes) as usize,
                &mut rng,
            )
        };
        values.push(reset as f64);
        if let Some((base_loss, kept)) = base {
            values.extend([base_loss.into_scalar::<f32>() as f64, kept]);
        }
        run.record(crops.batch, &values)?;

        let done = run.report_step(&limits, progress);
        let eval_due = limits.due(done, config.eval_every);
        if let Some(val) = val.as_ref().filter(|_| eval_due) {
            let e = reconstruction_errors(
                &model.valid(),
                val,
                &device.clone().without_autodiff(),
                64,
                match config.decoder_only_layers {
                    0 => usize::MAX,
                    layers => layers,
                },
            )?;
            progress(&format!(
                "step {done}: validation reconstruction error {:.1} mm root-aligned MPJPE, {:.1} mm with the root path integrated, {:.1} mm posture",
                e.root_aligned_mm, e.global_mm, e.posture_mm
            ));
            super::run::append_csv(
                &options.run_dir.join("val.csv"),
                "step,mpjpe_root_aligned_mm,error_root_integrated_mm,posture_mm",
                &format!(
                    "{done},{:.3},{:.3},{:.3}",
                    e.root_aligned_mm, e.global_mm, e.posture_mm
                ),
            )?;
        }
        if run.end_step(&model, &optim, &limits, "VQ-VAE training", progress)? {
            break;
        }
    }
    if run.state.step >= config.steps {
        run.save_weights(model.valid(), "vq.bpk", progress)?;
    }
    Ok(())
}

/// Reconstruction errors of a VQ-VAE on whole motions, in millimetres, each a mean over
/// every joint of every frame (the pelvis included).
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct ReconstructionError {
    /// Joints recovered from the features with the root path integrated (drift included).
    pub global_mm: f64,
    /// The same with both skeletons' pelvis put at the same place in every frame (the field's
    /// MPJPE). A drifting heading still turns the body here.
    pub root_aligned_mm: f64,
    /// The posture alone: pelvis-relative joints in the body's own facing frame, read from the
    /// features before any root motion is integrated. `root_aligned_mm` far above it means
    /// the error is in the integrated heading, not in the pose.
    pub posture_mm: f64,
    /// Motions measured.
    pub motions: usize,
    /// Joint positions measured (motions × frames × 22).
    joints: usize,
}

impl ReconstructionError {
    /// Pools two measurements, weighting each by its joint positions.
    pub fn pool(self, other: ReconstructionError) -> ReconstructionError {
        let n = (self.joints + other.joints).max(1) as f64;
        let mean = |a: f64, b: f64| (a * self.joints as f64 + b * other.joints as f64) / n;
        ReconstructionError {
            global_mm: mean(self.global_mm, other.global_mm),
            root_aligned_mm: mean(self.root_aligned_mm, other.root_aligned_mm),
            posture_mm: mean(self.posture_mm, other.posture_mm),
            motions: self.motions + other.motions,
            joints: self.joints + other.joints,
        }
    }
}

/// The errors of one motion reconstructed whole (cut to a multiple of 4 frames) from its
/// first `layers` residual layers (0: from the encoder's output unquantized); `None` for a
/// motion shorter than one token.
fn motion_error(
    model: &MotionVq,
    item: &[FeatureFrame],
    normalizer: &Normalizer,
    device: &Device,
    layers: usize,
) -> Result<Option<ReconstructionError>> {
    let t = item.len() / FRAMES_PER_TOKEN * FRAMES_PER_TOKEN;
    if t == 0 {
        return Ok(None);
    }
    let frames = &item[..t];
    let x = batch_tensor(frames.iter().flatten().copied().collect(), 1, t, device);
    // Only the first `layers` residual layers: what a decoder sees when the later layers
    // are left out (quantisation dropout trained it for that).
    let y = if layers == 0 {
        model.reconstruct_unquantized(x)
    } else {
        let tokens: Vec<_> = model
            .tokenize(x)
            .into_iter()
            .map(|mut part| {
                part.truncate(layers);
                part
            })
            .collect();
        model.decode(&tokens)
    };
    let y: Vec<f32> = y
        .try_into_vec_as::<f32>()
        .map_err(|e| anyhow::anyhow!("{e:?}"))?;
    let recon: Vec<FeatureFrame> = y
        .chunks_exact(FEATURE_DIM)
        .map(|c| c.try_into().expect("263 columns"))
        .collect();
    let (mut global, mut aligned, mut posture) = (0.0, 0.0, 0.0);
    let (truth_rows, guess_rows) = (
        normalizer.denormalize(frames),
        normalizer.denormalize(&recon),
    );
    for (a, b) in truth_rows.iter().zip(&guess_rows) {
        for j in 0..crate::skeleton::NUM_JOINTS - 1 {
            let c = POSITIONS.start + j * 3;
            let (p, q) = (&a[c..c + 3], &b[c..c + 3]);
            posture += p
                .iter()
                .zip(q)
                .map(|(u, v)| ((u - v) as f64).powi(2))
                .sum::<f64>()
                .sqrt();
        }
    }
    let truth = features::features_to_joints(&truth_rows);
    let guess = features::features_to_joints(&guess_rows);
    for (a, b) in truth.iter().zip(&guess) {
        for (p, q) in a.iter().zip(b) {
            global += geom::dist(*p, *q);
            aligned += geom::dist(geom::sub(*p, a[0]), geom::sub(*q, b[0]));
        }
    }
    let joints = t * crate::skeleton::NUM_JOINTS;
    let mm = |sum: f64| sum / joints as f64 * 1000.0;
    Ok(Some(ReconstructionError {
        global_mm: mm(global),
        root_aligned_mm: mm(aligned),
        posture_mm: mm(posture),
        motions: 1,
        joints,
    }))
}

/// Reconstructs up to `limit` motions of `set` whole (each cut to a multiple of 4 frames) and
/// measures the joint errors, pooled over every motion and per group that `group` names
/// (source, action): each motion is reconstructed once.
pub fn reconstruction_errors_by(
    model: &MotionVq,
    set: &MotionSet,
    device: &Device,
    limit: usize,
    layers: usize,
    group: impl Fn(&crate::dataset::motions::MotionItem) -> Option<String>,
) -> Result<(
    ReconstructionError,
    std::collections::BTreeMap<String, ReconstructionError>,
)> {
    let mut all = ReconstructionError::default();
    let mut groups = std::collections::BTreeMap::<String, ReconstructionError>::new();
    for item in set.items.iter().take(limit) {
        if let Some(e) = motion_error(model, &item.features, &set.normalizer, device, layers)? {
            all = all.pool(e);
            if let Some(key) = group(item) {
                let slot = groups.entry(key).or_default();
                *slot = slot.pool(e);
            }
        }
    }
    Ok((all, groups))
}

/// [`reconstruction_errors_by`] pooled over every motion only.
pub fn reconstruction_errors(
    model: &MotionVq,
    set: &MotionSet,
    device: &Device,
    limit: usize,
    layers: usize,
) -> Result<ReconstructionError> {
    Ok(reconstruction_errors_by(model, set, device, limit, layers, |_| None)?.0)
}

/// Share of the layer-0 codes that two VQ-VAEs give the same motions, over every part and
/// step: how much of what a base transformer learned on `other`'s tokens still holds for
/// `model`'s (1 when a fine-tune moved no code).
pub fn base_code_agreement(
    model: &MotionVq,
    other: &MotionVq,
    set: &MotionSet,
    device: &Device,
    limit: usize,
) -> f64 {
    let (mut same, mut all) = (0usize, 0usize);
    for item in set.items.iter().take(limit) {
        let a = model.tokenize_motion(&item.features, device);
        let b = other.tokenize_motion(&item.features, device);
        for (pa, pb) in a.iter().zip(&b) {
            same += pa[0].iter().zip(&pb[0]).filter(|(x, y)| x == y).count();
            all += pa[0].len();
        }
    }
    same as f64 / all.max(1) as f64
}

/// How predictable one residual layer's codes are, over a set of motions: entropies in nats
/// (ln 256 = 5.55 for codes used uniformly at random), from code counts per body part.
#[derive(Clone, Debug)]
pub struct LayerCodeStats {
    pub layer: usize,
    /// H(code): how evenly the layer's codes are used.
    pub entropy: f64,
    /// H(code | the code of the layer below at the same step and part): what the layer
    /// below leaves unexplained. Near `entropy` means the layers are independent.
    pub given_previous: f64,
    /// H(code | the layer-0 code at the same step and part).
    pub given_first: f64,
    /// Distinct codes used.
    pub used: usize,
}

/// Entropy in nats of the counts' distribution.
fn entropy(counts: impl Iterator<Item = usize>) -> f64 {
    let counts: Vec<f64> = counts.filter(|&c| c > 0).map(|c| c as f64).collect();
    let total: f64 = counts.iter().sum();
    counts.iter().map(|c| -(c / total) * (c / total).ln()).sum()
}

/// H(B | A) in nats from counts of the pairs `(a, b)`: H(A, B) − H(A).
fn conditional_entropy(pairs: &std::collections::HashMap<(u32, u32), usize>) -> f64 {
    let mut first: std::collections::HashMap<u32, usize> = std::collections::HashMap::new();
    for ((a, _), n) in pairs {
        *first.entry(*a).or_default() += n;
    }
    entropy(pairs.values().copied()) - entropy(first.values().copied())
}

/// Code statistics of every residual layer over up to `limit` motions of `set`, pooled over
/// the four body parts (each part's pairs kept apart). Conditional entropies from counts are
/// biased low when codes outnumber the samples per code: compare layers with each other, not
/// with ln 256.
pub fn code_statistics(
    model: &MotionVq,
    set: &MotionSet,
    device: &Device,
    limit: usize,
) -> Vec<LayerCodeStats> {
    use std::collections::HashMap;
    let mut single: Vec<HashMap<(usize, u32), usize>> = Vec::new();
    let mut previous: Vec<HashMap<(u32, u32), usize>> = Vec::new();
    let mut from_first: Vec<HashMap<(u32, u32), usize>> = Vec::new();
    for item in set.items.iter().take(limit) {
        let tokens = model.tokenize_motion(&item.features, device);
        for (part, layers) in tokens.iter().enumerate() {
            if single.len() < layers.len() {
                single.resize_with(layers.len(), HashMap::new);
                previous.resize_with(layers.len(), HashMap::new);
                from_first.resize_with(layers.len(), HashMap::new);
            }
            // Part-specific keys: codes of different parts are different symbols.
            let key = |c: u32| c + (part as u32) * 1_000_000;
            for (l, codes) in layers.iter().enumerate() {
                for (s, &c) in codes.iter().enumerate() {
                    *single[l].entry((part, c)).or_default() += 1;
                    if l > 0 {
                        *previous[l].entry((key(layers[l - 1][s]), c)).or_default() += 1;
                        *from_first[l].entry((key(layers[0][s]), c)).or_default() += 1;
                    }
                }
            }
        }
    }
    let parts = 4.0f64;
    (0..single.len())
        .map(|l| {
            // Pooled over parts: subtract the part's own entropy (ln 4 when parts are equally
            // represented, which they are: every motion has all four).
            let h = entropy(single[l].values().copied()) - parts.ln();
            LayerCodeStats {
                layer: l,
                entropy: h,
                given_previous: if l > 0 {
                    conditional_entropy(&previous[l])
                } else {
                    h
                },
                given_first: if l > 0 {
                    conditional_entropy(&from_first[l])
                } else {
                    h
                },
                used: single[l].len(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::motions::MotionItem;

    fn motions() -> MotionSet {
        let mut rng = Rng::new(11);
        let items = (0..3)
            .map(|i| MotionItem {
                name: format!("m{i}"),
                features: (0..24)
                    .map(|_| std::array::from_fn(|_| rng.uniform() * 2.0 - 1.0))
                    .collect(),
                captions: Vec::new(),
                parts: Default::default(),
                content: None,
                source: None,
            })
            .collect();
        crate::dataset::motions::tests::plain_set(items)
    }

    #[test]
    fn a_model_agrees_with_itself_on_every_base_code_and_not_with_another() {
        let device = Device::flex();
        let config = crate::model::generate::tests::tiny_vq();
        let (a, b) = (config.init(&device), config.init(&device));
        let set = motions();
        assert_eq!(base_code_agreement(&a, &a, &set, &device, 10), 1.0);
        let other = base_code_agreement(&a, &b, &set, &device, 10);
        assert!(other < 0.9, "two random models agree on {other}");
    }
}
