//! The evaluation protocol of `coma eval`: on the test split, each source of motions (the
//! real test motions, a retrieval baseline, SPAM, SPAM with the review loop) answers the test
//! captions, the evaluator embeds texts and motions, and the field's metrics are computed,
//! repeated with fresh caption draws and seeds to give a mean and a 95 % interval per figure.

use super::probes::foot_skating;
use crate::agents::llm::UreqTransport;
use crate::dataset::motions::MotionSet;
use crate::executor::block_on;
use crate::features::{features_to_joints, FeatureFrame};
use crate::metrics::{batch_ranks, diversity, fid, mm_dist, multimodality, r_precision, Interval};
use crate::model::edit::part_text;
use crate::model::evaluator::{Evaluator, EvaluatorConfig};
use crate::model::generate::SamplingOptions;
use crate::model::transformer::TEXT_DIM;
use crate::model::Spam;
use crate::plan::{PartEdits, Plan, PlannerKind, Segment};
use crate::posture::measure::{floating_share, floor_penetration};
use crate::rng::Rng;
use crate::session::{finish, Command, Llm, Outcome, Session};
use crate::skeleton::Pose;
use crate::timing::FPS;
use anyhow::Result;
use burn::prelude::*;
use std::cell::RefCell;
use std::collections::{BTreeMap, HashMap};

/// How the protocol is run.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ProtocolOptions {
    /// Repetitions (fresh caption draws and seeds each time).
    pub repeats: usize,
    /// Test motions per repetition, rounded down to whole batches of 32; every source
    /// answers the same captions.
    pub motions: usize,
    /// Random pairs for diversity.
    pub diversity_pairs: usize,
    /// Captions and motions per caption for multimodality (generating sources only).
    pub multimodality_texts: usize,
    pub multimodality_samples: usize,
    /// Random pairs within a caption's motions for multimodality.
    pub multimodality_pairs: usize,
    pub seed: u64,
}

impl Default for ProtocolOptions {
    fn default() -> Self {
        ProtocolOptions {
            repeats: 10,
            motions: 1024,
            diversity_pairs: 300,
            multimodality_texts: 32,
            multimodality_samples: 10,
            multimodality_pairs: 10,
            seed: 0,
        }
    }
}

/// R-precision batch size of the protocol.
pub const BATCH: usize = 32;

/// One row of the results table.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Row {
    pub top1: Interval,
    pub top2: Interval,
    pub top3: Interval,
    pub fid: Interval,
    pub mm_dist: Interval,
    pub diversity: Interval,
    /// Absent for the real motions (one motion per caption).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub multimodality: Option<Interval>,
    /// Share of frames with a skating foot (see [`super::probes::foot_skating`]).
    pub foot_skating: Interval,
    /// Share of frames in which the body floats (no joint near the floor, longer than a
    /// jump's flight; see [`crate::posture::measure::floating_share`]).
    pub floating: Interval,
    /// Deepest any joint of any motion went under the floor (y = 0), metres.
    pub floor_penetration: f64,
    /// Repetitions the row was measured on.
    pub repeats: usize,
    /// Top-3 R-precision of the captions of each motion capture source's test motions
    /// (pooled over repetitions; the batches mix sources as the draw does), with how many
    /// captions it counts. Empty when the dataset names no sources.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub top3_by_source: BTreeMap<String, SourceTop3>,
}

/// Top-3 R-precision over one source's test captions.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct SourceTop3 {
    pub top3: f64,
    pub captions: usize,
}

/// The metrics of one repetition of one source.
#[derive(Default)]
struct Figures {
    top: Vec<[f64; 3]>,
    fid: Vec<f64>,
    mm_dist: Vec<f64>,
    diversity: Vec<f64>,
    multimodality: Vec<f64>,
    skating: Vec<f64>,
    floating: Vec<f64>,
    floor_penetration: f64,
    /// Per source: captions whose own motion ranked in the top 3, and captions counted.
    by_source: BTreeMap<String, (usize, usize)>,
}

impl Figures {
    fn row(&self) -> Row {
        let top = |k: usize| Interval::of(&self.top.iter().map(|t| t[k]).collect::<Vec<_>>());
        Row {
            top1: top(0),
            top2: top(1),
            top3: top(2),
            fid: Interval::of(&self.fid),
            mm_dist: Interval::of(&self.mm_dist),
            diversity: Interval::of(&self.diversity),
            multimodality: (!self.multimodality.is_empty())
                .then(|| Interval::of(&self.multimodality)),
            foot_skating: Interval::of(&self.skating),
            floating: Interval::of(&self.floating),
            floor_penetration: self.floor_penetration,
            repeats: self.top.len(),
            top3_by_source: self
                .by_source
                .iter()
                .map(|(source, (hits, n))| {
                    let top3 = *hits as f64 / (*n).max(1) as f64;
                    (source.clone(), SourceTop3 { top3, captions: *n })
                })
                .collect(),
        }
    }
}

/// What the protocol needs: the evaluator, the sentence embeddings of every caption used, and
/// the test and training motions.
pub struct Protocol<'a> {
    pub evaluator: &'a Evaluator,
    pub config: &'a EvaluatorConfig,
    pub device: &'a Device,
    pub test: &'a MotionSet,
    pub train: &'a MotionSet,
    /// MiniLM embedding of each caption of the test and training sets.
    pub sentences: &'a HashMap<String, [f32; TEXT_DIM]>,
}

/// A source of motions answering captions.
pub enum Motions<'a> {
    /// The test motion the caption belongs to.
    Real,
    /// The training motion whose caption is nearest (MiniLM cosine) to the test caption.
    Retrieval,
    /// SPAM, generating a motion of the test motion's length from the caption with these
    /// sampling options (each motion's seed replaces theirs).
    Spam(&'a Spam, &'a SamplingOptions),
    /// The very motions of [`Motions::Spam`] (same captions, lengths and seeds) as the VQ-VAE
    /// decodes them, before the engine's clean-up (reference skeleton, planted feet): what
    /// the clean-up costs or gains in every figure. Decoded once for both rows.
    SpamDecoded(&'a Spam, &'a SamplingOptions),
    /// The same, then reviewed for up to `rounds` rounds by the loop of
    /// the engine ([`crate::session`]) with the evaluator as judge (no LLM): the caption is one
    /// segment. No multimodality (it would cost ten reviewed motions a caption). A reviewed
    /// motion costs several generations, so the row may be measured on only the first
    /// `repeats` repetitions (same motions per repetition as every other row, so its FID
    /// compares).
    ReviewedSpam {
        session: &'a Session,
        rounds: usize,
        repeats: usize,
    },
}

/// The motion (normalised features) the engine's review loop makes of one caption, `frames`
/// long (at most 196).
fn reviewed(
    session: &Session,
    caption: &str,
    frames: usize,
    rounds: usize,
    seed: u64,
) -> Vec<FeatureFrame> {
    let segment = Segment {
        text: caption.to_string(),
        seconds: frames as f64 / FPS,
        base: caption.to_string(),
        parts: PartEdits::default(),
        trajectory: None,
        postures: None,
    };
    let plan = Plan {
        prompt: caption.to_string(),
        rewritten: caption.to_string(),
        segments: vec![segment],
        clips: Vec::new(),
        planner: PlannerKind::Offline,
        notes: Vec::new(),
    };
    let command = Command::Run {
        prompt: caption.to_string(),
        seed,
        rounds,
        seconds: None,
        plan: Some(plan),
    };
    block_on(async {
        let outcome = session
            .execute(command, &Llm::<UreqTransport>::Off, &mut |_| {})
            .await;
        let Ok(Outcome::Run(run)) = outcome else {
            unreachable!("a run of a valid plan answers with its motion: {outcome:?}")
        };
        session.model().normalizer.normalize(&run.motion.features)
    })
}

fn cosine(a: &[f32], b: &[f32]) -> f64 {
    let dot: f64 = a.iter().zip(b).map(|(x, y)| *x as f64 * *y as f64).sum();
    let na: f64 = a.iter().map(|x| (*x as f64).powi(2)).sum::<f64>().sqrt();
    let nb: f64 = b.iter().map(|x| (*x as f64).powi(2)).sum::<f64>().sqrt();
    dot / (na * nb).max(1e-12)
}

impl Protocol<'_> {
    fn embed(&self, motions: &[&[FeatureFrame]]) -> Vec<Vec<f32>> {
        self.evaluator
            .embed_motions(self.config, motions, self.device)
    }

    /// For each distinct test caption, the training motion with the nearest caption.
    fn nearest_training(&self) -> HashMap<&str, usize> {
        let train: Vec<(usize, &[f32; TEXT_DIM])> = self
            .train
            .items
            .iter()
            .enumerate()
            .flat_map(|(i, item)| item.captions.iter().map(move |c| (i, c)))
            .filter_map(|(i, c)| self.sentences.get(c).map(|e| (i, e)))
            .collect();
        let mut out = HashMap::new();
        for item in &self.test.items {
            for caption in &item.captions {
                if out.contains_key(caption.as_str()) {
                    continue;
                }
                let Some(own) = self.sentences.get(caption) else {
                    continue;
                };
                let best = train
                    .iter()
                    .map(|(i, e)| (*i, cosine(own, *e)))
                    .max_by(|a, b| a.1.total_cmp(&b.1))
                    .map_or(0, |b| b.0);
                out.insert(caption.as_str(), best);
            }
        }
        out
    }

    /// Runs the protocol for every source; `progress` hears about each repetition.
    pub fn run(
        &self,
        sources: &[(&str, Motions)],
        options: &ProtocolOptions,
        progress: &dyn Fn(&str),
    ) -> Result<BTreeMap<String, Row>> {
        let captioned: Vec<usize> = (0..self.test.items.len())
            .filter(|&i| !self.test.items[i].captions.is_empty())
            .collect();
        let n = options.motions.min(captioned.len()) / BATCH * BATCH;
        anyhow::ensure!(
            n >= BATCH,
            "the measured split has {} captioned motions; the protocol needs at least {BATCH}",
            captioned.len()
        );
        let all: Vec<&[FeatureFrame]> = self
            .test
            .items
            .iter()
            .map(|i| i.features.as_slice())
            .collect();
        let real = self.embed(&all);
        let nearest = self.nearest_training();
        let mut figures: Vec<Figures> = sources.iter().map(|_| Figures::default()).collect();
        for repeat in 0..options.repeats {
            // Decoded motions (denormalised) by seed, so the planted and the as-decoded rows
            // measure the same samples for the price of one generation.
            let decoded_by_seed: RefCell<HashMap<u64, Vec<FeatureFrame>>> = Default::default();
            let mut rng = Rng::new(options.seed ^ (repeat as u64 + 1).wrapping_mul(0x9E37_79B9));
            let mut order = captioned.clone();
            rng.shuffle(&mut order);
            order.truncate(n);
            let captions: Vec<&str> = order
                .iter()
                .map(|&i| {
                    let c = &self.test.items[i].captions;
                    c[rng.below(c.len())].as_str()
                })
                .collect();
            let sentences: Vec<[f32; TEXT_DIM]> = captions
                .iter()
                .map(|c| self.sentences.get(*c).copied().unwrap_or([0.0; TEXT_DIM]))
                .collect();
            let texts = self.evaluator.embed_texts(&sentences, self.device);
            for ((name, source), fig) in sources.iter().zip(&mut figures) {
                if matches!(source, Motions::ReviewedSpam { repeats, .. } if repeat >= *repeats) {
                    continue;
                }
                let features: Vec<&[FeatureFrame]>;
                let generated: Vec<Vec<FeatureFrame>>;
                match source {
                    Motions::Real => {
                        features = order.iter().map(|&i| all[i]).collect();
                    }
                    Motions::Retrieval => {
                        features = captions
                            .iter()
                            .map(|c| self.train.items[nearest[c]].features.as_slice())
                            .collect();
                    }
                    Motions::Spam(spam, sampling) | Motions::SpamDecoded(spam, sampling) => {
                        let planted = matches!(source, Motions::Spam(..));
                        let normalizer = &self.test.normalizer;
                        let generate = |sentence: &[f32; TEXT_DIM], frames: usize, seed: u64| {
                            let decoded = decoded_by_seed
                                .borrow_mut()
                                .entry(seed)
                                .or_insert_with(|| {
                                    block_on(async {
                                        let options = SamplingOptions {
                                            seed,
                                            ..(*sampling).clone()
                                        };
                                        let text = part_text(sentence, &[]);
                                        let tokens =
                                            spam.generate(&text, frames.min(196), &options).await;
                                        normalizer.denormalize(&spam.decode(&tokens).await)
                                    })
                                })
                                .clone();
                            if planted {
                                // As the engine shows it.
                                normalizer.normalize(&finish(&decoded))
                            } else {
                                normalizer.normalize(&decoded)
                            }
                        };
                        let length = |k: usize| self.test.items[order[k]].features.len();
                        generated = sentences
                            .iter()
                            .enumerate()
                            .map(|(k, s)| generate(s, length(k), (repeat * 100_000 + k) as u64))
                            .collect();
                        features = generated.iter().map(Vec::as_slice).collect();
                        let groups: Vec<Vec<Vec<f32>>> = sentences
                            .iter()
                            .take(options.multimodality_texts)
                            .enumerate()
                            .map(|(k, s)| {
                                let samples: Vec<Vec<FeatureFrame>> = (0..options
                                    .multimodality_samples)
                                    .map(|j| {
                                        let seed =
                                            (1u64 << 40) + (repeat * 100_000 + k * 100 + j) as u64;
                                        generate(s, length(k), seed)
                                    })
                                    .collect();
                                let refs: Vec<&[FeatureFrame]> =
                                    samples.iter().map(Vec::as_slice).collect();
                                self.embed(&refs)
                            })
                            .collect();
                        fig.multimodality.push(multimodality(
                            &groups,
                            options.multimodality_pairs,
                            &mut rng,
                        ));
                    }
                    Motions::ReviewedSpam {
                        session, rounds, ..
                    } => {
                        generated = captions
                            .iter()
                            .enumerate()
                            .map(|(k, c)| {
                                let frames = self.test.items[order[k]].features.len().min(196);
                                reviewed(session, c, frames, *rounds, (repeat * 100_000 + k) as u64)
                            })
                            .collect();
                        features = generated.iter().map(Vec::as_slice).collect();
                    }
                }
                let motions = self.embed(&features);
                let joints: Vec<Vec<Pose>> = features
                    .iter()
                    .map(|f| features_to_joints(&self.test.normalizer.denormalize(f)))
                    .collect();
                let mean = |measure: fn(&[Pose]) -> f64| {
                    joints.iter().map(|j| measure(j)).sum::<f64>() / joints.len() as f64
                };
                fig.skating.push(mean(foot_skating));
                fig.floating.push(mean(floating_share));
                fig.floor_penetration = joints
                    .iter()
                    .map(|j| floor_penetration(j))
                    .fold(fig.floor_penetration, f64::max);
                if matches!(source, Motions::Retrieval) {
                    // The same caption always retrieves the same motion.
                    fig.multimodality.push(0.0);
                }
                fig.top.push(r_precision(&texts, &motions, BATCH));
                for (k, rank) in batch_ranks(&texts, &motions, BATCH).iter().enumerate() {
                    let (Some(rank), Some(source)) = (rank, &self.test.items[order[k]].source)
                    else {
                        continue;
                    };
                    let entry = fig.by_source.entry(source.clone()).or_default();
                    entry.0 += (*rank < 3) as usize;
                    entry.1 += 1;
                }
                fig.fid.push(fid(&real, &motions));
                fig.mm_dist.push(mm_dist(&texts, &motions));
                fig.diversity
                    .push(diversity(&motions, options.diversity_pairs, &mut rng));
                progress(&format!(
                    "repeat {}/{}: {name} top-3 {:.3}, FID {:.3}",
                    repeat + 1,
                    options.repeats,
                    fig.top.last().unwrap()[2],
                    fig.fid.last().unwrap()
                ));
            }
        }
        Ok(sources
            .iter()
            .zip(&figures)
            .map(|((name, _), f)| (name.to_string(), f.row()))
            .collect())
    }
}

/// The rows as a Markdown table.
pub fn markdown_table(rows: &BTreeMap<String, Row>, order: &[&str]) -> String {
    let mut out = String::from(
        "| motions | R-precision top-1 ↑ | top-2 ↑ | top-3 ↑ | FID ↓ | MM-Dist ↓ | diversity → | multimodality ↑ |\n|---|---|---|---|---|---|---|---|\n",
    );
    for name in order {
        let Some(r) = rows.get(*name) else { continue };
        out.push_str(&format!(
            "| {name} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.top1,
            r.top2,
            r.top3,
            r.fid,
            r.mm_dist,
            r.diversity,
            r.multimodality.map_or("–".to_string(), |m| m.to_string())
        ));
    }
    let sources: Vec<&String> = {
        let mut all: Vec<&String> = rows
            .values()
            .flat_map(|r| r.top3_by_source.keys())
            .collect();
        all.sort();
        all.dedup();
        all
    };
    if !sources.is_empty() {
        out.push_str("\nTop-3 R-precision of each source's test captions (pooled over the repetitions; captions counted in brackets):\n\n| motions |");
        for s in &sources {
            out.push_str(&format!(" {s} |"));
        }
        out.push_str("\n|---|");
        out.push_str(&"---|".repeat(sources.len()));
        out.push('\n');
        for name in order {
            let Some(r) = rows.get(*name) else { continue };
            out.push_str(&format!("| {name} |"));
            for s in &sources {
                match r.top3_by_source.get(*s) {
                    Some(t) => out.push_str(&format!(" {:.3} ({}) |", t.top3, t.captions)),
                    None => out.push_str(" – |"),
                }
            }
            out.push('\n');
        }
    }
    out
}
