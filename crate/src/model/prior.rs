//! The retrieval prior: the layer-0 tokens of the training motions, indexed by the sentence
//! embeddings of their captions. A new motion starts from the tokens of a training motion
//! whose caption is nearest the prompt: a share of them is kept where they fall and the base
//! transformer fills in the rest, conditioned on the prompt as always (see
//! [`super::Spam::generate`]). Prompts far from every caption get no prior, and the
//! transformer generates them alone.
//!
//! The file `prior.bin` of a model folder holds it, in a format of its own (little-endian):
//!
//! ```text
//! "COMAPRI1"  u32 text_dim  u32 parts  u32 token_bytes (1 or 2)  u32 texts  u32 motions
//! texts ×   { text_dim / 2 bytes (the embedding in 4 bits), u32 count, u32 × count motions }
//! motions × { u16 steps, parts × steps tokens of token_bytes each }
//! ```
//!
//! A caption's embedding is kept in 4 bits a value (−7 to 7, two's complement, two a byte,
//! the first in the low half), scaled by its own largest value: only cosine similarities are
//! taken, which the scale does not change, and 4 bits move them by about 0.01 while the file
//! is the largest part of what the prior adds to the page's download.
//!
//! Written by hand: it is a few flat arrays read once in the page, and every field is checked
//! where it is read, so a damaged file gives a message instead of a panic.

use super::transformer::{PARTS, TEXT_DIM};
use crate::rng::Rng;

const MAGIC: &[u8; 8] = b"COMAPRI1";

/// Most motions one caption may name, and most token steps of a stored motion: bounds that a
/// damaged file cannot make the reader allocate past.
const MAX_MOTIONS_PER_TEXT: usize = 1 << 20;
const MAX_PRIOR_STEPS: usize = 1 << 12;

/// Largest magnitude of a 4-bit embedding value.
const LEVELS: f32 = 7.0;

/// One distinct training caption: its sentence embedding quantized to 4 bits (up to a scale),
/// and the training motions it describes.
#[derive(Clone, Debug, PartialEq)]
struct Key {
    embedding: Vec<i8>,
    norm: f32,
    motions: Vec<u32>,
}

/// Training motions' layer-0 tokens (`[part][step]`, one step per 4 frames at 20 fps) and
/// their captions' embeddings.
#[derive(Clone, Debug, PartialEq)]
pub struct MotionPrior {
    keys: Vec<Key>,
    motions: Vec<PriorMotion>,
}

/// One stored training motion's layer-0 codes, `[part][step]`.
pub type PriorMotion = [Vec<u32>; PARTS];

/// How generation uses the prior.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PriorOptions {
    /// Share of the retrieved motion's tokens kept in place (0 turns the prior off).
    pub keep: f32,
    /// Least cosine similarity between the prompt and the nearest caption for the prior to
    /// apply.
    pub min_similarity: f32,
    /// Captions within this much of the nearest one's similarity are as near: a seed draws
    /// among all their motions, so one caption still gives varied motions.
    pub margin: f32,
}

impl Default for PriorOptions {
    fn default() -> Self {
        PriorOptions {
            keep: 0.5,
            min_similarity: 0.7,
            margin: 0.02,
        }
    }
}

/// Why a prior file could not be read.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PriorError {
    #[error("not a retrieval prior (it does not start with {MAGIC:?})")]
    Magic,
    #[error("the file ends inside {0}")]
    Truncated(&'static str),
    #[error("{0}")]
    Invalid(String),
}

/// Reads little-endian fields off a byte slice, naming what it was reading when it ran out.
struct Reader<'a> {
    bytes: &'a [u8],
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize, what: &'static str) -> Result<&'a [u8], PriorError> {
        if self.bytes.len() < n {
            return Err(PriorError::Truncated(what));
        }
        let (head, rest) = self.bytes.split_at(n);
        self.bytes = rest;
        Ok(head)
    }

    fn u32(&mut self, what: &'static str) -> Result<u32, PriorError> {
        Ok(u32::from_le_bytes(
            self.take(4, what)?.try_into().expect("4 bytes"),
        ))
    }

    fn u16(&mut self, what: &'static str) -> Result<u16, PriorError> {
        Ok(u16::from_le_bytes(
            self.take(2, what)?.try_into().expect("2 bytes"),
        ))
    }
}

impl MotionPrior {
    /// A prior from each distinct caption's embedding with the indices of the motions it
    /// describes, and each motion's layer-0 tokens `[part][step]`.
    pub fn new(captions: &[([f32; TEXT_DIM], Vec<u32>)], motions: Vec<[Vec<u32>; PARTS]>) -> Self {
        let keys = captions
            .iter()
            .filter(|(_, m)| !m.is_empty())
            .map(|(e, m)| {
                let max = e.iter().fold(0f32, |a, x| a.max(x.abs()));
                let scale = if max > 0.0 { max / LEVELS } else { 1.0 };
                let embedding: Vec<i8> = e.iter().map(|x| (x / scale).round() as i8).collect();
                Key {
                    norm: norm(&embedding),
                    embedding,
                    motions: m.clone(),
                }
            })
            .collect();
        MotionPrior { keys, motions }
    }

    /// Distinct captions and motions held.
    pub fn len(&self) -> (usize, usize) {
        (self.keys.len(), self.motions.len())
    }

    /// True when it holds no caption.
    pub fn is_empty(&self) -> bool {
        self.keys.is_empty()
    }

    /// The file's bytes (see the module's docs).
    pub fn to_bytes(&self) -> Vec<u8> {
        let wide = self
            .motions
            .iter()
            .flatten()
            .flatten()
            .any(|t| *t > u8::MAX as u32);
        let mut out = MAGIC.to_vec();
        for v in [
            TEXT_DIM as u32,
            PARTS as u32,
            if wide { 2 } else { 1 },
            self.keys.len() as u32,
            self.motions.len() as u32,
        ] {
            out.extend(v.to_le_bytes());
        }
        for key in &self.keys {
            out.extend(
                key.embedding
                    .chunks(2)
                    .map(|pair| (pair[0] as u8 & 0x0f) | ((pair[1] as u8 & 0x0f) << 4)),
            );
            out.extend((key.motions.len() as u32).to_le_bytes());
            for m in &key.motions {
                out.extend(m.to_le_bytes());
            }
        }
        for motion in &self.motions {
            out.extend((motion[0].len() as u16).to_le_bytes());
            for t in motion.iter().flatten() {
                if wide {
                    out.extend((*t as u16).to_le_bytes());
                } else {
                    out.push(*t as u8);
                }
            }
        }
        out
    }

    /// Reads a prior file, checking every count against the file's length and the model's
    /// sizes (`codebook` codes).
    pub fn from_bytes(bytes: &[u8], codebook: usize) -> Result<MotionPrior, PriorError> {
        let mut r = Reader { bytes };
        if r.take(MAGIC.len(), "the header")
            .map_err(|_| PriorError::Magic)?
            != MAGIC
        {
            return Err(PriorError::Magic);
        }
        let (dim, parts) = (r.u32("the header")?, r.u32("the header")?);
        if (dim as usize, parts as usize) != (TEXT_DIM, PARTS) {
            return Err(PriorError::Invalid(format!(
                "made for {dim}-dimensional sentences and {parts} body parts; the model has \
                 {TEXT_DIM} and {PARTS}"
            )));
        }
        let token_bytes = r.u32("the header")? as usize;
        if !(1..=2).contains(&token_bytes) {
            return Err(PriorError::Invalid(format!(
                "tokens of {token_bytes} bytes (1 or 2 expected)"
            )));
        }
        let (texts, motions) = (r.u32("the header")? as usize, r.u32("the header")? as usize);
        let mut keys = Vec::with_capacity(texts.min(bytes.len() / TEXT_DIM));
        for _ in 0..texts {
            // Shifting the nibble to the top and back extends its sign.
            let embedding: Vec<i8> = r
                .take(TEXT_DIM / 2, "a caption")?
                .iter()
                .flat_map(|b| [((b << 4) as i8) >> 4, (*b as i8) >> 4])
                .collect();
            let count = r.u32("a caption")? as usize;
            if count == 0 || count > MAX_MOTIONS_PER_TEXT || count * 4 > r.bytes.len() {
                return Err(PriorError::Invalid(format!(
                    "a caption names {count} motions"
                )));
            }
            let list = (0..count)
                .map(|_| {
                    let m = r.u32("a caption's motions")?;
                    if m as usize >= motions {
                        return Err(PriorError::Invalid(format!(
                            "a caption names motion {m} of {motions}"
                        )));
                    }
                    Ok(m)
                })
                .collect::<Result<Vec<u32>, PriorError>>()?;
            keys.push(Key {
                norm: norm(&embedding),
                embedding,
                motions: list,
            });
        }
        let mut stored = Vec::with_capacity(motions.min(bytes.len()));
        for _ in 0..motions {
            let steps = r.u16("a motion")? as usize;
            if steps == 0 || steps > MAX_PRIOR_STEPS {
                return Err(PriorError::Invalid(format!("a motion of {steps} steps")));
            }
            let raw = r.take(PARTS * steps * token_bytes, "a motion's tokens")?;
            let codes: Vec<u32> = raw
                .chunks(token_bytes)
                .map(|c| match c {
                    [a] => *a as u32,
                    [a, b] => u16::from_le_bytes([*a, *b]) as u32,
                    _ => unreachable!("chunks of 1 or 2 bytes"),
                })
                .collect();
            if let Some(bad) = codes.iter().find(|c| **c as usize >= codebook) {
                return Err(PriorError::Invalid(format!(
                    "code {bad} in a motion; the model's codebook has {codebook}"
                )));
            }
            stored.push(std::array::from_fn(|p| {
                codes[p * steps..(p + 1) * steps].to_vec()
            }));
        }
        if !r.bytes.is_empty() {
            return Err(PriorError::Invalid(format!(
                "{} bytes after the last motion",
                r.bytes.len()
            )));
        }
        Ok(MotionPrior {
            keys,
            motions: stored,
        })
    }

    /// The tokens `[part][step]` of a training motion whose caption is nearest `text` (cosine
    /// similarity, at least `options.min_similarity`), drawn with `rng` among the motions of
    /// every caption within `options.margin` of the nearest, and among those the ones closest
    /// to `steps` long (within a quarter of it, or the closest if none is); `None` when no
    /// caption is near.
    pub fn nearest(
        &self,
        text: &[f32; TEXT_DIM],
        steps: usize,
        options: &PriorOptions,
        rng: &mut Rng,
    ) -> Option<&PriorMotion> {
        let query_norm = text.iter().map(|x| x * x).sum::<f32>().sqrt();
        if query_norm == 0.0 {
            return None;
        }
        let similarity: Vec<f32> = self
            .keys
            .iter()
            .map(|k| {
                let dot: f32 = k
                    .embedding
                    .iter()
                    .zip(text)
                    .map(|(a, b)| *a as f32 * b)
                    .sum();
                dot / (k.norm * query_norm).max(1e-12)
            })
            .collect();
        let best = similarity.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        if best < options.min_similarity {
            return None;
        }
        let mut candidates: Vec<u32> = self
            .keys
            .iter()
            .zip(&similarity)
            .filter(|(_, s)| **s >= best - options.margin)
            .flat_map(|(k, _)| k.motions.iter().copied())
            .collect();
        candidates.sort_unstable();
        candidates.dedup();
        // A motion cut short or stretched far does not do what its caption says in the time
        // asked (a lie-down cut at 5.8 s of 8 is still going down).
        let misfit = |m: &u32| {
            (self.motions[*m as usize][0].len() as f32 / steps.max(1) as f32)
                .ln()
                .abs()
        };
        let closest = candidates.iter().map(misfit).fold(f32::INFINITY, f32::min);
        candidates.retain(|m| misfit(m) <= closest.max(1.25f32.ln()));
        Some(&self.motions[candidates[rng.below(candidates.len())] as usize])
    }
}

fn norm(embedding: &[i8]) -> f32 {
    embedding
        .iter()
        .map(|x| (*x as f32).powi(2))
        .sum::<f32>()
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(axis: usize) -> [f32; TEXT_DIM] {
        let mut e = [0.0; TEXT_DIM];
        e[axis] = 1.0;
        e
    }

    fn motion(code: u32, steps: usize) -> [Vec<u32>; PARTS] {
        std::array::from_fn(|p| vec![code + p as u32; steps])
    }

    fn sample() -> MotionPrior {
        let mut near = unit(0);
        near[1] = 0.1;
        MotionPrior::new(
            &[(unit(0), vec![0, 1]), (near, vec![2]), (unit(5), vec![3])],
            vec![motion(1, 3), motion(10, 3), motion(20, 3), motion(300, 5)],
        )
    }

    #[test]
    fn motions_near_the_asked_length_are_preferred() {
        let prior = MotionPrior::new(&[(unit(0), vec![0, 1])], vec![motion(1, 4), motion(2, 12)]);
        let options = PriorOptions::default();
        let mut rng = Rng::new(2);
        for (steps, code) in [(5, 1), (10, 2), (40, 2), (1, 1)] {
            for _ in 0..20 {
                let m = prior.nearest(&unit(0), steps, &options, &mut rng).unwrap();
                assert_eq!(m[0][0], code, "{steps} steps");
            }
        }
    }

    #[test]
    fn the_file_reads_back_as_written() {
        let prior = sample();
        let bytes = prior.to_bytes();
        assert_eq!(MotionPrior::from_bytes(&bytes, 512), Ok(prior.clone()));
        // Codes that fit a byte are stored in one.
        let small = MotionPrior::new(&[(unit(0), vec![0])], vec![motion(1, 3)]);
        let one = small.to_bytes();
        assert_eq!(one.len(), 8 + 20 + TEXT_DIM / 2 + 4 + 4 + 2 + PARTS * 3);
        assert_eq!(MotionPrior::from_bytes(&one, 256), Ok(small));
    }

    #[test]
    fn damaged_files_are_refused_with_a_reason() {
        let bytes = sample().to_bytes();
        assert_eq!(
            MotionPrior::from_bytes(b"COMA", 512),
            Err(PriorError::Magic)
        );
        for cut in [10, 40, bytes.len() - 1] {
            assert!(
                MotionPrior::from_bytes(&bytes[..cut], 512).is_err(),
                "cut at {cut}"
            );
        }
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(MotionPrior::from_bytes(&longer, 512).is_err());
        let err = MotionPrior::from_bytes(&bytes, 256).unwrap_err();
        assert!(err.to_string().contains("codebook has 256"), "{err}");
        let mut wrong_motion = bytes.clone();
        // The first caption's first motion index sits after the header, embedding and count.
        let at = 8 + 20 + TEXT_DIM / 2 + 4;
        wrong_motion[at..at + 4].copy_from_slice(&99u32.to_le_bytes());
        let err = MotionPrior::from_bytes(&wrong_motion, 512).unwrap_err();
        assert!(err.to_string().contains("motion 99 of 4"), "{err}");
    }

    #[test]
    fn the_nearest_captions_motions_are_drawn_and_far_prompts_get_none() {
        let prior = sample();
        let options = PriorOptions::default();
        let mut rng = Rng::new(1);
        let mut seen = std::collections::BTreeSet::new();
        for _ in 0..100 {
            let m = prior.nearest(&unit(0), 3, &options, &mut rng).unwrap();
            seen.insert(m[0][0]);
        }
        // Motions 0 and 1 belong to the caption itself; motion 2's caption is 0.995 similar,
        // within the margin.
        assert_eq!(seen.into_iter().collect::<Vec<_>>(), vec![1, 10, 20]);
        let strict = PriorOptions {
            margin: 0.0,
            ..options
        };
        for _ in 0..50 {
            let m = prior.nearest(&unit(0), 3, &strict, &mut rng).unwrap();
            assert!(m[0][0] == 1 || m[0][0] == 10);
        }
        assert_eq!(
            prior.nearest(&unit(5), 3, &options, &mut rng).unwrap()[0][0],
            300
        );
        assert!(prior.nearest(&unit(9), 3, &options, &mut rng).is_none());
        assert!(prior
            .nearest(&[0.0; TEXT_DIM], 3, &options, &mut rng)
            .is_none());
    }
}
