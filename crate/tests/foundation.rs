//! The motion foundation against real data in `../shared/data`: HumanML3D reference files and
//! the Bandai-Namco archive.

use coma::bvh::{self, Bvh};
use coma::dataset::bandai::{read_clips, Selection, SourceClip};
use coma::features::{self, check::check_reference};
use coma::geom;
use coma::npy::NpyArray;
use coma::skeleton::{self, joint, Offsets, Pose, NUM_JOINTS};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn shared() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data")
}

fn archive() -> PathBuf {
    shared().join("bandai-namco-bvh.tar.xz")
}

const WALK: &str = "dataset-2_walk_normal_001";
const WAVE_LEFT: &str = "dataset-2_wave-left-hand_normal_001";
const BOW: &str = "dataset-1_bow_normal_001";

/// The three clips the acceptance looks at, read once from the archive.
fn clips() -> &'static [SourceClip] {
    static CLIPS: OnceLock<Vec<SourceClip>> = OnceLock::new();
    CLIPS.get_or_init(|| {
        let stems = [WALK, WAVE_LEFT, BOW].map(String::from).to_vec();
        read_clips(&archive(), &Selection::Stems(stems)).expect("reading the Bandai-Namco archive")
    })
}

/// A clip retargeted, made uniform and canonical (origin, facing +Z), as the dataset holds it.
fn canonical(stem: &str, mirrored: bool) -> (features::Features, Vec<Pose>) {
    let clip = clips()
        .iter()
        .find(|c| c.stem == stem)
        .expect("clip in archive");
    let poses = bvh::bandai::retarget(&Bvh::parse(&clip.bvh).unwrap()).unwrap();
    let poses = if mirrored {
        skeleton::mirror_poses(&poses)
    } else {
        poses
    };
    features::joints_to_features(&poses, &Offsets::reference()).unwrap()
}

fn max_height(poses: &[Pose], j: usize) -> f64 {
    poses.iter().map(|p| p[j][1]).fold(f64::MIN, f64::max)
}

#[test]
fn features_reproduce_the_humanml3d_reference() {
    let report = check_reference(&shared().join("humanml3d-reference"), "012314").unwrap();
    assert!(report.passes(), "{report}");
    let rotations = report
        .group_errors
        .iter()
        .find(|(n, _)| *n == "6D rotations")
        .unwrap()
        .1;
    assert!(rotations < 1e-3, "{report}");
}

#[test]
fn reference_bone_lengths_are_those_of_the_example_skeleton() {
    let example =
        NpyArray::read(shared().join("humanml3d-reference/skeleton_example_h3d.npy")).unwrap();
    let pose = features::joints_from_npy(&example).unwrap()[0];
    let from_file = Offsets::from_pose(&pose);
    let built_in = Offsets::reference();
    for j in 0..NUM_JOINTS {
        assert!(
            geom::dist(from_file.0[j], built_in.0[j]) < 1e-12,
            "joint {j}"
        );
    }
}

#[test]
fn bandai_walk_goes_forward_upright() {
    let (feats, poses) = canonical(WALK, false);
    assert!(feats.len() > 40);
    let end = poses.last().unwrap()[0];
    assert!(
        end[2] > 2.0,
        "a walk travels forward (+Z): ended at {end:?}"
    );
    assert!(
        end[0].abs() < 0.3 * end[2],
        "and roughly straight: ended at {end:?}"
    );
    for p in &poses {
        assert!(p[joint::HEAD][1] > p[joint::PELVIS][1] + 0.4, "upright");
        assert!(p[joint::PELVIS][1] > 0.7 && p[joint::PELVIS][1] < 1.1);
    }
}

#[test]
fn bandai_wave_left_hand_raises_the_left_wrist_and_its_mirror_the_right() {
    let (_, poses) = canonical(WAVE_LEFT, false);
    let (l, r) = (
        max_height(&poses, joint::L_WRIST),
        max_height(&poses, joint::R_WRIST),
    );
    assert!(
        l > r + 0.3,
        "left wrist peaks at {l:.2} m, right at {r:.2} m"
    );
    // The character faces +Z, so its left side is +X.
    let top = poses
        .iter()
        .max_by(|a, b| a[joint::L_WRIST][1].total_cmp(&b[joint::L_WRIST][1]))
        .unwrap();
    assert!(top[joint::L_WRIST][0] > top[joint::R_WRIST][0]);

    let (_, mirrored) = canonical(WAVE_LEFT, true);
    let (l, r) = (
        max_height(&mirrored, joint::L_WRIST),
        max_height(&mirrored, joint::R_WRIST),
    );
    assert!(
        r > l + 0.3,
        "mirrored: right wrist peaks at {r:.2} m, left at {l:.2} m"
    );
}

#[test]
fn mirroring_twice_is_the_identity_on_real_data() {
    let (feats, poses) = canonical(WAVE_LEFT, false);
    assert_eq!(
        skeleton::mirror_poses(&skeleton::mirror_poses(&poses)),
        poses
    );
    assert_eq!(
        features::mirror_features(&features::mirror_features(&feats)),
        feats
    );
    // Mirrored features describe exactly the mirrored joints. (Features computed from mirrored
    // joints differ slightly: the reference skeleton's left and right bones differ in length.)
    let from_mirrored_features = features::features_to_joints(&features::mirror_features(&feats));
    let mirrored_joints = skeleton::mirror_poses(&features::features_to_joints(&feats));
    let worst = skeleton::max_joint_distance(&from_mirrored_features, &mirrored_joints);
    assert!(worst < 1e-5, "largest joint difference {worst} m");
}

#[test]
fn bandai_bow_bends_forward_and_comes_back() {
    let (_, poses) = canonical(BOW, false);
    let lean = |p: &Pose| {
        let up = geom::sub(p[joint::NECK], p[joint::PELVIS]);
        (up[1] / geom::norm(up)).acos().to_degrees()
    };
    let deepest = poses.iter().map(lean).fold(0.0, f64::max);
    assert!(
        deepest > 30.0,
        "a bow leans the torso forward: at most {deepest:.0}°"
    );
    assert!(
        lean(&poses[0]) < 20.0 && lean(poses.last().unwrap()) < 20.0,
        "upright at both ends"
    );
    let p = poses
        .iter()
        .max_by(|a, b| lean(a).total_cmp(&lean(b)))
        .unwrap();
    assert!(
        p[joint::HEAD][2] > p[joint::PELVIS][2],
        "the head goes forward (+Z), not back"
    );
}

#[test]
fn bvh_written_and_read_back_gives_the_same_joints_within_a_millimetre() {
    let (feats, _) = canonical(WALK, false);
    let poses = features::features_to_joints(&feats);
    let text = bvh::writer::write_bvh(&poses, coma::timing::FPS).unwrap();
    let back = bvh::to_smpl_motion(&Bvh::parse(&text).unwrap()).unwrap();
    assert_eq!(back.len(), poses.len());
    let worst = skeleton::max_joint_distance(&poses, &back);
    assert!(worst < 1e-3, "worst joint error {:.2} mm", worst * 1e3);
}
