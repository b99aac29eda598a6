//! `coma serve`: the built page on localhost.

use anyhow::{bail, Result};
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
    if !args.dir.join("index.html").exists() {
        bail!(
            "{} has no index.html: build the page first (see README.md)",
            args.dir.display()
        );
    }
    coma::serve::serve(&args.dir, args.port)?;
    Ok(())
}
