//! `coma render`: a motion drawn as a PNG filmstrip.

use anyhow::Result;
use clap::{Args, ValueEnum};
use coma::motion_file::read_motion;
use coma::render::{FilmstripOptions, View};
use std::path::PathBuf;

#[derive(Args)]
pub struct RenderArgs {
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
}

#[derive(Clone, Copy, ValueEnum)]
enum ViewArg {
    Front,
    Side,
    ThreeQuarter,
}

pub fn run(args: RenderArgs) -> Result<()> {
    let RenderArgs {
        input,
        out,
        frames,
        columns,
        view,
        title,
    } = args;
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
    Ok(())
}
