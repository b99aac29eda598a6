//! One skeleton everywhere (issue 17): every motion the engine answers with, generated,
//! edited, run through the whole loop with a blend of two segments, or decoded from a link,
//! has the reference skeleton's bone lengths within 1 mm, and what the page shows (the
//! joints), what the command line exports (from the features) and the BVH export (read back)
//! are the same motion.

use coma::bvh::{to_smpl_motion, writer::write_bvh, Bvh};
use coma::executor::block_on;
use coma::features::features_to_joints;
use coma::session::{Command, Llm, Motion, Outcome, Session};
use coma::skeleton::{max_bone_deviation, max_joint_distance, Pose};
use std::path::Path;

fn execute(session: &Session, command: Command) -> Outcome {
    block_on(session.execute(
        command,
        &Llm::<coma::agents::llm::UreqTransport>::Off,
        &mut |_| {},
    ))
    .unwrap()
}

fn motion_of(outcome: Outcome) -> Motion {
    match outcome {
        Outcome::Motion { motion, .. } => motion,
        Outcome::Run(run) => run.motion,
        other => panic!("{other:?}"),
    }
}

/// The checks of one motion; returns its joints.
fn one_skeleton(what: &str, motion: &Motion) -> Vec<Pose> {
    let joints: Vec<Pose> = motion
        .joints
        .iter()
        .map(|p| p.map(|j| j.map(f64::from)))
        .collect();
    let bones = max_bone_deviation(&joints);
    assert!(bones <= 1e-3, "{what}: a bone is {:.2} mm off", bones * 1e3);
    let exported = max_joint_distance(&joints, &features_to_joints(&motion.features));
    assert!(
        exported < 1e-5,
        "{what}: the features describe joints {exported} m away"
    );
    let bvh = write_bvh(&joints, coma::timing::FPS).unwrap();
    let back = to_smpl_motion(&Bvh::parse(&bvh).unwrap()).unwrap();
    let read = max_joint_distance(&joints, &back);
    assert!(
        read < 1e-3,
        "{what}: the BVH reads back {:.2} mm away",
        read * 1e3
    );
    joints
}

#[test]
fn every_motion_the_engine_answers_with_has_the_reference_bones() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../static/models");
    let (session, _) = Session::load(&dir, &burn::tensor::Device::flex()).unwrap();

    let generated = motion_of(execute(
        &session,
        Command::Generate {
            prompt: "a person waves the left hand".into(),
            seconds: 5.0,
            seed: 2,
            parts: vec![],
            guidance: None,
        },
    ));
    one_skeleton("generated", &generated);

    let edited = motion_of(execute(
        &session,
        Command::EditParts {
            tokens: generated.tokens.clone(),
            text: "raises the right hand".into(),
            parts: vec![coma::skeleton::BodyPart::RightArm],
            seed: 3,
            plan: None,
        },
    ));
    one_skeleton("edited", &edited);

    let Outcome::Run(run) = execute(
        &session,
        Command::Run {
            prompt: "a person walks forward then waves the right hand".into(),
            seed: 1,
            rounds: 1,
            seconds: None,
            plan: None,
        },
    ) else {
        panic!("a run answered with something else")
    };
    assert_eq!(run.plan.segments.len(), 2, "{:?}", run.plan);
    let blended = one_skeleton("blended run", &run.motion);

    // A link of the run (its tokens and plan) opens to the same joints.
    let decoded = motion_of(execute(
        &session,
        Command::Decode {
            tokens: run.motion.tokens.clone(),
            plan: Some(run.plan.clone()),
        },
    ));
    let opened = one_skeleton("decoded link", &decoded);
    assert!(max_joint_distance(&blended, &opened) < 1e-6);
}
