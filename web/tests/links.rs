//! The share-link decoder compiled to wasm and run in headless Chromium: broken links give a
//! message, never a panic, and a real link survives the trip (run by scripts/test.sh with
//! wasm-bindgen-test-runner, as `wasm-pack test --headless --chrome` would).
#![cfg(target_arch = "wasm32")]

use coma::model::tokens::MotionTokens;
use coma::share::{decode, encode, Edit, EditKind, LinkPlan, LinkSegment, RunRecord, SharedMotion};
use wasm_bindgen_test::*;

wasm_bindgen_test_configure!(run_in_browser);

fn sample() -> SharedMotion {
    SharedMotion {
        model_id: *b"\x01\x23\x45\x67\x89\xab\xcd\xef",
        seed: 42,
        prompt: "a person walks forward, then bows".into(),
        plan: LinkPlan::Segments(vec![LinkSegment {
            text: "a person walks forward".into(),
            from: 0,
            to: 80,
        }]),
        record: Some(RunRecord {
            steps: vec!["segment 1: generated".into()],
            ..Default::default()
        }),
        history: vec![Edit {
            kind: EditKind::Generate,
            text: "a person walks forward".into(),
            from_frame: 0,
            to_frame: 80,
            parts: 0,
            seed: 42,
        }],
        tokens: MotionTokens::new(
            (0..4)
                .map(|p| {
                    (0..4)
                        .map(|l| (0..20).map(|s| (p * 97 + l * 13 + s) % 512).collect())
                        .collect()
                })
                .collect(),
        )
        .unwrap(),
        notes: Vec::new(),
    }
}

#[wasm_bindgen_test]
fn a_link_survives_the_round_trip_in_the_browser() {
    let motion = sample();
    let link = encode(&motion);
    assert_eq!(decode(&link).unwrap(), motion);
    assert_eq!(
        decode(&format!("https://example.com/#{link}")).unwrap(),
        motion
    );
}

#[wasm_bindgen_test]
fn every_broken_link_of_the_corpus_gives_a_message() {
    let corpus = include_str!("fixtures_broken_links.txt");
    let good = encode(&sample());
    let mut links: Vec<String> = corpus
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with("# ") && *l != "#")
        .map(String::from)
        .collect();
    // Every cut of a real link, and single-character substitutions along it.
    for end in 0..good.len() {
        links.push(good[..end].to_string());
    }
    let bytes = good.as_bytes();
    for (i, replacement) in (0..bytes.len()).zip("AZaz09-_!".chars().cycle()) {
        let mut s = bytes.to_vec();
        s[i] = replacement as u8;
        links.push(String::from_utf8_lossy(&s).into_owned());
    }
    let mut refused = 0;
    for link in &links {
        match decode(link) {
            Err(e) => {
                let message = e.to_string();
                assert!(
                    !message.is_empty() && message.len() < 300,
                    "{link:?}: {message}"
                );
                refused += 1;
            }
            // A substitution can land in a spot that still decodes (a token value, a letter of
            // the prompt); then what comes out must still be a well-formed motion.
            Ok(m) => assert!(m.tokens.len() <= 8 && m.prompt.len() <= 4096, "{link:?}"),
        }
    }
    assert!(
        links.len() > 100 && refused > links.len() / 2,
        "{refused} of {}",
        links.len()
    );
}
