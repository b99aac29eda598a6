//! The `coma` command line as a user runs it.

use std::path::{Path, PathBuf};
use std::process::Command;

fn coma() -> Command {
    Command::new(env!("CARGO_BIN_EXE_coma"))
}

fn reference() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/humanml3d-reference")
}

#[test]
fn features_check_passes_on_the_reference_and_prints_every_group() {
    let out = coma()
        .args(["features", "check"])
        .arg(reference())
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for group in [
        "root angular velocity",
        "joint positions",
        "6D rotations",
        "joint velocities",
        "foot contacts",
    ] {
        assert!(text.contains(group), "{text}");
    }
    assert!(text.contains("PASS"));
}

#[test]
fn features_check_fails_when_the_features_are_wrong() {
    let tmp = tempfile::tempdir().unwrap();
    for sub in ["new_joint_vecs", "new_joints"] {
        std::fs::create_dir_all(tmp.path().join(sub)).unwrap();
        std::fs::copy(
            reference().join(sub).join("012314.npy"),
            tmp.path().join(sub).join("012314.npy"),
        )
        .unwrap();
    }
    std::fs::copy(
        reference().join("skeleton_example_h3d.npy"),
        tmp.path().join("skeleton_example_h3d.npy"),
    )
    .unwrap();
    // Perturb one root-height value by 1 cm: joints and features no longer agree.
    let path = tmp.path().join("new_joint_vecs/012314.npy");
    let mut array = coma::npy::NpyArray::read(&path).unwrap();
    array.data[263 * 50 + 3] += 0.01;
    array.write_f32(&path).unwrap();
    let out = coma()
        .args(["features", "check"])
        .arg(tmp.path())
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("FAIL"));

    let missing = coma()
        .args(["features", "check", "/nonexistent"])
        .output()
        .unwrap();
    assert!(!missing.status.success());
    assert!(String::from_utf8_lossy(&missing.stderr).contains("/nonexistent"));
}

#[test]
fn convert_to_bvh_and_render_the_bvh() {
    let tmp = tempfile::tempdir().unwrap();
    let bvh = tmp.path().join("m.bvh");
    let features = reference().join("new_joint_vecs/012314.npy");
    assert!(coma()
        .arg("convert")
        .arg(&features)
        .arg(&bvh)
        .status()
        .unwrap()
        .success());
    let png = tmp.path().join("m.png");
    let out = coma()
        .arg("render")
        .arg(&bvh)
        .arg("--out")
        .arg(&png)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");

    let json = tmp.path().join("m.json");
    assert!(coma()
        .arg("convert")
        .arg(&bvh)
        .arg(&json)
        .status()
        .unwrap()
        .success());
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["frames"].as_array().unwrap().len(), 170);
}

#[test]
fn convert_to_glb_with_either_naming() {
    let tmp = tempfile::tempdir().unwrap();
    let features = reference().join("new_joint_vecs/012314.npy");
    for (flags, hips) in [(&[][..], "pelvis"), (&["--mixamo"][..], "mixamorig:Hips")] {
        let glb = tmp.path().join("m.glb");
        let out = coma()
            .arg("convert")
            .arg(&features)
            .arg(&glb)
            .args(flags)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let bytes = std::fs::read(&glb).unwrap();
        assert_eq!(&bytes[..4], b"glTF");
        let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        assert_eq!(word(8), bytes.len());
        let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + word(12)]).unwrap();
        assert_eq!(json["nodes"][0]["name"], hips);
        // One key per frame of the 170-frame motion.
        let input = json["animations"][0]["samplers"][0]["input"]
            .as_u64()
            .unwrap() as usize;
        assert_eq!(json["accessors"][input]["count"], 170);
    }
}

#[test]
fn bad_input_files_give_messages_not_panics() {
    let tmp = tempfile::tempdir().unwrap();
    let junk = tmp.path().join("junk.bvh");
    std::fs::write(&junk, "HIERARCHY\nROOT a\n{\nOFFSET 0 0\n").unwrap();
    let out = coma()
        .arg("render")
        .arg(&junk)
        .arg("--out")
        .arg(tmp.path().join("x.png"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("junk.bvh") && !err.contains("panicked"),
        "{err}"
    );

    let wrong = tmp.path().join("wrong.npy");
    coma::npy::NpyArray::new(vec![2, 5], vec![0.0; 10])
        .write_f32(&wrong)
        .unwrap();
    let out = coma()
        .arg("render")
        .arg(&wrong)
        .arg("--out")
        .arg(tmp.path().join("y.png"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("(T, 263)"));
}

#[test]
fn generate_without_a_model_says_which_file_is_missing() {
    let tmp = tempfile::tempdir().unwrap();
    let out = coma()
        .args(["generate", "a person walks forward", "--models"])
        .arg(tmp.path())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("spam.json") && !err.contains("panicked"),
        "{err}"
    );
}

#[test]
fn edit_refuses_unknown_parts_and_missing_ranges() {
    let out = coma()
        .args([
            "edit",
            "x.npy",
            "--text",
            "wave",
            "--out",
            "y.npy",
            "--models",
            "/nonexistent",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(!String::from_utf8_lossy(&out.stderr).contains("panicked"));
}
