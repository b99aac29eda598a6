//! Records share links as the page made them before the engine refactor (issue 16): one v2
//! link of a planned run (plan JSON and run record) and one v1 link of the older format
//! (segments-only plan), with the joints each must open to. Run at the commit that recorded
//! `crate/tests/fixtures/links/`, and again whenever the shipped model changes (a link names
//! its model): `cargo run --release -p coma --example record_links` from the repository root.
use coma::agents::llm::{LlmClient, UreqTransport};
use coma::agents::pipeline::{self, RunOptions};
use coma::agents::planner::offline;
use coma::executor::block_on;
use coma::features::features_to_joints;
use coma::model::MotionModel;
use coma::share;
use std::io::Write;

fn main() -> anyhow::Result<()> {
    let dir = std::path::Path::new("static/models");
    let out = std::path::Path::new("crate/tests/fixtures/links");
    std::fs::create_dir_all(out)?;
    let model = MotionModel::load(dir, &burn::tensor::Device::flex())?;
    let prompt = "a person walks forward, then waves the left hand";
    let embed = |s: &str| model.text.encode(&[s])[0].to_vec();
    let plan = offline::plan(prompt, Some(&embed));
    let seed = 3;
    let run = block_on(pipeline::run(
        &model,
        None,
        None::<&LlmClient<UreqTransport>>,
        plan,
        RunOptions { rounds: 0, seed },
        &mut |_| {},
    ));
    let (features, _) = block_on(pipeline::motion_features(&model, &run.plan, &run.tokens));
    let record = serde_json::json!({
        "steps": ["plan: \"a person walks forward, then waves the left hand\""],
        "notes": ["recorded before the engine refactor"],
    })
    .to_string();
    let id = share::model_id_bytes(&model.id).unwrap();
    let plan = serde_json::to_string(&run.plan)?;
    let link2 = link(
        2,
        &id,
        seed,
        prompt,
        &plan,
        Some(&record),
        &run.history,
        &run.tokens,
    );
    // v1: the older page's segments-only plan (serde_json's sorted keys, as its `json!` wrote
    // it), no record; the same tokens.
    let frames = run.tokens[0][0].len() * 4;
    let segments = serde_json::json!({"segments": [{"text": prompt, "from": 0, "to": frames}]});
    let link1 = link(
        1,
        &id,
        seed,
        prompt,
        &segments.to_string(),
        None,
        &run.history,
        &run.tokens,
    );
    let plain = block_on(model.features(&run.tokens));
    for (name, link, features) in [("v2", &link2, &features), ("v1", &link1, &plain)] {
        std::fs::write(out.join(format!("{name}.link")), link)?;
        let joints = features_to_joints(features);
        let mut f = std::fs::File::create(out.join(format!("{name}.joints.csv")))?;
        for pose in &joints {
            let row: Vec<String> = pose.iter().flatten().map(|v| format!("{v:.6}")).collect();
            writeln!(f, "{}", row.join(","))?;
        }
        println!("{name}: {} chars, {} frames", link.len(), joints.len());
    }
    Ok(())
}

/// A link in format `version`, byte by byte as `share`'s module documentation lays it out.
#[allow(clippy::too_many_arguments)]
fn link(
    version: u8,
    id: &[u8; 8],
    seed: u64,
    prompt: &str,
    plan: &str,
    record: Option<&str>,
    history: &[share::Edit],
    tokens: &[Vec<Vec<u32>>],
) -> String {
    use base64::Engine;
    fn varint(out: &mut Vec<u8>, mut v: u64) {
        while v >= 0x80 {
            out.push((v as u8 & 0x7f) | 0x80);
            v >>= 7;
        }
        out.push(v as u8);
    }
    fn text(out: &mut Vec<u8>, s: &str) {
        varint(out, s.len() as u64);
        out.extend_from_slice(s.as_bytes());
    }
    let mut out = b"CM".to_vec();
    out.push(version);
    out.extend_from_slice(id);
    varint(&mut out, seed);
    text(&mut out, prompt);
    text(&mut out, plan);
    if version == 2 {
        text(&mut out, record.unwrap_or(""));
    }
    varint(&mut out, history.len() as u64);
    for e in history {
        out.push(e.kind as u8);
        text(&mut out, &e.text);
        varint(&mut out, e.from_frame as u64);
        varint(&mut out, e.to_frame as u64);
        out.push(e.parts);
        varint(&mut out, e.seed);
    }
    out.push(tokens.len() as u8);
    out.push(tokens[0].len() as u8);
    varint(&mut out, tokens[0][0].len() as u64);
    let (mut acc, mut n) = (0u64, 0u32);
    for code in tokens.iter().flatten().flatten() {
        acc |= (*code as u64) << n;
        n += 9;
        while n >= 8 {
            out.push(acc as u8);
            acc >>= 8;
            n -= 8;
        }
    }
    if n > 0 {
        out.push(acc as u8);
    }
    let packed = miniz_oxide::deflate::compress_to_vec(&out, 9);
    format!(
        "m={}",
        base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(packed)
    )
}
