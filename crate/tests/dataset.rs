//! The dataset builder on a spread of real Bandai-Namco clips.

use coma::dataset::{build, BuildOptions};
use coma::features::{self, Normalizer, FEATURE_DIM};
use coma::npy::NpyArray;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

fn archive() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/bandai-namco-bvh.tar.xz")
}

#[test]
fn small_build_writes_the_humanml3d_layout() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("bandai");
    let archive =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/bandai-namco-bvh.tar.xz");
    let lines = std::sync::Mutex::new(Vec::new());
    let options = BuildOptions {
        bandai: Some(archive),
        out: out.clone(),
        limit: Some(40),
        ..Default::default()
    };
    let summary = build(&options, &|l| lines.lock().unwrap().push(l.to_string())).unwrap();
    assert!(
        lines.lock().unwrap().iter().any(|l| l.contains("ETA")),
        "progress is reported"
    );

    // Every clip gives at least one item and its mirror.
    assert_eq!(summary.source_clips, 40);
    assert!(summary.clips >= 80, "{} items", summary.clips);
    let names: BTreeSet<String> = summary.items.iter().map(|i| i.name.clone()).collect();
    for item in summary.items.iter().filter(|i| !i.mirrored) {
        assert!(
            names.contains(&format!("M{}", item.name)),
            "mirror of {}",
            item.name
        );
    }

    // Files of every item, with consistent shapes.
    for item in &summary.items {
        let f = NpyArray::read(
            out.join("new_joint_vecs")
                .join(format!("{}.npy", item.name)),
        )
        .unwrap();
        assert_eq!(f.shape, vec![item.frames, FEATURE_DIM]);
        assert!(item.frames <= 196 && item.frames >= 20);
        let j = NpyArray::read(out.join("new_joints").join(format!("{}.npy", item.name))).unwrap();
        assert_eq!(j.shape, vec![item.frames, 22, 3]);
        let texts =
            std::fs::read_to_string(out.join("texts").join(format!("{}.txt", item.name))).unwrap();
        assert!(texts.lines().count() >= 3);
        assert!(texts.lines().all(|l| l.split('#').count() == 4), "{texts}");
        let parts =
            std::fs::read_to_string(out.join("part_texts").join(format!("{}.txt", item.name)))
                .unwrap();
        let heads: Vec<&str> = parts
            .lines()
            .map(|l| l.split('#').next().unwrap())
            .collect();
        assert_eq!(heads, ["left arm", "left leg", "right arm", "right leg"]);
    }

    // Splits: disjoint, and every clip in exactly one.
    let mut split_of_clip: BTreeMap<String, String> = BTreeMap::new();
    let mut listed = 0;
    for split in ["train", "val", "test"] {
        let text = std::fs::read_to_string(out.join(format!("{split}.txt"))).unwrap();
        for name in text.lines().filter(|l| !l.is_empty()) {
            listed += 1;
            let item = summary.items.iter().find(|i| i.name == name).unwrap();
            let previous = split_of_clip.insert(item.clip.clone(), split.to_string());
            assert!(
                previous.is_none_or(|p| p == split),
                "{} is in two splits",
                item.clip
            );
        }
    }
    assert_eq!(listed, summary.clips);
    assert!(split_of_clip.values().any(|s| s == "test"));

    // Mirrors swap sides in labels and captions.
    for item in summary
        .items
        .iter()
        .filter(|i| i.mirrored && i.content.contains("left"))
    {
        assert!(
            item.captions.iter().all(|c| !c.contains("right")),
            "{:?}",
            item.captions
        );
    }

    // Statistics and the summary.
    let norm = Normalizer::read(out.join("Mean.npy"), out.join("Std.npy")).unwrap();
    assert!(norm.std.iter().all(|s| *s > 0.0));
    let first = features::features_from_npy(
        &NpyArray::read(
            out.join("new_joint_vecs")
                .join(format!("{}.npy", summary.items[0].name)),
        )
        .unwrap(),
    )
    .unwrap();
    let z = norm.normalize(&first);
    assert!(z.iter().flatten().all(|v| v.is_finite()));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("dataset.json")).unwrap()).unwrap();
    for key in [
        "clips",
        "frames",
        "hours",
        "captions",
        "vocabulary",
        "licence",
    ] {
        assert!(json.get(key).is_some(), "dataset.json has {key}");
    }
    assert_eq!(json["licence"], "CC BY-NC 4.0");
    assert_eq!(json["sources"]["bandai"]["source_clips"], 40);
    assert!(json["vocabulary"]["words"].as_array().unwrap().len() > 20);
    assert!(
        !out.with_extension("partial").exists(),
        "the partial build was moved into place"
    );
}

#[test]
fn full_build_has_enough_clips_and_hours() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("bandai");
    let options = BuildOptions {
        bandai: Some(archive()),
        out: out.clone(),
        limit: None,
        ..Default::default()
    };
    let summary = build(&options, &|_| {}).unwrap();
    assert_eq!(summary.source_clips, 3076);
    assert!(summary.clips >= 5800, "{} clips", summary.clips);
    assert!(summary.hours >= 7.0, "{:.2} hours", summary.hours);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("dataset.json")).unwrap()).unwrap();
    assert_eq!(json["clips"].as_u64().unwrap() as usize, summary.clips);
    let actions = json["vocabulary"]["actions"].as_object().unwrap();
    for action in [
        "walk",
        "bow",
        "wave-left-hand",
        "wave-right-hand",
        "raise-up-left-hand",
        "run",
    ] {
        assert!(actions.contains_key(action), "vocabulary has {action}");
    }
    // Kicks and punches carry the side the motion shows, and mirrors the other.
    for sided in [
        "kick-left-leg",
        "kick-right-leg",
        "punch-left-hand",
        "punch-right-hand",
    ] {
        assert!(
            actions.contains_key(sided),
            "vocabulary has {sided}: {actions:?}"
        );
    }
}

#[test]
fn missing_archive_gives_a_clear_error() {
    let tmp = tempfile::tempdir().unwrap();
    let options = BuildOptions {
        bandai: Some(tmp.path().join("nope.tar.xz")),
        out: tmp.path().join("out"),
        limit: None,
        ..Default::default()
    };
    let err = build(&options, &|_| {}).unwrap_err();
    assert!(format!("{err:#}").contains("nope.tar.xz"), "{err:#}");
    assert!(!tmp.path().join("out").exists());
}

#[test]
fn training_loads_the_split_crops_it_and_resumes_a_run() {
    use burn::prelude::*;
    use coma::dataset::motions::{CropSpec, MotionSet};
    use coma::dataset::Split;
    use coma::model::vq::VqConfig;
    use coma::rng::Rng;
    use coma::train::vq::{train_vq, VqTrainOptions, VqTrainingConfig};

    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("bandai");
    build(
        &BuildOptions {
            bandai: Some(archive()),
            out: out.clone(),
            limit: Some(12),
            ..Default::default()
        },
        &|_| {},
    )
    .unwrap();
    let set = MotionSet::load(&out, Split::Train).unwrap();
    let mut rng = Rng::new(3);
    for _ in 0..10 {
        let crops = set.sample_crops(&mut rng, 8, &CropSpec::plain(64, 4));
        assert_eq!(crops.frames % 4, 0);
        assert!(crops.frames <= 64 && crops.frames >= 20);
        assert_eq!(crops.data.len(), 8 * crops.frames * FEATURE_DIM);
    }

    let model = VqConfig::new()
        .with_encoder_width(8)
        .with_decoder_width(8)
        .with_code_dim(4)
        .with_codebook_size(8)
        .with_layers(2)
        .with_res_blocks(1);
    let config = VqTrainingConfig::new(model)
        .with_batch_size(4)
        .with_max_frames(16)
        .with_steps(3)
        .with_eval_every(3)
        .with_log_every(1);
    let run = tmp.path().join("run");
    let options = VqTrainOptions {
        data: out.clone(),
        run_dir: run.clone(),
        minutes: None,
        init: None,
    };
    let lines = std::sync::Mutex::new(Vec::new());
    let device = Device::flex().autodiff();
    train_vq(&config.clone().with_steps(2), &options, &device, &|l| {
        lines.lock().unwrap().push(l.to_string())
    })
    .unwrap();
    assert!(run.join("checkpoint/model.bpk").exists() && run.join("losses.png").exists());
    train_vq(&config, &options, &device, &|l| {
        lines.lock().unwrap().push(l.to_string())
    })
    .unwrap();
    let lines = lines.into_inner().unwrap();
    assert!(
        lines.iter().any(|l| l.contains("resumed at step 2")),
        "{lines:?}"
    );
    assert!(
        lines
            .iter()
            .any(|l| l.contains("samples/s") && l.contains("ETA")),
        "{lines:?}"
    );
    assert!(
        lines.iter().any(|l| l.contains("empty validation split")),
        "{lines:?}"
    );
    assert!(run.join("vq.bpk").exists());
    let log = std::fs::read_to_string(run.join("log.csv")).unwrap();
    assert_eq!(log.lines().count(), 4, "header and three steps:\n{log}");
}

#[test]
fn every_source_builds_into_one_dataset_split_by_actor() {
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data");
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("all");
    let summary = build(
        &BuildOptions {
            bandai: Some(archive()),
            hdm05: Some(shared.join("hdm05-subset/hdm05-subset-amc.tar.xz")),
            cmu: Some(shared.join("cmu-8action-expmap/cmu-8action-expmap.tar.xz")),
            deepmimic: Some(shared.join("deepmimic")),
            out: out.clone(),
            limit: Some(30),
            hdm05_test_actors: None,
        },
        &|_| {},
    )
    .unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("dataset.json")).unwrap()).unwrap();
    for (source, licence) in [
        ("bandai", "CC BY-NC 4.0"),
        ("hdm05", "CC BY-SA 3.0"),
        ("deepmimic", "MIT"),
    ] {
        assert_eq!(json["sources"][source]["licence"], licence, "{source}");
        assert!(json["licence"].as_str().unwrap().contains(licence));
    }
    assert!(json["sources"]["cmu"]["source_clips"].as_u64().unwrap() > 0);
    assert!(json["attribution"].as_str().unwrap().contains("HDM05"));

    // HDM05's test actor never trains; every other HDM05 actor does.
    let hdm: Vec<_> = summary
        .items
        .iter()
        .filter(|i| i.source == coma::dataset::Source::Hdm05)
        .collect();
    assert!(!hdm.is_empty());
    for item in &hdm {
        let test_actor = coma::dataset::HDM05_TEST_ACTORS.contains(&item.actor.as_str());
        assert_eq!(
            item.split == coma::dataset::Split::Test,
            test_actor,
            "{} by {}",
            item.name,
            item.actor
        );
    }

    // New actions arrive with their own words, and mirrors swap the side of one-sided ones.
    let actions = json["vocabulary"]["actions"].as_object().unwrap();
    for action in ["squat", "lie-down", "kick-left-leg", "kick-right-leg"] {
        assert!(actions.contains_key(action), "{action}: {actions:?}");
    }
    let kick = summary
        .items
        .iter()
        .find(|i| i.content == "kick-left-leg" && i.source == coma::dataset::Source::Hdm05)
        .unwrap();
    assert!(kick.captions.iter().all(|c| c.contains("left")));
    let mirror = summary
        .items
        .iter()
        .find(|i| i.name == format!("M{}", kick.name))
        .unwrap();
    assert_eq!(mirror.content, "kick-right-leg");
    assert!(mirror
        .captions
        .iter()
        .all(|c| c.contains("right") && !c.contains("left")));
}

#[test]
fn other_hdm05_actors_can_be_held_out_for_testing() {
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data");
    let tmp = tempfile::tempdir().unwrap();
    let summary = build(
        &BuildOptions {
            hdm05: Some(shared.join("hdm05-subset/hdm05-subset-amc.tar.xz")),
            out: tmp.path().join("hdm05"),
            hdm05_test_actors: Some(vec!["mm".into(), "bd".into()]),
            ..Default::default()
        },
        &|_| {},
    )
    .unwrap();
    let actors = |split| {
        summary
            .items
            .iter()
            .filter(|i| i.split == split)
            .map(|i| i.actor.as_str())
            .collect::<std::collections::BTreeSet<_>>()
    };
    assert_eq!(
        actors(coma::dataset::Split::Test),
        ["bd", "mm"].into_iter().collect()
    );
    assert!(actors(coma::dataset::Split::Train).contains("tr"));
}

#[test]
fn no_source_at_all_is_a_clear_error() {
    let tmp = tempfile::tempdir().unwrap();
    let err = build(
        &BuildOptions {
            out: tmp.path().join("out"),
            ..Default::default()
        },
        &|_| {},
    )
    .unwrap_err();
    assert!(format!("{err:#}").contains("--hdm05"), "{err:#}");
}
