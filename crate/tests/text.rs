//! The tokenizer and sentence encoder against the reference implementation's outputs
//! (`fixtures/minilm_reference.json`, made by `scripts/minilm_fixture.py`).

use coma::text::tokenizer::Tokenizer;
use std::path::Path;

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

fn reference() -> serde_json::Value {
    let text =
        std::fs::read_to_string(root().join("crate/tests/fixtures/minilm_reference.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

#[test]
fn tokenizer_matches_the_reference_ids() {
    let vocab = std::fs::read_to_string(root().join("static/models/minilm-vocab.txt")).unwrap();
    let tokenizer = Tokenizer::from_vocab(&vocab).unwrap();
    assert_eq!(tokenizer.vocab_size(), 30522);
    let fixture = reference();
    let sentences = fixture["sentences"].as_array().unwrap();
    assert!(sentences.len() >= 20);
    for s in sentences {
        let expected: Vec<u32> = s["tokens"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_u64().unwrap() as u32)
            .collect();
        assert_eq!(
            tokenizer.encode(s["text"].as_str().unwrap()),
            expected,
            "{}",
            s["text"]
        );
    }
}
