use super::check::{fuzz, round_trip_random};
use super::script::{describe_pose, Constraint, PostureScript, ScriptError};
use super::solver::{pose_of, rest_angles, solve};
use super::track::PostureTrack;
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

#[test]
fn a_lead_in_is_played_once_and_the_cycle_comes_back_to_it() {
    use super::library::Library;
    let library = Library::builtin();
    let push_up = library
        .actions
        .iter()
        .find(|a| a.name == "push-up")
        .expect("the library has push-ups");
    let track = push_up.track(Some(3), [0.0, 0.0]);
    assert_eq!(track.lead_in, 1);
    // Into the plank once, down and up three times, then back to standing.
    let (plank, down) = (Some(0), Some(1));
    assert_eq!(
        track.played(),
        vec![plank, down, plank, down, plank, down, plank, None]
    );
    // Timeline marks follow the same order and leave out the way back.
    let marks: Vec<usize> = track.key_times(20.0).iter().map(|m| m.2).collect();
    assert_eq!(marks, vec![0, 1, 0, 1, 0, 1, 0]);
    let times: Vec<f64> = track.key_times(20.0).iter().map(|m| m.0).collect();
    assert!(times.windows(2).all(|w| w[0] < w[1]), "{times:?}");

    // Without a lead-in a repeated track comes back to the starting pose (squats).
    let mut squats = track.clone();
    squats.lead_in = 0;
    squats.returns = false;
    assert_eq!(
        squats.played(),
        vec![plank, down, None, plank, down, None, plank, down, None]
    );
    let once = PostureTrack {
        repeat: 1,
        ..squats
    };
    assert_eq!(once.played(), vec![plank, down]);
    // A lead-in that leaves nothing to repeat is refused with a message.
    let bad = PostureTrack {
        lead_in: 2,
        ..track
    };
    let err = bad.checked().unwrap_err();
    assert!(err.contains("lead-in"), "{err}");
}

#[test]
fn getting_down_to_the_floor_never_floats() {
    use super::go::{go, KeyPose};
    use super::library::Library;
    use crate::posture::measure::in_flight;
    let library = Library::builtin();
    let stand = pose_of(&rest_angles());
    for name in ["lie on the back", "lie on the front", "sit on the floor"] {
        let posture = library.get(name).expect("a library posture");
        let down = solve(&posture.script, None).pose;
        let motion = go(&[
            KeyPose::new(stand, 0.0, 0.2),
            KeyPose::new(down, 1.0, 0.5),
            KeyPose::new(stand, 1.0, 0.2),
        ]);
        let floating = in_flight(&motion).iter().filter(|f| **f).count();
        assert_eq!(
            floating, 0,
            "{name}: {floating} frames with nothing on the floor"
        );
    }
}

/// A named posture of the built-in library, solved.
fn library_pose(name: &str) -> crate::skeleton::Pose {
    let posture = super::library::Library::builtin()
        .get(name)
        .expect("a library posture");
    solve(&posture.script, None).pose
}

#[test]
fn adjacent_posture_segments_join_without_the_generated_frame_between_them() {
    use super::track::{lay_tracks, TrackSpan};
    use crate::skeleton::{joint, BodyPart};
    let stand = pose_of(&rest_angles());
    let arms_up = library_pose("stretching arms up");
    // "Generated" frames: standing, then arms up everywhere a posture does not replace them.
    let base: Vec<_> = (0..90)
        .map(|f| if f < 10 { stand } else { arms_up })
        .collect();
    let library = super::library::Library::builtin();
    let track = |name: &str| {
        PostureTrack::holding(
            BodyPart::ALL.to_vec(),
            library.get(name).unwrap().script.clone(),
        )
    };
    let (t_pose, squat) = (track("T-pose"), track("squat"));
    let spans = [
        TrackSpan {
            frames: 10..40,
            track: &t_pose,
        },
        TrackSpan {
            frames: 40..70,
            track: &squat,
        },
    ];
    let (laid, _) = lay_tracks(&base, &spans, None);
    // From the T-pose to the end of the squat's hold the hands never go above the head, as
    // they would passing through the generated frame at the join.
    let above_head = |p: &crate::skeleton::Pose| {
        p[joint::L_WRIST][1] > p[joint::HEAD][1] && p[joint::R_WRIST][1] > p[joint::HEAD][1]
    };
    let t_at = laid
        .iter()
        .position(|p| (p[joint::L_WRIST][1] - p[joint::L_SHOULDER][1]).abs() < 0.05)
        .expect("the T-pose is reached");
    let squat_at = laid
        .iter()
        .position(|p| p[joint::PELVIS][1] < stand[joint::PELVIS][1] - 0.2)
        .expect("the squat is reached");
    assert!(t_at < squat_at);
    let raised = (t_at..squat_at).filter(|&f| above_head(&laid[f])).count();
    assert_eq!(
        raised, 0,
        "{raised} frames with the hands up between the poses"
    );
}

#[test]
fn a_kneel_held_on_the_legs_kneels_on_the_floor() {
    use super::track::{lay_tracks, TrackSpan};
    use crate::posecodes::{Support, KNEE_CONTACT_M};
    use crate::skeleton::BodyPart;
    let stand = pose_of(&rest_angles());
    let base = vec![stand; 60];
    let kneel = super::library::Library::builtin()
        .get("kneel on both knees")
        .unwrap()
        .script
        .clone();
    let track = PostureTrack::holding(vec![BodyPart::LeftLeg, BodyPart::RightLeg], kneel);
    let spans = [TrackSpan {
        frames: 0..60,
        track: &track,
    }];
    let (laid, _) = lay_tracks(&base, &spans, None);
    let skating = crate::posture::measure::foot_skating(&laid);
    assert!(
        skating <= 0.051,
        "the feet slide into the kneel: skating {skating}"
    );
    let held = &laid[40];
    let low = held.iter().map(|j| j[1]).fold(f64::INFINITY, f64::min);
    assert!(low.abs() < 0.02, "lowest joint {low} m above the floor");
    for knee in [Support::LeftKnee, Support::RightKnee] {
        let (height, _) = knee.clearance(held, 0.0);
        assert!(height < KNEE_CONTACT_M, "{} {height} m up", knee.as_str());
    }

    // Let go before the motion ends, the kneel stands up again over planted feet and hands
    // the legs back to the generated motion.
    let base = vec![stand; 90];
    let spans = [TrackSpan {
        frames: 0..60,
        track: &track,
    }];
    let (laid, _) = lay_tracks(&base, &spans, None);
    assert_eq!(laid.len(), 90);
    let skating = crate::posture::measure::foot_skating(&laid);
    assert!(
        skating <= 0.051,
        "the feet slide on the way out: skating {skating}"
    );
    let kneeling = laid[..60]
        .iter()
        .any(|p| Support::LeftKnee.clearance(p, 0.0).0 < KNEE_CONTACT_M);
    assert!(kneeling, "never kneels");
    for (f, pose) in laid[60..].iter().enumerate() {
        let moved = pose
            .iter()
            .zip(&stand)
            .map(|(a, b)| crate::geom::dist(*a, *b))
            .fold(0.0, f64::max);
        assert!(
            moved < 0.02,
            "frame {}: {moved} m from the generated pose",
            60 + f
        );
    }
}

#[test]
fn a_mirrored_script_solves_to_the_mirrored_pose() {
    use crate::posture::library::Library;
    use crate::skeleton::mirror_poses;
    let library = Library::builtin();
    let pointing = &library.get("pointing forward").unwrap().script;
    let mirrored = pointing.mirrored();
    assert_ne!(&mirrored, pointing);
    assert_eq!(&mirrored.mirrored(), pointing);
    assert_eq!(mirrored.name, pointing.name);
    assert!(mirrored.clone().check().is_ok());
    // Solved, the mirrored script meets as many of its constraints as the original meets of
    // its own, and is the original's pose reflected up to the solver's iterations (its rest
    // pose is not exactly symmetric: 5.8 cm at the worst joint on this pose).
    let pose = solve(pointing, None).pose;
    let there = solve(&mirrored, None).pose;
    let held = |script: &PostureScript, pose| {
        script
            .constraints
            .iter()
            .filter(|c| c.holds(pose, 0.0))
            .count()
    };
    assert_eq!(held(&mirrored, &there), held(pointing, &pose));
    let reflected = mirror_poses(&[pose])[0];
    let worst = (0..pose.len())
        .map(|j| crate::geom::dist(there[j], reflected[j]))
        .fold(0.0, f64::max);
    assert!(worst < 0.1, "{worst} m");
    // A symmetric pose mirrored is as good a script of it.
    let t = &library.get("T-pose").unwrap().script;
    let solved = solve(&t.mirrored(), None).pose;
    assert_eq!(held(&t.mirrored(), &solved), held(t, &solve(t, None).pose));
}
