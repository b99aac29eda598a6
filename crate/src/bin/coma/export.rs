//! `coma export`: trained runs assembled into a model folder, and what rounding them to f16
//! or quantizing them changes.

use anyhow::Result;
use clap::{Args, ValueEnum};
use coma::export::{self, EvaluatorRounding};
use coma::model::prior::PriorOptions;
use coma::quant::Bits;
use std::path::PathBuf;

#[derive(Args)]
pub struct ExportArgs {
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
    #[arg(long, default_value = "data/coma")]
    data: PathBuf,
    #[arg(long, default_value = "static/models")]
    out: PathBuf,
    /// Quantize the large tensors to 4 or 8 bits in blocks of 32 (see coma::weights);
    /// without it every float is rounded to f16.
    #[arg(long, value_parser = ["4", "8"])]
    bits: Option<String>,
    /// Share of a retrieved training motion's tokens a new motion keeps (prior).
    #[arg(long, default_value_t = PriorOptions::default().keep)]
    prior_keep: f32,
    /// Least cosine similarity between a prompt and a training caption for the prior to
    /// apply (prior).
    #[arg(long, default_value_t = PriorOptions::default().min_similarity)]
    prior_min_similarity: f32,
    /// Most training motions of one action the prior holds (prior): the rare actions keep
    /// all theirs, and the download stays small.
    #[arg(long, default_value_t = 24)]
    prior_per_action: usize,
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
    /// The retrieval prior: the training motions of --data as tokens of the --vq run, indexed
    /// by their captions, added to the model in --out (after `coma export spam`).
    Prior,
}

pub fn run(args: ExportArgs) -> Result<()> {
    let ExportArgs {
        what,
        evaluator,
        vq,
        base,
        res,
        data,
        out,
        bits,
        prior_keep,
        prior_min_similarity,
        prior_per_action,
    } = args;
    let bits = bits.map(|b| if b == "4" { Bits::Four } else { Bits::Eight });
    let precision = match bits {
        None => "f16".to_string(),
        Some(Bits::Four) => "4-bit".to_string(),
        Some(Bits::Eight) => "8-bit".to_string(),
    };
    match what {
        ExportWhat::Random => {
            use burn::config::Config;
            let sizes = coma::model::SpamConfig::load("configs/spam.json")
                .map_err(|e| anyhow::anyhow!("configs/spam.json: {e}"))?;
            export::export_random(&sizes, &data, &out)?;
            println!("wrote SPAM with random weights into {}", out.display());
        }
        ExportWhat::Prior => {
            let options = PriorOptions {
                keep: prior_keep,
                min_similarity: prior_min_similarity,
                ..Default::default()
            };
            let p = export::export_prior(&vq, &data, &out, options, prior_per_action, &|l| {
                eprintln!("{l}")
            })?;
            println!(
                "wrote the retrieval prior into {}: {} training motions under {} distinct captions, {} bytes; model id {}",
                out.display(),
                p.motions,
                p.captions,
                p.bytes,
                p.id
            );
        }
        ExportWhat::Vocabulary => {
            let words = export::export_vocabulary(&data, &out)?;
            println!(
                "wrote {} words into {}",
                words,
                out.join("vocabulary.json").display()
            );
        }
        ExportWhat::Evaluator => {
            let exported = export::export_evaluator(&evaluator, &out, bits)?;
            println!(
                "exported the evaluator into {} ({precision}, {} bytes)",
                out.display(),
                exported.bytes
            );
            match exported.rounding(&data) {
                EvaluatorRounding::NoTestSplit => {
                    println!(
                        "no test split in {}: {precision} not compared",
                        data.display()
                    )
                }
                EvaluatorRounding::NoSentenceEncoder => {
                    println!(
                        "no sentence encoder in {}: {precision} not compared",
                        out.display()
                    )
                }
                EvaluatorRounding::Compared(a) => {
                    let [full, rounded] = a.r_precision;
                    println!(
                        "{precision} against the run's weights on {} random test motions and captions: alignment \
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
                }
            }
        }
        ExportWhat::Spam => {
            let exported = export::export_spam(&vq, &base, res.as_deref(), &data, &out, bits)?;
            println!(
                "exported SPAM ({}) into {}: {precision}, {} bytes, model id {}",
                if exported.has_residual() {
                    "with its residual transformer"
                } else {
                    "base-only"
                },
                out.display(),
                exported.bytes,
                exported.id
            );
            let e = exported.vq_rounding(&data)?;
            println!(
                "VQ-VAE on {} test motions, {} of {} layers: {:.2} mm (f32) -> {:.2} mm ({precision}), root aligned",
                e.motions, e.layers, e.vq_layers, e.f32_mm, e.shipped_mm
            );
            // The weights are written; a folder without the sentence encoder only skips the
            // comparison.
            match exported.token_rounding() {
                Ok(t) => println!(
                    "greedily decoded tokens of 4 prompts (196 frames): {} of {} the same with {precision} as with f32",
                    t.same, t.total
                ),
                Err(e) => println!(
                    "greedy decoding not compared ({e:#}): the sentence encoder's minilm-* files belong beside the weights"
                ),
            }
        }
    }
    Ok(())
}
