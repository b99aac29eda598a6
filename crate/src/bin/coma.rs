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

#[derive(Clone, Copy, ValueEnum)]
enum ViewArg {
    Front,
    Side,
    ThreeQuarter,
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
