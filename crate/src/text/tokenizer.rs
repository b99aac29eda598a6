//! The uncased BERT WordPiece tokenizer of all-MiniLM-L6-v2: text → token ids, the input of
//! the sentence encoder that conditions motion generation.
//!
//! Steps, as BERT's: clean the text (drop control characters, map whitespace to spaces), put
//! spaces around CJK ideographs, lower-case and strip accents (NFD, drop combining marks),
//! split on whitespace and punctuation, then split each word greedily into the longest
//! vocabulary pieces (continuations prefixed `##`; a word that cannot be split becomes
//! `[UNK]`). The result is framed as `[CLS] … [SEP]` and capped at [`MAX_TOKENS`].
//!
//! Written by hand because the `tokenizers` crate builds for wasm32 only behind its unstable
//! wasm feature and brings a regex engine and every tokenizer family into the page's
//! download, while this one vocabulary needs only the steps above.

use std::collections::HashMap;
use unicode_normalization::char::is_combining_mark;
use unicode_normalization::UnicodeNormalization;

/// Longest token sequence the encoder sees, `[CLS]` and `[SEP]` included (the sentence
/// encoder's own limit).
pub const MAX_TOKENS: usize = 256;
/// Words longer than this many characters become `[UNK]`.
const MAX_WORD_CHARS: usize = 100;

/// Why a vocabulary could not be loaded.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum VocabError {
    #[error("vocabulary lacks the special token {0}")]
    MissingSpecial(&'static str),
    #[error("vocabulary is empty")]
    Empty,
}

/// A WordPiece vocabulary and the ids of its special tokens.
#[derive(Clone, Debug)]
pub struct Tokenizer {
    ids: HashMap<String, u32>,
    tokens: Vec<String>,
    pub cls: u32,
    pub sep: u32,
    pub unk: u32,
    pub pad: u32,
}

impl Tokenizer {
    /// Builds the tokenizer from `vocab.txt` content: one token per line, the line number is
    /// the id.
    pub fn from_vocab(text: &str) -> Result<Tokenizer, VocabError> {
        let tokens: Vec<String> = text
            .lines()
            .map(|l| l.trim_end_matches('\r').to_string())
            .collect();
        if tokens.is_empty() {
            return Err(VocabError::Empty);
        }
        let ids: HashMap<String, u32> = tokens
            .iter()
            .enumerate()
            .map(|(i, t)| (t.clone(), i as u32))
            .collect();
        let special = |name: &'static str| {
            ids.get(name)
                .copied()
                .ok_or(VocabError::MissingSpecial(name))
        };
        Ok(Tokenizer {
            cls: special("[CLS]")?,
            sep: special("[SEP]")?,
            unk: special("[UNK]")?,
            pad: special("[PAD]")?,
            ids,
            tokens,
        })
    }

    /// Number of tokens in the vocabulary.
    pub fn vocab_size(&self) -> usize {
        self.tokens.len()
    }

    /// The token text of an id.
    pub fn token(&self, id: u32) -> Option<&str> {
        self.tokens.get(id as usize).map(String::as_str)
    }

    /// Token ids of `text`, framed by `[CLS]` and `[SEP]`, at most [`MAX_TOKENS`] long.
    pub fn encode(&self, text: &str) -> Vec<u32> {
        let mut out = vec![self.cls];
        'words: for word in basic_tokens(text) {
            for id in self.word_pieces(&word) {
                if out.len() == MAX_TOKENS - 1 {
                    break 'words;
                }
                out.push(id);
            }
        }
        out.push(self.sep);
        out
    }

    /// Greedy longest-match-first split of one word into vocabulary ids.
    fn word_pieces(&self, word: &str) -> Vec<u32> {
        let chars: Vec<char> = word.chars().collect();
        if chars.len() > MAX_WORD_CHARS {
            return vec![self.unk];
        }
        let mut pieces = Vec::new();
        let mut start = 0;
        while start < chars.len() {
            let mut end = chars.len();
            let mut found = None;
            while start < end {
                let piece: String = chars[start..end].iter().collect();
                let piece = if start > 0 {
                    format!("##{piece}")
                } else {
                    piece
                };
                if let Some(id) = self.ids.get(&piece) {
                    found = Some(*id);
                    break;
                }
                end -= 1;
            }
            match found {
                Some(id) => pieces.push(id),
                None => return vec![self.unk],
            }
            start = end;
        }
        pieces
    }
}

/// BERT's punctuation: ASCII symbols and the Unicode punctuation blocks.
fn is_punctuation(c: char) -> bool {
    c.is_ascii_punctuation()
        || matches!(c as u32,
            0x00A1..=0x00BF | 0x2010..=0x2027 | 0x2030..=0x205E | 0x3001..=0x3003 | 0x3008..=0x3011
            | 0x3014..=0x301F | 0xFF01..=0xFF0F | 0xFF1A..=0xFF20 | 0xFF3B..=0xFF40 | 0xFF5B..=0xFF65)
}

fn is_cjk(c: char) -> bool {
    matches!(c as u32,
        0x4E00..=0x9FFF | 0x3400..=0x4DBF | 0x20000..=0x2A6DF | 0x2A700..=0x2B73F
        | 0x2B740..=0x2B81F | 0x2B820..=0x2CEAF | 0xF900..=0xFAFF | 0x2F800..=0x2FA1F)
}

/// Lower-cased, accent-free words and punctuation marks of `text`.
fn basic_tokens(text: &str) -> Vec<String> {
    let mut cleaned = String::with_capacity(text.len());
    for c in text.chars() {
        if c == '\0' || c == '\u{FFFD}' || (c.is_control() && !c.is_whitespace()) {
            continue;
        }
        if c.is_whitespace() {
            cleaned.push(' ');
        } else if is_cjk(c) {
            cleaned.push(' ');
            cleaned.push(c);
            cleaned.push(' ');
        } else {
            cleaned.push(c);
        }
    }
    let mut out = Vec::new();
    for word in cleaned.split_whitespace() {
        let normal: String = word
            .to_lowercase()
            .nfd()
            .filter(|c| !is_combining_mark(*c))
            .collect();
        let mut current = String::new();
        for c in normal.chars() {
            if is_punctuation(c) {
                if !current.is_empty() {
                    out.push(std::mem::take(&mut current));
                }
                out.push(c.to_string());
            } else {
                current.push(c);
            }
        }
        if !current.is_empty() {
            out.push(current);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tiny() -> Tokenizer {
        let vocab = "[PAD]\n[UNK]\n[CLS]\n[SEP]\na\nperson\nwave\n##s\nthe\nleft\nhand\n,\nthen\nbow\n##ing\ncafe\n";
        Tokenizer::from_vocab(vocab).unwrap()
    }

    #[test]
    fn splits_words_into_pieces_and_frames_them() {
        let t = tiny();
        let ids = t.encode("A person WAVES the left hand, then bowing");
        let tokens: Vec<&str> = ids.iter().map(|i| t.token(*i).unwrap()).collect();
        assert_eq!(
            tokens,
            [
                "[CLS]", "a", "person", "wave", "##s", "the", "left", "hand", ",", "then", "bow",
                "##ing", "[SEP]"
            ]
        );
    }

    #[test]
    fn unknown_words_accents_and_control_characters() {
        let t = tiny();
        let tokens: Vec<&str> = t
            .encode("Café\u{0007} zebra")
            .iter()
            .map(|i| t.token(*i).unwrap())
            .collect();
        assert_eq!(tokens, ["[CLS]", "cafe", "[UNK]", "[SEP]"]);
    }

    #[test]
    fn long_text_is_capped() {
        let t = tiny();
        let ids = t.encode(&"wave ".repeat(1000));
        assert_eq!(ids.len(), MAX_TOKENS);
        assert_eq!(*ids.last().unwrap(), t.sep);
    }

    #[test]
    fn vocabulary_needs_special_tokens() {
        assert_eq!(
            Tokenizer::from_vocab("a\nb\n").unwrap_err(),
            VocabError::MissingSpecial("[CLS]")
        );
    }
}
