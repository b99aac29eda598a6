//! The plan as a timeline (issue 38): a clip on a body-part track changes its parts over its
//! span only, and moving a clip regenerates only the spans it left and entered.

use coma::agents::pipeline::{clip_frames, clip_steps};
use coma::agents::planner::offline;
use coma::executor::block_on;
use coma::model::edit::SEAM_STEPS;
use coma::model::motion_model::steps_of;
use coma::plan::{Clip, Plan};
use coma::session::{Command, Llm, Motion, Outcome, Session};
use coma::skeleton::{BodyPart, Pose};
use coma::timing::FRAMES_PER_TOKEN;
use std::ops::Range;
use std::path::Path;

fn session() -> Session {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../static/models");
    Session::load(&dir, &burn::tensor::Device::flex())
        .unwrap()
        .0
}

fn execute(session: &Session, command: Command) -> Motion {
    let outcome = block_on(session.execute(
        command,
        &Llm::<coma::agents::llm::UreqTransport>::Off,
        &mut |_| {},
    ))
    .unwrap();
    match outcome {
        Outcome::Motion { motion, .. } => motion,
        Outcome::Run(run) => run.motion,
        other => panic!("{other:?}"),
    }
}

fn run(session: &Session, plan: &Plan) -> Motion {
    execute(
        session,
        Command::Run {
            prompt: plan.prompt.clone(),
            seed: 7,
            rounds: 0,
            seconds: None,
            plan: Some(plan.clone()),
        },
    )
}

/// A walk then a run, 5 s each, and a wave of the left hand from `start` to `end` seconds.
fn walk_run(wave: Option<(f64, f64)>) -> Plan {
    walk_run_with(BodyPart::LeftArm, "a person waves the left hand", wave)
}

/// A walk then a run, 5 s each, and a clip of `text` on `part` from `start` to `end` seconds.
fn walk_run_with(part: BodyPart, text: &str, span: Option<(f64, f64)>) -> Plan {
    let mut plan = offline::plan("a person walks forward, then runs forward", None);
    plan.fit_seconds(10.0);
    plan.clips = span
        .map(|(start, end)| Clip {
            parts: vec![part],
            text: text.into(),
            start,
            end,
            postures: None,
        })
        .into_iter()
        .collect();
    plan.checked().unwrap()
}

/// The token steps (all parts, all layers) where two motions differ, as part indices.
fn changed_steps(a: &Motion, b: &Motion) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for p in 0..a.tokens.len() {
        for (ra, rb) in a.tokens[p].iter().zip(&b.tokens[p]) {
            for s in 0..ra.len() {
                if ra[s] != rb[s] && !out.contains(&(p, s)) {
                    out.push((p, s));
                }
            }
        }
    }
    out
}

fn joints(motion: &Motion) -> Vec<Pose> {
    motion
        .joints
        .iter()
        .map(|p| p.map(|j| j.map(f64::from)))
        .collect()
}

/// The largest difference (metres) of any joint of frame `f` between two motions, relative to
/// the pelvis and in world space.
fn moved_at(a: &[Pose], b: &[Pose], f: usize) -> (f64, f64) {
    let mut out = (0.0f64, 0.0f64);
    for (ja, jb) in a[f].iter().zip(&b[f]) {
        for i in 0..3 {
            let local = (ja[i] - a[f][0][i]) - (jb[i] - b[f][0][i]);
            out.0 = out.0.max(local.abs());
            out.1 = out.1.max((ja[i] - jb[i]).abs());
        }
    }
    out
}

/// The largest differences (metres, relative to the pelvis and in world space) of the frames
/// `frames` between two motions.
fn moved(a: &[Pose], b: &[Pose], frames: Range<usize>) -> (f64, f64) {
    frames
        .map(|f| moved_at(a, b, f))
        .fold((0.0, 0.0), |m, d| (m.0.max(d.0), m.1.max(d.1)))
}

/// Joints outside the affected steps must not move at all: the base motion is decoded there
/// and nothing after the decoder reads across time into them. 0.1 mm leaves room for f32
/// rounding only.
const UNCHANGED_M: f64 = 1e-4;

/// Asserts that no joint of `b` outside the token `steps` moved from `a` (relative to the
/// pelvis and in world space, before and after the steps), printing the largest moves.
fn assert_unchanged_outside(a: &[Pose], b: &[Pose], steps: &Range<usize>, what: &str) {
    let (before, after) = (
        moved(a, b, 0..steps.start * FRAMES_PER_TOKEN),
        moved(a, b, steps.end * FRAMES_PER_TOKEN..a.len()),
    );
    eprintln!(
        "{what}: joints outside the affected steps {steps:?} move by up to {:.4} mm before and \
         {:.4} mm after (relative to the pelvis), {:.4} mm and {:.4} mm in world space",
        before.0 * 1e3,
        after.0 * 1e3,
        before.1 * 1e3,
        after.1 * 1e3
    );
    for d in [before.0, before.1, after.0, after.1] {
        assert!(d < UNCHANGED_M, "{what}: {d} m");
    }
}

#[test]
fn a_clip_changes_its_parts_over_its_span_and_moving_it_only_the_spans_it_left_and_entered() {
    let session = session();
    let bare = walk_run(None);
    let waving = walk_run(Some((3.0, 7.0)));
    let without = run(&session, &bare);
    let with = run(&session, &waving);
    // The clip spans the join of the walk and the run; the rest of the run is the same.
    let span = clip_frames(&waving, &waving.clips[0], &with.tokens);
    let steps = steps_of(span.clone());
    let reach = steps.start - SEAM_STEPS..steps.end + SEAM_STEPS;
    assert_eq!(clip_steps(&waving, &waving.clips[0], &with.tokens), reach);
    let changed = changed_steps(&without, &with);
    assert!(!changed.is_empty());
    for (p, s) in &changed {
        assert_eq!(*p, 0, "part {p} changed at step {s}");
        assert!(reach.contains(s), "step {s} outside {reach:?}");
    }
    // The clip is a layer over the walk and run without it: their tokens are its base, and
    // outside its reach the motion is theirs.
    assert_eq!(with.tokens.base(), without.tokens);
    let (a, b) = (joints(&without), joints(&with));
    assert_unchanged_outside(&a, &b, &reach, "laying the clip");

    // Moved later: only the steps of the old and the new span (and their seams) change.
    let mut moved_plan = waving.clone();
    moved_plan.clips[0].start = 6.0;
    moved_plan.clips[0].end = 8.5;
    let moved_plan = moved_plan.checked().unwrap();
    let moved_clip = execute(
        &session,
        Command::EditClips {
            tokens: with.tokens.clone(),
            before: waving.clone(),
            plan: moved_plan.clone(),
            seed: 11,
        },
    );
    let new_span = clip_frames(&moved_plan, &moved_plan.clips[0], &moved_clip.tokens);
    let new_steps = steps_of(new_span);
    let both =
        steps.start.min(new_steps.start) - SEAM_STEPS..steps.end.max(new_steps.end) + SEAM_STEPS;
    let changed = changed_steps(&with, &moved_clip);
    assert!(!changed.is_empty());
    for (p, s) in &changed {
        assert_eq!(*p, 0, "part {p} changed at step {s}");
        assert!(both.contains(s), "step {s} outside {both:?}");
    }
    // The base under the clip is the same motion wherever the clip lies.
    assert_eq!(moved_clip.tokens.base(), with.tokens.base());
    // What the token change does to the joints outside the affected steps: nothing. The
    // decoder is shared by the parts and reads the whole sequence, and the root's turn is
    // integrated, but the base is decoded there and the clip's parts are taken from the final
    // tokens over the clip's steps only.
    let (a, b) = (joints(&with), joints(&moved_clip));
    assert_unchanged_outside(&a, &b, &both, "moving the clip");
    // Inside, the waving arm moved with its clip.
    let (_, inside) = moved(
        &a,
        &b,
        both.start * FRAMES_PER_TOKEN..both.end * FRAMES_PER_TOKEN,
    );
    assert!(inside > 0.01, "{inside} m");

    // Deleted: the base motion again, exactly.
    let deleted = execute(
        &session,
        Command::EditClips {
            tokens: with.tokens.clone(),
            before: waving.clone(),
            plan: bare.clone(),
            seed: 12,
        },
    );
    assert_eq!(deleted.tokens, without.tokens);
    assert!(deleted.tokens.base_patches().is_empty());
    let (all_local, all_world) = moved(&joints(&without), &joints(&deleted), 0..a.len());
    eprintln!(
        "deleting the clip: joints differ from the motion without it by {:.4} mm (relative to \
         the pelvis), {:.4} mm in world space",
        all_local * 1e3,
        all_world * 1e3
    );
    assert!(all_local < UNCHANGED_M && all_world < UNCHANGED_M);
    // And the deletion undoes: the clip laid again at its place is the motion with it.
    let again = execute(
        &session,
        Command::Decode {
            tokens: with.tokens.clone(),
            plan: Some(waving.clone()),
        },
    );
    assert_eq!(again.joints, with.joints);
}

#[test]
fn a_legs_clip_moved_leaves_the_frames_outside_its_spans_as_they_were() {
    // Planting the feet carries the body by its feet over the whole motion and puts the lowest
    // contact on the floor: a kick finished with the rest of the motion would move every frame
    // after it. The base is finished on its own, so it does not.
    let session = session();
    let kick = "a person kicks with the right leg";
    let plan = walk_run_with(BodyPart::RightLeg, kick, Some((3.0, 5.0)));
    let with = run(&session, &plan);
    let moved_plan = walk_run_with(BodyPart::RightLeg, kick, Some((6.0, 8.0)));
    let moved_clip = execute(
        &session,
        Command::EditClips {
            tokens: with.tokens.clone(),
            before: plan.clone(),
            plan: moved_plan.clone(),
            seed: 11,
        },
    );
    let (old, new) = (
        clip_steps(&plan, &plan.clips[0], &with.tokens),
        clip_steps(&moved_plan, &moved_plan.clips[0], &moved_clip.tokens),
    );
    let both = old.start.min(new.start)..old.end.max(new.end);
    let (a, b) = (joints(&with), joints(&moved_clip));
    assert_unchanged_outside(&a, &b, &both, "moving a kick");
    // Every bone keeps its length under the clip too, where the kick eases in and out.
    assert!(coma::skeleton::max_bone_deviation(&b) < 1e-3);
}
