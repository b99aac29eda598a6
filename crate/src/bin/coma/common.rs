//! What several commands share: the model folder argument and loading it, writing a
//! generated motion, the LLM's arguments, and the arguments of every training command.

use anyhow::{bail, Result};
use clap::Args;
use coma::agents::llm::{LlmClient, LlmConfig, UreqTransport};
use coma::executor::block_on;
use coma::motion_file::write_motion;
use coma::render::FilmstripOptions;
use coma::session::{Command, Llm, Motion, Outcome, Session};
use std::path::{Path, PathBuf};

#[derive(Args)]
pub struct ModelArgs {
    /// Folder with spam.json, vq.bpk, base.bpk, residual.bpk, mean.npy, std.npy and the
    /// sentence encoder files.
    #[arg(long, default_value = "static/models")]
    pub models: PathBuf,
}

/// SPAM and the sentence encoder from a model folder, on the CPU.
pub fn load_model(dir: &Path) -> Result<coma::model::MotionModel> {
    Ok(coma::model::MotionModel::load(
        dir,
        &burn::tensor::Device::flex(),
    )?)
}

/// The engine with the model in `dir` on the CPU (what did not load is said on stderr).
pub fn load_session(dir: &Path) -> Result<Session> {
    let (session, missing) = Session::load(dir, &burn::tensor::Device::flex())?;
    for m in &missing {
        eprintln!("note: not loaded: {m}");
    }
    Ok(session)
}

/// Carries out a command that makes a motion without the agents (no LLM), and says on stderr
/// which paths could not be laid.
pub fn execute_motion(session: &Session, command: Command) -> Result<Motion> {
    let outcome = block_on(session.execute(command, &Llm::<UreqTransport>::Off, &mut |_| {}))?;
    match outcome {
        Outcome::Motion { motion, notes } => {
            for n in notes {
                eprintln!("note: {n}");
            }
            Ok(motion)
        }
        _ => anyhow::bail!("the engine answered with something other than a motion"),
    }
}

/// Writes the motion file and/or filmstrip of generated features.
pub fn write_outputs(
    features: &[coma::features::FeatureFrame],
    out: Option<&Path>,
    png: Option<&Path>,
    title: &str,
) -> Result<()> {
    let motion = coma::motion_file::MotionData::Features(features.to_vec());
    if let Some(path) = out {
        write_motion(path, &motion, true)?;
        println!(
            "wrote {} ({} frames, {:.1} s)",
            path.display(),
            features.len(),
            features.len() as f64 / coma::timing::FPS
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

/// Where the LLM is, if one is used.
#[derive(Args, Clone)]
pub struct LlmArgs {
    /// OpenAI-compatible base URL (e.g. http://127.0.0.1:8080/v1); without it the built-in
    /// planner and the evaluator do the work.
    #[arg(long)]
    llm: Option<String>,
    /// Model name sent to the LLM server.
    #[arg(long, default_value = "default")]
    model: String,
    /// Environment variable holding the API key (the key itself is never an argument, so it
    /// stays out of shell history and process lists).
    #[arg(long, default_value = "COMA_LLM_KEY")]
    api_key_env: String,
    /// Seconds to wait for one LLM reply.
    #[arg(long, default_value_t = 60.0)]
    timeout: f64,
    /// A vision model on the same server: during review it is shown a filmstrip of each
    /// segment and its description goes to the judge with the pose codes.
    #[arg(long, requires = "llm")]
    vision_model: Option<String>,
}

/// The engine's view of the LLM a command was given.
pub fn llm_of(client: &Option<LlmClient<UreqTransport>>) -> Llm<'_, UreqTransport> {
    match client {
        Some(client) => Llm::On(client),
        None => Llm::Off,
    }
}

impl LlmArgs {
    pub fn client(&self) -> Result<Option<LlmClient<UreqTransport>>> {
        let Some(url) = &self.llm else {
            return Ok(None);
        };
        let mut config = LlmConfig::new(url.clone(), self.model.clone());
        if let Ok(key) = std::env::var(&self.api_key_env) {
            config = config.with_api_key(key);
        }
        if !(self.timeout.is_finite() && self.timeout > 0.0) {
            bail!("--timeout must be a positive number of seconds");
        }
        config.timeout = std::time::Duration::from_secs_f64(self.timeout);
        config.vision_model = self.vision_model.clone().filter(|m| !m.trim().is_empty());
        Ok(Some(LlmClient::native(config)?))
    }
}

/// What every training command takes: the data, the run folder, the configuration and the
/// limits of this invocation.
#[derive(Args)]
pub struct RunArgs {
    /// Dataset folder (from `coma data build`).
    #[arg(long, default_value = "data/coma")]
    pub data: PathBuf,
    /// Run folder: checkpoints, logs, plots and the final weights (default: runs/<network>).
    #[arg(long)]
    pub run: Option<PathBuf>,
    /// Training configuration (JSON); default: the run's own config.json when resuming,
    /// otherwise configs/<network>.json.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Stop (with a checkpoint) after this many minutes.
    #[arg(long)]
    pub minutes: Option<f64>,
    /// Override the total number of steps.
    #[arg(long)]
    pub steps: Option<usize>,
    /// Start a fresh run from these trained weights (fine-tuning on new data) instead of
    /// random ones; a run that resumes from its checkpoint ignores it.
    #[arg(long)]
    pub init: Option<PathBuf>,
    /// Training backend: flex (pure Rust) or tch (libtorch; needs the `tch` feature).
    #[arg(long, default_value = "flex")]
    pub device: String,
}

impl RunArgs {
    /// The run folder of network `name` and its configuration, with `--steps` applied by
    /// `set_steps`.
    pub fn open<C: coma::train::ReadConfig>(
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
        let mut config = C::read(&path)?;
        if let Some(s) = self.steps {
            set_steps(&mut config, s);
        }
        Ok((run, config))
    }
}
