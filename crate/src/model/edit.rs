//! Generating and editing motions as tokens, with no extra training: every edit masks some
//! tokens and lets the transformers fill them in, conditioned on the rest.
//!
//! - generate: everything masked;
//! - in-between: the steps covering frames α..β masked in all parts;
//! - body part: the chosen parts' tokens replaced by those of a motion generated from their
//!   text, the other parts' tokens kept (the decoder is shared, so the kept parts still move
//!   a little: `coma probe locality` measures it);
//! - blend: two motions joined with a masked transition between the end of one and the start
//!   of the next.

use super::generate::{KeepResidual, MotionTokens, SamplingOptions};
use super::prior::PriorMotion;
use super::transformer::{PARTS, TEXT_DIM};
use super::Spam;
use crate::features::{FeatureFrame, FEATURE_DIM};
use crate::rng::Rng;
use crate::skeleton::BodyPart;
use crate::timing::FRAMES_PER_TOKEN;
use burn::prelude::*;
use burn::tensor::{Int, TensorData};

/// The text condition of each part (model order: left arm, right arm, left leg, right leg).
pub type PartText = [[f32; TEXT_DIM]; PARTS];

/// The condition of every part: the global prompt's embedding, replaced for the parts that
/// have their own instruction.
pub fn part_text(global: &[f32; TEXT_DIM], overrides: &[(BodyPart, [f32; TEXT_DIM])]) -> PartText {
    std::array::from_fn(|p| {
        overrides
            .iter()
            .find(|(part, _)| *part == BodyPart::ALL[p])
            .map_or(*global, |(_, e)| *e)
    })
}

/// Steps either side of a seam that [`Spam::edit_parts_span`] regenerates (0.4 s at 20 fps).
pub const SEAM_STEPS: usize = 2;
/// Steps of context either side of the masked steps when only a window of a motion is filled.
const WINDOW_CONTEXT_STEPS: usize = 6;

/// The model indices of `parts`, in model order.
pub fn part_indices(parts: &[BodyPart]) -> Vec<usize> {
    (0..PARTS)
        .filter(|p| parts.contains(&BodyPart::ALL[*p]))
        .collect()
}

/// Time steps (of 4 frames) needed for `frames` frames, within the model's range.
pub fn steps_for_frames(frames: usize, max_steps: usize) -> usize {
    (frames.div_ceil(FRAMES_PER_TOKEN)).clamp(1, max_steps)
}

impl Spam {
    /// Fills the masked base positions, then the residual layers, keeping what is fixed.
    async fn fill(
        &self,
        text: &PartText,
        original: Option<&MotionTokens>,
        editable: &[Vec<bool>],
        options: &SamplingOptions,
    ) -> MotionTokens {
        let mut rng = Rng::new(options.seed);
        let fixed: Vec<Vec<Option<u32>>> = editable
            .iter()
            .enumerate()
            .map(|(p, row)| {
                row.iter()
                    .enumerate()
                    .map(|(s, e)| {
                        if *e {
                            None
                        } else {
                            original.map(|o| o[p][0][s])
                        }
                    })
                    .collect()
            })
            .collect();
        let base = self.decode_base(text, &fixed, options, &mut rng).await;
        let keep = original.map(|tokens| KeepResidual { tokens, editable });
        self.decode_residual(text, base, keep, options, &mut rng)
            .await
    }

    /// A new motion of about `frames` frames (a multiple of 4, at most the model's maximum).
    pub async fn generate(
        &self,
        text: &PartText,
        frames: usize,
        options: &SamplingOptions,
    ) -> MotionTokens {
        let n = steps_for_frames(frames, self.base_config.max_steps - 1);
        self.generate_steps(text, n, options).await
    }

    /// A new motion of exactly `n` time steps: from the text alone, or from a training
    /// motion near it when the model has a retrieval prior (see [`Spam::prior_tokens`]).
    async fn generate_steps(
        &self,
        text: &PartText,
        n: usize,
        options: &SamplingOptions,
    ) -> MotionTokens {
        match self.prior_tokens(text, n, options) {
            None => {
                self.fill(text, None, &vec![vec![true; n]; PARTS], options)
                    .await
            }
            Some(fixed) => {
                let mut rng = Rng::new(options.seed);
                let base = self.decode_base(text, &fixed, options, &mut rng).await;
                self.decode_residual(text, base, None, options, &mut rng)
                    .await
            }
        }
    }

    /// The layer-0 tokens a new motion of `n` steps keeps from the retrieval prior: for each
    /// part, the training motion nearest its text (drawn by the seed among equally near
    /// ones of about that length; parts with the same text share it), stretched to `n` steps,
    /// with a random `keep` share of its steps kept in every part and the rest left to the
    /// transformer. `None` when the model has
    /// no prior, it is turned off, or no part's text is near a training caption.
    fn prior_tokens(
        &self,
        text: &PartText,
        n: usize,
        options: &SamplingOptions,
    ) -> Option<Vec<Vec<Option<u32>>>> {
        let prior = self.prior.as_ref()?;
        let settings = options.prior.unwrap_or(prior.options);
        if settings.keep <= 0.0 {
            return None;
        }
        // Its own stream, so that a model without a prior samples what it always did.
        let mut rng = Rng::new(options.seed ^ 0x5052_494f_5221);
        // Parts that share a text share one training motion, and every part keeps the same
        // steps: whole-body key poses of one motion, which a mix of motions would not be.
        let mut chosen: Vec<Option<&PriorMotion>> = Vec::with_capacity(PARTS);
        for (p, t) in text.iter().enumerate() {
            let motion = match text[..p].iter().position(|u| u == t) {
                Some(q) => chosen[q],
                None => prior.motions.nearest(t, n, &settings, &mut rng),
            };
            chosen.push(motion);
        }
        let kept: Vec<bool> = (0..n).map(|_| rng.uniform() < settings.keep).collect();
        let found = chosen.iter().any(Option::is_some);
        let fixed = chosen
            .iter()
            .enumerate()
            .map(|(p, motion)| {
                (0..n)
                    .map(|s| {
                        // Stretched to the asked length (within about a quarter of it).
                        let code = motion.map(|m| m[p][s * m[p].len() / n]);
                        code.filter(|_| kept[s])
                    })
                    .collect()
            })
            .collect();
        found.then_some(fixed)
    }

    /// Regenerates frames `from..to` of every part.
    pub async fn inbetween(
        &self,
        tokens: &MotionTokens,
        text: &PartText,
        from: usize,
        to: usize,
        options: &SamplingOptions,
    ) -> MotionTokens {
        let n = tokens[0][0].len();
        let (a, b) = (
            from / FRAMES_PER_TOKEN,
            to.div_ceil(FRAMES_PER_TOKEN).min(n),
        );
        let editable: Vec<Vec<bool>> = (0..PARTS)
            .map(|_| (0..n).map(|s| s >= a && s < b).collect())
            .collect();
        self.fill(text, Some(tokens), &editable, options).await
    }

    /// Gives the chosen parts new tokens from their text; the other parts keep theirs. The
    /// new tokens come from a motion generated with the whole body following the chosen parts'
    /// text, and are moved onto this one: the dataset has few motions that, say, walk and wave
    /// at once, so a part regenerated beside the walking legs tends to move as in a walk,
    /// whereas the shared decoder turns a waving arm's tokens beside walking legs into both.
    pub async fn edit_parts(
        &self,
        tokens: &MotionTokens,
        text: &PartText,
        parts: &[BodyPart],
        options: &SamplingOptions,
    ) -> MotionTokens {
        let n = tokens[0][0].len();
        let chosen = part_indices(parts);
        let Some(&first) = chosen.first() else {
            return tokens.clone();
        };
        let donor_text: PartText = std::array::from_fn(|p| {
            if chosen.contains(&p) {
                text[p]
            } else {
                text[first]
            }
        });
        let donor = self.generate_steps(&donor_text, n, options).await;
        tokens.with_parts_from(&donor, &chosen)
    }

    /// Gives the chosen parts new tokens from their text over time steps `steps` only; the
    /// other parts, and the chosen ones outside the span, keep theirs (a clip on a body-part
    /// track). As in [`Spam::edit_parts`], the new tokens come from a donor motion made with
    /// the whole body following the chosen parts' text; a span longer than one generation is
    /// made in pieces. The [`SEAM_STEPS`] steps either side of each seam (the span's ends,
    /// the joins of pieces) are then regenerated on the chosen parts with their neighbours
    /// kept, so the parts move into and out of the clip rather than jump.
    pub async fn edit_parts_span(
        &self,
        tokens: &MotionTokens,
        text: &PartText,
        parts: &[BodyPart],
        steps: std::ops::Range<usize>,
        options: &SamplingOptions,
    ) -> MotionTokens {
        let n = tokens[0][0].len();
        let (a, b) = (steps.start.min(n), steps.end.min(n));
        let chosen = part_indices(parts);
        let Some(&first) = chosen.first() else {
            return tokens.clone();
        };
        if a >= b {
            return tokens.clone();
        }
        let donor_text: PartText = std::array::from_fn(|p| {
            if chosen.contains(&p) {
                text[p]
            } else {
                text[first]
            }
        });
        let most = self.base_config.max_steps - 1;
        let mut grid = tokens.clone().into_grid();
        let mut seams = vec![a, b];
        let mut start = a;
        for piece in 0u64.. {
            if start >= b {
                break;
            }
            let len = (b - start).min(most);
            let piece_options = SamplingOptions {
                seed: options.seed.wrapping_add(piece),
                ..options.clone()
            };
            let donor = self.generate_steps(&donor_text, len, &piece_options).await;
            for &p in &chosen {
                for (row, from) in grid[p].iter_mut().zip(&donor[p]) {
                    row[start..start + len].copy_from_slice(&from[..len]);
                }
            }
            start += len;
            if start < b {
                seams.push(start);
            }
        }
        let mut joined = MotionTokens::from_model(grid);
        for (k, &seam) in seams.iter().enumerate() {
            if seam == 0 || seam == n {
                continue;
            }
            let seam_options = SamplingOptions {
                seed: options.seed.wrapping_add(1000 + k as u64),
                ..options.clone()
            };
            let masked = seam.saturating_sub(SEAM_STEPS)..(seam + SEAM_STEPS).min(n);
            joined = self
                .fill_window(text, &joined, &chosen, masked, &seam_options)
                .await;
        }
        joined
    }

    /// Regenerates the chosen parts over time steps `steps` from `text`, with the other parts
    /// and the steps around kept (a clip taken off a body-part track: the parts go back to
    /// what the text of the rest says). A span longer than a window is filled a piece at a
    /// time, each piece reading the one before as context.
    pub async fn regenerate_parts_span(
        &self,
        tokens: &MotionTokens,
        text: &PartText,
        parts: &[BodyPart],
        steps: std::ops::Range<usize>,
        options: &SamplingOptions,
    ) -> MotionTokens {
        let n = tokens[0][0].len();
        let chosen = part_indices(parts);
        let most = self.base_config.max_steps - 1 - 2 * WINDOW_CONTEXT_STEPS;
        let mut out = tokens.clone();
        let mut start = steps.start.min(n);
        let end = steps.end.min(n);
        let mut piece = 0u64;
        while start < end && !chosen.is_empty() {
            let to = (start + most).min(end);
            let piece_options = SamplingOptions {
                seed: options.seed.wrapping_add(piece),
                ..options.clone()
            };
            out = self
                .fill_window(text, &out, &chosen, start..to, &piece_options)
                .await;
            start = to;
            piece += 1;
        }
        out
    }

    /// Regenerates steps `masked` of the parts `chosen` (model indices) with the rest kept,
    /// reading [`WINDOW_CONTEXT_STEPS`] steps of context either side: the window, not the
    /// whole motion, goes through the transformers, so it works on motions longer than one
    /// generation.
    async fn fill_window(
        &self,
        text: &PartText,
        tokens: &MotionTokens,
        chosen: &[usize],
        masked: std::ops::Range<usize>,
        options: &SamplingOptions,
    ) -> MotionTokens {
        let n = tokens[0][0].len();
        let from = masked.start.saturating_sub(WINDOW_CONTEXT_STEPS);
        let to = (masked.end + WINDOW_CONTEXT_STEPS).min(n);
        let window = MotionTokens::from_model(
            tokens
                .iter()
                .map(|part| part.iter().map(|row| row[from..to].to_vec()).collect())
                .collect(),
        );
        let editable: Vec<Vec<bool>> = (0..PARTS)
            .map(|p| {
                (from..to)
                    .map(|s| chosen.contains(&p) && masked.contains(&s))
                    .collect()
            })
            .collect();
        let filled = self.fill(text, Some(&window), &editable, options).await;
        let mut grid = tokens.clone().into_grid();
        for (part, new) in grid.iter_mut().zip(filled.iter()) {
            for (row, new) in part.iter_mut().zip(new) {
                row[from..to].copy_from_slice(new);
            }
        }
        MotionTokens::from_model(grid)
    }

    /// Joins `a` then `b`: the last `overlap` steps of `a` and the first `overlap` of `b` are
    /// regenerated as a transition, conditioned on both sides (text: the mean of the two).
    pub async fn blend(
        &self,
        a: &MotionTokens,
        b: &MotionTokens,
        text_a: &PartText,
        text_b: &PartText,
        overlap: usize,
        options: &SamplingOptions,
    ) -> MotionTokens {
        let (na, nb) = (a[0][0].len(), b[0][0].len());
        let ov_a = overlap.min(na / 2);
        let ov_b = overlap.min(nb / 2);
        // The transition window: a bit of context from each side around the masked steps.
        let context = 6usize;
        let start_a = na.saturating_sub(ov_a + context);
        let end_b = (ov_b + context).min(nb);
        let layers = a[0].len();
        let joined = MotionTokens::from_model(
            (0..PARTS)
                .map(|p| {
                    (0..layers)
                        .map(|l| {
                            a[p][l][start_a..]
                                .iter()
                                .chain(&b[p][l][..end_b])
                                .copied()
                                .collect()
                        })
                        .collect()
                })
                .collect(),
        );
        let w = joined[0][0].len();
        let (mask_from, mask_to) = (na - start_a - ov_a, na - start_a + ov_b);
        let editable: Vec<Vec<bool>> = (0..PARTS)
            .map(|_| (0..w).map(|s| s >= mask_from && s < mask_to).collect())
            .collect();
        let text: PartText = std::array::from_fn(|p| {
            let mut v: [f32; TEXT_DIM] = std::array::from_fn(|i| text_a[p][i] + text_b[p][i]);
            let norm = v.iter().map(|x| x * x).sum::<f32>().sqrt().max(1e-6);
            v.iter_mut().for_each(|x| *x /= norm);
            v
        });
        let window = self.fill(&text, Some(&joined), &editable, options).await;
        let grid = (0..PARTS)
            .map(|p| {
                (0..layers)
                    .map(|l| {
                        let mut row: Vec<u32> = a[p][l][..start_a].to_vec();
                        row.extend(&window[p][l]);
                        row.extend(&b[p][l][end_b..]);
                        row
                    })
                    .collect()
            })
            .collect();
        MotionTokens::from_model(grid)
    }

    /// Tokens of normalised features (cut to a multiple of 4 frames).
    pub fn tokenize(&self, features: &[FeatureFrame]) -> MotionTokens {
        MotionTokens::from_model(self.vq.tokenize_motion(features, &self.device))
    }

    /// Normalised features of tokens (`4 × steps` frames).
    pub async fn decode(&self, tokens: &MotionTokens) -> Vec<FeatureFrame> {
        let n = tokens[0][0].len();
        let parts = tokens
            .iter()
            .map(|layers| {
                layers
                    .iter()
                    .map(|row| {
                        let ids: Vec<i32> = row.iter().map(|t| *t as i32).collect();
                        Tensor::<2, Int>::from_data(TensorData::new(ids, [1, n]), &self.device)
                    })
                    .collect()
            })
            .collect();
        let out = super::read_floats(self.vq.decode(&parts)).await;
        out.chunks_exact(FEATURE_DIM)
            .map(|c| c.try_into().expect("263 columns"))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::executor::block_on;
    use crate::model::generate::tests::{small, tiny_vq};

    fn seeded(seed: u64) -> SamplingOptions {
        SamplingOptions {
            seed,
            ..Default::default()
        }
    }

    fn spam() -> Spam {
        Spam::random(&tiny_vq(), &small(), Some(&small()), &Device::flex())
    }

    #[test]
    fn generated_length_follows_the_request() {
        block_on(async {
            let s = spam();
            let text = [[0.05f32; TEXT_DIM]; PARTS];
            for frames in [40, 42, 120] {
                let tokens = s.generate(&text, frames, &SamplingOptions::default()).await;
                let got = s.decode(&tokens).await.len();
                assert!(
                    (got as i64 - frames as i64).abs() <= 4,
                    "asked {frames}, got {got}"
                );
            }
        })
    }

    #[test]
    fn a_prior_seeds_new_motions_and_keep_zero_turns_it_off() {
        use crate::model::prior::{MotionPrior, PriorOptions};
        use crate::model::Prior;
        block_on(async {
            let mut s = spam();
            let near = [0.05f32; TEXT_DIM];
            let mut far = [0.0f32; TEXT_DIM];
            far[0] = 1.0;
            let without = s.generate(&[near; PARTS], 40, &seeded(4)).await;
            // One training motion of 6 steps whose every code is 9, under a caption that is
            // the prompt itself.
            s.prior = Some(Prior {
                motions: MotionPrior::new(
                    &[(near, vec![0])],
                    vec![std::array::from_fn(|_| vec![9; 6])],
                ),
                options: PriorOptions {
                    keep: 0.5,
                    ..Default::default()
                },
            });
            let with = s.generate(&[near; PARTS], 40, &seeded(4)).await;
            let nines = |t: &MotionTokens| -> usize {
                (0..PARTS)
                    .map(|p| t[p][0][..6].iter().filter(|c| **c == 9).count())
                    .sum()
            };
            // About half of the 24 prior positions are kept; random codes of 16 rarely hit 9.
            assert!(nines(&with) >= 6, "{} nines in {with:?}", nines(&with));
            assert!(nines(&with) > nines(&without) + 3);
            let off = SamplingOptions {
                prior: Some(PriorOptions {
                    keep: 0.0,
                    ..Default::default()
                }),
                ..seeded(4)
            };
            assert_eq!(s.generate(&[near; PARTS], 40, &off).await, without);
            // A prompt far from every caption gets no prior.
            let text = [far; PARTS];
            let plain = {
                let prior = s.prior.take();
                let t = s.generate(&text, 40, &seeded(4)).await;
                s.prior = prior;
                t
            };
            assert_eq!(s.generate(&text, 40, &seeded(4)).await, plain);
        })
    }

    #[test]
    fn inbetween_keeps_everything_outside_the_range() {
        block_on(async {
            let s = spam();
            let text = [[0.05f32; TEXT_DIM]; PARTS];
            let original = s.generate(&text, 48, &seeded(1)).await;
            let edited = s
                .inbetween(&original, &[[0.3f32; TEXT_DIM]; PARTS], 16, 32, &seeded(2))
                .await;
            for p in 0..PARTS {
                for l in 0..original[p].len() {
                    assert_eq!(original[p][l][..4], edited[p][l][..4]);
                    assert_eq!(original[p][l][8..], edited[p][l][8..]);
                }
            }
        })
    }

    #[test]
    fn part_edit_moves_the_instruction_s_part_onto_the_motion() {
        block_on(async {
            let s = spam();
            let text = [[0.05f32; TEXT_DIM]; PARTS];
            let original = s.generate(&text, 160, &seeded(1)).await;
            let edited = s
                .edit_parts(&original, &text, &[BodyPart::LeftArm], &seeded(3))
                .await;
            assert_eq!(
                original[1..],
                edited[1..],
                "right arm and legs keep every token"
            );
            assert_ne!(original[0], edited[0], "the left arm is generated again");
            let donor = s.generate(&text, 160, &seeded(3)).await;
            assert_eq!(
                edited[0], donor[0],
                "the left arm of the instruction's own motion"
            );
        })
    }

    #[test]
    fn blend_joins_lengths() {
        block_on(async {
            let s = spam();
            let text = [[0.05f32; TEXT_DIM]; PARTS];
            let a = s.generate(&text, 64, &seeded(1)).await;
            let b = s.generate(&text, 80, &seeded(2)).await;
            let joined = s
                .blend(&a, &b, &text, &text, 2, &SamplingOptions::default())
                .await;
            assert_eq!(joined[0][0].len(), 16 + 20);
            assert_eq!(joined[1][0][..5], a[1][0][..5]);
            assert_eq!(
                joined[2][2][joined[2][2].len() - 5..],
                b[2][2][b[2][2].len() - 5..]
            );
        })
    }
}
