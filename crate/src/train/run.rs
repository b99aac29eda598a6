//! What every training run shares: its folder, resumable checkpoints written every few
//! minutes, the loss log (CSV) with its PNG plot, and the progress line.
//!
//! A run folder holds `config.json`, `log.csv`, `losses.png` and `checkpoint/` with
//! `model.bpk`, `optim.bpk` and `state.json`. A checkpoint is written to `checkpoint.tmp/`
//! and renamed into place, so a run stopped at any moment leaves the previous one intact.

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Where a run stands; saved with every checkpoint.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct RunState {
    /// Optimizer steps done.
    pub step: usize,
    /// Seconds of training so far, over all sessions.
    pub seconds: f64,
    /// Samples seen so far.
    pub samples: u64,
}

impl RunState {
    /// The state of a run folder's latest checkpoint, if it has a readable one.
    pub fn of(dir: &Path) -> Option<RunState> {
        let text = std::fs::read_to_string(dir.join("checkpoint").join("state.json")).ok()?;
        serde_json::from_str(&text).ok()
    }
}

/// When a loop logs, checkpoints and stops: its total steps, steps between log lines and the
/// steps of one epoch (for the log's epoch count), minutes between checkpoints, and this
/// session's time limit in minutes.
#[derive(Clone, Copy, Debug)]
pub struct StepLimits {
    pub steps: usize,
    pub log_every: usize,
    pub epoch_steps: f64,
    pub checkpoint_minutes: f64,
    pub minutes: Option<f64>,
}

impl StepLimits {
    /// Whether step `done` is due for what a loop does every `every` steps (and always at its
    /// last step).
    pub fn due(&self, done: usize, every: usize) -> bool {
        done % every.max(1) == 0 || done == self.steps
    }
}

/// A training run's folder and bookkeeping.
pub struct Run {
    pub dir: PathBuf,
    pub state: RunState,
    started: Instant,
    seconds_at_start: f64,
    step_at_start: usize,
    samples_at_start: u64,
    /// Values recorded since the last progress line.
    recent: Vec<Vec<f64>>,
    last_checkpoint: Instant,
    log: std::fs::File,
    columns: Vec<String>,
}

impl Run {
    /// Opens (or starts) the run in `dir`. Returns the run and whether a checkpoint exists to
    /// resume from.
    pub fn open(dir: &Path, columns: &[&str]) -> Result<(Run, bool)> {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let state_path = dir.join("checkpoint").join("state.json");
        let (state, resumed) = match std::fs::read_to_string(&state_path) {
            Ok(text) => (
                serde_json::from_str(&text)
                    .with_context(|| format!("{} is damaged", state_path.display()))?,
                true,
            ),
            Err(_) => (RunState::default(), false),
        };
        let log_path = dir.join("log.csv");
        let new_log = !log_path.exists() || !resumed;
        if !new_log {
            // Steps logged after the checkpoint will be trained again: drop them.
            let text = std::fs::read_to_string(&log_path)?;
            let kept: Vec<&str> = text
                .lines()
                .enumerate()
                .filter(|(i, l)| {
                    *i == 0
                        || l.split(',')
                            .next()
                            .and_then(|s| s.parse::<usize>().ok())
                            .is_some_and(|s| s <= state.step)
                })
                .map(|(_, l)| l)
                .collect();
            std::fs::write(&log_path, kept.join("\n") + "\n")?;
        }
        let mut log = if new_log {
            std::fs::File::create(&log_path)?
        } else {
            std::fs::OpenOptions::new().append(true).open(&log_path)?
        };
        if new_log {
            writeln!(log, "step,seconds,{}", columns.join(","))?;
        }
        let (seconds_at_start, step_at_start, samples_at_start) =
            (state.seconds, state.step, state.samples);
        Ok((
            Run {
                dir: dir.to_path_buf(),
                state,
                started: Instant::now(),
                seconds_at_start,
                step_at_start,
                samples_at_start,
                recent: Vec::new(),
                last_checkpoint: Instant::now(),
                log,
                columns: columns.iter().map(|c| c.to_string()).collect(),
            },
            resumed,
        ))
    }

    /// Path of a file of the latest checkpoint.
    pub fn checkpoint_file(&self, name: &str) -> PathBuf {
        self.dir.join("checkpoint").join(name)
    }

    /// Records one step: `samples` processed and the logged values (in column order).
    pub fn record(&mut self, samples: usize, values: &[f64]) -> Result<()> {
        self.state.step += 1;
        self.state.samples += samples as u64;
        self.state.seconds = self.seconds_at_start + self.started.elapsed().as_secs_f64();
        let cells: Vec<String> = values.iter().map(|v| format!("{v:.6}")).collect();
        writeln!(
            self.log,
            "{},{:.1},{}",
            self.state.step,
            self.state.seconds,
            cells.join(",")
        )?;
        self.recent.push(values.to_vec());
        Ok(())
    }

    /// Minutes this session has trained.
    pub fn session_minutes(&self) -> f64 {
        self.started.elapsed().as_secs_f64() / 60.0
    }

    /// A progress line: step, epoch, each column averaged over the steps since the last line,
    /// this session's throughput and the time left.
    pub fn progress_line(&mut self, total_steps: usize, epoch: f64) -> String {
        let n = self.recent.len().max(1) as f64;
        let named: Vec<String> = self
            .columns
            .iter()
            .enumerate()
            .map(|(i, c)| {
                format!(
                    "{c} {:.4}",
                    // A fold from +0 so an empty window prints 0 rather than −0.
                    self.recent.iter().fold(0.0, |acc, r| acc + r[i]) / n
                )
            })
            .collect();
        self.recent.clear();
        let seconds = self.started.elapsed().as_secs_f64().max(1e-9);
        let samples_per_second = (self.state.samples - self.samples_at_start) as f64 / seconds;
        let seconds_per_step = seconds / (self.state.step - self.step_at_start).max(1) as f64;
        let eta = (total_steps.saturating_sub(self.state.step)) as f64 * seconds_per_step;
        format!(
            "epoch {epoch:.2} step {}/{total_steps} {} | {samples_per_second:.1} samples/s | ETA {}",
            self.state.step,
            named.join(" "),
            format_duration(eta)
        )
    }

    /// True when `minutes` have passed since the last checkpoint.
    pub fn checkpoint_due(&self, minutes: f64) -> bool {
        self.last_checkpoint.elapsed().as_secs_f64() >= minutes * 60.0
    }

    /// Writes a checkpoint: `write` puts its files into the given folder, then the state is
    /// added and the folder atomically replaces the previous checkpoint.
    pub fn checkpoint(&mut self, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
        let tmp = self.dir.join("checkpoint.tmp");
        let _ = std::fs::remove_dir_all(&tmp);
        std::fs::create_dir_all(&tmp)?;
        write(&tmp)?;
        std::fs::write(
            tmp.join("state.json"),
            serde_json::to_string_pretty(&self.state)?,
        )?;
        let dest = self.dir.join("checkpoint");
        let old = self.dir.join("checkpoint.old");
        let _ = std::fs::remove_dir_all(&old);
        if dest.exists() {
            std::fs::rename(&dest, &old)?;
        }
        std::fs::rename(&tmp, &dest)?;
        let _ = std::fs::remove_dir_all(&old);
        self.log.flush()?;
        self.last_checkpoint = Instant::now();
        Ok(())
    }

    /// The model and optimizer as the latest checkpoint left them.
    pub fn restore<M: burn::module::Module>(
        &self,
        model: M,
        optim: burn::optim::ModuleOptimizer,
    ) -> Result<(M, burn::optim::ModuleOptimizer)> {
        let model = model
            .try_load_file(self.checkpoint_file("model.bpk"))
            .map_err(|e| anyhow::anyhow!("cannot load the checkpoint's model: {e:?}"))?;
        let optim = optim
            .load(self.checkpoint_file("optim.bpk"))
            .map_err(|e| anyhow::anyhow!("cannot load the checkpoint's optimizer: {e:?}"))?;
        Ok((model, optim))
    }

    /// A line saying where a resumed run stands.
    pub fn resumed_line(&self) -> String {
        format!(
            "resumed at step {} ({} trained)",
            self.state.step,
            format_duration(self.state.seconds)
        )
    }

    /// A fresh run's model started from trained weights (`init`: fine-tuning on new data)
    /// instead of random ones. A resumed run keeps its checkpoint, and says `init` is unused.
    pub fn start_from<M: burn::store::ModuleSnapshot>(
        &self,
        model: M,
        init: Option<&Path>,
        resumed: bool,
        progress: &dyn Fn(&str),
    ) -> Result<M> {
        match init {
            None => Ok(model),
            Some(path) if resumed => {
                progress(&format!(
                    "not starting from {}: the run resumes from its checkpoint",
                    path.display()
                ));
                Ok(model)
            }
            Some(path) => {
                let model = crate::weights::load_file(model, path)
                    .with_context(|| format!("starting from {}", path.display()))?;
                progress(&format!("starting from the weights in {}", path.display()));
                Ok(model)
            }
        }
    }

    /// Checkpoints the model and optimizer.
    pub fn save<M: burn::module::Module>(
        &mut self,
        model: &M,
        optim: &burn::optim::ModuleOptimizer,
    ) -> Result<()> {
        self.checkpoint(|dir| {
            model
                .clone()
                .save_file(dir.join("model.bpk"))
                .map_err(|e| anyhow::anyhow!("saving the model: {e:?}"))?;
            optim
                .save(dir.join("optim.bpk"))
                .map_err(|e| anyhow::anyhow!("saving the optimizer: {e:?}"))?;
            Ok(())
        })
    }

    /// What every loop does first after a step it recorded: the progress line, when one is
    /// due. Returns the steps done.
    pub fn report_step(&mut self, limits: &StepLimits, progress: &dyn Fn(&str)) -> usize {
        let done = self.state.step;
        if limits.due(done, limits.log_every) {
            progress(&self.progress_line(limits.steps, done as f64 / limits.epoch_steps));
        }
        done
    }

    /// What every loop does last after a step: checkpoints (and redraws the plot titled `title`)
    /// when one is due, at the last step, or when this session's minutes are up. Returns
    /// true when the loop must stop for time.
    pub fn end_step<M: burn::module::Module>(
        &mut self,
        model: &M,
        optim: &burn::optim::ModuleOptimizer,
        limits: &StepLimits,
        title: &str,
        progress: &dyn Fn(&str),
    ) -> Result<bool> {
        let done = self.state.step;
        let out_of_time = limits.minutes.is_some_and(|m| self.session_minutes() >= m);
        if self.checkpoint_due(limits.checkpoint_minutes) || done == limits.steps || out_of_time {
            self.save(model, optim)?;
            self.plot(title, 20)?;
            progress(&format!("checkpoint at step {done}"));
        }
        if out_of_time {
            progress("time limit reached; run the same command again to resume");
        }
        Ok(out_of_time)
    }

    /// Saves a finished run's weights as `name` in the run folder.
    pub fn save_weights<M: burn::module::Module>(
        &self,
        model: M,
        name: &str,
        progress: &dyn Fn(&str),
    ) -> Result<()> {
        let weights = self.dir.join(name);
        model
            .save_file(&weights)
            .map_err(|e| anyhow::anyhow!("saving {}: {e:?}", weights.display()))?;
        progress(&format!("finished: weights in {}", weights.display()));
        Ok(())
    }

    /// Redraws `losses.png` from `log.csv`, one curve per column, averaged over windows of
    /// `smooth` steps so the trend is readable.
    pub fn plot(&self, title: &str, smooth: usize) -> Result<()> {
        let series = read_log(&self.dir.join("log.csv"), smooth)?;
        let options = crate::render::plot::PlotOptions {
            title: title.to_string(),
            x_label: "step".into(),
            y_label: "loss".into(),
            log_y: true,
            ..Default::default()
        };
        crate::render::plot::write_line_plot(&self.dir.join("losses.png"), &series, &options)?;
        Ok(())
    }
}

/// The curves of a `log.csv`, averaged over consecutive windows of `smooth` rows.
pub fn read_log(path: &Path, smooth: usize) -> Result<Vec<crate::render::plot::Series>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let mut columns: BTreeMap<usize, Vec<(f64, f64)>> = BTreeMap::new();
    for line in lines {
        let cells: Vec<f64> = line
            .split(',')
            .map(|c| c.parse().unwrap_or(f64::NAN))
            .collect();
        for (i, v) in cells.iter().enumerate().skip(2) {
            columns.entry(i).or_default().push((cells[0], *v));
        }
    }
    let smooth = smooth.max(1);
    Ok(columns
        .into_iter()
        .map(|(i, points)| crate::render::plot::Series {
            name: header.get(i).unwrap_or(&"?").to_string(),
            points: points
                .chunks(smooth)
                .map(|c| {
                    let finite: Vec<&(f64, f64)> = c.iter().filter(|p| p.1.is_finite()).collect();
                    let n = finite.len().max(1) as f64;
                    (
                        c[c.len() - 1].0,
                        finite.iter().map(|p| p.1).sum::<f64>() / n,
                    )
                })
                .collect(),
        })
        .collect())
}

/// Appends a row to a CSV file, writing `header` first when the file is new (validation
/// figures of a run, one row per evaluation).
pub fn append_csv(path: &Path, header: &str, row: &str) -> Result<()> {
    let fresh = !path.exists();
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .with_context(|| format!("opening {}", path.display()))?;
    if fresh {
        writeln!(f, "{header}")?;
    }
    writeln!(f, "{row}")?;
    Ok(())
}

/// `1h 02m` / `3m 20s` / `12s`.
pub fn format_duration(seconds: f64) -> String {
    let s = seconds.max(0.0) as u64;
    if s >= 3600 {
        format!("{}h {:02}m", s / 3600, (s % 3600) / 60)
    } else if s >= 60 {
        format!("{}m {:02}s", s / 60, s % 60)
    } else {
        format!("{s}s")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checkpoints_resume_state_and_log() {
        let tmp = tempfile::tempdir().unwrap();
        let (mut run, resumed) = Run::open(tmp.path(), &["loss"]).unwrap();
        assert!(!resumed);
        run.record(8, &[1.5]).unwrap();
        run.record(8, &[1.0]).unwrap();
        let line = run.progress_line(10, 0.5);
        assert!(
            line.contains("loss 1.2500") && line.contains("step 2/10"),
            "{line}"
        );
        assert!(
            run.progress_line(10, 0.5).contains("loss 0.0000"),
            "the window restarts"
        );
        run.checkpoint(|dir| Ok(std::fs::write(dir.join("model.bpk"), b"weights")?))
            .unwrap();
        run.record(8, &[0.5]).unwrap();
        drop(run);
        let (run, resumed) = Run::open(tmp.path(), &["loss"]).unwrap();
        assert!(resumed);
        assert_eq!(
            run.state.step, 2,
            "resumes from the checkpoint, not from the last step"
        );
        assert_eq!(
            std::fs::read(run.checkpoint_file("model.bpk")).unwrap(),
            b"weights"
        );
        let series = read_log(&tmp.path().join("log.csv"), 1).unwrap();
        assert_eq!(series[0].name, "loss");
        assert_eq!(
            series[0].points.len(),
            2,
            "the step after the checkpoint is dropped"
        );
    }

    #[test]
    fn durations_read_well() {
        assert_eq!(format_duration(12.4), "12s");
        assert_eq!(format_duration(200.0), "3m 20s");
        assert_eq!(format_duration(3720.0), "1h 02m");
    }
}
