//! `coma serve`: the built page on localhost (the `coma-serve` crate's server).

use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

#[derive(Args)]
pub struct ServeArgs {
    /// Folder to serve.
    #[arg(default_value = "dist")]
    dir: PathBuf,
    #[arg(long, default_value_t = 8080)]
    port: u16,
}

pub fn run(args: ServeArgs) -> Result<()> {
    coma_serve::serve_page(&args.dir, args.port)
}
