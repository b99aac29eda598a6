//! The product's clock. Every motion runs at 20 frames per second (HumanML3D's rate); the
//! VQ-VAE turns every 4 frames (0.2 s) into one token step; one generation makes at most 196
//! frames (9.8 s), the longest motion of the training data.

/// Frames per second of every motion in the product: data, model, page and exports.
pub const FPS: f64 = 20.0;
/// Frames per token step: the VQ-VAE's encoders downsample time by 4, so a motion of T frames
/// is T / 4 token steps per part and layer.
pub const FRAMES_PER_TOKEN: usize = 4;
/// Longest motion one generation makes and the dataset holds in one item: 196 frames, 9.8 s.
pub const MAX_FRAMES: usize = 196;

/// Frames for a length in seconds, within what one generation makes (4 to [`MAX_FRAMES`]);
/// a length that is not a number gives the longest motion.
pub fn frames_for_seconds(seconds: f64) -> usize {
    if seconds.is_finite() {
        ((seconds * FPS).round().max(FRAMES_PER_TOKEN as f64) as usize).min(MAX_FRAMES)
    } else {
        MAX_FRAMES
    }
}

/// The length in seconds of `frames` frames.
pub fn seconds(frames: usize) -> f64 {
    frames as f64 / FPS
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seconds_and_frames_agree() {
        assert_eq!(frames_for_seconds(4.0), 80);
        assert_eq!(frames_for_seconds(100.0), MAX_FRAMES);
        assert_eq!(frames_for_seconds(0.0), FRAMES_PER_TOKEN);
        assert_eq!(frames_for_seconds(f64::NAN), MAX_FRAMES);
        assert_eq!(seconds(MAX_FRAMES), 9.8);
        assert_eq!(MAX_FRAMES % FRAMES_PER_TOKEN, 0);
    }
}
