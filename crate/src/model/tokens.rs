//! A motion's tokens: for each of the four body parts (left arm, right arm, left leg, right
//! leg, in model order), layers of VQ-VAE codes (layer 0 from the base transformer, the others
//! residual), one code per token step of [`FRAMES_PER_TOKEN`] frames (0.2 s at 20 fps).
//!
//! The type is checked where tokens enter (a share link, a worker message, a file): four parts,
//! the same number of layers in each, the same number of steps in every layer, codes that fit
//! 9 bits. Whether they fit a particular model (its layer count and codebook) is
//! [`MotionTokens::fits`].

use crate::timing::FRAMES_PER_TOKEN;
use serde::{Deserialize, Serialize};

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
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "Vec<Vec<Vec<u32>>>", into = "Vec<Vec<Vec<u32>>>")]
pub struct MotionTokens(Vec<Vec<Vec<u32>>>);

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
        Ok(MotionTokens(grid))
    }

    /// Tokens the model made itself, right by construction (checked in debug builds).
    pub(crate) fn from_model(grid: Vec<Vec<Vec<u32>>>) -> MotionTokens {
        debug_assert!(
            MotionTokens::new(grid.clone()).is_ok(),
            "the model made tokens of an impossible shape"
        );
        MotionTokens(grid)
    }

    /// Layers per part.
    pub fn layers(&self) -> usize {
        self.0[0].len()
    }

    /// Token steps (each [`FRAMES_PER_TOKEN`] frames).
    pub fn steps(&self) -> usize {
        self.0[0][0].len()
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
            .0
            .iter()
            .flatten()
            .flatten()
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
    /// must have the same shape.
    pub fn with_parts_from(&self, donor: &MotionTokens, parts: &[usize]) -> MotionTokens {
        let mut grid = self.0.clone();
        for &p in parts {
            grid[p] = donor.0[p].clone();
        }
        MotionTokens::from_model(grid)
    }

    /// The grid `[part][layer][step]`.
    pub fn into_grid(self) -> Vec<Vec<Vec<u32>>> {
        self.0
    }
}

impl std::ops::Deref for MotionTokens {
    type Target = [Vec<Vec<u32>>];

    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

impl TryFrom<Vec<Vec<Vec<u32>>>> for MotionTokens {
    type Error = TokenError;

    fn try_from(grid: Vec<Vec<Vec<u32>>>) -> Result<Self, Self::Error> {
        MotionTokens::new(grid)
    }
}

impl From<MotionTokens> for Vec<Vec<Vec<u32>>> {
    fn from(tokens: MotionTokens) -> Self {
        tokens.0
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
}
