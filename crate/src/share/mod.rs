//! Share links: a motion, its prompt, plan and edit history packed into the URL fragment, so
//! that opening the link rebuilds the same motion with no server and no language model.
//!
//! A link's fragment is `m=` + base64url(deflate(payload)), no padding. The payload, version 3:
//!
//! ```text
//!  "CM" 0x02                      magic and version
//!  model id                       8 bytes (the hash of the weights that made the tokens)
//!  seed                           varint
//!  prompt, plan, record           varint length + UTF-8 each (plan and record as JSON, may
//!                                   be empty; read into types by [`record`])
//!  edits                          varint count, then per edit:
//!                                   kind u8, text, from and to frame (varints),
//!                                   body-part mask u8 (bit p = part p), seed varint
//!  tokens                         parts u8, layers u8, steps varint,
//!                                   then parts × layers × steps codes of 9 bits, packed
//!                                   little-endian, part-major, then layer, then step
//!  base patches                   varint count (at most 4 × steps), then per patch: body
//!                                   part u8, first step varint, steps varint (≥ 1, ending
//!                                   within the motion), then layers × steps codes of 9 bits
//!                                   packed as the tokens' are (layer-major, from a fresh
//!                                   byte); patches of one part never overlap
//! ```
//!
//! The base patches are the base (whole-body) motion's codes under the body-part clips, which
//! lie on it as layers (see [`crate::model::tokens`]): the tokens above are the final ones.
//! Version 2 is the same without the base patches (a motion with no clip layers), and version
//! 1 is version 2 without the record; links in both still open.
//!
//! Decoding never panics on any input and caps every size before it allocates, so a hostile
//! link costs at most a few hundred kilobytes and a clear error.

pub mod record;

use crate::model::tokens::{BasePatch, MotionTokens, MAX_LAYERS, MAX_STEPS};
use base64::Engine;
pub use record::{LinkPlan, LinkSegment, RunRecord, SegmentScores};
use serde::{Deserialize, Serialize};

/// base64url without padding (RFC 4648 §5): the alphabet that survives in a URL fragment.
const BASE64: base64::engine::GeneralPurpose = base64::engine::general_purpose::URL_SAFE_NO_PAD;

/// The payload version this code writes.
pub const VERSION: u8 = 3;
/// The first version, without the run record.
const VERSION_1: u8 = 1;
/// The second version, without the base patches.
const VERSION_2: u8 = 2;
const MAGIC: &[u8; 2] = b"CM";
/// Longest fragment accepted, characters.
pub const MAX_LINK_CHARS: usize = 96 * 1024;
/// Largest payload after inflating, bytes.
pub const MAX_PAYLOAD: usize = 512 * 1024;
/// Longest prompt or edit text, bytes.
pub const MAX_TEXT: usize = 4 * 1024;
/// Longest plan, and longest run record, bytes.
pub const MAX_PLAN: usize = 64 * 1024;
/// Most edits in a history.
pub const MAX_EDITS: usize = 256;

/// What a step of the history did. (Serde only for the page's worker messages; links use the
/// byte layout above.)
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum EditKind {
    /// A whole motion from the prompt.
    Generate = 0,
    /// A time range regenerated (all parts).
    InBetween = 1,
    /// Some body parts regenerated.
    BodyParts = 2,
    /// One segment regenerated.
    Regenerate = 3,
    /// Segments joined with generated transitions.
    Blend = 4,
    /// A new root path.
    Trajectory = 5,
}

impl EditKind {
    fn from_byte(b: u8) -> Option<EditKind> {
        Some(match b {
            0 => EditKind::Generate,
            1 => EditKind::InBetween,
            2 => EditKind::BodyParts,
            3 => EditKind::Regenerate,
            4 => EditKind::Blend,
            5 => EditKind::Trajectory,
            _ => return None,
        })
    }
}

/// One step of the edit history.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Edit {
    pub kind: EditKind,
    /// The instruction (or prompt) of the step.
    pub text: String,
    /// Frame range the step touched, at 20 fps (0..0 when it is the whole motion).
    pub from_frame: u32,
    pub to_frame: u32,
    /// Body parts it touched: bit `p` is part `p` in model order (left arm, right arm, left
    /// leg, right leg).
    pub parts: u8,
    pub seed: u64,
}

/// Everything a link carries.
#[derive(Clone, Debug, PartialEq)]
pub struct SharedMotion {
    /// Id of the weights (first 8 bytes of their hash, see `model::model_id`).
    pub model_id: [u8; 8],
    pub seed: u64,
    pub prompt: String,
    /// The plan the motion followed.
    pub plan: LinkPlan,
    /// How the run that made the motion went (its step lines, the review's scores per
    /// segment, its notes), when a run made it.
    pub record: Option<RunRecord>,
    pub history: Vec<Edit>,
    /// Final tokens `[part][layer][step]`, with the base motion's codes under the body-part
    /// clips ([`MotionTokens::base_patches`]).
    pub tokens: MotionTokens,
    /// What the decoder could not read and dropped (a plan or record that does not read), for
    /// the user; never written into a link.
    pub notes: Vec<String>,
}

/// Why a link could not be opened.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LinkError {
    #[error("this is not a motion link (it has no 'm=' part)")]
    NotALink,
    #[error("the link is longer than {MAX_LINK_CHARS} characters")]
    TooLong,
    #[error("the link is damaged: it is not valid base64url")]
    BadEncoding,
    #[error("the link is damaged: its data does not inflate ({0})")]
    BadCompression(String),
    #[error("the link is not a CoMA motion link")]
    BadMagic,
    #[error("the link was made by a newer version of the page (format {0}); this page reads format {VERSION}")]
    UnknownVersion(u8),
    #[error("the link is damaged: it ends too early")]
    Truncated,
    #[error("the link is damaged: {0}")]
    Invalid(String),
}

/// Hex id ↔ bytes.
pub fn model_id_bytes(hex: &str) -> Option<[u8; 8]> {
    if hex.len() != 16 || !hex.is_ascii() {
        return None;
    }
    let mut out = [0u8; 8];
    for (i, b) in out.iter_mut().enumerate() {
        *b = u8::from_str_radix(&hex[2 * i..2 * i + 2], 16).ok()?;
    }
    Some(out)
}

/// The hex form of a model id.
pub fn model_id_hex(id: &[u8; 8]) -> String {
    id.iter().map(|b| format!("{b:02x}")).collect()
}

fn put_varint(out: &mut Vec<u8>, mut v: u64) {
    loop {
        let byte = (v & 0x7f) as u8;
        v >>= 7;
        if v == 0 {
            out.push(byte);
            return;
        }
        out.push(byte | 0x80);
    }
}

fn put_text(out: &mut Vec<u8>, s: &str) {
    put_varint(out, s.len() as u64);
    out.extend_from_slice(s.as_bytes());
}

/// Encodes a motion as a link fragment (`m=…`, without the `#`). Texts longer than the
/// decoder accepts are cut at a character boundary, so whatever this writes, [`decode`] reads
/// back.
pub fn encode(motion: &SharedMotion) -> String {
    let packed = miniz_oxide::deflate::compress_to_vec(&payload(motion), 9);
    format!("m={}", BASE64.encode(packed))
}

/// The uncompressed payload of a motion.
fn payload(motion: &SharedMotion) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend_from_slice(MAGIC);
    out.push(VERSION);
    out.extend_from_slice(&motion.model_id);
    put_varint(&mut out, motion.seed);
    put_text(&mut out, truncate(&motion.prompt, MAX_TEXT));
    put_text(&mut out, truncate(&motion.plan.to_json(), MAX_PLAN));
    put_text(
        &mut out,
        truncate(&record::record_to_json(&motion.record), MAX_PLAN),
    );
    let edits = &motion.history[..motion.history.len().min(MAX_EDITS)];
    put_varint(&mut out, edits.len() as u64);
    for e in edits {
        out.push(e.kind as u8);
        put_text(&mut out, truncate(&e.text, MAX_TEXT));
        put_varint(&mut out, e.from_frame as u64);
        put_varint(&mut out, e.to_frame as u64);
        out.push(e.parts & 0x0f);
        put_varint(&mut out, e.seed);
    }
    // Checked tokens: 4 parts, 1 to MAX_LAYERS layers, 1 to MAX_STEPS steps, 9-bit codes.
    let tokens = &motion.tokens;
    out.push(tokens.len() as u8);
    out.push(tokens.layers() as u8);
    put_varint(&mut out, tokens.steps() as u64);
    let mut bits = BitWriter::default();
    for code in tokens.iter().flatten().flatten() {
        bits.put(*code);
    }
    out.extend(bits.finish());
    // Checked patches: parts 0..4, within the steps, at most one per step of a part.
    let patches = tokens.base_patches();
    put_varint(&mut out, patches.len() as u64);
    for patch in patches {
        let steps = patch.steps();
        out.push(patch.part as u8);
        put_varint(&mut out, steps.start as u64);
        put_varint(&mut out, steps.len() as u64);
        let mut bits = BitWriter::default();
        for code in patch.codes.iter().flatten() {
            bits.put(*code);
        }
        out.extend(bits.finish());
    }
    out
}

/// The longest prefix of `s` of at most `max` bytes that ends on a character boundary.
fn truncate(s: &str, max: usize) -> &str {
    if s.len() <= max {
        return s;
    }
    let mut end = max;
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    &s[..end]
}

#[derive(Default)]
struct BitWriter {
    bytes: Vec<u8>,
    acc: u32,
    n: u32,
}

impl BitWriter {
    fn put(&mut self, code: u32) {
        self.acc |= code << self.n;
        self.n += 9;
        while self.n >= 8 {
            self.bytes.push(self.acc as u8);
            self.acc >>= 8;
            self.n -= 8;
        }
    }

    fn finish(mut self) -> Vec<u8> {
        if self.n > 0 {
            self.bytes.push(self.acc as u8);
        }
        self.bytes
    }
}

/// A bounds-checked reader over the payload.
struct Reader<'a> {
    data: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn byte(&mut self) -> Result<u8, LinkError> {
        let b = *self.data.get(self.at).ok_or(LinkError::Truncated)?;
        self.at += 1;
        Ok(b)
    }

    fn bytes(&mut self, n: usize) -> Result<&[u8], LinkError> {
        let end = self.at.checked_add(n).ok_or(LinkError::Truncated)?;
        let s = self.data.get(self.at..end).ok_or(LinkError::Truncated)?;
        self.at = end;
        Ok(s)
    }

    fn varint(&mut self) -> Result<u64, LinkError> {
        let mut v = 0u64;
        for shift in (0..64).step_by(7) {
            let b = self.byte()?;
            v |= ((b & 0x7f) as u64)
                .checked_shl(shift)
                .filter(|x| x >> shift == (b & 0x7f) as u64)
                .ok_or_else(|| LinkError::Invalid("a number is too large".into()))?;
            if b & 0x80 == 0 {
                return Ok(v);
            }
        }
        Err(LinkError::Invalid("a number is too large".into()))
    }

    fn bounded(&mut self, max: u64, what: &str) -> Result<usize, LinkError> {
        let v = self.varint()?;
        if v > max {
            return Err(LinkError::Invalid(format!(
                "{what} is {v}, at most {max} allowed"
            )));
        }
        Ok(v as usize)
    }

    /// `count` codes of 9 bits, packed little-endian from the next byte.
    fn codes(&mut self, count: usize) -> Result<Vec<u32>, LinkError> {
        let packed = self.bytes((count * 9).div_ceil(8))?;
        let mut codes = Vec::with_capacity(count);
        let (mut acc, mut n, mut at) = (0u32, 0u32, 0usize);
        while codes.len() < count {
            while n < 9 {
                acc |= (*packed.get(at).ok_or(LinkError::Truncated)? as u32) << n;
                at += 1;
                n += 8;
            }
            codes.push(acc & 0x1ff);
            acc >>= 9;
            n -= 9;
        }
        Ok(codes)
    }

    fn text(&mut self, max: usize, what: &str) -> Result<String, LinkError> {
        let n = self.bounded(max as u64, &format!("the {what}'s length"))?;
        let raw = self.bytes(n)?;
        String::from_utf8(raw.to_vec())
            .map_err(|_| LinkError::Invalid(format!("the {what} is not valid UTF-8")))
    }
}

/// Decodes a link: a whole URL, a fragment (`#m=…`) or the `m=…` part alone.
pub fn decode(link: &str) -> Result<SharedMotion, LinkError> {
    if link.len() > MAX_LINK_CHARS + 4096 {
        return Err(LinkError::TooLong);
    }
    let fragment = link.rsplit_once('#').map_or(link, |(_, f)| f);
    let value = fragment
        .split('&')
        .find_map(|kv| kv.strip_prefix("m="))
        .ok_or(LinkError::NotALink)?;
    if value.len() > MAX_LINK_CHARS {
        return Err(LinkError::TooLong);
    }
    let packed = BASE64.decode(value).map_err(|_| LinkError::BadEncoding)?;
    let payload = miniz_oxide::inflate::decompress_to_vec_with_limit(&packed, MAX_PAYLOAD)
        .map_err(|e| LinkError::BadCompression(format!("{:?}", e.status)))?;
    parse_payload(&payload)
}

/// Reads an inflated payload.
fn parse_payload(payload: &[u8]) -> Result<SharedMotion, LinkError> {
    let mut r = Reader {
        data: payload,
        at: 0,
    };
    if r.bytes(2).map_err(|_| LinkError::BadMagic)? != MAGIC {
        return Err(LinkError::BadMagic);
    }
    let version = r.byte()?;
    if ![VERSION_1, VERSION_2, VERSION].contains(&version) {
        return Err(LinkError::UnknownVersion(version));
    }
    let mut model_id = [0u8; 8];
    model_id.copy_from_slice(r.bytes(8)?);
    let seed = r.varint()?;
    let prompt = r.text(MAX_TEXT, "prompt")?;
    let plan = r.text(MAX_PLAN, "plan")?;
    let record = if version == VERSION_1 {
        String::new()
    } else {
        r.text(MAX_PLAN, "run record")?
    };
    let mut notes = Vec::new();
    let count = r.bounded(MAX_EDITS as u64, "the number of edits")?;
    let mut history = Vec::with_capacity(count);
    for _ in 0..count {
        let kind = EditKind::from_byte(r.byte()?)
            .ok_or_else(|| LinkError::Invalid("an edit of an unknown kind".into()))?;
        let text = r.text(MAX_TEXT, "edit text")?;
        let from_frame = r.bounded(u32::MAX as u64, "an edit's first frame")? as u32;
        let to_frame = r.bounded(u32::MAX as u64, "an edit's last frame")? as u32;
        if to_frame < from_frame {
            return Err(LinkError::Invalid("an edit ends before it starts".into()));
        }
        let parts = r.byte()?;
        if parts > 0x0f {
            return Err(LinkError::Invalid(
                "an edit names an unknown body part".into(),
            ));
        }
        let seed = r.varint()?;
        history.push(Edit {
            kind,
            text,
            from_frame,
            to_frame,
            parts,
            seed,
        });
    }
    let parts = r.byte()? as usize;
    if parts != 4 {
        return Err(LinkError::Invalid(format!(
            "the motion has {parts} body parts, 4 expected"
        )));
    }
    let layers = r.byte()? as usize;
    if layers == 0 || layers > MAX_LAYERS {
        return Err(LinkError::Invalid(format!(
            "the motion has {layers} token layers, 1 to {MAX_LAYERS} allowed"
        )));
    }
    let steps = r.bounded(MAX_STEPS as u64, "the number of time steps")?;
    if steps == 0 {
        return Err(LinkError::Invalid("the motion is empty".into()));
    }
    let codes = r.codes(parts * layers * steps)?;
    let mut patches = Vec::new();
    if version >= VERSION {
        // Patches of one part never overlap and cover a step at least: at most one per step.
        let count = r.bounded((parts * steps) as u64, "the number of base patches")?;
        for _ in 0..count {
            let part = r.byte()? as usize;
            let start = r.bounded(steps as u64 - 1, "a base patch's first step")?;
            let len = r.bounded((steps - start) as u64, "a base patch's length")?;
            let mut codes = r.codes(layers * len)?.into_iter();
            patches.push(BasePatch {
                part,
                start,
                codes: (0..layers)
                    .map(|_| codes.by_ref().take(len).collect())
                    .collect(),
            });
        }
    }
    if r.at != payload.len() {
        return Err(LinkError::Invalid(
            "unexpected data after the motion".into(),
        ));
    }
    let mut it = codes.into_iter();
    let tokens = MotionTokens::new(
        (0..parts)
            .map(|_| {
                (0..layers)
                    .map(|_| it.by_ref().take(steps).collect())
                    .collect()
            })
            .collect(),
    )
    .and_then(|tokens| tokens.with_base(patches))
    .map_err(|e| LinkError::Invalid(e.to_string()))?;
    let plan = LinkPlan::from_json(&plan, tokens.frames()).unwrap_or_else(|e| {
        notes.push(format!(
            "the link's plan does not read ({e}), so the motion shows without its segments' \
             plans and paths"
        ));
        LinkPlan::None
    });
    let record = record::record_from_json(&record).unwrap_or_else(|e| {
        notes.push(format!(
            "the link's record of its run does not read ({e}), so its steps and review \
             scores are not shown"
        ));
        None
    });
    Ok(SharedMotion {
        model_id,
        seed,
        prompt,
        plan,
        record,
        history,
        tokens,
        notes,
    })
}

#[cfg(test)]
mod tests;
