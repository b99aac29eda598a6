//! A motion's tokens: for each of the four body parts (left arm, right arm, left leg, right
//! leg, in model order), layers of VQ-VAE codes (layer 0 from the base transformer, the others
//! residual), one code per token step of [`FRAMES_PER_TOKEN`] frames (0.2 s at 20 fps).
//!
//! The type is checked where tokens enter (a share link, a worker message, a file): four parts,
//! the same number of layers in each, the same number of steps in every layer, codes that fit
//! 9 bits. Whether they fit a particular model (its layer count and codebook) is
//! [`MotionTokens::fits`].
//!
//! Body-part clips are layers over the base (whole-body) motion, as animation layers are in
//! MotionBuilder or Maya: the tokens are the final ones (clips laid), and beside them a sparse
//! list of [`BasePatch`]es keeps the base motion's codes of each part over the steps a clip
//! overwrote. The engine decodes the base everywhere and takes the clip's parts from the final
//! tokens over the clip's span only (see [`crate::model::layers`]), so a clip moved or
//! deleted leaves the motion outside its spans exactly as it was. Tokens without patches are a
//! motion of one layer, decoded as they are.

use crate::timing::FRAMES_PER_TOKEN;
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// Body parts of every motion.
pub const PARTS: usize = 4;
/// Most quantizer layers a motion carries.
pub const MAX_LAYERS: usize = 8;
/// Most token steps of one motion: the longest plan, 60 s at 20 fps in steps of 4 frames
/// (300), and one more for each of its up to 30 segments, which are generated in whole steps
/// and so may each round up by one.
pub const MAX_STEPS: usize = 330;
/// Largest code: codes are 9 bits.
pub const MAX_CODE: u32 = 511;

/// Tokens of one motion, `[part][layer][step]`; read them by indexing (`tokens[part][layer]`).
/// They are the final tokens, with body-part clips laid; [`MotionTokens::base_patches`] keeps
/// what the clips overwrote.
///
/// Serde writes tokens without patches as the plain `[part][layer][step]` array (as every
/// message, file and test had them before clips were layers), and tokens with patches as
/// `{"codes": [part][layer][step], "base": [patch, …]}`; it reads both.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "TokensForm", into = "TokensForm")]
pub struct MotionTokens {
    grid: Vec<Vec<Vec<u32>>>,
    /// Sorted by part, then first step; never overlapping or touching within a part.
    base: Vec<BasePatch>,
}

/// The base motion's codes of one body part over a run of token steps (4 frames, 0.2 s each
/// at 20 fps) where a body-part clip overwrote them: the layer under the clip. The run covers
/// the clip's frames and [`crate::model::edit::SEAM_STEPS`] steps either side of them, where
/// the part moves into and out of the clip.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct BasePatch {
    /// The body part, in model order (0 left arm, 1 right arm, 2 left leg, 3 right leg).
    pub part: usize,
    /// First token step covered: the patch starts at frame `4 × start`.
    pub start: usize,
    /// The base codes `[layer][step]`: one row per layer of the motion, all as long.
    pub codes: Vec<Vec<u32>>,
}

impl BasePatch {
    /// The token steps the patch covers.
    pub fn steps(&self) -> Range<usize> {
        self.start..self.start + self.codes.first().map_or(0, Vec::len)
    }
}

/// How serde writes and reads [`MotionTokens`]: the plain grid when there are no patches.
#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum TokensForm {
    Plain(Vec<Vec<Vec<u32>>>),
    Layered {
        codes: Vec<Vec<Vec<u32>>>,
        base: Vec<BasePatch>,
    },
}

impl TryFrom<TokensForm> for MotionTokens {
    type Error = TokenError;

    fn try_from(form: TokensForm) -> Result<Self, Self::Error> {
        match form {
            TokensForm::Plain(grid) => MotionTokens::new(grid),
            TokensForm::Layered { codes, base } => MotionTokens::new(codes)?.with_base(base),
        }
    }
}

impl From<MotionTokens> for TokensForm {
    fn from(tokens: MotionTokens) -> Self {
        if tokens.base.is_empty() {
            TokensForm::Plain(tokens.grid)
        } else {
            TokensForm::Layered {
                codes: tokens.grid,
                base: tokens.base,
            }
        }
    }
}

/// Why a grid of codes is not a motion's tokens, or not one a model can decode.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct TokenError(pub String);

impl MotionTokens {
    /// Checks a `[part][layer][step]` grid: [`PARTS`] parts, 1 to [`MAX_LAYERS`] layers and 1
    /// to [`MAX_STEPS`] steps, the same in every part and layer, codes up to [`MAX_CODE`].
    pub fn new(grid: Vec<Vec<Vec<u32>>>) -> Result<MotionTokens, TokenError> {
        if grid.len() != PARTS {
            return Err(TokenError(format!(
                "a motion has {PARTS} body parts of tokens, this one {}",
                grid.len()
            )));
        }
        let layers = grid[0].len();
        if !(1..=MAX_LAYERS).contains(&layers) {
            return Err(TokenError(format!(
                "a motion has 1 to {MAX_LAYERS} token layers, this one {layers}"
            )));
        }
        let steps = grid[0][0].len();
        if !(1..=MAX_STEPS).contains(&steps) {
            return Err(TokenError(format!(
                "a motion has 1 to {MAX_STEPS} token steps, this one {steps}"
            )));
        }
        if grid
            .iter()
            .any(|part| part.len() != layers || part.iter().any(|l| l.len() != steps))
        {
            return Err(TokenError(
                "the body parts' tokens differ in layers or steps".into(),
            ));
        }
        if let Some(code) = grid.iter().flatten().flatten().find(|c| **c > MAX_CODE) {
            return Err(TokenError(format!(
                "a token code of {code} (codes are 0 to {MAX_CODE})"
            )));
        }
        Ok(MotionTokens {
            grid,
            base: Vec::new(),
        })
    }

    /// Tokens the model made itself, right by construction (checked in debug builds).
    pub(crate) fn from_model(grid: Vec<Vec<Vec<u32>>>) -> MotionTokens {
        debug_assert!(
            MotionTokens::new(grid.clone()).is_ok(),
            "the model made tokens of an impossible shape"
        );
        MotionTokens {
            grid,
            base: Vec::new(),
        }
    }

    /// Layers per part.
    pub fn layers(&self) -> usize {
        self.grid[0].len()
    }

    /// Token steps (each [`FRAMES_PER_TOKEN`] frames).
    pub fn steps(&self) -> usize {
        self.grid[0][0].len()
    }

    /// Frames at 20 fps that the tokens decode to.
    pub fn frames(&self) -> usize {
        self.steps() * FRAMES_PER_TOKEN
    }

    /// Whether a model with `layers` quantizer layers and `codebook` codes per layer can
    /// decode these tokens (it decodes any prefix of its layers, so a base-only motion of one
    /// layer fits a residual model).
    pub fn fits(&self, layers: usize, codebook: usize) -> Result<(), TokenError> {
        let codes_fit = self
            .grid
            .iter()
            .flatten()
            .flatten()
            .chain(self.base.iter().flat_map(|p| p.codes.iter().flatten()))
            .all(|c| (*c as usize) < codebook);
        if self.layers() <= layers && codes_fit {
            Ok(())
        } else {
            Err(TokenError(format!(
                "these tokens do not fit the loaded model (4 parts × 1 to {layers} layers of \
                 codes below {codebook} expected)"
            )))
        }
    }

    /// These tokens with the parts `parts` (model order indices) taken from `donor`, which
    /// must have the same shape. (A model's result: no patches.)
    pub fn with_parts_from(&self, donor: &MotionTokens, parts: &[usize]) -> MotionTokens {
        let mut grid = self.grid.clone();
        for &p in parts {
            grid[p] = donor.grid[p].clone();
        }
        MotionTokens::from_model(grid)
    }

    /// The final grid `[part][layer][step]` (the patches are left behind).
    pub fn into_grid(self) -> Vec<Vec<Vec<u32>>> {
        self.grid
    }

    /// These tokens with `patches` as the base under their clips, checked: each patch on one
    /// of the [`PARTS`], as many rows as the tokens have layers, at least one step, inside
    /// the motion, codes up to [`MAX_CODE`], and patches of one part not overlapping (patches
    /// that touch are joined into one, as the engine keeps them).
    pub fn with_base(self, patches: Vec<BasePatch>) -> Result<MotionTokens, TokenError> {
        let (layers, steps) = (self.layers(), self.steps());
        for p in &patches {
            let len = p.codes.first().map_or(0, Vec::len);
            if p.part >= PARTS {
                return Err(TokenError(format!(
                    "a base patch names body part {} (0 to {} exist)",
                    p.part,
                    PARTS - 1
                )));
            }
            if p.codes.len() != layers || len == 0 || p.codes.iter().any(|r| r.len() != len) {
                return Err(TokenError(format!(
                    "a base patch must have {layers} layers of one length, at least one step"
                )));
            }
            if p.start.checked_add(len).is_none_or(|end| end > steps) {
                return Err(TokenError(format!(
                    "a base patch ends past the motion's {steps} token steps"
                )));
            }
            if let Some(code) = p.codes.iter().flatten().find(|c| **c > MAX_CODE) {
                return Err(TokenError(format!(
                    "a base patch holds a code of {code} (codes are 0 to {MAX_CODE})"
                )));
            }
        }
        let mut sorted: Vec<&BasePatch> = patches.iter().collect();
        sorted.sort_by_key(|p| (p.part, p.start));
        if sorted
            .windows(2)
            .any(|w| w[0].part == w[1].part && w[0].steps().end > w[1].start)
        {
            return Err(TokenError(
                "two base patches of one body part overlap".into(),
            ));
        }
        // The base grid of the checked patches, then the patches again from it: one patch per
        // run of covered steps.
        let mut base = self.grid.clone();
        let mut covered = Vec::new();
        for p in &patches {
            for (row, codes) in base[p.part].iter_mut().zip(&p.codes) {
                row[p.steps()].copy_from_slice(codes);
            }
            covered.push((p.part, p.steps()));
        }
        Ok(MotionTokens {
            base: patches_of(&base, covered),
            grid: self.grid,
        })
    }

    /// The base motion's codes under the clips, as a sparse list: empty when no clip is laid
    /// as a layer. Sorted by part, then first step.
    pub fn base_patches(&self) -> &[BasePatch] {
        &self.base
    }

    /// The base (whole-body) motion's tokens: these with every patch written back, and no
    /// patches. Without patches, the tokens themselves.
    pub fn base(&self) -> MotionTokens {
        MotionTokens::from_model(self.base_grid())
    }

    fn base_grid(&self) -> Vec<Vec<Vec<u32>>> {
        let mut grid = self.grid.clone();
        for p in &self.base {
            for (row, codes) in grid[p.part].iter_mut().zip(&p.codes) {
                row[p.steps()].copy_from_slice(codes);
            }
        }
        grid
    }

    /// The (part, steps) runs the patches cover.
    fn covered(&self) -> Vec<(usize, Range<usize>)> {
        self.base.iter().map(|p| (p.part, p.steps())).collect()
    }

    /// `laid`, made from these tokens by laying a clip on `parts` (model indices) over token
    /// steps `steps`, with the clip kept as a layer: these tokens' patches, and the base
    /// codes of `parts` over `steps` (steps past the motion's end are dropped). Where a patch
    /// of the part is there already, its codes stay the base: a clip over a clip still lies
    /// over the whole-body motion. `laid` must have these tokens' shape.
    pub fn layered(
        &self,
        laid: MotionTokens,
        parts: &[usize],
        steps: Range<usize>,
    ) -> MotionTokens {
        debug_assert_eq!((laid.layers(), laid.steps()), (self.layers(), self.steps()));
        let steps = steps.start.min(self.steps())..steps.end.min(self.steps());
        let mut covered = self.covered();
        if !steps.is_empty() {
            covered.extend(parts.iter().map(|&p| (p, steps.clone())));
        }
        MotionTokens {
            base: patches_of(&self.base_grid(), covered),
            grid: laid.grid,
        }
    }

    /// These tokens with the layer of `parts` (model indices) over token steps `steps` taken
    /// off: where a patch covers them, the part's codes go back to the base's exactly and the
    /// patch no longer covers them. Steps no patch covers are left as they are.
    pub fn without_layer(&self, parts: &[usize], steps: Range<usize>) -> MotionTokens {
        let base = self.base_grid();
        let mut grid = self.grid.clone();
        let mut covered = Vec::new();
        for (part, run) in self.covered() {
            let cut = run.start.max(steps.start)..run.end.min(steps.end);
            if !parts.contains(&part) || cut.is_empty() {
                covered.push((part, run));
                continue;
            }
            for (row, from) in grid[part].iter_mut().zip(&base[part]) {
                row[cut.clone()].copy_from_slice(&from[cut.clone()]);
            }
            covered.push((part, run.start..cut.start));
            covered.push((part, cut.end..run.end));
        }
        MotionTokens {
            base: patches_of(&base, covered),
            grid,
        }
    }

    /// Whether patches cover every step of `steps` for each of `parts` (model indices).
    pub fn covers(&self, parts: &[usize], steps: Range<usize>) -> bool {
        parts.iter().all(|&part| {
            steps.clone().all(|s| {
                self.base
                    .iter()
                    .any(|p| p.part == part && p.steps().contains(&s))
            })
        })
    }

    /// These tokens, made by an edit of `before` that rewrote parts through all their layers
    /// (a time range in-between, body parts regenerated, a segment made again), with the
    /// layers of `before` the edit left alone: a step of a part whose codes the edit changed
    /// is no longer under a clip (what the user asked there is the base now), every other
    /// step `before` had patched keeps its base codes. Without the same shape, no layers.
    pub fn keeping_layers_of(self, before: &MotionTokens) -> MotionTokens {
        if (self.layers(), self.steps()) != (before.layers(), before.steps()) {
            return MotionTokens::from_model(self.grid);
        }
        let changed = |part: usize, s: usize| {
            self.grid[part]
                .iter()
                .zip(&before.grid[part])
                .any(|(a, b)| a[s] != b[s])
        };
        let mut covered = Vec::new();
        for (part, run) in before.covered() {
            let mut start = run.start;
            for s in run.clone() {
                if changed(part, s) {
                    covered.push((part, start..s));
                    start = s + 1;
                }
            }
            covered.push((part, start..run.end));
        }
        MotionTokens {
            base: patches_of(&before.base_grid(), covered),
            grid: self.grid,
        }
    }
}

/// The patches of `base` (a `[part][layer][step]` grid) over the covered runs: runs of one
/// part that overlap or touch become one patch, empty runs none; sorted by part and start.
fn patches_of(base: &[Vec<Vec<u32>>], mut covered: Vec<(usize, Range<usize>)>) -> Vec<BasePatch> {
    covered.retain(|(_, r)| !r.is_empty());
    covered.sort_by_key(|(p, r)| (*p, r.start));
    let mut runs: Vec<(usize, Range<usize>)> = Vec::new();
    for (part, run) in covered {
        match runs.last_mut() {
            Some((p, last)) if *p == part && run.start <= last.end => {
                last.end = last.end.max(run.end)
            }
            _ => runs.push((part, run)),
        }
    }
    runs.into_iter()
        .map(|(part, run)| BasePatch {
            part,
            start: run.start,
            codes: base[part]
                .iter()
                .map(|row| row[run.clone()].to_vec())
                .collect(),
        })
        .collect()
}

impl std::ops::Deref for MotionTokens {
    type Target = [Vec<Vec<u32>>];

    fn deref(&self) -> &Self::Target {
        &self.grid
    }
}

impl TryFrom<Vec<Vec<Vec<u32>>>> for MotionTokens {
    type Error = TokenError;

    fn try_from(grid: Vec<Vec<Vec<u32>>>) -> Result<Self, Self::Error> {
        MotionTokens::new(grid)
    }
}

impl From<MotionTokens> for Vec<Vec<Vec<u32>>> {
    /// The final grid (the patches are left behind).
    fn from(tokens: MotionTokens) -> Self {
        tokens.grid
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_grids_of_a_motion_are_tokens() {
        let good = vec![vec![vec![3u32; 10]; 2]; 4];
        let tokens = MotionTokens::new(good.clone()).unwrap();
        assert_eq!(
            (tokens.layers(), tokens.steps(), tokens.frames()),
            (2, 10, 40)
        );
        assert_eq!(tokens[1][0][9], 3);
        let mut ragged = good.clone();
        ragged[2][1].pop();
        let mut big = good.clone();
        big[0][0][0] = 512;
        for (bad, why) in [
            (vec![vec![vec![0u32; 10]; 2]; 3], "4 body parts"),
            (vec![vec![vec![]; 2]; 4], "token steps"),
            (vec![vec![]; 4], "token layers"),
            (ragged, "differ"),
            (big, "512"),
        ] {
            let e = MotionTokens::new(bad).unwrap_err().to_string();
            assert!(e.contains(why), "{e}");
        }
        // Through serde, as a message or a file brings them.
        let json = serde_json::to_string(&tokens).unwrap();
        assert_eq!(serde_json::from_str::<MotionTokens>(&json).unwrap(), tokens);
        assert!(serde_json::from_str::<MotionTokens>("[[[1]]]").is_err());
        assert!(tokens.fits(2, 4).is_ok());
        assert!(tokens.fits(1, 512).is_err());
        assert!(tokens.fits(6, 3).is_err());
    }

    /// 4 parts × 2 layers × 20 steps, every code its part × 100 + its step.
    fn numbered() -> MotionTokens {
        MotionTokens::new(
            (0..4u32)
                .map(|p| {
                    (0..2)
                        .map(|_| (0..20).map(|s| p * 100 + s).collect())
                        .collect()
                })
                .collect(),
        )
        .unwrap()
    }

    /// `tokens` with part `part`'s codes over `steps` set to `code` (a clip laid).
    fn laid(tokens: &MotionTokens, part: usize, steps: Range<usize>, code: u32) -> MotionTokens {
        let mut grid = tokens.clone().into_grid();
        for row in &mut grid[part] {
            row[steps.clone()].iter_mut().for_each(|c| *c = code);
        }
        MotionTokens::new(grid).unwrap()
    }

    #[test]
    fn a_clip_layer_keeps_the_base_under_it_and_gives_it_back_exactly() {
        let base = numbered();
        let one = base.layered(laid(&base, 0, 4..9, 511), &[0], 4..9);
        assert_eq!(one[0][1][5], 511);
        assert_eq!(one.base(), base);
        assert_eq!(one.base_patches().len(), 1);
        assert_eq!(one.base_patches()[0].steps(), 4..9);
        assert_eq!(one.base_patches()[0].codes[0], vec![4, 5, 6, 7, 8]);
        // A second clip of the same part touching the first: one patch, still over the base.
        let two = one.layered(laid(&one, 0, 7..12, 300), &[0], 7..12);
        assert_eq!(two.base(), base);
        assert_eq!(
            two.base_patches()
                .iter()
                .map(|p| (p.part, p.steps()))
                .collect::<Vec<_>>(),
            [(0, 4..12)]
        );
        assert!(two.covers(&[0], 4..12) && !two.covers(&[0, 1], 4..12));
        // Taking the second off gives back the base where the first does not reach.
        let back = two.without_layer(&[0], 9..12);
        assert_eq!(back.base(), base);
        assert_eq!(&back[0][0][9..12], &[9, 10, 11]);
        assert_eq!(back.base_patches()[0].steps(), 4..9);
        // Both off: the motion is its base again, with no patches.
        assert_eq!(back.without_layer(&[0], 0..20), base);
        // Past the end: cut to the motion.
        let end = base.layered(laid(&base, 3, 18..20, 1), &[3], 18..25);
        assert_eq!(end.base_patches()[0].steps(), 18..20);
    }

    #[test]
    fn an_edit_through_all_layers_keeps_only_the_layers_it_left_alone() {
        let base = numbered();
        let one = base.layered(laid(&base, 0, 2..8, 511), &[0], 2..8);
        let clips = one.layered(laid(&one, 2, 12..16, 7), &[2], 12..16);
        // An in-between over steps 5..14 of every part.
        let mut grid = clips.clone().into_grid();
        for part in &mut grid {
            for row in part {
                row[5..14].iter_mut().for_each(|c| *c = 42);
            }
        }
        let edited = MotionTokens::new(grid).unwrap().keeping_layers_of(&clips);
        let runs: Vec<(usize, Range<usize>)> = edited
            .base_patches()
            .iter()
            .map(|p| (p.part, p.steps()))
            .collect();
        assert_eq!(runs, [(0, 2..5), (2, 14..16)]);
        assert_eq!(edited.base()[0][0][3], 3);
        assert_eq!(edited.base()[0][0][6], 42);
        // Another shape: no layers.
        let short = MotionTokens::new(vec![vec![vec![0; 5]; 2]; 4]).unwrap();
        assert!(short.keeping_layers_of(&clips).base_patches().is_empty());
    }

    #[test]
    fn patches_are_checked_and_travel_through_serde_beside_the_plain_form() {
        let base = numbered();
        let clips = base.layered(laid(&base, 1, 3..6, 9), &[1], 3..6);
        let json = serde_json::to_string(&clips).unwrap();
        assert!(json.starts_with("{\"codes\":"), "{json}");
        assert_eq!(serde_json::from_str::<MotionTokens>(&json).unwrap(), clips);
        // Without patches, the plain array as before.
        assert!(serde_json::to_string(&base).unwrap().starts_with("[[["));
        let patch = |part, start, len: usize| BasePatch {
            part,
            start,
            codes: vec![vec![1; len]; 2],
        };
        for (bad, why) in [
            (vec![patch(4, 0, 1)], "body part 4"),
            (vec![patch(0, 0, 0)], "at least one step"),
            (vec![patch(0, 18, 3)], "ends past"),
            (vec![patch(0, 0, 3), patch(0, 2, 3)], "overlap"),
            (
                vec![BasePatch {
                    part: 0,
                    start: 0,
                    codes: vec![vec![1]; 3],
                }],
                "2 layers",
            ),
            (
                vec![BasePatch {
                    part: 0,
                    start: 0,
                    codes: vec![vec![512]; 2],
                }],
                "512",
            ),
        ] {
            let e = base.clone().with_base(bad).unwrap_err().to_string();
            assert!(e.contains(why), "{e}");
        }
        // Touching patches are one.
        let joined = base
            .clone()
            .with_base(vec![patch(0, 2, 3), patch(0, 0, 2)])
            .unwrap();
        assert_eq!(joined.base_patches().len(), 1);
        assert!(joined.fits(2, 512).is_ok());
        let mut big = joined.clone();
        big.base[0].codes[0][0] = 300;
        assert!(big.fits(2, 300).is_err());
    }
}
