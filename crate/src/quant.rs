//! Block quantization of weights, for the page's download: values in blocks of consecutive
//! numbers (row-major; 32 at 4 bits, 128 at 8, [`Bits::block`]), each block stored as small
//! integers times its own f16 scale. A block is symmetric: `scale = max|v| / qmax` (rounded up to an f16), `q =
//! round(v / scale)` in `−qmax..=qmax`, so every value comes back within half a step,
//! `scale / 2`. Blocks follow the memory order whatever the tensor's shape, so one scheme
//! serves matrices, convolution kernels, embeddings and codebooks alike, and an outlier costs
//! precision only in its own block (per-row or per-column scales would spread it over a
//! whole row). Written by hand: the crates that do this (GGUF's formats) come with a model
//! runtime; this is 100 lines.

use burn::tensor::f16;
use serde::{Deserialize, Serialize};

/// Bits per stored value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Bits {
    /// 4 bits: `q` in −7..=7, two values per byte (the first in the low nibble), `q + 8`
    /// stored; blocks of 32. About 0.56 bytes a value with the scales.
    Four,
    /// 8 bits: `q` in −127..=127, one signed byte per value; blocks of 128 (at 255 levels a
    /// block needs fewer scales). About 1.02 bytes a value.
    Eight,
}

impl Bits {
    /// Values per block.
    pub fn block(self) -> usize {
        match self {
            Bits::Four => 32,
            Bits::Eight => 128,
        }
    }

    /// Blocks, and so scales, of `len` values.
    pub fn blocks(self, len: usize) -> usize {
        len.div_ceil(self.block())
    }

    /// Largest `|q|`.
    fn max_q(self) -> f32 {
        match self {
            Bits::Four => 7.0,
            Bits::Eight => 127.0,
        }
    }

    /// Bytes that hold `len` values.
    pub fn packed_len(self, len: usize) -> usize {
        match self {
            Bits::Four => len.div_ceil(2),
            Bits::Eight => len,
        }
    }
}

/// A run of `len` values quantized in blocks (see the module docs).
#[derive(Clone, PartialEq)]
pub struct Blocks {
    bits: Bits,
    len: usize,
    scales: Vec<f16>,
    packed: Vec<u8>,
}

// By hand: the derived form would print every byte.
impl std::fmt::Debug for Blocks {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Blocks")
            .field("bits", &self.bits)
            .field("len", &self.len)
            .finish_non_exhaustive()
    }
}

impl Blocks {
    /// `values` quantized; an infinite or NaN value is an error (it has no scale).
    pub fn quantize(values: &[f32], bits: Bits) -> Result<Blocks, String> {
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(format!("value {i} is {}", values[i]));
        }
        let max_q = bits.max_q();
        let mut scales = Vec::with_capacity(bits.blocks(values.len()));
        let mut q = Vec::with_capacity(values.len());
        for block in values.chunks(bits.block()) {
            let max = block.iter().fold(0f32, |m, v| m.max(v.abs()));
            let mut scale = f16::from_f32(max / max_q);
            // Rounded up, so the largest value still fits in −qmax..=qmax.
            if scale.to_f32() * max_q < max {
                scale = f16::from_bits(scale.to_bits() + 1);
            }
            let s = scale.to_f32();
            // An all-zero block keeps scale 0; dividing by it would give NaN.
            let inv = if s > 0.0 { 1.0 / s } else { 0.0 };
            q.extend(
                block
                    .iter()
                    .map(|v| (v * inv).round().clamp(-max_q, max_q) as i8),
            );
            scales.push(scale);
        }
        let packed = match bits {
            Bits::Eight => q.iter().map(|&q| q as u8).collect(),
            Bits::Four => q
                .chunks(2)
                .map(|pair| {
                    let nibble = |q: i8| (q + 8) as u8;
                    nibble(pair[0]) | pair.get(1).map_or(0, |&q| nibble(q) << 4)
                })
                .collect(),
        };
        Ok(Blocks {
            bits,
            len: values.len(),
            scales,
            packed,
        })
    }

    /// Blocks read back from storage, checked: as many scales and bytes as `len` values
    /// need, every scale finite and ≥ 0.
    pub fn from_parts(
        bits: Bits,
        len: usize,
        scales: Vec<f16>,
        packed: Vec<u8>,
    ) -> Result<Blocks, String> {
        if scales.len() != bits.blocks(len) {
            return Err(format!(
                "{} scales for {len} values, {} expected",
                scales.len(),
                bits.blocks(len)
            ));
        }
        if packed.len() != bits.packed_len(len) {
            return Err(format!(
                "{} bytes for {len} values of {bits:?} bits, {} expected",
                packed.len(),
                bits.packed_len(len)
            ));
        }
        if let Some(i) = scales
            .iter()
            .position(|s| !s.to_f32().is_finite() || s.to_f32() < 0.0)
        {
            return Err(format!("scale {i} is {}", scales[i]));
        }
        Ok(Blocks {
            bits,
            len,
            scales,
            packed,
        })
    }

    pub fn bits(&self) -> Bits {
        self.bits
    }

    /// Number of values.
    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// One f16 scale per block.
    pub fn scales(&self) -> &[f16] {
        &self.scales
    }

    /// The stored integers (see [`Bits`]).
    pub fn packed(&self) -> &[u8] {
        &self.packed
    }

    /// `q` of value `i`.
    fn q(&self, i: usize) -> i8 {
        match self.bits {
            Bits::Eight => self.packed[i] as i8,
            Bits::Four => ((self.packed[i / 2] >> (4 * (i % 2))) & 0xF) as i8 - 8,
        }
    }

    /// Values `start..start + count`, dequantized.
    ///
    /// # Panics
    /// If the range passes the end.
    pub fn values(&self, start: usize, count: usize) -> Vec<f32> {
        assert!(
            start + count <= self.len,
            "values past the end of the blocks"
        );
        // Block by block, so each scale is widened once: loading dequantizes millions of
        // values.
        let (block, end) = (self.bits.block(), start + count);
        let mut out = Vec::with_capacity(count);
        let mut i = start;
        while i < end {
            let stop = ((i / block + 1) * block).min(end);
            let scale = self.scales[i / block].to_f32();
            out.extend((i..stop).map(|k| self.q(k) as f32 * scale));
            i = stop;
        }
        out
    }

    /// Every value, dequantized.
    pub fn dequantize(&self) -> Vec<f32> {
        self.values(0, self.len)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wave(len: usize) -> Vec<f32> {
        (0..len)
            .map(|i| ((i as f32 * 0.37).sin() * 0.05) * if i == 40 { 30.0 } else { 1.0 })
            .collect()
    }

    #[test]
    fn values_come_back_within_half_a_step_of_their_block() {
        let values = wave(101);
        for bits in [Bits::Four, Bits::Eight] {
            let blocks = Blocks::quantize(&values, bits).unwrap();
            assert_eq!(blocks.scales().len(), bits.blocks(101));
            assert_eq!(blocks.packed().len(), bits.packed_len(101));
            let back = blocks.dequantize();
            for (i, (v, b)) in values.iter().zip(&back).enumerate() {
                let step = blocks.scales()[i / bits.block()].to_f32();
                assert!((v - b).abs() <= step / 2.0 + 1e-7, "{bits:?} value {i}");
            }
            // The outlier at 40 coarsens its own block only.
            if bits == Bits::Four {
                assert!(blocks.scales()[1] > blocks.scales()[0]);
            }
            assert_eq!(blocks.values(33, 5), back[33..38]);
            let again = Blocks::from_parts(
                bits,
                101,
                blocks.scales().to_vec(),
                blocks.packed().to_vec(),
            )
            .unwrap();
            assert_eq!(again, blocks, "a round trip through storage");
        }
    }

    #[test]
    fn extremes_zeros_and_bad_input() {
        let blocks = Blocks::quantize(&[0.0; 40], Bits::Four).unwrap();
        assert_eq!(blocks.dequantize(), vec![0.0; 40]);
        let edge = Blocks::quantize(&[1.0, -1.0, 0.5], Bits::Four).unwrap();
        let step = edge.scales()[0].to_f32();
        let back = edge.dequantize();
        assert!(
            (back[0] - 1.0).abs() <= step / 2.0 && (back[1] + 1.0).abs() <= step / 2.0,
            "the largest values fit: {back:?}"
        );
        assert!(Blocks::quantize(&[1.0, f32::NAN], Bits::Eight)
            .unwrap_err()
            .contains("value 1 is NaN"));
        let err = |scales: Vec<f16>, packed: Vec<u8>| {
            Blocks::from_parts(Bits::Four, 33, scales, packed).unwrap_err()
        };
        assert!(err(vec![f16::ONE], vec![0; 17]).contains("1 scales for 33 values, 2"));
        assert!(err(vec![f16::ONE; 2], vec![0; 16]).contains("16 bytes"));
        assert!(err(vec![f16::ONE, f16::NEG_ONE], vec![0; 17]).contains("scale 1 is -1"));
    }
}
