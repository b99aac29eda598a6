//! The whole CoMA loop for one plan: generate each segment's base motion, edit its body
//! parts, review and correct it for up to K rounds, blend the segments, and lay the root on
//! the requested paths.
//!
//! Everything a run decides is kept: the plan (with its paths), the seeds, every edit and
//! review, and the final tokens, so a share link rebuilds the exact motion with
//! [`motion_features`] and no LLM.

use crate::agents::llm::{LlmClient, Transport};
use crate::agents::reviewer::{self, Review, Scorer};
use crate::features::{features_to_joints, FeatureFrame, Features};
use crate::model::edit::{part_indices, PartText, SEAM_STEPS};
use crate::model::generate::MotionTokens;
use crate::model::motion_model::{sampling, steps_of};
use crate::model::MotionModel;
use crate::plan::{Clip, Plan, Segment};
use crate::share::{Edit, EditKind};
use crate::skeleton::{BodyPart, Pose};
use crate::timing::frames_for_seconds;
use crate::timing::FRAMES_PER_TOKEN;
use crate::trajectory::{self, circle_report, CircleReport, MapOptions, Shape, Trajectory};
use serde::{Deserialize, Serialize};

/// Review rounds per segment by default (K in the design).
pub const DEFAULT_ROUNDS: usize = 2;

/// Token steps (of 4 frames) regenerated on each side of a join when segments are blended.
pub const BLEND_OVERLAP_STEPS: usize = 2;

/// How a run samples and reviews.
#[derive(Clone, Copy, Debug)]
pub struct RunOptions {
    /// Review rounds per segment (0 turns the reviewer off).
    pub rounds: usize,
    /// Seed of the whole run; each segment, edit and round derives its own from it.
    pub seed: u64,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            rounds: DEFAULT_ROUNDS,
            seed: 0,
        }
    }
}

/// A step of a run, reported as it ends (the page shows each).
#[derive(Clone, Debug)]
pub enum RunEvent<'a> {
    /// Segment `index`'s base motion exists.
    Generated { index: usize, segment: &'a Segment },
    /// Segment `index` had `part`s regenerated from `text`.
    Edited {
        index: usize,
        parts: &'a [BodyPart],
        text: &'a str,
    },
    /// A review round of segment `index` ended; `accepted` says whether its corrections were
    /// kept.
    Reviewed {
        index: usize,
        round: usize,
        review: &'a Review,
        accepted: bool,
    },
    /// The segments are joined.
    Blended,
    /// Clip `index` of the body-part tracks was generated over its span.
    ClipLaid { index: usize, clip: &'a Clip },
}

/// One review round as it was decided.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReviewRound {
    pub review: Review,
    /// The corrections were applied and kept (the evaluator did not score the result lower).
    pub accepted: bool,
    /// The segment's 0–100 similarity with its text after the round, where an evaluator
    /// was at hand.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub score: Option<f64>,
}

/// What happened to one segment.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SegmentRun {
    /// Frames (20 fps) of the segment before blending.
    pub frames: usize,
    /// The evaluator's similarity of the segment's text with its motion before review.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub score_before: Option<f64>,
    /// The same after the last review round.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub score_after: Option<f64>,
    pub rounds: Vec<ReviewRound>,
}

/// A finished run.
#[derive(Clone, Debug, Serialize)]
pub struct Run {
    pub plan: Plan,
    pub segments: Vec<SegmentRun>,
    pub seed: u64,
    /// Every step, as a share link records it.
    #[serde(skip)]
    pub history: Vec<Edit>,
    /// The motion's final tokens `[part][layer][step]`, with the base (whole-body) motion's
    /// codes under each body-part clip as a layer.
    #[serde(skip)]
    pub tokens: MotionTokens,
    /// Notes of the reviewer (a judge that failed, a review skipped).
    pub notes: Vec<String>,
}

fn part_bits(parts: &[BodyPart]) -> u8 {
    parts
        .iter()
        .map(|p| 1u8 << BodyPart::ALL.iter().position(|q| q == p).unwrap_or(0))
        .fold(0, |a, b| a | b)
}

/// Seed of step `k` of segment `index`: distinct for every sampling of the run.
fn seed_of(run_seed: u64, index: usize, k: u64) -> u64 {
    run_seed
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(index as u64 * 1000 + k)
}

/// The parts that share each instruction, so parts asked the same thing change together.
fn grouped_edits(segment: &Segment) -> Vec<(String, Vec<BodyPart>)> {
    let mut groups: Vec<(String, Vec<BodyPart>)> = Vec::new();
    for (part, text) in segment.parts.edits() {
        match groups.iter_mut().find(|(t, _)| *t == text) {
            Some((_, parts)) => parts.push(part),
            None => groups.push((text, vec![part])),
        }
    }
    groups
}

/// Each part a review corrects, with the instruction of the last correction naming it (as
/// if the corrections were applied one after another).
fn round_edits(review: &Review) -> Vec<(BodyPart, String)> {
    let mut edits: Vec<(BodyPart, String)> = Vec::new();
    for c in &review.corrections {
        for part in c.region.parts() {
            edits.retain(|(p, _)| p != part);
            edits.push((*part, c.instruction.clone()));
        }
    }
    edits
}

/// Runs the loop over `plan`. `scorer` (the evaluator) judges without an LLM and keeps a
/// correction only when it does not lower the score; `llm` judges when given.
pub async fn run<T: Transport>(
    model: &MotionModel,
    scorer: Option<&Scorer<'_>>,
    llm: Option<&LlmClient<T>>,
    plan: Plan,
    options: RunOptions,
    progress: &mut dyn FnMut(RunEvent),
) -> Run {
    let mut history = Vec::new();
    let mut segments = Vec::new();
    // Each segment's tokens after review, to blend.
    let mut segment_tokens = Vec::new();
    let mut notes = Vec::new();
    if options.rounds > 0 && scorer.is_none() && llm.is_none() {
        notes.push("no evaluator and no LLM: the segments were not reviewed".into());
    }
    let mut start_frame = 0u32;
    for (index, segment) in plan.segments.iter().enumerate() {
        let frames = frames_for_seconds(segment.seconds);
        let seed = seed_of(options.seed, index, 0);
        let mut tokens = model.generate(&segment.base, &[], frames, seed).await;
        let frames = tokens[0][0].len() * FRAMES_PER_TOKEN;
        let range = (start_frame, start_frame + frames as u32);
        history.push(Edit {
            kind: EditKind::Generate,
            text: segment.base.clone(),
            from_frame: range.0,
            to_frame: range.1,
            parts: 0,
            seed,
        });
        progress(RunEvent::Generated { index, segment });
        for (k, (text, parts)) in grouped_edits(segment).into_iter().enumerate() {
            let seed = seed_of(options.seed, index, 1 + k as u64);
            tokens = model
                .edit_parts(&tokens, &text, &parts, &segment.base, seed)
                .await;
            history.push(Edit {
                kind: EditKind::BodyParts,
                text: text.clone(),
                from_frame: range.0,
                to_frame: range.1,
                parts: part_bits(&parts),
                seed,
            });
            progress(RunEvent::Edited {
                index,
                parts: &parts,
                text: &text,
            });
        }
        // The segment's features, decoded once per token set: scoring and reviewing read them.
        let mut normalized = if scorer.is_some() || options.rounds > 0 {
            model.spam.decode(&tokens).await
        } else {
            Vec::new()
        };
        let score_before = scorer.map(|s| s.segment_score(segment, &normalized));
        let mut current = score_before;
        let mut rounds = Vec::new();
        // Key poses replace a posture segment's generated motion: nothing to review there.
        let review_rounds = if segment.is_posture_segment() {
            0
        } else {
            options.rounds
        };
        for round in 0..review_rounds {
            let poses = features_to_joints(&model.normalizer.denormalize(&normalized));
            let mut review = match scorer {
                Some(s) => reviewer::judge_offline(segment, &poses, &normalized, s),
                None => Review {
                    description: reviewer::describe(&poses),
                    scores: Vec::new(),
                    corrections: Vec::new(),
                    judge: reviewer::JudgeKind::Evaluator,
                    note: None,
                },
            };
            if let Some(client) = llm {
                review = reviewer::review_llm(client, segment, &poses, review).await;
            } else if scorer.is_none() {
                break;
            }
            if let Some(note) = &review.note {
                notes.push(format!(
                    "segment {}, round {}: {note}",
                    index + 1,
                    round + 1
                ));
            }
            if review.corrections.is_empty() {
                progress(RunEvent::Reviewed {
                    index,
                    round,
                    review: &review,
                    accepted: false,
                });
                rounds.push(ReviewRound {
                    review,
                    accepted: false,
                    score: current,
                });
                break;
            }
            // Every correction of the round in one generation, each part conditioned on its
            // own instruction: one generation per round, not one per corrected region.
            let seed = seed_of(options.seed, index, 100 + 10 * round as u64);
            let candidate = model
                .edit_parts_each(&tokens, &round_edits(&review), &segment.base, seed)
                .await;
            let edits: Vec<Edit> = review
                .corrections
                .iter()
                .map(|c| Edit {
                    kind: EditKind::BodyParts,
                    text: c.instruction.clone(),
                    from_frame: range.0,
                    to_frame: range.1,
                    parts: part_bits(c.region.parts()),
                    seed,
                })
                .collect();
            let decoded = model.spam.decode(&candidate).await;
            let after = scorer.map(|s| s.segment_score(segment, &decoded));
            let accepted = match (current, after) {
                (Some(before), Some(after)) => after >= before,
                _ => true,
            };
            if accepted {
                tokens = candidate;
                normalized = decoded;
                current = after;
                history.extend(edits);
            }
            progress(RunEvent::Reviewed {
                index,
                round,
                review: &review,
                accepted,
            });
            rounds.push(ReviewRound {
                review,
                accepted,
                score: current,
            });
        }
        segments.push(SegmentRun {
            frames,
            score_before,
            score_after: current,
            rounds,
        });
        segment_tokens.push(tokens);
        start_frame = range.1;
    }
    let tokens = blend(model, &plan, &segment_tokens, options.seed, &mut history).await;
    if plan.segments.len() > 1 {
        progress(RunEvent::Blended);
    }
    let tokens = lay_clips(model, &plan, tokens, options.seed, &mut history, progress).await;
    Run {
        plan,
        segments,
        seed: options.seed,
        history,
        tokens,
        notes,
    }
}

/// The condition a segment's motion was made with, for the transition into or out of it.
fn condition(model: &MotionModel, segment: &Segment) -> PartText {
    model.condition(&segment.base, &segment.parts.edits())
}

async fn blend(
    model: &MotionModel,
    plan: &Plan,
    segments: &[MotionTokens],
    seed: u64,
    history: &mut Vec<Edit>,
) -> MotionTokens {
    let mut joined = segments[0].clone();
    let mut end = segments[0].frames() as u32;
    for (i, next) in segments.iter().enumerate().skip(1) {
        let seed = seed_of(seed, i, 900);
        let a = condition(model, &plan.segments[i - 1]);
        let b = condition(model, &plan.segments[i]);
        joined = model
            .spam
            .blend(&joined, next, &a, &b, BLEND_OVERLAP_STEPS, &sampling(seed))
            .await;
        let overlap = (BLEND_OVERLAP_STEPS * FRAMES_PER_TOKEN) as u32;
        history.push(Edit {
            kind: EditKind::Blend,
            text: String::new(),
            from_frame: end.saturating_sub(overlap),
            to_frame: end + overlap,
            parts: 0b1111,
            seed,
        });
        end += next.frames() as u32;
    }
    joined
}

/// The plan's clips that generate motion (not key poses) laid on the blended motion in start
/// order, each on its parts over its span (see [`MotionModel::edit_parts_span`]) as a layer:
/// the blended tokens are the base motion, and the tokens returned keep its codes under every
/// clip ([`MotionTokens::base_patches`]), so the engine shows the base outside the clips'
/// spans exactly and a clip can be moved or taken off without touching the rest. Clip `index`
/// samples with its own seed, so a link's history names it.
pub async fn lay_clips(
    model: &MotionModel,
    plan: &Plan,
    mut tokens: MotionTokens,
    run_seed: u64,
    history: &mut Vec<Edit>,
    progress: &mut dyn FnMut(RunEvent),
) -> MotionTokens {
    for (index, clip) in plan.clips.iter().enumerate() {
        if clip.postures.is_some() {
            continue;
        }
        let seed = seed_of(run_seed, CLIP_SEED_BASE + index, 0);
        let (laid, edit) = lay_clip(model, plan, clip, &tokens, seed).await;
        tokens = laid;
        history.push(edit);
        progress(RunEvent::ClipLaid { index, clip });
    }
    tokens
}

/// The motion of `tokens`, made under `before`, changed to follow `after`'s clips: a clip
/// `after` no longer has (deleted, or moved) gives its parts back to the base motion over its
/// old span, exactly, from the base codes its layer kept (see [`MotionTokens::base_patches`]);
/// a clip `after` has anew (added, moved, reworded) is laid over its span on the base, as a
/// layer. The tokens outside those spans (and [`crate::model::edit::SEAM_STEPS`] steps around
/// them) stay as they were, and so does the motion there. A clip without a layer to take off
/// (a segment's own part instruction lifted onto the tracks, or tokens from before clips were
/// layers) has its span regenerated from the segment under it instead. Only the clips may
/// differ: a changed whole-body track is a new run. Returns the tokens and the edits, as a
/// link's history records them (a clip's layer taken off is an edit of its parts and frames
/// with no text and seed 0: nothing was sampled).
pub async fn edit_clips(
    model: &MotionModel,
    before: &Plan,
    after: &Plan,
    mut tokens: MotionTokens,
    seed: u64,
) -> Result<(MotionTokens, Vec<Edit>), String> {
    if before.segments != after.segments {
        return Err(
            "only the body-part clips may change here; a changed whole-body track is a new run"
                .into(),
        );
    }
    let generated = |c: &&Clip| c.postures.is_none();
    let mut edits = Vec::new();
    // The steps each clip that stays keeps under its layer, per part: taking a clip off must
    // not take them.
    let kept: Vec<(usize, std::ops::Range<usize>)> = after
        .clips
        .iter()
        .filter(generated)
        .filter(|c| before.clips.contains(c))
        .flat_map(|c| {
            let steps = clip_steps(before, c, &tokens);
            part_indices(&c.parts)
                .into_iter()
                .map(move |p| (p, steps.clone()))
        })
        .collect();
    let gone = before
        .clips
        .iter()
        .filter(generated)
        .filter(|c| !after.clips.contains(c));
    for (k, clip) in gone.enumerate() {
        let frames = clip_frames(before, clip, &tokens);
        let steps = clip_steps(before, clip, &tokens);
        let free: Vec<(usize, std::ops::Range<usize>)> = part_indices(&clip.parts)
            .into_iter()
            .flat_map(|p| {
                let others: Vec<std::ops::Range<usize>> = kept
                    .iter()
                    .filter(|(q, _)| *q == p)
                    .map(|(_, r)| r.clone())
                    .collect();
                subtract(steps.clone(), &others)
                    .into_iter()
                    .map(move |r| (p, r))
            })
            .collect();
        if free.iter().all(|(p, r)| tokens.covers(&[*p], r.clone())) {
            for (p, r) in &free {
                tokens = tokens.without_layer(&[*p], r.clone());
            }
            edits.push(clip_edit("", &clip.parts, frames, 0));
            continue;
        }
        let segment = &before.segments[before.segment_at(clip.middle())];
        let seed = seed_of(seed, CLIP_SEED_BASE + k, 1);
        let regenerated = model
            .regenerate_parts_span(
                &tokens,
                &clip.parts,
                &segment.base,
                &segment.parts.edits(),
                frames.clone(),
                seed,
            )
            .await;
        tokens = regenerated.keeping_layers_of(&tokens);
        edits.push(clip_edit(&segment.base, &clip.parts, frames, seed));
    }
    let new = after
        .clips
        .iter()
        .filter(generated)
        .filter(|c| !before.clips.contains(c));
    for (k, clip) in new.enumerate() {
        let (laid, edit) = lay_clip(
            model,
            after,
            clip,
            &tokens,
            seed_of(seed, CLIP_SEED_BASE + k, 0),
        )
        .await;
        tokens = laid;
        edits.push(edit);
    }
    Ok((tokens, edits))
}

/// The steps of `range` that none of `others` covers, as runs.
fn subtract(
    range: std::ops::Range<usize>,
    others: &[std::ops::Range<usize>],
) -> Vec<std::ops::Range<usize>> {
    let mut runs = Vec::new();
    let mut start = range.start;
    for s in range.clone() {
        if others.iter().any(|o| o.contains(&s)) {
            if start < s {
                runs.push(start..s);
            }
            start = s + 1;
        }
    }
    if start < range.end {
        runs.push(start..range.end);
    }
    runs
}

/// One clip that generates motion laid on `tokens` over its span, the rest of the body
/// conditioned on the base motion of the segment under the clip's middle, and kept as a
/// layer: the base codes of its parts over [`clip_steps`] go with the tokens. With the edit a
/// link's history records.
async fn lay_clip(
    model: &MotionModel,
    plan: &Plan,
    clip: &Clip,
    tokens: &MotionTokens,
    seed: u64,
) -> (MotionTokens, Edit) {
    let frames = clip_frames(plan, clip, tokens);
    let rest = &plan.segments[plan.segment_at(clip.middle())].base;
    let laid = model
        .edit_parts_span(tokens, &clip.text, &clip.parts, rest, frames.clone(), seed)
        .await;
    let laid = tokens.layered(
        laid,
        &part_indices(&clip.parts),
        clip_steps(plan, clip, tokens),
    );
    (laid, clip_edit(&clip.text, &clip.parts, frames, seed))
}

/// The history's record of a body-part edit of `frames`.
fn clip_edit(text: &str, parts: &[BodyPart], frames: std::ops::Range<usize>, seed: u64) -> Edit {
    Edit {
        kind: EditKind::BodyParts,
        text: text.to_string(),
        from_frame: frames.start as u32,
        to_frame: frames.end as u32,
        parts: part_bits(parts),
        seed,
    }
}

/// Where clips' seeds start in [`seed_of`]'s segment index, past any segment's.
const CLIP_SEED_BASE: usize = 5000;

/// Feature rows (20 fps) a clip covers in the blended motion: each end at the same place
/// within its segment as in the plan (segments are generated in whole token steps, so their
/// frames drift from their seconds; a clip keeps to its segments).
pub fn clip_frames(plan: &Plan, clip: &Clip, tokens: &MotionTokens) -> std::ops::Range<usize> {
    let ranges = segment_ranges(plan, tokens);
    let starts = plan.segment_starts();
    let at = |t: f64| {
        let k = plan.segment_at(t);
        let within = ((t - starts[k]) * crate::timing::FPS).round().max(0.0) as usize;
        (ranges[k].start + within).min(ranges[k].end)
    };
    let (from, to) = (at(clip.start), at(clip.end));
    from..to.max(from)
}

/// Token steps (of 4 frames) a clip's layer covers: the steps of its frames
/// ([`clip_frames`]) and [`crate::model::edit::SEAM_STEPS`] more either side, where laying it
/// regenerates the seams, within the motion.
pub fn clip_steps(plan: &Plan, clip: &Clip, tokens: &MotionTokens) -> std::ops::Range<usize> {
    let steps = steps_of(clip_frames(plan, clip, tokens));
    steps.start.saturating_sub(SEAM_STEPS)..(steps.end + SEAM_STEPS).min(tokens.steps())
}

/// Feature rows whose root travel is a path laid on purpose (segments with a trajectory):
/// what [`crate::feet::plant_feet`] must not carry back to the feet.
pub fn path_ranges(plan: &Plan, tokens: &MotionTokens) -> Vec<std::ops::Range<usize>> {
    plan.segments
        .iter()
        .zip(segment_ranges(plan, tokens))
        .filter(|(s, _)| s.trajectory.is_some())
        .map(|(_, r)| r)
        .collect()
}

/// Feature rows of each segment in the blended motion: blending keeps every segment's
/// length, so segment `i` starts where the ones before it end.
pub fn segment_ranges(plan: &Plan, tokens: &MotionTokens) -> Vec<std::ops::Range<usize>> {
    let total = tokens[0][0].len() * FRAMES_PER_TOKEN;
    let mut start = 0;
    plan.segments
        .iter()
        .map(|s| {
            let frames =
                frames_for_seconds(s.seconds).div_ceil(FRAMES_PER_TOKEN) * FRAMES_PER_TOKEN;
            let r = start.min(total)..(start + frames).min(total);
            start += frames;
            r
        })
        .collect()
}

/// The plan's posture tracks laid over a motion's features (not normalised, 20 fps, after its
/// paths): posture segments replace the generated frames with their key poses, held postures
/// (a segment's, or a clip's over its span) take over their body parts (see [`crate::posture::track::lay_tracks`]). The features are
/// computed again from the new joints, on the reference skeleton. The notes say which key
/// poses could not be met in full.
pub fn lay_postures(
    plan: &Plan,
    tokens: &MotionTokens,
    features: &[FeatureFrame],
) -> (Features, Vec<String>) {
    use crate::posture::track::{lay_tracks, TrackSpan};
    let mut spans: Vec<TrackSpan> = plan
        .segments
        .iter()
        .zip(segment_ranges(plan, tokens))
        .filter_map(|(s, frames)| {
            s.postures.as_ref().map(|track| TrackSpan {
                frames: track.frames_within(frames),
                track,
            })
        })
        .collect();
    spans.extend(plan.clips.iter().filter_map(|clip| {
        clip.postures.as_ref().map(|track| TrackSpan {
            frames: clip_frames(plan, clip, tokens),
            track,
        })
    }));
    if spans.is_empty() || features.is_empty() {
        return (features.to_vec(), Vec::new());
    }
    let joints = crate::features::features_to_joints_with_final(features);
    let bridges = crate::posture::library::Library::builtin_bridges();
    let (laid, notes) = lay_tracks(&joints, &spans, bridges);
    match crate::features::joints_to_features(&laid, &crate::skeleton::Offsets::reference()) {
        Ok((laid, _)) => (laid, notes),
        Err(e) => (
            features.to_vec(),
            vec![format!(
                "the key postures could not be laid on the motion: {e}"
            )],
        ),
    }
}

/// The features (not normalised, 20 fps) of a run's tokens with every segment's path laid on
/// the root; body-part clips laid as layers are composed over the base motion (see
/// [`MotionModel::features`]). A link rebuilds the motion with this and its plan alone.
pub async fn motion_features(
    model: &MotionModel,
    plan: &Plan,
    tokens: &MotionTokens,
) -> (Features, Vec<String>) {
    let (features, _, notes) = motion_features_and_base(model, plan, tokens).await;
    (features, notes)
}

/// [`motion_features`], and the base motion's features alone with the same paths where clips
/// lie on the tokens as layers (`None` without). The paths are laid from the root's columns,
/// which the base and the composed motion share, so both walk them the same way.
pub async fn motion_features_and_base(
    model: &MotionModel,
    plan: &Plan,
    tokens: &MotionTokens,
) -> (Features, Option<Features>, Vec<String>) {
    let (features, base) = model.features_and_base(tokens).await;
    let (features, notes) = lay_paths(plan, tokens, features);
    let base = base.map(|base| lay_paths(plan, tokens, base).0);
    (features, base, notes)
}

/// `features` with every segment's path laid on the root, and notes for the paths that could
/// not be.
fn lay_paths(
    plan: &Plan,
    tokens: &MotionTokens,
    mut features: Features,
) -> (Features, Vec<String>) {
    let mut notes = Vec::new();
    for (segment, range) in plan.segments.iter().zip(segment_ranges(plan, tokens)) {
        if let Some(path) = &segment.trajectory {
            match trajectory::apply(&features[range.clone()], path, &MapOptions::default()) {
                Ok((walked, _)) => features[range].copy_from_slice(&walked),
                Err(e) => notes.push(format!(
                    "the path of \"{}\" was not applied: {e}",
                    segment.text
                )),
            }
        }
    }
    (features, notes)
}

/// Joint positions (metres, 20 fps) of a run.
pub async fn motion_joints(model: &MotionModel, plan: &Plan, tokens: &MotionTokens) -> Vec<Pose> {
    features_to_joints(&motion_features(model, plan, tokens).await.0)
}

/// How well a segment walked the path it asked for.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathReport {
    /// Segment number, from 1.
    pub segment: usize,
    /// The path asked for ("a circle, clockwise").
    pub path: String,
    /// For circles: closure, distance to the circle, turning direction.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub circle: Option<CircleReport>,
}

impl PathReport {
    /// One line for the terminal.
    pub fn summary(&self) -> String {
        match &self.circle {
            Some(c) => {
                format!(
                "segment {}: {}: turned {:.0}° {}, closure error {:.2} m, mean distance to the \
                 circle {:.2} m (radius {:.2} m)",
                self.segment,
                self.path,
                c.total_turn_deg,
                if c.turned_clockwise { "clockwise" } else { "counter-clockwise" },
                c.closure_error_m,
                c.mean_radius_error_m,
                c.radius_m
            )
            }
            None => format!("segment {}: walked {}", self.segment, self.path),
        }
    }
}

/// The paths of a run's segments as walked in `features` (from [`motion_features`]).
pub fn path_reports(
    plan: &Plan,
    tokens: &MotionTokens,
    features: &[FeatureFrame],
) -> Vec<PathReport> {
    plan.segments
        .iter()
        .zip(segment_ranges(plan, tokens))
        .enumerate()
        .filter_map(|(i, (segment, range))| {
            let path = segment.trajectory.as_ref()?;
            let circle = match path {
                Trajectory::Shape {
                    shape: Shape::Circle(side),
                } => Some(circle_report(
                    &trajectory::root_path(&features[range]),
                    side.is_clockwise(),
                )),
                _ => None,
            };
            Some(PathReport {
                segment: i + 1,
                path: path.describe(),
                circle,
            })
        })
        .collect()
}

/// One line for a progress log.
pub fn describe_event(event: &RunEvent) -> String {
    match event {
        RunEvent::Generated { index, segment } => {
            format!("segment {}: generated \"{}\"", index + 1, segment.base)
        }
        RunEvent::Edited { index, parts, text } => {
            let names: Vec<&str> = parts.iter().map(|p| p.name()).collect();
            format!(
                "segment {}: {} ← \"{text}\"",
                index + 1,
                names.join(" and ")
            )
        }
        RunEvent::Reviewed {
            index,
            round,
            review,
            accepted,
        } => {
            let what = if review.corrections.is_empty() {
                "nothing to correct".to_string()
            } else {
                let fixes: Vec<String> = review
                    .corrections
                    .iter()
                    .map(|c| format!("{} ← \"{}\"", c.region.name(), c.instruction))
                    .collect();
                format!(
                    "{} ({})",
                    fixes.join(", "),
                    if *accepted {
                        "kept"
                    } else {
                        "scored lower, dropped"
                    }
                )
            };
            format!("segment {}, review {}: {what}", index + 1, round + 1)
        }
        RunEvent::Blended => "segments blended".to_string(),
        RunEvent::ClipLaid { index, clip } => {
            let names: Vec<&str> = clip.parts.iter().map(|p| p.name()).collect();
            format!(
                "clip {} ({:.1}–{:.1} s): {} ← \"{}\"",
                index + 1,
                clip.start,
                clip.end,
                names.join(" and "),
                clip.text
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::{PartEdits, PlannerKind};

    fn segment(seconds: f64, parts: PartEdits) -> Segment {
        Segment {
            text: "a person walks forward".into(),
            seconds,
            base: "a person walks forward".into(),
            parts,
            trajectory: None,
            postures: None,
        }
    }

    #[test]
    fn parts_asked_the_same_thing_are_edited_together() {
        let both = "a person waves both hands".to_string();
        let s = segment(
            4.0,
            PartEdits {
                left_arm: Some(both.clone()),
                right_arm: Some(both.clone()),
                left_leg: Some("a person kicks forward with a leg".into()),
                right_leg: None,
            },
        );
        let groups = grouped_edits(&s);
        assert_eq!(groups.len(), 2);
        assert_eq!(
            groups[0],
            (both, vec![BodyPart::LeftArm, BodyPart::RightArm])
        );
        assert_eq!(part_bits(&groups[0].1), 0b0011);
        assert_eq!(part_bits(&[BodyPart::RightLeg]), 0b1000);
    }

    #[test]
    fn a_rounds_corrections_become_one_edit_with_an_instruction_per_part() {
        use crate::agents::reviewer::{Correction, JudgeKind, Region};
        let correction = |region, instruction: &str| Correction {
            region,
            instruction: instruction.into(),
        };
        let review = Review {
            description: String::new(),
            scores: Vec::new(),
            corrections: vec![
                correction(Region::LeftArm, "a person waves"),
                correction(Region::LowerBody, "a person squats"),
                correction(Region::LeftArm, "a person raises the left hand"),
            ],
            judge: JudgeKind::Evaluator,
            note: None,
        };
        let edits = round_edits(&review);
        let text_of = |part| {
            let found: Vec<&String> = edits
                .iter()
                .filter(|(p, _)| *p == part)
                .map(|(_, t)| t)
                .collect();
            found
        };
        assert_eq!(edits.len(), 3, "{edits:?}");
        assert_eq!(
            text_of(BodyPart::LeftArm),
            ["a person raises the left hand"]
        );
        assert!(text_of(BodyPart::RightArm).is_empty());
        for leg in Region::LowerBody.parts() {
            assert_eq!(text_of(*leg), ["a person squats"]);
        }
    }

    #[test]
    fn every_sampling_of_a_run_has_its_own_seed() {
        let mut seeds: Vec<u64> = (0..4)
            .flat_map(|i| [0, 1, 2, 100, 110, 900].map(|k| seed_of(7, i, k)))
            .collect();
        let n = seeds.len();
        seeds.sort_unstable();
        seeds.dedup();
        assert_eq!(seeds.len(), n);
        assert_ne!(seed_of(7, 0, 0), seed_of(8, 0, 0));
    }

    #[test]
    fn segments_keep_their_frames_in_the_blended_motion() {
        let plan = Plan {
            prompt: String::new(),
            rewritten: String::new(),
            segments: vec![
                segment(4.0, PartEdits::default()),
                segment(2.1, PartEdits::default()),
            ],
            clips: Vec::new(),
            planner: PlannerKind::Offline,
            notes: Vec::new(),
        };
        // The longest plan's segments, each rounded up to whole steps, still make tokens.
        let longest: usize = std::iter::repeat_n(2.1, 28)
            .map(|s| frames_for_seconds(s).div_ceil(FRAMES_PER_TOKEN))
            .sum();
        assert_eq!(longest, 308);
        assert!(MotionTokens::new(vec![vec![vec![0; longest]; 4]; 4]).is_ok());
        // 80 frames = 20 steps, then 42 frames rounded up to 11 steps: 31 steps in all.
        let tokens = MotionTokens::new(vec![vec![vec![0; 31]; 4]; 4]).unwrap();
        assert_eq!(segment_ranges(&plan, &tokens), vec![0..80, 80..124]);
    }
}
