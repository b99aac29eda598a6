use super::*;
use crate::rng::Rng;

fn sample(steps: usize) -> SharedMotion {
    let mut rng = Rng::new(11);
    SharedMotion {
        model_id: model_id_bytes("0123456789abcdef").unwrap(),
        seed: 42,
        prompt: "a person walks forward waving the left hand, then bows — «politely»".into(),
        plan: LinkPlan::Segments(vec![LinkSegment {
            text: "walk forward".into(),
            from: 0,
            to: steps.min(2) * 4,
        }]),
        record: Some(RunRecord {
            steps: vec!["segment 1: generated".into()],
            scores: vec![SegmentScores {
                before: Some(31.5),
                ..Default::default()
            }],
            notes: Vec::new(),
        }),
        history: vec![
            Edit {
                kind: EditKind::Generate,
                text: "a person walks forward".into(),
                from_frame: 0,
                to_frame: 0,
                parts: 0,
                seed: 42,
            },
            Edit {
                kind: EditKind::BodyParts,
                text: "waves the left hand".into(),
                from_frame: 0,
                to_frame: 80,
                parts: 0b0001,
                seed: u64::MAX,
            },
        ],
        tokens: MotionTokens::new(
            (0..4)
                .map(|_| {
                    (0..4)
                        .map(|_| (0..steps).map(|_| rng.below(512) as u32).collect())
                        .collect()
                })
                .collect(),
        )
        .unwrap(),
        notes: Vec::new(),
    }
}

/// [`sample`] with body-part clips laid as layers: the base codes of the left arm over steps
/// 5..15 and of the right leg from step `steps − 9` to the end.
fn layered(steps: usize) -> SharedMotion {
    let mut motion = sample(steps);
    let patch = |part, start, len: usize| BasePatch {
        part,
        start,
        codes: (0..4)
            .map(|l| (0..len).map(|s| ((l * 37 + s * 11) % 512) as u32).collect())
            .collect(),
    };
    motion.tokens = motion
        .tokens
        .with_base(vec![patch(0, 5, 10), patch(3, steps - 9, 9)])
        .unwrap();
    motion
}

#[test]
fn a_motion_survives_the_round_trip_in_any_form_of_link() {
    let motion = sample(49);
    let fragment = encode(&motion);
    assert!(fragment.starts_with("m="));
    assert!(fragment
        .bytes()
        .all(|b| b.is_ascii_alphanumeric() || b"-_=".contains(&b)));
    assert_eq!(decode(&fragment).unwrap(), motion);
    assert_eq!(decode(&format!("#{fragment}")).unwrap(), motion);
    let url = format!("http://127.0.0.1:8080/index.html#{fragment}");
    assert_eq!(decode(&url).unwrap(), motion);
    assert_eq!(decode(&format!("#x=1&{fragment}")).unwrap(), motion);
}

#[test]
fn the_base_under_the_clips_survives_the_round_trip() {
    let motion = layered(49);
    assert_eq!(motion.tokens.base_patches().len(), 2);
    let back = decode(&encode(&motion)).unwrap();
    assert_eq!(back, motion);
    assert_eq!(back.tokens.base(), motion.tokens.base());
    // The patches cost their codes, 9 bits each, and a few bytes apiece.
    let plain = payload(&sample(49)).len();
    let codes = (4 * 10 * 9usize).div_ceil(8) + (4 * 9 * 9usize).div_ceil(8);
    assert!(
        payload(&motion).len() <= plain + codes + 8,
        "{}",
        payload(&motion).len()
    );
}

#[test]
fn a_truncated_or_oversized_list_of_base_patches_is_refused() {
    let good = payload(&layered(20));
    assert!(parse_payload(&good).is_ok());
    // Cut anywhere in the patches: the link ends too early.
    let plain = payload(&sample(20)).len();
    for cut in plain..good.len() {
        assert_eq!(
            parse_payload(&good[..cut]),
            Err(LinkError::Truncated),
            "cut at {cut}"
        );
    }
    // More patches than the motion has steps of parts.
    let mut many = payload(&sample(20));
    many.pop();
    many.extend_from_slice(&[81, 0, 0, 1, 0, 0, 0, 0, 0]);
    let e = parse_payload(&many).unwrap_err();
    assert!(e.to_string().contains("base patches is 81"), "{e}");
    // One patch past the motion's end, one on a fifth part, two overlapping.
    let patch = |part: u8, start: u8, len: u8| {
        let mut p = vec![part, start, len];
        p.extend(std::iter::repeat_n(0, (4 * len as usize * 9).div_ceil(8)));
        p
    };
    for (patches, why) in [
        (vec![patch(0, 18, 3)], "length"),
        (vec![patch(0, 20, 1)], "first step"),
        (vec![patch(0, 3, 0)], "at least one step"),
        (vec![patch(4, 0, 1)], "body part 4"),
        (vec![patch(1, 0, 3), patch(1, 2, 2)], "overlap"),
    ] {
        let mut p = payload(&sample(20));
        p.pop();
        p.push(patches.len() as u8);
        p.extend(patches.concat());
        let e = parse_payload(&p).unwrap_err();
        assert!(matches!(e, LinkError::Invalid(_)), "{e:?}");
        assert!(e.to_string().contains(why), "{e}");
    }
}

#[test]
fn tokens_are_packed_in_nine_bits() {
    let motion = sample(49);
    // 4 parts × 4 layers × 49 steps × 9 bits.
    let tokens_bytes = (4 * 4 * 49 * 9usize).div_ceil(8);
    let p = payload(&motion);
    assert!(p.len() < tokens_bytes + 300, "{} bytes", p.len());
    // A 196-frame motion with its plan fits comfortably in a URL.
    assert!(encode(&motion).len() < 2500, "{}", encode(&motion).len());
}

#[test]
fn oversized_fields_are_cut_so_the_link_still_opens() {
    let mut motion = sample(3);
    motion.prompt = "é".repeat(MAX_TEXT);
    let back = decode(&encode(&motion)).unwrap();
    assert!(back.prompt.len() <= MAX_TEXT && back.prompt.chars().all(|c| c == 'é'));
}

#[test]
fn a_plan_or_record_that_does_not_read_leaves_a_note_and_the_motion_opens_whole() {
    let motion = sample(10);
    let raw = |plan: &str, record: &str| {
        let mut p = payload(&SharedMotion {
            plan: LinkPlan::None,
            record: None,
            ..motion.clone()
        });
        // The plan's and the record's empty lengths sit right after the prompt.
        let at = 3 + 8 + 1 + 1 + motion.prompt.len();
        assert_eq!(&p[at..at + 2], &[0, 0]);
        let mut texts = Vec::new();
        put_text(&mut texts, plan);
        put_text(&mut texts, record);
        p.splice(at..at + 2, texts);
        parse_payload(&p).unwrap()
    };
    let opened = raw(
        r#"{"segments":[{"text":"walk","from":0,"to":4000}]}"#,
        "[1]",
    );
    assert_eq!(opened.tokens, motion.tokens);
    assert_eq!((&opened.plan, &opened.record), (&LinkPlan::None, &None));
    assert_eq!(opened.notes.len(), 2, "{:?}", opened.notes);
    assert!(opened.notes[0].contains("plan does not read"));
    assert!(opened.notes[1].contains("record of its run does not read"));
    // An older link's segments, and a planner's plan, read as such.
    let older = raw(r#"{"segments":[{"text":"walk","from":0,"to":40}]}"#, "");
    assert!(matches!(&older.plan, LinkPlan::Segments(s) if s[0].to == 40));
    let plan = crate::agents::planner::offline::plan("a person walks forward", None);
    let planned = raw(&serde_json::to_string(&plan).unwrap(), "");
    assert_eq!(planned.plan.plan(), Some(&plan));
    assert!(planned.notes.is_empty());
}

#[test]
fn broken_links_give_clear_errors() {
    let good = encode(&sample(10));
    let id = model_id_bytes("0123456789abcdef").unwrap();
    let link = |payload: &[u8]| {
        format!(
            "m={}",
            BASE64.encode(miniz_oxide::deflate::compress_to_vec(payload, 6))
        )
    };
    let mut future = payload(&sample(10));
    future[2] = 4;
    let mut header = b"CM\x01".to_vec();
    header.extend_from_slice(&id);
    let cases: Vec<(String, LinkError)> = vec![
        ("".into(), LinkError::NotALink),
        ("#".into(), LinkError::NotALink),
        ("http://127.0.0.1:8080/".into(), LinkError::NotALink),
        ("#q=abc".into(), LinkError::NotALink),
        (
            "m=".into(),
            LinkError::BadCompression("FailedCannotMakeProgress".into()),
        ),
        ("m=%%%".into(), LinkError::BadEncoding),
        ("m=A".into(), LinkError::BadEncoding),
        (
            format!("m={}", "A".repeat(MAX_LINK_CHARS + 4)),
            LinkError::TooLong,
        ),
        (link(b"XY\x01"), LinkError::BadMagic),
        (link(b""), LinkError::BadMagic),
        (link(&future), LinkError::UnknownVersion(4)),
        (link(&header), LinkError::Truncated),
        (
            good[..good.len() / 2].to_string(),
            LinkError::BadCompression("FailedCannotMakeProgress".into()),
        ),
    ];
    for (input, expected) in cases {
        let got = decode(&input);
        match (&got, &expected) {
            // The exact inflate status of a cut stream is the library's business.
            (Err(LinkError::BadCompression(_)), LinkError::BadCompression(_)) => {}
            (Err(LinkError::BadEncoding), LinkError::BadCompression(_)) => {}
            _ => assert_eq!(got, Err(expected.clone()), "input {input:?}"),
        }
    }
    // Every error reads as a sentence for the page.
    assert!(LinkError::UnknownVersion(4)
        .to_string()
        .contains("newer version"));
}

#[test]
fn links_of_the_second_version_still_open() {
    // Version 2 is version 3 without the base patches: cut the empty list (one zero byte).
    let motion = sample(7);
    let mut v2 = payload(&motion);
    assert_eq!(v2.pop(), Some(0), "no patches is one zero count byte");
    v2[2] = 2;
    let opened = parse_payload(&v2).unwrap();
    assert_eq!(opened, motion);
    assert!(opened.tokens.base_patches().is_empty());
    // A version 2 payload has nothing after its tokens: a patch list there is refused.
    let mut layered_v2 = payload(&layered(20));
    layered_v2[2] = 2;
    assert!(matches!(
        parse_payload(&layered_v2),
        Err(LinkError::Invalid(_))
    ));
}

#[test]
fn links_of_the_first_version_still_open() {
    // Version 1 is version 2 without the record: cut the record out of a version 2 payload.
    let mut motion = sample(7);
    motion.record = None;
    let mut v2 = payload(&motion);
    v2.pop();
    v2[2] = 2;
    let plan = motion.plan.to_json();
    let record_at = 3 + 8 + 1 + (1 + motion.prompt.len()) + (1 + plan.len());
    assert_eq!(v2[record_at], 0, "an empty record is one zero length byte");
    let mut v1 = v2.clone();
    v1.remove(record_at);
    v1[2] = 1;
    assert_eq!(parse_payload(&v1).unwrap(), motion);
}

#[test]
fn payloads_with_impossible_fields_are_refused() {
    let base = payload(&sample(5));
    let parsed = |p: &[u8]| parse_payload(p);
    assert!(parsed(&base).is_ok());
    // Trailing garbage.
    let mut extra = base.clone();
    extra.push(0);
    assert!(matches!(parsed(&extra), Err(LinkError::Invalid(_))));
    // A prompt length of 2^62.
    let mut huge = base[..11].to_vec();
    huge.push(42);
    huge.extend_from_slice(&[0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x3f]);
    assert!(matches!(parsed(&huge), Err(LinkError::Invalid(_))));
    // A varint of more than 64 bits.
    let mut long = base[..11].to_vec();
    long.extend_from_slice(&[0xff; 11]);
    assert!(matches!(parsed(&long), Err(LinkError::Invalid(_))));
}

/// Flips, inserts, deletes and overwrites bytes of `data`.
fn mutate(data: &mut Vec<u8>, rng: &mut Rng) {
    for _ in 0..1 + rng.below(4) {
        let at = if data.is_empty() {
            0
        } else {
            rng.below(data.len())
        };
        match rng.below(5) {
            0 if !data.is_empty() => data[at] ^= 1 << rng.below(8),
            1 => data.insert(at.min(data.len()), rng.below(256) as u8),
            2 if !data.is_empty() => {
                data.remove(at);
            }
            3 if !data.is_empty() => data[at] = [0, 0xff, 0x7f, 0x80, 1][rng.below(5)],
            _ => data.truncate(at),
        }
    }
}

#[test]
fn the_decoder_survives_a_million_random_and_mutated_links() {
    let seeds: Vec<Vec<u8>> = [1usize, 10, 49, 196]
        .iter()
        .map(|&s| payload(&sample(s)))
        .chain([payload(&layered(20))])
        .collect();
    let fragments: Vec<String> = [1usize, 10, 49]
        .iter()
        .map(|&s| encode(&sample(s)))
        .collect();
    let mut rng = Rng::new(2024);
    let mut outcomes = [0usize; 2];
    let alphabet = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_=#&%";
    for i in 0..1_000_000 {
        let result = match i % 4 {
            // Mutated payloads, compressed properly: they reach the parser.
            0 | 1 => {
                let mut p = seeds[rng.below(seeds.len())].clone();
                mutate(&mut p, &mut rng);
                decode(&format!(
                    "m={}",
                    BASE64.encode(miniz_oxide::deflate::compress_to_vec(&p, 1))
                ))
            }
            // Mutated link text.
            2 => {
                let mut f = fragments[rng.below(fragments.len())].clone().into_bytes();
                mutate(&mut f, &mut rng);
                decode(&String::from_utf8_lossy(&f))
            }
            // Random text.
            _ => {
                let n = rng.below(64);
                let text: String = std::iter::once("m=")
                    .map(String::from)
                    .chain(
                        (0..n).map(|_| (alphabet[rng.below(alphabet.len())] as char).to_string()),
                    )
                    .collect();
                decode(&text)
            }
        };
        outcomes[result.is_ok() as usize] += 1;
    }
    // Most inputs are refused, and none panicked on the way.
    assert_eq!(outcomes[0] + outcomes[1], 1_000_000);
    assert!(outcomes[0] > 500_000, "{outcomes:?}");
}
