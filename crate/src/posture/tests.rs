use super::check::{fuzz, round_trip_random};
use super::script::{describe_pose, Constraint, PostureScript, ScriptError};
use super::solver::{pose_of, rest_angles, solve};
use crate::posecodes::{body_level, torso_lean, Lean, PelvisLevel};
use crate::skeleton::{PARENTS, REFERENCE_BONE_LENGTHS};

fn clock() -> f64 {
    use std::sync::OnceLock;
    static START: OnceLock<std::time::Instant> = OnceLock::new();
    START
        .get_or_init(std::time::Instant::now)
        .elapsed()
        .as_secs_f64()
        * 1e3
}

#[test]
fn the_rest_pose_stands_upright_on_reference_bones() {
    let pose = pose_of(&rest_angles());
    assert_eq!(body_level(&pose, 0.0), PelvisLevel::Standing);
    assert_eq!(torso_lean(&pose), Lean::Upright);
    for j in 1..22 {
        let p = PARENTS[j].unwrap();
        let len = crate::geom::dist(pose[j], pose[p]);
        assert!((len - REFERENCE_BONE_LENGTHS[j]).abs() < 1e-9, "bone {j}");
    }
    println!("pelvis height {:.3}", pose[0][1]);
    println!("{:#?}", describe_pose(&pose, 0.0));
}

#[test]
fn a_t_pose_script_solves() {
    let script = PostureScript::parse(
        r#"{"name":"T-pose","constraints":[
        {"kind":"bend","joint":"left_elbow","is":"straight"},
        {"kind":"bend","joint":"right_elbow","is":"straight"},
        {"kind":"orientation","limb":"left_upper_arm","is":"horizontal"},
        {"kind":"orientation","limb":"right_upper_arm","is":"horizontal"},
        {"kind":"orientation","limb":"left_forearm","is":"horizontal"},
        {"kind":"orientation","limb":"right_forearm","is":"horizontal"},
        {"kind":"distance","a":"left_hand","b":"right_hand","is":"wide"},
        {"kind":"level","is":"standing"}]}"#,
    )
    .unwrap();
    let solved = solve(&script, None);
    assert!(solved.unmet.is_empty(), "{:?}", solved.unmet);
}

#[test]
fn errors_name_the_constraint_and_the_word() {
    let e = PostureScript::parse(
        r#"{"constraints":[{"kind":"level","is":"standing"},{"kind":"bend","joint":"left_elbow","is":"bent"}]}"#,
    )
    .unwrap_err();
    let text = e.to_string();
    assert!(text.starts_with("constraint 2"), "{text}");
    assert!(text.contains("bent") && text.contains("straight"), "{text}");
    let e = PostureScript::parse(
        r#"{"constraints":[{"kind":"bend","joint":"left_knee","is":"straight"},{"kind":"bend","joint":"left_knee","is":"completely_bent"}]}"#,
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            ScriptError::Contradiction {
                first: 1,
                second: 2,
                ..
            }
        ),
        "{e}"
    );
    let e = PostureScript::parse(
        r#"{"constraints":[{"kind":"relation","a":"left_hand","b":"head","is":"above"},{"kind":"relation","a":"head","b":"left_hand","is":"above"}]}"#,
    )
    .unwrap_err();
    assert!(matches!(e, ScriptError::Contradiction { .. }), "{e}");
    let e = PostureScript::parse(
        r#"{"constraints":[{"kind":"distance","a":"left_hand","b":"left_shoulder","is":"wide"}]}"#,
    )
    .unwrap_err();
    assert!(e.to_string().contains("at most"), "{e}");
    let e = PostureScript::parse(
        r#"{"constraints":[{"kind":"level","is":"kneeling"},{"kind":"contact","point":"left_knee","on_ground":false},{"kind":"contact","point":"right_knee","on_ground":false}]}"#,
    )
    .unwrap_err();
    assert!(matches!(e, ScriptError::Contradiction { .. }), "{e}");
    assert!(PostureScript::parse(r#"{"constraints":[],"hold":1}"#).is_err());
    assert!(
        PostureScript::parse(r#"{"constraints":[{"kind":"lean","is":"upright"}],"hold":99}"#)
            .is_err()
    );
    assert!(
        PostureScript::parse(r#"{"constraints":[{"kind":"lean","is":"upright","extra":1}]}"#)
            .is_err()
    );
}

#[test]
fn random_valid_scripts_round_trip() {
    let report = round_trip_random(300, 17, &clock);
    println!(
        "{} scripts, {} of {} constraints read back ({:.1} %), {} scripts met, {:.1} ms/pose; misses {:#?}",
        report.scripts,
        report.read_back,
        report.constraints,
        100.0 * report.rate(),
        report.scripts_met,
        report.mean_ms,
        report.misses
    );
    assert_eq!(report.limit_breaks, 0);
    assert_eq!(report.below_floor, 0);
    assert!(report.rate() >= 0.98, "round trip {:.3}", report.rate());
}

#[test]
fn fuzzed_scripts_get_a_message_or_a_sound_pose() {
    let report = fuzz(2_000, 5);
    println!("{report:#?}");
    assert_eq!(report.silent_refusals, 0);
    assert_eq!(report.bad_poses, 0);
    assert!(report.solved > 100 && report.refused > 100, "{report:?}");
}

#[test]
fn the_schema_lists_every_constraint_kind() {
    let schema = super::script::schema();
    let kinds = schema["properties"]["constraints"]["items"]["oneOf"]
        .as_array()
        .unwrap();
    assert_eq!(kinds.len(), 8);
    let _ = Constraint::Lean { is: Lean::Upright };
}

#[test]
fn every_named_posture_and_movement_key_is_read_back_in_full() {
    let library = super::library::Library::builtin();
    let scripts = library
        .postures
        .iter()
        .map(|p| (p.name.clone(), &p.script))
        .chain(
            library
                .actions
                .iter()
                .flat_map(|a| a.keys.iter().map(move |k| (a.name.clone(), &k.script))),
        );
    let report = super::check::round_trip_scripts(scripts, &clock);
    assert!(report.scripts >= 40 + 8, "{} scripts", report.scripts);
    assert_eq!(report.read_back, report.constraints, "{:#?}", report.misses);
    assert_eq!(report.limit_breaks + report.below_floor, 0);
}
