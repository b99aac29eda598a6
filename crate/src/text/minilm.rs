//! The all-MiniLM-L6-v2 sentence encoder (a 6-layer BERT, 384 wide) in burn: text → one
//! L2-normalised 384-d vector per sentence, or per-token states for token-level conditioning.
//!
//! The page downloads the weights, so they are split in two files, neither needing the file
//! system to load:
//!
//! - `minilm-words.i8`: the 30522 × 384 word-embedding table, 47 MB in f32, quantized in
//!   blocks ([`crate::quant`]; 6.6 MB at the shipped 4 bits, see [`WordEmbeddings`] for the
//!   format). It is read on the CPU in plain Rust because a sentence touches a dozen of its
//!   rows: giving the whole table to the tensor backend would cost memory for nothing.
//! - `minilm-encoder.bpk`: everything else ([`MiniLm`]), 11 MB: a burnpack in
//!   [`crate::weights`]' layout whose matrices and embeddings (the 36 Linear weights of the 6
//!   layers are 10.6 M of the 10.8 M values) are quantized in blocks (8 bits shipped) and
//!   whose other tensors are f16. Everything is widened to f32 on load, so the encoder
//!   computes in f32.
//!
//! [`convert_minilm`] writes both from the original `model.safetensors`; [`SentenceEncoder`]
//! ties them to the tokenizer. Results match sentence-transformers (mean pooling over real
//! tokens, then L2 normalisation) to a cosine above 0.999 (`crate/tests/text.rs` checks it on
//! 20 reference sentences).

use super::tokenizer::{Tokenizer, VocabError};
use crate::quant::{Bits, Blocks};
use burn::module::Module;
use burn::nn::attention::{MhaInput, MultiHeadAttention, MultiHeadAttentionConfig};
use burn::nn::{Embedding, EmbeddingConfig, LayerNorm, LayerNormConfig, Linear, LinearConfig};
use burn::prelude::*;
use burn::store::burn_pack::Tensor as PackTensor;
use burn::store::{bridge, KeyRemapper, ModuleSnapshot, PyTorchToBurnAdapter, SafetensorsStore};
use burn::tensor::activation::gelu;
use burn::tensor::{f16, DType};
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Width of the sentence embeddings and token states.
pub const EMBEDDING_DIM: usize = 384;

/// The vocabulary (HF's `vocab.txt` as is) that [`SentenceEncoder::from_dir`] reads.
pub const VOCAB_FILE: &str = "minilm-vocab.txt";
/// The quantized word-embedding table (see [`WordEmbeddings`]) written by [`convert_minilm`].
pub const WORDS_FILE: &str = "minilm-words.i8";

/// Bits per value of the shipped word table (`static/models`): 4 bits halve its download,
/// and sentence embeddings stay within 0.997 cosine of the reference (`crate/tests/text.rs`;
/// 0.9996 at 8 bits), which `EVAL.md`'s figures bear.
pub const SHIPPED_WORD_BITS: Bits = Bits::Four;

/// Bits per value of the shipped encoder's matrices: at 4 bits a sentence's embedding drifts
/// to 0.97 cosine of the reference ("a person walks forward"), too far to keep.
pub const SHIPPED_ENCODER_BITS: Bits = Bits::Eight;
/// The burnpack of the rest of the encoder ([`MiniLm`], quantized matrices) written by
/// [`convert_minilm`].
pub const MODEL_FILE: &str = "minilm-encoder.bpk";

/// Shape of the encoder; the defaults are all-MiniLM-L6-v2's `config.json`.
#[derive(Config, Debug)]
pub struct MiniLmConfig {
    /// Rows of the word-embedding table (kept outside the module, checked against it).
    #[config(default = 30522)]
    pub vocab_size: usize,
    /// Width of every token state.
    #[config(default = 384)]
    pub hidden: usize,
    /// Number of encoder layers.
    #[config(default = 6)]
    pub layers: usize,
    /// Attention heads per layer.
    #[config(default = 12)]
    pub heads: usize,
    /// Width of the feed-forward block.
    #[config(default = 1536)]
    pub intermediate: usize,
    /// Longest sequence the position table covers.
    #[config(default = 512)]
    pub max_positions: usize,
    /// Rows of the token-type table (only type 0 is used: one sentence per input).
    #[config(default = 2)]
    pub type_vocab: usize,
    /// LayerNorm epsilon.
    #[config(default = 1e-12)]
    pub layer_norm_eps: f64,
}

impl MiniLmConfig {
    /// A randomly initialised encoder; load weights into it with [`MiniLm::from_bytes`] or
    /// burn-store.
    pub fn init(&self, device: &Device) -> MiniLm {
        let norm = LayerNormConfig::new(self.hidden).with_epsilon(self.layer_norm_eps);
        MiniLm {
            embeddings: Embeddings {
                position: EmbeddingConfig::new(self.max_positions, self.hidden).init(device),
                token_type: EmbeddingConfig::new(self.type_vocab, self.hidden).init(device),
                layer_norm: norm.init(device),
            },
            layers: (0..self.layers)
                .map(|_| EncoderLayer {
                    // Inference only: dropout would be a no-op anyway, zero makes it explicit.
                    attention: MultiHeadAttentionConfig::new(self.hidden, self.heads)
                        .with_dropout(0.0)
                        .init(device),
                    attention_norm: norm.init(device),
                    intermediate: LinearConfig::new(self.hidden, self.intermediate).init(device),
                    output: LinearConfig::new(self.intermediate, self.hidden).init(device),
                    output_norm: norm.init(device),
                })
                .collect(),
        }
    }
}

/// Position and token-type embeddings plus their LayerNorm (the word embeddings are added
/// before, outside burn).
#[derive(Module, Debug)]
pub struct Embeddings {
    position: Embedding,
    token_type: Embedding,
    layer_norm: LayerNorm,
}

/// One post-norm BERT layer: self-attention, then a GELU feed-forward block, each followed by
/// a residual sum and a LayerNorm.
#[derive(Module, Debug)]
pub struct EncoderLayer {
    attention: MultiHeadAttention,
    attention_norm: LayerNorm,
    intermediate: Linear,
    output: Linear,
    output_norm: LayerNorm,
}

impl EncoderLayer {
    fn forward(&self, x: Tensor<3>, padding: Tensor<2, Bool>) -> Tensor<3> {
        let attended = self
            .attention
            .forward(MhaInput::self_attn(x.clone()).mask_pad(padding))
            .context;
        let x = self.attention_norm.forward(x + attended);
        // burn's `gelu` is the exact erf form, as BERT's "gelu".
        let hidden = gelu(self.intermediate.forward(x.clone()));
        self.output_norm.forward(x + self.output.forward(hidden))
    }
}

/// The all-MiniLM-L6-v2 encoder minus its word-embedding table: word vectors in, contextual
/// token states out.
///
/// ```text
///  word vectors [B, L, 384]            (looked up on the CPU, see WordEmbeddings)
///        |
///        +-- + position[0..L] + token_type[0]
///        v
///    LayerNorm
///        |
///  6 x   +------------------------------------------------------+
///        | x --> 12-head self-attention (padded keys masked)    |
///        |   --> + x --> LayerNorm = y                          |
///        | y --> Linear 384->1536 --> GELU --> Linear 1536->384 |
///        |   --> + y --> LayerNorm                              |
///        +------------------------------------------------------+
///        v
///  token states [B, L, 384]
/// ```
///
/// File format ([`MODEL_FILE`]): [`Self::to_bytes`] writes [`crate::weights`]' layout with
/// metadata `format` = [`Self::FORMAT`], tensors named by their path in this module.
/// [`Self::from_bytes`] also reads the earlier [`Self::FORMAT_COLUMNS`]: a burnpack container
/// (burn's own format) with one tensor per parameter:
///
/// | tensors | dtype | shape | content |
/// |---|---|---|---|
/// | `layers.{0‥5}.{attention.query, attention.key, attention.value, attention.output, intermediate, output}.weight` (36) | i8 | `[in, out]` (burn's layout, PyTorch's transposed) | `q`, the weight being `w[i, o] ≈ q[i, o] · scale[o]` |
/// | the same names + `_scale` | f32 | `[out]` | `scale[o] = max_i \|w[i, o]\| / 127`: symmetric, one per output (per row of PyTorch's `[out, in]` matrix), 0 for an all-zero output |
/// | every other parameter: Linear biases, LayerNorm `gamma`/`beta`, `embeddings.position.weight` `[512, 384]`, `embeddings.token_type.weight` `[2, 384]` | f16 | as in the module | the value |
///
/// [`Self::from_bytes`] also takes f32 (or f16) for any tensor, and refuses a file with a
/// tensor too many or too few.
#[derive(Module, Debug)]
pub struct MiniLm {
    embeddings: Embeddings,
    layers: Vec<EncoderLayer>,
}

impl MiniLm {
    /// Token states `[B, L, 384]` of word vectors `[B, L, 384]`. `padding` is `[B, L]`, true
    /// at padded positions: they are never attended to, and their own output rows are
    /// meaningless (mask them out downstream).
    pub fn forward(&self, words: Tensor<3>, padding: Tensor<2, Bool>) -> Tensor<3> {
        let [_, len, _] = words.dims();
        let device = words.device();
        let positions = Tensor::<1, Int>::arange(0..len as i64, &device).reshape([1, len]);
        let token_type = Tensor::<2, Int>::zeros([1, 1], &device);
        let x = words
            + self.embeddings.position.forward(positions)
            + self.embeddings.token_type.forward(token_type);
        let mut x = self.embeddings.layer_norm.forward(x);
        for layer in &self.layers {
            x = layer.forward(x, padding.clone());
        }
        x
    }

    /// Value of the `format` metadata of [`MODEL_FILE`] that [`Self::to_bytes`] writes:
    /// [`crate::weights`]' layout (floats in f16, matrices and embeddings quantized in blocks).
    pub const FORMAT: &'static str = "coma-minilm-encoder/2";
    /// The earlier format (the table above), still read.
    pub const FORMAT_COLUMNS: &'static str = "coma-minilm-encoder/1";
    /// Name suffix of the scales of an int8 matrix in [`Self::FORMAT_COLUMNS`].
    const SCALE_SUFFIX: &'static str = "_scale";

    /// Loads an encoder from the bytes of [`MODEL_FILE`] (either format), widening every
    /// tensor to f32. Damaged bytes give an error, not a panic (checked for empty, garbage
    /// and truncated input, and for files of another format).
    pub fn from_bytes(bytes: &[u8], device: &Device) -> Result<MiniLm, MiniLmError> {
        let error = |message: String| MiniLmError::Model(message);
        let (tensors, metadata) = crate::weights::read_widened(bytes).map_err(error)?;
        let tensors = match metadata.get("format").map(String::as_str) {
            Some(Self::FORMAT) => tensors,
            Some(Self::FORMAT_COLUMNS) => Self::widen_columns(tensors)?,
            format => {
                return Err(error(format!(
                    "format {format:?}, expected {:?} (an older minilm.bpk? convert again with \
                     `coma text convert`)",
                    Self::FORMAT
                )))
            }
        };
        let mut model = MiniLmConfig::new().init(device);
        let result = model.apply(tensors, None, None, false);
        if !(result.errors.is_empty() && result.missing.is_empty() && result.unused.is_empty()) {
            return Err(error(result.to_string()));
        }
        Ok(model)
    }

    /// The tensors of a [`Self::FORMAT_COLUMNS`] file with its int8 matrices widened by their
    /// column scales.
    fn widen_columns(tensors: Vec<PackTensor>) -> Result<Vec<PackTensor>, MiniLmError> {
        let error = |message: String| MiniLmError::Model(message);
        let pack = |e: burn::store::burn_pack::Error| MiniLmError::Model(e.to_string());
        let mut tensors: BTreeMap<String, PackTensor> =
            tensors.into_iter().map(|t| (t.name.clone(), t)).collect();
        let mut scales = crate::weights::take_suffixed(&mut tensors, Self::SCALE_SUFFIX);
        let mut widened = Vec::with_capacity(tensors.len());
        for (name, tensor) in tensors {
            if tensor.dtype != DType::I8 {
                widened.push(tensor);
                continue;
            }
            let data = bridge::into_data(tensor).map_err(pack)?;
            let shape = data.shape().to_vec();
            let scale_name = format!("{name}{}", Self::SCALE_SUFFIX);
            let scale = scales
                .remove(&scale_name)
                .ok_or_else(|| error(format!("{name}: int8 without {scale_name}")))?;
            let scale = bridge::into_data(scale).map_err(pack)?;
            let values =
                dequantize_columns(&data, &scale).map_err(|m| error(format!("{name}: {m}")))?;
            widened.push(bridge::from_data(
                TensorData::new(values, shape),
                name,
                None,
            ));
        }
        if let Some(name) = scales.keys().next() {
            return Err(error(format!("{name} scales no int8 matrix")));
        }
        Ok(widened)
    }

    /// The bytes of [`MODEL_FILE`] for this encoder in [`Self::FORMAT`], its matrices and
    /// embeddings quantized to `bits`. The bytes depend on the weights only, so a conversion
    /// always gives the same file.
    pub fn to_bytes(&self, bits: Bits) -> Result<Vec<u8>, MiniLmError> {
        crate::weights::shipped_bytes(
            self,
            &|_| Some(bits),
            &[
                ("format", Self::FORMAT),
                ("model", "all-MiniLM-L6-v2 without word embeddings"),
            ],
        )
        .map_err(|e| MiniLmError::Model(e.to_string()))
    }
}

/// The f32 values of an int8 `[rows, cols]` matrix with `[cols]` scales (each column `c` is
/// `q[r, c] · scale[c]`), checking the shapes and that every scale is finite and ≥ 0.
fn dequantize_columns(values: &TensorData, scales: &TensorData) -> Result<Vec<f32>, String> {
    let shape = values.shape().to_vec();
    let &[_, cols] = shape.as_slice() else {
        return Err(format!("int8 tensor of shape {shape:?}, expected a matrix"));
    };
    if scales.shape().to_vec() != [cols] || scales.dtype() != DType::F32 {
        return Err(format!(
            "scales are {:?} {:?}, expected F32 [{cols}]",
            scales.dtype(),
            scales.shape()
        ));
    }
    let scales: Vec<f32> = scales.iter::<f32>().collect();
    if let Some(bad) = scales.iter().position(|s| !s.is_finite() || *s < 0.0) {
        return Err(format!("scale {bad} is {}", scales[bad]));
    }
    let q: &[i8] = values.as_slice::<i8>().map_err(|e| format!("{e:?}"))?;
    Ok(q.chunks_exact(cols)
        .flat_map(|row| row.iter().zip(&scales).map(|(&q, &s)| q as f32 * s))
        .collect())
}

/// Why an encoder could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum MiniLmError {
    /// The vocabulary text is unusable.
    #[error("vocabulary: {0}")]
    Vocab(#[from] VocabError),
    /// The word-embedding bytes are not a valid table.
    #[error("word embeddings: {0}")]
    Words(#[from] WordsFormatError),
    /// The burnpack bytes are not a valid encoder.
    #[error("encoder weights: {0}")]
    Model(String),
    /// The three parts do not belong together.
    #[error("mismatched parts: {0}")]
    Mismatch(String),
    /// A file of [`SentenceEncoder::from_dir`] could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

/// Why bytes are not a word-embedding table.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum WordsFormatError {
    /// The first four bytes are not [`WordEmbeddings::MAGIC`].
    #[error("not a word-embedding file (bad magic bytes)")]
    BadMagic,
    /// A format version this code does not know.
    #[error("unsupported format version {0}")]
    Version(u32),
    /// The byte count disagrees with the header's rows and columns.
    #[error("expected {expected} bytes, found {found}")]
    Length {
        /// Byte count the header implies.
        expected: u64,
        /// Byte count given.
        found: u64,
    },
    /// A scale is negative, infinite or NaN.
    #[error("a scale is negative, infinite or NaN")]
    BadScale,
    /// Bits per value other than 4 or 8.
    #[error("{0} bits per value; 4 or 8 are read")]
    Bits(u32),
}

/// The word-embedding table, quantized ([`Blocks`]) and looked up on the CPU row by row.
///
/// File format (`minilm-words.i8`), little endian, no padding:
///
/// | offset | size | content |
/// |---|---|---|
/// | 0 | 4 | magic `b"CMWE"` ([`Self::MAGIC`]) |
/// | 4 | 4 | `u32` version: 2 (1, the earlier per-row int8, is still read) |
/// | 8 | 4 | `u32` rows |
/// | 12 | 4 | `u32` cols |
/// | 16 | 4 | `u32` bits per value, 4 or 8 |
/// | 20 | 2 × blocks | `f16` scale of each block ([`Bits::block`] values) |
/// | then | the rest | the packed values, row-major, as [`Bits`] says |
///
/// Version 1: `rows`, `cols`, then an `f32` scale per row and `rows × cols` `i8` values; it
/// is read by re-quantizing it to 8-bit blocks.
#[derive(Clone, PartialEq)]
pub struct WordEmbeddings {
    rows: usize,
    cols: usize,
    blocks: Blocks,
}

impl WordEmbeddings {
    /// First bytes of the file ("CoMA word embeddings").
    pub const MAGIC: [u8; 4] = *b"CMWE";
    /// Format version written by [`Self::to_bytes`].
    pub const VERSION: u32 = 2;

    /// Quantizes a row-major `rows × cols` f32 table to `bits`.
    ///
    /// # Panics
    /// If `table.len() != rows * cols` or a value is not finite.
    pub fn quantize(table: &[f32], rows: usize, cols: usize, bits: Bits) -> WordEmbeddings {
        assert_eq!(table.len(), rows * cols, "table is not rows × cols");
        WordEmbeddings {
            rows,
            cols,
            blocks: Blocks::quantize(table, bits).expect("a finite word table"),
        }
    }

    /// Parses the file format above, checking the header against the byte count.
    pub fn from_bytes(bytes: &[u8]) -> Result<WordEmbeddings, WordsFormatError> {
        let length_error = |expected: u64| WordsFormatError::Length {
            expected,
            found: bytes.len() as u64,
        };
        if bytes.len() < 16 {
            return Err(length_error(16));
        }
        if bytes[0..4] != Self::MAGIC {
            return Err(WordsFormatError::BadMagic);
        }
        let word = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().unwrap());
        // u64 so that a corrupt header cannot overflow the size computations.
        let (rows, cols) = (word(8) as u64, word(12) as u64);
        match word(4) {
            1 => Self::from_rows(bytes, rows, cols),
            2 => {
                if bytes.len() < 20 {
                    return Err(length_error(20));
                }
                let bits = match word(16) {
                    4 => Bits::Four,
                    8 => Bits::Eight,
                    other => return Err(WordsFormatError::Bits(other)),
                };
                let len = rows * cols;
                let scales_end = 20 + 2 * len.div_ceil(bits.block() as u64);
                let expected = scales_end + bits.packed_len(len as usize) as u64;
                if bytes.len() as u64 != expected {
                    return Err(length_error(expected));
                }
                let scales = bytes[20..scales_end as usize]
                    .chunks_exact(2)
                    .map(|b| f16::from_le_bytes([b[0], b[1]]))
                    .collect();
                let packed = bytes[scales_end as usize..].to_vec();
                let blocks = Blocks::from_parts(bits, len as usize, scales, packed)
                    .map_err(|_| WordsFormatError::BadScale)?;
                Ok(WordEmbeddings {
                    rows: rows as usize,
                    cols: cols as usize,
                    blocks,
                })
            }
            version => Err(WordsFormatError::Version(version)),
        }
    }

    /// Version 1 (per-row int8), re-quantized to 8-bit blocks.
    fn from_rows(bytes: &[u8], rows: u64, cols: u64) -> Result<WordEmbeddings, WordsFormatError> {
        let expected = 16 + 4 * rows + rows * cols;
        if bytes.len() as u64 != expected {
            return Err(WordsFormatError::Length {
                expected,
                found: bytes.len() as u64,
            });
        }
        let (rows, cols) = (rows as usize, cols as usize);
        let scales_end = 16 + 4 * rows;
        let scales: Vec<f32> = bytes[16..scales_end]
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
            .collect();
        if scales.iter().any(|s| !s.is_finite() || *s < 0.0) {
            return Err(WordsFormatError::BadScale);
        }
        let table: Vec<f32> = bytes[scales_end..]
            .chunks_exact(cols.max(1))
            .zip(&scales)
            .flat_map(|(row, s)| row.iter().map(move |&q| q as i8 as f32 * s))
            .collect();
        Ok(Self::quantize(&table, rows, cols, Bits::Eight))
    }

    /// The file format above.
    pub fn to_bytes(&self) -> Vec<u8> {
        let bits: u32 = match self.blocks.bits() {
            Bits::Four => 4,
            Bits::Eight => 8,
        };
        let mut out =
            Vec::with_capacity(20 + 2 * self.blocks.scales().len() + self.blocks.packed().len());
        out.extend_from_slice(&Self::MAGIC);
        for word in [Self::VERSION, self.rows as u32, self.cols as u32, bits] {
            out.extend_from_slice(&word.to_le_bytes());
        }
        for s in self.blocks.scales() {
            out.extend_from_slice(&s.to_le_bytes());
        }
        out.extend_from_slice(self.blocks.packed());
        out
    }

    /// The table at `bits` (from its present values).
    pub fn requantized(&self, bits: Bits) -> WordEmbeddings {
        Self::quantize(&self.blocks.dequantize(), self.rows, self.cols, bits)
    }

    /// Number of rows (vocabulary size).
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Width of each row.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// The dequantised rows of `ids`, concatenated (`ids.len() × cols` values).
    ///
    /// # Panics
    /// If an id is not below [`Self::rows`].
    pub fn lookup(&self, ids: &[u32]) -> Vec<f32> {
        let mut out = Vec::with_capacity(ids.len() * self.cols);
        for &id in ids {
            let id = id as usize;
            assert!(id < self.rows, "token id {id} outside the word table");
            out.extend(self.blocks.values(id * self.cols, self.cols));
        }
        out
    }
}

// By hand: the derived form would print millions of table entries.
impl std::fmt::Debug for WordEmbeddings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WordEmbeddings")
            .field("rows", &self.rows)
            .field("cols", &self.cols)
            .finish_non_exhaustive()
    }
}

/// all-MiniLM-L6-v2 end to end: tokenizer, quantized word table and burn encoder on one device.
pub struct SentenceEncoder {
    tokenizer: Tokenizer,
    words: WordEmbeddings,
    model: MiniLm,
    device: Device,
    /// Embeddings of single sentences already encoded, by text: a run conditions and scores
    /// the same few sentences again and again (a segment's base for each of its edits, review
    /// rounds and transitions, its text for each score), and each encoding is a pass of the
    /// encoder. A sentence alone always encodes to the same bits (no padding), so the stored
    /// one is the one a new pass would give.
    single: Mutex<HashMap<String, [f32; EMBEDDING_DIM]>>,
}

/// Most sentences [`SentenceEncoder`] keeps: far more than one run says, few enough that a
/// page left open for hours holds a bounded table (384 floats a sentence).
const KEPT_SENTENCES: usize = 4096;

// By hand: the derived form would print the whole vocabulary.
impl std::fmt::Debug for SentenceEncoder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SentenceEncoder")
            .field("vocab_size", &self.tokenizer.vocab_size())
            .field("words", &self.words)
            .field("device", &self.device)
            .finish_non_exhaustive()
    }
}

impl SentenceEncoder {
    /// Builds the encoder from the contents of its three files (no file system access, so it
    /// works in the browser): `vocab` is `minilm-vocab.txt`, `words` `minilm-words.i8`,
    /// `model` `minilm-encoder.bpk`.
    pub fn from_bytes(
        vocab: &str,
        words: &[u8],
        model: &[u8],
        device: &Device,
    ) -> Result<SentenceEncoder, MiniLmError> {
        let tokenizer = Tokenizer::from_vocab(vocab)?;
        let words = WordEmbeddings::from_bytes(words)?;
        if words.rows() != tokenizer.vocab_size() || words.cols() != EMBEDDING_DIM {
            return Err(MiniLmError::Mismatch(format!(
                "vocabulary of {} tokens, word table of {} × {} (expected {} × {EMBEDDING_DIM})",
                tokenizer.vocab_size(),
                words.rows(),
                words.cols(),
                tokenizer.vocab_size()
            )));
        }
        let model = MiniLm::from_bytes(model, device)?;
        Ok(SentenceEncoder {
            tokenizer,
            words,
            model,
            device: device.clone(),
            single: Mutex::new(HashMap::new()),
        })
    }

    /// Reads [`VOCAB_FILE`], [`WORDS_FILE`] and [`MODEL_FILE`] from `dir` (e.g.
    /// `static/models`) and calls [`Self::from_bytes`].
    pub fn from_dir(dir: &Path, device: &Device) -> Result<SentenceEncoder, MiniLmError> {
        let read = |name: &str| {
            let path = dir.join(name);
            std::fs::read(&path).map_err(|source| MiniLmError::Io { path, source })
        };
        let vocab = read(VOCAB_FILE)?;
        let vocab = String::from_utf8(vocab).map_err(|e| MiniLmError::Io {
            path: dir.join(VOCAB_FILE),
            source: std::io::Error::new(std::io::ErrorKind::InvalidData, e),
        })?;
        Self::from_bytes(&vocab, &read(WORDS_FILE)?, &read(MODEL_FILE)?, device)
    }

    /// The tokenizer, e.g. to show how a prompt was split.
    pub fn tokenizer(&self) -> &Tokenizer {
        &self.tokenizer
    }

    /// The device the encoder runs on.
    pub fn device(&self) -> &Device {
        &self.device
    }

    /// Token states `[B, L, 384]` of `texts`, padded to the longest (`L` counts `[CLS]` and
    /// `[SEP]`), and the padding mask `[B, L]`, true at padded positions, whose states are
    /// meaningless.
    ///
    /// # Panics
    /// If `texts` is empty.
    pub fn encode_tokens(&self, texts: &[&str]) -> (Tensor<3>, Tensor<2, Bool>) {
        assert!(!texts.is_empty(), "encode_tokens needs at least one text");
        let ids: Vec<Vec<u32>> = texts.iter().map(|t| self.tokenizer.encode(t)).collect();
        let len = ids.iter().map(Vec::len).max().unwrap_or(0);
        let mut flat = Vec::with_capacity(texts.len() * len);
        let mut padding = Vec::with_capacity(texts.len() * len);
        for row in &ids {
            flat.extend_from_slice(row);
            flat.resize(flat.len() + len - row.len(), self.tokenizer.pad);
            padding.extend((0..len).map(|i| i >= row.len()));
        }
        let words = Tensor::<3>::from_data(
            TensorData::new(self.words.lookup(&flat), [texts.len(), len, EMBEDDING_DIM]),
            &self.device,
        );
        let padding = Tensor::<2, Bool>::from_data(
            TensorData::new(padding, [texts.len(), len]),
            &self.device,
        );
        (self.model.forward(words, padding.clone()), padding)
    }

    /// One L2-normalised sentence embedding per text: the mean of its token states over real
    /// tokens (`[CLS]` and `[SEP]` included, padding excluded), as sentence-transformers. A
    /// single sentence met before is answered from memory.
    pub fn encode(&self, texts: &[&str]) -> Vec<[f32; EMBEDDING_DIM]> {
        if let [text] = texts {
            // A poisoned lock only means a panic elsewhere mid-insert; the table is still
            // whole entries.
            let known = self.single.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(embedding) = known.get(*text) {
                return vec![*embedding];
            }
            drop(known);
            let embedding = self.encode_anew(texts)[0];
            let mut known = self.single.lock().unwrap_or_else(|e| e.into_inner());
            if known.len() >= KEPT_SENTENCES {
                known.clear();
            }
            known.insert(text.to_string(), embedding);
            return vec![embedding];
        }
        self.encode_anew(texts)
    }

    /// [`SentenceEncoder::encode`] with a pass of the encoder even for a sentence met before:
    /// what timing the encoder measures.
    pub fn encode_anew(&self, texts: &[&str]) -> Vec<[f32; EMBEDDING_DIM]> {
        if texts.is_empty() {
            return Vec::new();
        }
        let (states, padding) = self.encode_tokens(texts);
        let keep = padding.bool_not().float().unsqueeze_dim::<3>(2);
        let counts = keep.clone().sum_dim(1);
        let mean = (states * keep).sum_dim(1) / counts;
        let norm = mean
            .clone()
            .powi_scalar(2)
            .sum_dim(2)
            .sqrt()
            .clamp_min(1e-12);
        let pooled: Vec<f32> = (mean / norm)
            .try_into_vec_as::<f32>()
            .expect("a float tensor reads back as f32");
        pooled
            .chunks_exact(EMBEDDING_DIM)
            .map(|c| c.try_into().unwrap())
            .collect()
    }
}

/// What [`convert_minilm`] wrote.
#[derive(Clone, Debug)]
pub struct ConvertReport {
    /// The quantized word-embedding table.
    pub words_path: PathBuf,
    /// Its size in bytes.
    pub words_bytes: u64,
    /// The burnpack of the rest.
    pub model_path: PathBuf,
    /// Its size in bytes.
    pub model_bytes: u64,
    /// Largest absolute error of a dequantised word-embedding value.
    pub words_max_error: f32,
    /// Largest absolute error of an encoder parameter as loaded back from the burnpack (int8
    /// Linear weights, f16 rest).
    pub model_max_error: f32,
}

/// The original checkpoint as one module, so that a single safetensors load fills both the
/// word table and the encoder.
#[derive(Module, Debug)]
struct Checkpoint {
    words: Embedding,
    encoder: MiniLm,
}

/// HF BERT key → path in [`Checkpoint`]. Patterns run in order on the already-renamed key;
/// each one's prefix (`embeddings.`, `encoder.layer.`) no longer matches once renamed.
const KEY_MAP: [(&str, &str); 9] = [
    (r"^embeddings\.word_embeddings\.", "words."),
    (
        r"^embeddings\.LayerNorm\.",
        "encoder.embeddings.layer_norm.",
    ),
    (
        r"^embeddings\.(position|token_type)_embeddings\.",
        "encoder.embeddings.$1.",
    ),
    (
        r"^encoder\.layer\.(\d+)\.attention\.self\.(query|key|value)\.",
        "encoder.layers.$1.attention.$2.",
    ),
    (
        r"^encoder\.layer\.(\d+)\.attention\.output\.dense\.",
        "encoder.layers.$1.attention.output.",
    ),
    (
        r"^encoder\.layer\.(\d+)\.attention\.output\.LayerNorm\.",
        "encoder.layers.$1.attention_norm.",
    ),
    (
        r"^encoder\.layer\.(\d+)\.intermediate\.dense\.",
        "encoder.layers.$1.intermediate.",
    ),
    (
        r"^encoder\.layer\.(\d+)\.output\.dense\.",
        "encoder.layers.$1.output.",
    ),
    (
        r"^encoder\.layer\.(\d+)\.output\.LayerNorm\.",
        "encoder.layers.$1.output_norm.",
    ),
];

/// Converts the original all-MiniLM-L6-v2 checkpoint (`model_dir` holds HF's
/// `model.safetensors` and `config.json`) into [`WORDS_FILE`] and [`MODEL_FILE`] in `out_dir`.
/// The vocabulary is not touched: `minilm-vocab.txt` is HF's `vocab.txt` as is.
pub fn convert_minilm(
    model_dir: &Path,
    out_dir: &Path,
    word_bits: Bits,
    encoder_bits: Bits,
) -> anyhow::Result<ConvertReport> {
    use anyhow::Context;
    let config = MiniLmConfig::new();
    check_hf_config(&model_dir.join("config.json"), &config)?;

    // The conversion is a one-off on the CPU, whatever the page later runs on.
    let device = Device::flex();
    let mut checkpoint = Checkpoint {
        words: EmbeddingConfig::new(config.vocab_size, config.hidden).init(&device),
        encoder: config.init(&device),
    };
    let remapper = KEY_MAP
        .iter()
        .try_fold(KeyRemapper::new(), |r, (from, to)| r.add_pattern(from, *to))
        .map_err(|e| anyhow::anyhow!("bad key pattern: {e}"))?;
    let weights = model_dir.join("model.safetensors");
    // PyTorchToBurnAdapter transposes Linear weights ([out, in] → [in, out]) and renames
    // LayerNorm weight/bias to gamma/beta; unused keys (position_ids, pooler) are ignored,
    // missing ones are an error.
    let mut store = SafetensorsStore::from_file(&weights)
        .remap(remapper)
        .with_from_adapter(PyTorchToBurnAdapter);
    let result = checkpoint
        .load_from(&mut store)
        .map_err(|e| anyhow::anyhow!("{}: {e}", weights.display()))?;
    anyhow::ensure!(
        result.errors.is_empty() && result.missing.is_empty(),
        "{}: {result}",
        weights.display()
    );

    let table: Vec<f32> = checkpoint
        .words
        .weight
        .val()
        .try_into_vec_as::<f32>()
        .map_err(|e| anyhow::anyhow!("reading the word table: {e:?}"))?;
    let words = WordEmbeddings::quantize(&table, config.vocab_size, config.hidden, word_bits);
    let ids: Vec<u32> = (0..config.vocab_size as u32).collect();
    let words_max_error = words
        .lookup(&ids)
        .iter()
        .zip(&table)
        .fold(0f32, |m, (a, b)| m.max((a - b).abs()));

    std::fs::create_dir_all(out_dir).with_context(|| out_dir.display().to_string())?;
    let words_path = out_dir.join(WORDS_FILE);
    let words_bytes = words.to_bytes();
    std::fs::write(&words_path, &words_bytes).with_context(|| words_path.display().to_string())?;
    let model_path = out_dir.join(MODEL_FILE);
    let model_bytes = checkpoint.encoder.to_bytes(encoder_bits)?;
    let model_max_error = max_difference(
        &checkpoint.encoder,
        &MiniLm::from_bytes(&model_bytes, &device)?,
    )?;
    std::fs::write(&model_path, &model_bytes).with_context(|| model_path.display().to_string())?;
    Ok(ConvertReport {
        words_path,
        words_bytes: words_bytes.len() as u64,
        model_path,
        model_bytes: model_bytes.len() as u64,
        words_max_error,
        model_max_error,
    })
}

/// Largest absolute difference between the parameters of two encoders.
fn max_difference(a: &MiniLm, b: &MiniLm) -> anyhow::Result<f32> {
    let mut max = 0f32;
    for (x, y) in a
        .collect(None, None, false)
        .iter()
        .zip(b.collect(None, None, false).iter())
    {
        anyhow::ensure!(x.name == y.name, "{} vs {}", x.name, y.name);
        let values = |t: &PackTensor| -> anyhow::Result<Vec<f32>> {
            bridge::to_data(t)
                .map_err(|e| anyhow::anyhow!("{e}"))?
                .try_into_vec_as::<f32>()
                .map_err(|e| anyhow::anyhow!("{e:?}"))
        };
        for (p, q) in values(x)?.iter().zip(&values(y)?) {
            max = max.max((p - q).abs());
        }
    }
    Ok(max)
}

/// Refuses a checkpoint whose HF `config.json` describes another shape than `config`.
fn check_hf_config(path: &Path, config: &MiniLmConfig) -> anyhow::Result<()> {
    let text =
        std::fs::read_to_string(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let hf: serde_json::Value = serde_json::from_str(&text)?;
    anyhow::ensure!(
        hf["hidden_act"] == "gelu",
        "{}: hidden_act is {}, expected \"gelu\" (erf)",
        path.display(),
        hf["hidden_act"]
    );
    let expected = [
        ("vocab_size", config.vocab_size as f64),
        ("hidden_size", config.hidden as f64),
        ("num_hidden_layers", config.layers as f64),
        ("num_attention_heads", config.heads as f64),
        ("intermediate_size", config.intermediate as f64),
        ("max_position_embeddings", config.max_positions as f64),
        ("type_vocab_size", config.type_vocab as f64),
        ("layer_norm_eps", config.layer_norm_eps),
    ];
    for (key, value) in expected {
        let found = hf[key].as_f64();
        anyhow::ensure!(
            found == Some(value),
            "{}: {key} is {:?}, expected {value}",
            path.display(),
            found
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::store::burn_pack::Writer as PackWriter;

    #[test]
    fn bad_scales_are_errors() {
        let q = TensorData::new(vec![1i8, -2, 3, 4], [2, 2]);
        assert!(dequantize_columns(&q, &TensorData::new(vec![1f32, f32::NAN], [2])).is_err());
        assert!(dequantize_columns(&q, &TensorData::new(vec![1f32, -1.0], [2])).is_err());
        assert!(dequantize_columns(&q, &TensorData::new(vec![1f32, 1.0, 1.0], [3])).is_err());
        assert!(dequantize_columns(&q, &TensorData::new(vec![1f64, 1.0], [2])).is_err());
        let vector = TensorData::new(vec![1i8, 2], [2]);
        assert!(dequantize_columns(&vector, &TensorData::new(vec![1f32, 1.0], [2])).is_err());
        assert_eq!(
            dequantize_columns(&q, &TensorData::new(vec![0.5f32, 2.0], [2])).unwrap(),
            [0.5, -4.0, 1.5, 8.0]
        );
    }

    /// A burnpack of the given tensors with or without the tag of the columns format.
    fn pack(tensors: Vec<(&str, TensorData)>, tagged: bool) -> Vec<u8> {
        let tensors = tensors
            .into_iter()
            .map(|(n, d)| bridge::from_data(d, n.to_string(), None))
            .collect();
        let mut writer = PackWriter::new(tensors);
        if tagged {
            writer = writer.with_metadata("format", MiniLm::FORMAT_COLUMNS);
        }
        writer.into_bytes().unwrap().to_vec()
    }

    #[test]
    fn malformed_encoder_files_are_errors() {
        let device = Device::flex();
        let bias = || TensorData::new(vec![0f32; 384], [384]);
        let weight = || TensorData::new(vec![1i8; 4], [2, 2]);
        let scale = || TensorData::new(vec![1f32; 2], [2]);
        let cases = [
            (
                "untagged (the old minilm.bpk)",
                pack(vec![("layers.0.output.bias", bias())], false),
            ),
            (
                "int8 without scales",
                pack(vec![("layers.0.output.weight", weight())], true),
            ),
            (
                "scales without int8",
                pack(vec![("layers.0.output.weight_scale", scale())], true),
            ),
            (
                "int8 of the wrong shape",
                pack(
                    vec![
                        ("layers.0.output.weight", weight()),
                        ("layers.0.output.weight_scale", scale()),
                    ],
                    true,
                ),
            ),
            (
                "most tensors missing",
                pack(vec![("layers.0.output.bias", bias())], true),
            ),
        ];
        for (what, bytes) in cases {
            let r = MiniLm::from_bytes(&bytes, &device);
            assert!(
                matches!(r, Err(MiniLmError::Model(_))),
                "{what}: {:?}",
                r.map(|_| ())
            );
        }
    }
}
