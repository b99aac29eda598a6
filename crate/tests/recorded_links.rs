//! Share links made before the engine refactor (issue 16) still open to the same motion: a
//! version-2 link of a planned run and a version-1 link with an older segments-only plan,
//! recorded with `crate/examples/record_links.rs` at that time, with the joints each opened
//! to then (`fixtures/links/*.joints.csv`, 6 decimals).
//!
//! A link is exact only for the model that made it (the page offers to regenerate a link of
//! another model from its prompt), so when the shipped weights change the links are recorded
//! again with the same example and the new model: in session 14 the weights became quantized
//! (`crate/src/weights.rs`), and in session 18 the dataset v2 model shipped; `v1.link` and
//! `v2.link` were recorded again both times. What they keep testing is that both link formats
//! decode, through today's engine, to the joints the engine gave when they were recorded.
//!
//! Since issue 17 the engine puts every motion on the one reference skeleton
//! ([`coma::skeleton::fixed_bones`]: bones keep their directions and get the reference
//! lengths). The recordings are kept as they were made, with the model's stretched bones, and
//! the test applies the same fix to them: the fix is a function of the joints alone, so equal
//! fixed joints still prove the link decodes to the motion it was made with (and re-recording
//! would have the fixtures prove only that the engine agrees with itself today).
//!
//! Since issue 37 the engine also plants the feet of every motion ([`coma::feet`]), which
//! needs the decoded features (their contact channels), not the joints alone. So the test
//! holds the recording against the motion as decoded and put on the reference skeleton, and
//! then checks that the engine's answer is exactly that motion with its feet planted
//! ([`coma::session::finish`]'s two steps): the link still opens to the motion it was made
//! with, as the engine now shows it.

use coma::agents::pipeline;
use coma::executor::block_on;
use coma::features::{features_to_joints, with_reference_bones};
use coma::feet::plant_feet;
use coma::session::{Command, Llm, Outcome, Session};
use coma::share::{self, LinkPlan};
use coma::skeleton::{self, Pose};
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .into()
}

/// The joints recorded with the link, as the engine shows them now: on the reference
/// skeleton.
fn recorded_joints(name: &str) -> Vec<Pose> {
    let path = repo().join(format!("crate/tests/fixtures/links/{name}.joints.csv"));
    let recorded: Vec<Pose> = std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| {
            let values: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
            std::array::from_fn(|j| std::array::from_fn(|k| values[j * 3 + k]))
        })
        .collect();
    skeleton::fixed_bones(&recorded)
}

#[test]
fn links_of_both_versions_open_to_the_motion_they_were_made_with() {
    let (session, _) =
        Session::load(&repo().join("static/models"), &burn::tensor::Device::flex()).unwrap();
    for name in ["v1", "v2"] {
        let text =
            std::fs::read_to_string(repo().join(format!("crate/tests/fixtures/links/{name}.link")))
                .unwrap();
        let link = share::decode(text.trim()).unwrap();
        assert_eq!(share::model_id_hex(&link.model_id), session.model().id);
        assert!(link.notes.is_empty(), "{name}: {:?}", link.notes);
        match (name, &link.plan) {
            ("v1", LinkPlan::Segments(s)) => assert_eq!(s[0].to, link.tokens.frames()),
            ("v2", LinkPlan::Planned(plan)) => {
                assert_eq!(plan.segments.len(), 2);
                assert_eq!(link.record.as_ref().unwrap().steps.len(), 1);
            }
            _ => panic!("{name}: {:?}", link.plan),
        }
        let command = Command::Decode {
            tokens: link.tokens.clone(),
            plan: link.plan.plan().cloned(),
        };
        let outcome = block_on(session.execute(
            command,
            &Llm::<coma::agents::llm::UreqTransport>::Off,
            &mut |_| {},
        ));
        let Ok(Outcome::Motion { motion, notes }) = outcome else {
            panic!("{outcome:?}")
        };
        assert!(notes.is_empty(), "{notes:?}");
        let recorded = recorded_joints(name);
        let decoded = match link.plan.plan() {
            Some(plan) => {
                block_on(pipeline::motion_features(
                    session.model(),
                    plan,
                    &link.tokens,
                ))
                .0
            }
            None => block_on(session.model().features(&link.tokens)),
        };
        let decoded = with_reference_bones(&decoded);
        let before_planting: Vec<Pose> = features_to_joints(&decoded);
        assert_eq!(before_planting.len(), recorded.len(), "{name}");
        let worst = skeleton::max_joint_distance(&before_planting, &recorded);
        assert!(worst < 2e-5, "{name}: joints differ by up to {worst} m");
        let paths = link
            .plan
            .plan()
            .map_or_else(Vec::new, |plan| pipeline::path_ranges(plan, &link.tokens));
        let planted: Vec<Pose> = features_to_joints(&plant_feet(&decoded, &paths));
        let shown: Vec<Pose> = motion
            .joints
            .iter()
            .map(|p| p.map(|j| j.map(f64::from)))
            .collect();
        let off = skeleton::max_joint_distance(&shown, &planted);
        assert!(
            off < 1e-5,
            "{name}: the engine's joints are {off} m from the planted motion"
        );
    }
}
