//! The committed default model in `static/models`: it loads, names itself by the hash of its
//! files, gives the asked length, repeats itself for a seed, and walks when asked to.

use coma::executor::block_on;
use coma::model::MotionModel;
use std::path::PathBuf;

fn default_model() -> MotionModel {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../static/models");
    MotionModel::load(&dir, &burn::tensor::Device::flex())
        .unwrap_or_else(|e| panic!("the committed default model does not load: {e}"))
}

#[test]
fn the_default_model_loads_and_is_named_by_its_files() {
    let model = default_model();
    assert_eq!(model.id.len(), 16);
    assert!(model.id.chars().all(|c| c.is_ascii_hexdigit()));
    assert_eq!(model.id, default_model().id, "the id is a hash, not a draw");
}

#[test]
fn generated_length_and_seed_hold() {
    block_on(async {
        let model = default_model();
        for frames in [40, 100, 196] {
            let tokens = model
                .generate("a person walks forward", &[], frames, 7)
                .await;
            let joints = model.joints(&tokens).await;
            assert!(
                joints.len().abs_diff(frames) <= 4,
                "asked {frames} frames, got {}",
                joints.len()
            );
            assert!(joints.iter().flatten().flatten().all(|v| v.is_finite()));
        }
        let a = model.generate("a person bows", &[], 80, 11).await;
        assert_eq!(a, model.generate("a person bows", &[], 80, 11).await);
        assert_ne!(a, model.generate("a person bows", &[], 80, 12).await);
    })
}

#[test]
fn asked_to_walk_forward_it_covers_ground() {
    block_on(async {
        let model = default_model();
        // Random weights stand nearly still or drift; a person walking for 6 s covers metres.
        let mut distances = Vec::new();
        for seed in 0..4 {
            let joints = model
                .joints(
                    &model
                        .generate("a person walks forward", &[], 120, seed)
                        .await,
                )
                .await;
            let (first, last) = (joints[0][0], joints[joints.len() - 1][0]);
            distances.push(((last[0] - first[0]).powi(2) + (last[2] - first[2]).powi(2)).sqrt());
        }
        let mean = distances.iter().sum::<f64>() / distances.len() as f64;
        assert!(mean > 2.0, "root travelled {distances:?} m in 6 s");
    })
}
