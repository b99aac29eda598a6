//! Planted feet: the clean-up every motion gets before the engine hands it out (generated,
//! edited, blended or built from key postures), so feet that carry weight stay where they are
//! put and nothing sinks into the floor.
//!
//! The motion model predicts each joint on its own, so a foot that should rest on the floor
//! drifts a few centimetres a frame (SPAM's foot skating was 0.203 against 0.056 for real
//! motions, `EVAL.md`). [`plant_feet`], on features that are not normalised:
//! 1. finds the contacts of each foot joint (ankle, toe): frames where the joint is near its
//!    lowest height and either the model's contact channel says so or it barely moves; where
//!    no joint is in contact, the lower foot carries the body;
//! 2. around a jump, moves the whole body back by the slide of its stillest firm contact, so
//!    it travels only as far as its feet carry it (a generated body glides over its stance
//!    foot while it gathers and lands), except along a path the person asked for;
//! 3. pins each contact span, along the floor, where the joint is on average over the span
//!    (the joint keeps the height the model gave it; a slide longer than [`STEP_M`] is cut
//!    into stances with a step between), and eases the pin in and out over
//!    [`BLEND_FRAMES`] (two spans of one joint close together hand the offset from one to the
//!    other), so feet never jump;
//! 4. puts the lowest pinned contact on the floor (y = 0) and keeps every foot joint above it;
//!    a foot that moves along the floor out of contact (a swing that skims the ground) is
//!    raised to clear it by [`SWING_CLEARANCE_M`];
//! 5. bends each leg onto its targets by two-bone IK from the hip ([`crate::limb::two_bone`]),
//!    which keeps every bone's length; the upper body does not move about the pelvis;
//! 6. lifts a frame whose other joints (knees, hands, a lying body) would be under the floor;
//! 7. writes the features again: the root's height and travel, root-relative positions and
//!    velocities from the new joints, the hips' and knees' 6D rotations turned by as much as
//!    their bones turned, the ankles' and toes' rotations those of the final joints as the
//!    dataset computes them (the clean-up moves the feet most; `EVAL.md`'s FID went from
//!    0.0917 with the turned rotations to 0.0897, top-3 0.835 to 0.826, both within the
//!    intervals), and the foot contact channels as the dataset computes them from its
//!    joints ([`crate::features::FOOT_CONTACT_THRESHOLD`]): a planted foot is marked in
//!    contact, one the clean-up moved is not, where the model's channel said otherwise.
//!
//! It is deterministic (no randomness, no state: the same features give the same joints on the
//! same build), so a share link, which carries tokens, rebuilds the same cleaned motion.

use crate::features::{
    features_to_joints_with_final, recover_root, rotation_6d, set_rotation_6d, write_pose_columns,
    FeatureFrame, Features, CONTACTS, FOOT_CONTACT_THRESHOLD,
};
use crate::geom::{self, Quat, Vec3};
use crate::limb::two_bone;
use crate::skeleton::{inverse_kinematics, joint, Pose, Rotations};
use crate::timing::FPS;
use std::ops::Range;

/// Height above a foot joint's lowest point in the motion (metres) under which it can be in
/// contact with the floor.
pub const CONTACT_BAND_M: f64 = 0.06;
/// Horizontal speed (m/s) under which a low foot joint counts as planted even where the
/// model's contact channel says it is lifted.
pub const PLANT_SPEED: f64 = 0.6;
/// A foot joint whose lowest point stays this far above the motion's lowest foot point
/// (metres) never touches the floor (a leg held up) and is never pinned.
pub const NEVER_DOWN_M: f64 = 0.15;
/// Farthest (metres) a foot joint in contact may travel along the floor and still be one
/// stance; a longer slide is cut into stances with steps between them.
pub const STEP_M: f64 = 0.25;
/// Frames (20 fps) a foot takes to step from one stance to the next where a slide is cut.
pub const STEP_GAP_FRAMES: usize = 2;
/// Height (metres) above its resting height that a moving foot joint out of contact is
/// raised to: the skating measure counts a foot within 5 cm of the floor as on it.
pub const SWING_CLEARANCE_M: f64 = 0.06;
/// Frames (20 fps) over which a pin eases in before its span and out after it.
pub const BLEND_FRAMES: usize = 4;
/// Frames (20 fps) before and after a frame in flight (no foot joint within
/// [`CONTACT_BAND_M`] of the floor) in which a body gliding over its stance foot is carried
/// back: the gathering for a jump and the landing.
pub const GLIDE_FLIGHT_REACH_FRAMES: usize = 10;

/// The four foot joints in the features' contact order: left ankle, left toe, right ankle,
/// right toe.
const FEET: [usize; 4] = [joint::L_ANKLE, joint::L_FOOT, joint::R_ANKLE, joint::R_FOOT];

/// A leg: hip, knee, ankle, toe.
struct Leg {
    joints: [usize; 4],
    /// Indices into [`FEET`] of its ankle and toe.
    feet: [usize; 2],
}

const LEGS: [Leg; 2] = [
    Leg {
        joints: [joint::L_HIP, joint::L_KNEE, joint::L_ANKLE, joint::L_FOOT],
        feet: [0, 1],
    },
    Leg {
        joints: [joint::R_HIP, joint::R_KNEE, joint::R_ANKLE, joint::R_FOOT],
        feet: [2, 3],
    },
];

/// A run of contact frames of one foot joint, inclusive, and where it is pinned.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Span {
    start: usize,
    end: usize,
    pin: Vec3,
}

/// Per frame, whether each of the four foot joints ([`FEET`] order) is in contact with the
/// floor: near its lowest height and either marked so by the model's contact channel or
/// moving slower than [`PLANT_SPEED`]; where no joint is, the low joints of the lower foot. `poses` has one pose more than `features` has rows
/// (the last row's velocities lead to it); that pose takes the last row's channel.
fn contacts(features: &[FeatureFrame], poses: &[Pose]) -> Vec<Contact> {
    let (lowest, down) = lowest_points(poses);
    (0..poses.len())
        .map(|t| {
            let row = &features[t.min(features.len() - 1)];
            let low: [bool; 4] = std::array::from_fn(|k| {
                down[k] && poses[t][FEET[k]][1] - lowest[k] < CONTACT_BAND_M
            });
            let mut contact: [bool; 4] = std::array::from_fn(|k| {
                let marked = row[CONTACTS.start + k] > 0.5;
                let slow = horizontal_speed(poses, FEET[k], t) < PLANT_SPEED;
                low[k] && (marked || slow)
            });
            let firm = contact;
            // A body near the floor stands on something: with no foot joint in contact, the
            // low joints of the lower foot carry it (a generated run's stance foot slides
            // with the body and is marked as lifted).
            if !contact.iter().any(|&c| c) && low.iter().any(|&l| l) {
                let height = |leg: &Leg| {
                    leg.feet
                        .iter()
                        .map(|&k| poses[t][FEET[k]][1] - lowest[k])
                        .fold(f64::INFINITY, f64::min)
                };
                let leg = if height(&LEGS[0]) <= height(&LEGS[1]) {
                    &LEGS[0]
                } else {
                    &LEGS[1]
                };
                for &k in &leg.feet {
                    contact[k] = low[k];
                }
            }
            Contact { on: contact, firm }
        })
        .collect()
}

/// One frame's contacts of the four foot joints ([`FEET`] order).
#[derive(Clone, Copy)]
struct Contact {
    /// In contact with the floor.
    on: [bool; 4],
    /// In contact by the model's channel or by standing still, not only as the lower foot of
    /// a body with no other support: these may carry the body along the floor.
    firm: [bool; 4],
}

/// Per frame, how far (metres, horizontal) the whole body moves so that it travels only as
/// far as its feet carry it around a jump: between two frames in which a foot joint is firmly
/// in contact, within [`GLIDE_FLIGHT_REACH_FRAMES`] of a frame in flight, the body is moved
/// back by that joint's slide along the floor, taking the joint that slides least (the one
/// that bears the weight; a foot starting its swing still counts as firm for a frame or two).
/// A generated body glides over its stance foot most of all while it gathers for a jump or
/// lands from one (a jump forward covered 1.4 m against the real clips' 1.0); moving the body
/// instead of the foot keeps the legs as the model made them. Elsewhere (a walk's stance) the
/// body's travel is the model's and the pins of step 3 hold the feet: carrying every stance
/// back too made motions the text-motion evaluator scores as less real (with
/// [`crate::features::with_joint_rotations`], FID 0.097 → 0.092, `EVAL.md`). In flight and
/// between stances nothing firm holds the body and its travel is its own.
fn glide_corrections(contact: &[Contact], poses: &[Pose], root_held: &[Range<usize>]) -> Vec<Vec3> {
    let (lowest, _) = lowest_points(poses);
    let ground = lowest.iter().copied().fold(f64::INFINITY, f64::min);
    let flight: Vec<bool> = poses
        .iter()
        .map(|p| FEET.iter().all(|&j| p[j][1] - ground > CONTACT_BAND_M))
        .collect();
    let near_flight = |t: usize| {
        let lo = t.saturating_sub(GLIDE_FLIGHT_REACH_FRAMES);
        let hi = (t + GLIDE_FLIGHT_REACH_FRAMES).min(poses.len() - 1);
        flight[lo..=hi].iter().any(|&f| f)
    };
    let mut shift = [0.0; 3];
    let mut out = vec![shift; poses.len()];
    for t in 1..poses.len() {
        let own_travel = !near_flight(t)
            || root_held
                .iter()
                .any(|r| r.contains(&(t - 1)) && r.contains(&t));
        let slide = (0..FEET.len())
            .filter(|&k| !own_travel && contact[t - 1].firm[k] && contact[t].firm[k])
            .map(|k| {
                let d = geom::sub(poses[t][FEET[k]], poses[t - 1][FEET[k]]);
                [d[0], 0.0, d[2]]
            })
            .min_by(|a, b| geom::norm(*a).total_cmp(&geom::norm(*b)));
        if let Some(slide) = slide {
            shift = geom::sub(shift, slide);
        }
        out[t] = shift;
    }
    out
}

/// Each foot joint's lowest height over the motion, and whether it comes down to the floor at
/// all (within [`NEVER_DOWN_M`] of the lowest foot point).
fn lowest_points(poses: &[Pose]) -> ([f64; 4], [bool; 4]) {
    let lowest = FEET.map(|j| poses.iter().map(|p| p[j][1]).fold(f64::INFINITY, f64::min));
    let ground = lowest.iter().copied().fold(f64::INFINITY, f64::min);
    (lowest, lowest.map(|l| l - ground < NEVER_DOWN_M))
}

/// Joint `j`'s horizontal speed at frame `t` (m/s), by central differences.
fn horizontal_speed(poses: &[Pose], j: usize, t: usize) -> f64 {
    let (before, after) = (t.saturating_sub(1), (t + 1).min(poses.len() - 1));
    let (a, b) = (poses[before][j], poses[after][j]);
    (a[0] - b[0]).hypot(a[2] - b[2]) / (after - before).max(1) as f64 * FPS
}

/// Per frame and leg, how far (metres) to raise the foot so that a foot joint that is not
/// planted (`planted`: inside one of its contact spans) clears its resting height (`floors`)
/// by [`SWING_CLEARANCE_M`]: a swing that skims the floor, the commonest slide of a generated
/// walk, and the steps cut into a long slide; only while the other foot is planted. Eased in
/// and out over [`BLEND_FRAMES`] so the foot rises and sets down smoothly.
fn swing_lifts(poses: &[Pose], planted: &[[bool; 4]], floors: [f64; 4]) -> Vec<[f64; 2]> {
    let (_, down) = lowest_points(poses);
    let needed: Vec<[f64; 2]> = (0..poses.len())
        .map(|t| {
            let standing = LEGS.map(|leg| leg.feet.iter().any(|&k| planted[t][k]));
            std::array::from_fn(|side| {
                // Only a foot whose other foot stands is lifted: with neither planted (a run
                // between stances), lifting would leave the body floating.
                if !standing[1 - side] {
                    return 0.0;
                }
                LEGS[side]
                    .feet
                    .iter()
                    .filter(|&&k| down[k] && !planted[t][k])
                    .map(|&k| floors[k] + SWING_CLEARANCE_M - poses[t][FEET[k]][1])
                    .fold(0.0, f64::max)
            })
        })
        .collect();
    let reach = (BLEND_FRAMES + 1) as f64;
    (0..poses.len())
        .map(|t| {
            let lo = t.saturating_sub(BLEND_FRAMES);
            let hi = (t + BLEND_FRAMES).min(poses.len() - 1);
            std::array::from_fn(|leg| {
                (lo..=hi)
                    .map(|u| needed[u][leg] * geom::ease(1.0 - t.abs_diff(u) as f64 / reach))
                    .fold(0.0, f64::max)
            })
        })
        .collect()
}

/// The contact spans of one foot joint: runs of contact frames (a one-frame gap is closed),
/// each pinned where the joint is on average over it, horizontally, at its median height. A
/// run along which the joint travels further than [`STEP_M`] is a foot that slides while it
/// should stand: it is cut into stances of at most that travel, with [`STEP_GAP_FRAMES`]
/// between them for the foot to step from one to the next. Stances of one frame pin nothing
/// and are left out.
fn spans(contact: &[bool], positions: &[Vec3]) -> Vec<Span> {
    let mut on = contact.to_vec();
    for t in 1..on.len().saturating_sub(1) {
        if !on[t] && on[t - 1] && on[t + 1] {
            on[t] = true;
        }
    }
    let flat = |a: Vec3, b: Vec3| (a[0] - b[0]).hypot(a[2] - b[2]);
    let mut out = Vec::new();
    let mut t = 0;
    while t < on.len() {
        if !on[t] {
            t += 1;
            continue;
        }
        let start = t;
        while t + 1 < on.len() && on[t + 1] && flat(positions[t + 1], positions[start]) <= STEP_M {
            t += 1;
        }
        let end = t;
        // Cut short by its travel: the next stance starts after a step.
        t += if t + 1 < on.len() && on[t + 1] {
            1 + STEP_GAP_FRAMES
        } else {
            1
        };
        if end == start {
            continue;
        }
        let frames = &positions[start..=end];
        let count = frames.len() as f64;
        let mut heights: Vec<f64> = frames.iter().map(|p| p[1]).collect();
        heights.sort_by(f64::total_cmp);
        let pin = [
            frames.iter().map(|p| p[0]).sum::<f64>() / count,
            heights[heights.len() / 2],
            frames.iter().map(|p| p[2]).sum::<f64>() / count,
        ];
        out.push(Span { start, end, pin });
    }
    out
}

/// Per frame, the pin's weight (0–1) and the horizontal offset that would put the joint over
/// its pin (metres): inside a span the full offset; between two spans the offset of one
/// handed to the other's with an eased blend; the weight eases from 1 to 0 over
/// [`BLEND_FRAMES`] on either side of a span.
fn pin_offsets(spans: &[Span], positions: &[Vec3]) -> Vec<(f64, Vec3)> {
    // Along the floor only: the height the model gave a stance foot (a heel rolling, a toe
    // pushing off) is its own, and pulling it onto the pin's height turns the knee and ankle
    // away from the model's leg; step 4 still keeps it above the floor.
    let offset = |t: usize, s: &Span| [s.pin[0] - positions[t][0], 0.0, s.pin[2] - positions[t][2]];
    let reach = (BLEND_FRAMES + 1) as f64;
    let fade = |gap: usize| geom::ease(1.0 - gap as f64 / reach);
    (0..positions.len())
        .map(|t| {
            let before = spans.iter().rev().find(|s| s.start <= t);
            let after = spans.iter().find(|s| s.end >= t);
            match (before, after) {
                (Some(b), _) if t <= b.end => (1.0, offset(t, b)),
                (Some(b), Some(a)) => {
                    let (d0, d1) = (offset(b.end, b), offset(a.start, a));
                    let u = (t - b.end) as f64 / (a.start - b.end) as f64;
                    let weight = fade(t - b.end).max(fade(a.start - t));
                    (weight, geom::lerp(d0, d1, geom::ease(u)))
                }
                (Some(b), None) => (fade(t - b.end), offset(b.end, b)),
                (None, Some(a)) => (fade(a.start - t), offset(a.start, a)),
                (None, None) => (0.0, [0.0; 3]),
            }
        })
        .collect()
}

/// Bends `leg` of `pose` so its ankle and toe reach `targets` as near as the bones allow,
/// keeping the hip where it is and every bone's length.
fn bend_leg(pose: &mut Pose, leg: &Leg, [ankle_target, toe_target]: [Vec3; 2]) {
    let [hip, knee, ankle, toe] = leg.joints;
    let lengths = [
        geom::dist(pose[hip], pose[knee]),
        geom::dist(pose[knee], pose[ankle]),
    ];
    let foot = geom::sub(pose[toe], pose[ankle]);
    let foot_length = geom::norm(foot);
    // A straight leg bends its knee over the toes.
    let hint = geom::normalize([foot[0], 0.0, foot[2]]);
    let (new_knee, new_ankle) = two_bone(
        [pose[hip], pose[knee], pose[ankle]],
        ankle_target,
        lengths,
        hint,
        0.0,
    );
    let aim = geom::sub(toe_target, new_ankle);
    let aim = if geom::norm(aim) > 1e-9 { aim } else { foot };
    pose[knee] = new_knee;
    pose[ankle] = new_ankle;
    pose[toe] = geom::add(new_ankle, geom::scale(geom::normalize(aim), foot_length));
}

/// The same motion with planted feet (see the module's doc): features that are not
/// normalised in, as many rows out. `root_held` are the feature rows whose root travel was
/// laid on purpose (a path): the body there is never carried back to its feet, so the path
/// keeps its shape. Motions of fewer than 2 rows come back unchanged.
pub fn plant_feet(features: &[FeatureFrame], root_held: &[Range<usize>]) -> Features {
    if features.len() < 2 {
        return features.to_vec();
    }
    let original = features_to_joints_with_final(features);
    if original.iter().flatten().flatten().any(|v| !v.is_finite()) {
        return features.to_vec();
    }
    let contact = contacts(features, &original);
    let carried: Vec<Pose> = original
        .iter()
        .zip(glide_corrections(&contact, &original, root_held))
        .map(|(p, d)| p.map(|v| geom::add(v, d)))
        .collect();
    let spans: Vec<Vec<Span>> = (0..FEET.len())
        .map(|k| {
            let on: Vec<bool> = contact.iter().map(|c| c.on[k]).collect();
            let at: Vec<Vec3> = carried.iter().map(|p| p[FEET[k]]).collect();
            spans(&on, &at)
        })
        .collect();

    // The lowest pinned contact goes on the floor; without any, the lowest joint does.
    let floor = spans
        .iter()
        .flatten()
        .map(|s| s.pin[1])
        .reduce(f64::min)
        .unwrap_or_else(|| crate::skeleton::lowest_joint(&carried));
    let mut poses: Vec<Pose> = carried
        .iter()
        .map(|p| p.map(|v| [v[0], v[1] - floor, v[2]]))
        .collect();
    let offsets: Vec<Vec<(f64, Vec3)>> = (0..FEET.len())
        .map(|k| {
            let at: Vec<Vec3> = poses.iter().map(|p| p[FEET[k]]).collect();
            let lowered: Vec<Span> = spans[k]
                .iter()
                .map(|s| Span {
                    pin: [s.pin[0], s.pin[1] - floor, s.pin[2]],
                    ..*s
                })
                .collect();
            pin_offsets(&lowered, &at)
        })
        .collect();

    // Each foot joint rests at its lowest pin (or, never pinned, at its lowest point).
    let floors: [f64; 4] = std::array::from_fn(|k| {
        spans[k]
            .iter()
            .map(|s| s.pin[1] - floor)
            .reduce(f64::min)
            .unwrap_or_else(|| lowest_points(&poses).0[k])
    });
    let planted: Vec<[bool; 4]> = (0..poses.len())
        .map(|t| std::array::from_fn(|k| spans[k].iter().any(|s| (s.start..=s.end).contains(&t))))
        .collect();
    let lifts = swing_lifts(&poses, &planted, floors);

    for (t, pose) in poses.iter_mut().enumerate() {
        for (side, leg) in LEGS.iter().enumerate() {
            let [a, b] = leg.feet;
            let ((wa, da), (wb, db)) = (offsets[a][t], offsets[b][t]);
            let (oa, ob) = (geom::scale(da, wa), geom::scale(db, wb));
            // An unpinned ankle follows its pinned toe (a heel rising off a planted toe), and
            // the other way round, so the foot keeps its shape.
            let move_a = geom::add(oa, geom::scale(ob, 1.0 - wa));
            let move_b = geom::add(ob, geom::scale(oa, 1.0 - wb));
            let [_, _, ankle, toe] = leg.joints;
            let mut targets = [geom::add(pose[ankle], move_a), geom::add(pose[toe], move_b)];
            for target in &mut targets {
                target[1] = (target[1] + lifts[t][side]).max(0.0);
            }
            if geom::dist(targets[0], pose[ankle]) > 1e-9
                || geom::dist(targets[1], pose[toe]) > 1e-9
            {
                bend_leg(pose, leg, targets);
            }
        }
    }

    // What still goes under the floor (knees, hands, a lying body) lifts its frame, eased
    // over the neighbouring frames so the lift is not a jump.
    let sunk: Vec<f64> = poses
        .iter()
        .map(|p| (-p.iter().map(|v| v[1]).fold(f64::INFINITY, f64::min)).max(0.0))
        .collect();
    if sunk.iter().any(|&s| s > 0.0) {
        let reach = (BLEND_FRAMES + 1) as f64;
        let lifts: Vec<f64> = (0..poses.len())
            .map(|t| {
                let lo = t.saturating_sub(BLEND_FRAMES);
                let hi = (t + BLEND_FRAMES).min(poses.len() - 1);
                (lo..=hi)
                    .map(|u| sunk[u] * geom::ease(1.0 - t.abs_diff(u) as f64 / reach))
                    .fold(0.0, f64::max)
            })
            .collect();
        for (pose, lift) in poses.iter_mut().zip(lifts) {
            for v in pose.iter_mut() {
                v[1] += lift;
            }
        }
    }
    rewrite(features, &original, &poses)
}

/// `features` rewritten to describe `poses` (one more than the rows), whose pelvis differs
/// from `original`'s in height and in travel along the floor and whose legs may have turned.
fn rewrite(features: &[FeatureFrame], original: &[Pose], poses: &[Pose]) -> Features {
    let (facing, _) = recover_root(features);
    // A row's root velocity is the step to the next pose in that pose's facing.
    let last = features[features.len() - 1][0] as f64;
    let facing_next = |t: usize| match facing.get(t + 1) {
        Some(q) => *q,
        None => facing[t].mul(Quat([last.cos(), 0.0, last.sin(), 0.0])),
    };
    let before: Vec<Rotations> = inverse_kinematics(original, true);
    let after: Vec<Rotations> = inverse_kinematics(poses, true);
    let legs: Vec<usize> = LEGS.iter().flat_map(|leg| leg.joints).collect();
    features
        .iter()
        .enumerate()
        .map(|(t, row)| {
            let mut out = *row;
            let pose = &poses[t];
            write_pose_columns(&mut out, pose, &poses[t + 1], facing[t]);
            let step = geom::sub(poses[t + 1][0], pose[0]);
            let was = geom::sub(original[t + 1][0], original[t][0]);
            if (step[0] - was[0]).hypot(step[2] - was[2]) > 1e-9 {
                let v = facing_next(t).rotate([step[0], 0.0, step[2]]);
                out[1] = v[0] as f32;
                out[2] = v[2] as f32;
            }
            // Relative to the pelvis: a frame only lifted keeps its rotations.
            let moved = legs.iter().any(|&j| {
                let now = geom::sub(pose[j], pose[0]);
                geom::dist(now, geom::sub(original[t][j], original[t][0])) > 1e-9
            });
            if moved {
                for &j in &legs {
                    // A foot's rotation describes the foot where it now is; a hip or knee
                    // keeps the model's rotation, turned with its bone.
                    let turned = if FEET.contains(&j) {
                        after[t][j]
                    } else {
                        let turn = after[t][j].mul(before[t][j].inv());
                        turn.mul(rotation_6d(row, j)).normalized()
                    };
                    set_rotation_6d(&mut out, j, turned);
                }
            }
            for (k, &j) in FEET.iter().enumerate() {
                let d = geom::sub(poses[t + 1][j], pose[j]);
                out[CONTACTS.start + k] = (geom::dot(d, d) < FOOT_CONTACT_THRESHOLD) as u8 as f32;
            }
            out
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::{features_to_joints, joints_to_features, POSITIONS, ROOT_HEIGHT};
    use crate::posture::measure::foot_skating;
    use crate::skeleton::{forward_kinematics, max_bone_deviation, Offsets, PARENTS};

    /// A person standing still, 30 frames, then the given change per frame.
    fn standing(frames: usize) -> Vec<Pose> {
        let offsets = Offsets::reference();
        let rest = forward_kinematics(&[[Quat::IDENTITY; 22]], &offsets, &[[0.0, 0.0, 0.0]])[0];
        // Pelvis at the height that puts the lowest joint on the floor.
        let low = rest.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
        let rest = rest.map(|p| [p[0], p[1] - low, p[2]]);
        vec![rest; frames]
    }

    /// Features of `poses` as the dataset would compute them.
    fn features_of(poses: &[Pose]) -> Features {
        joints_to_features(poses, &Offsets::from_pose(&poses[0]))
            .unwrap()
            .0
    }

    /// A standing person whose left foot slides 21.6 cm sideways along the floor at 0.54 m/s
    /// (frames 10–18), as a drifting generated foot does.
    fn sliding_left_foot() -> Features {
        let mut poses = standing(40);
        for (t, pose) in poses.iter_mut().enumerate() {
            let shift = [0.027 * t.clamp(10, 18).saturating_sub(10) as f64, 0.0, 0.0];
            let leg = &LEGS[0];
            let [_, _, ankle, toe] = leg.joints;
            let targets = [geom::add(pose[ankle], shift), geom::add(pose[toe], shift)];
            bend_leg(pose, leg, targets);
        }
        features_of(&poses)
    }

    fn bone_lengths(pose: &Pose) -> Vec<f64> {
        (1..22)
            .map(|j| geom::dist(pose[j], pose[PARENTS[j].unwrap()]))
            .collect()
    }

    #[test]
    fn a_sliding_planted_foot_stays_put_and_the_bones_keep_their_lengths() {
        let features = sliding_left_foot();
        let before = features_to_joints(&features);
        let skating_before = foot_skating(&before);
        let cleaned = plant_feet(&features, &[]);
        assert_eq!(cleaned.len(), features.len());
        let after = features_to_joints(&cleaned);
        assert!(
            skating_before > 0.15,
            "the test motion skates: {skating_before}"
        );
        assert_eq!(foot_skating(&after), 0.0);
        let drift = geom::dist(
            after[0][joint::L_FOOT],
            after[after.len() - 1][joint::L_FOOT],
        );
        let moved = geom::dist(
            before[0][joint::L_FOOT],
            before[before.len() - 1][joint::L_FOOT],
        );
        assert!(
            moved > 0.2 && drift < 0.01,
            "toe drift {drift} m (was {moved} m)"
        );
        let reference = bone_lengths(&before[0]);
        for pose in &after {
            for (a, b) in bone_lengths(pose).iter().zip(&reference) {
                assert!((a - b).abs() < 1e-4, "bone {a} vs {b}");
            }
        }
        assert!(max_bone_deviation(&after) < 1e-4);
        // The pelvis, the upper body and the other leg do not move, but for the one lift that
        // puts the lowest contact on the floor.
        let lift = after[0][0][1] - before[0][0][1];
        assert!(lift.abs() < 0.02, "lifted {lift} m");
        for (a, b) in after.iter().zip(&before) {
            for j in [0, 3, 6, 9, 12, 15, 20, 21, joint::R_KNEE, joint::R_FOOT] {
                let b = [b[j][0], b[j][1] + lift, b[j][2]];
                // 0.1 mm: the stance foot keeps its own f32 height, so the floor rule may
                // lift a frame by a rounding step.
                assert!(geom::dist(a[j], b) < 1e-4, "joint {j} moved");
            }
        }
    }

    /// A standing person carried sideways along +X at `speed` (m/s) over frames 10–30, feet
    /// and all, as a generated body glides, with or without a 30 cm jump at frames 20–23
    /// (flight); the pelvis's travel before and after cleaning.
    fn glide(speed: f64, jump: bool) -> (f64, f64) {
        let mut poses = standing(40);
        for (t, pose) in poses.iter_mut().enumerate() {
            let x = speed / FPS * t.clamp(10, 30).saturating_sub(10) as f64;
            let up = if jump && (20..24).contains(&t) {
                0.3
            } else {
                0.0
            };
            for v in pose.iter_mut() {
                v[0] += x;
                v[1] += up;
            }
        }
        let features = features_of(&poses);
        let travel = |p: &[Pose]| geom::dist(p[0][0], p[p.len() - 1][0]);
        let before = features_to_joints(&features);
        let after = features_to_joints(&plant_feet(&features, &[]));
        (travel(&before), travel(&after))
    }

    #[test]
    fn a_body_gliding_over_its_standing_feet_around_a_jump_stays_where_its_feet_are() {
        let (before, after) = glide(0.3, true);
        assert!(before > 0.29, "the test body travels {before} m");
        // What is left is the travel in flight: 5 steps (take-off to landing) of 1.5 cm.
        assert!(after < 0.08, "travelled {after} m on feet that stand");
    }

    #[test]
    fn far_from_a_jump_the_body_keeps_its_travel_and_the_feet_stay_pinned() {
        let (before, after) = glide(0.3, false);
        assert!(
            (after - before).abs() < 1e-3,
            "travel {before} m became {after} m"
        );
    }

    #[test]
    fn a_body_moving_fast_with_its_feet_off_keeps_its_travel() {
        // 2 m/s: no foot is marked in contact or still, so nothing firm holds the body.
        let (before, after) = glide(2.0, true);
        assert!(before > 1.9, "the test body travels {before} m");
        assert!(
            (after - before).abs() < 1e-3,
            "travel {before} m became {after} m"
        );
    }

    #[test]
    fn the_lowest_contact_is_on_the_floor_and_nothing_is_under_it() {
        // The whole motion 7 cm too high, and one frame's knee pushed under the floor.
        let mut features = sliding_left_foot();
        for row in &mut features {
            row[ROOT_HEIGHT.start] += 0.07;
            for j in 1..22 {
                row[POSITIONS.start + (j - 1) * 3 + 1] += 0.07;
            }
        }
        let cleaned = plant_feet(&features, &[]);
        let poses = features_to_joints(&cleaned);
        let lowest = crate::skeleton::lowest_joint(&poses);
        // Within a millimetre: a toe reaches its pin only as far as the foot's length allows.
        assert!(lowest.abs() < 1e-3, "lowest joint at {lowest} m");
        let mut sunk = features.clone();
        let knee = POSITIONS.start + (joint::L_KNEE - 1) * 3 + 1;
        sunk[10][knee] = -0.05;
        let poses = features_to_joints(&plant_feet(&sunk, &[]));
        assert!(crate::skeleton::lowest_joint(&poses) > -1e-5);
    }

    #[test]
    fn feet_in_the_air_are_not_pulled_down() {
        // Stands, jumps 30 cm for 8 frames, lands.
        let mut poses = standing(40);
        for (t, pose) in poses.iter_mut().enumerate() {
            let up = if (15..23).contains(&t) { 0.3 } else { 0.0 };
            for p in pose.iter_mut() {
                p[1] += up;
            }
        }
        let features = features_of(&poses);
        let after = features_to_joints(&plant_feet(&features, &[]));
        let before = features_to_joints(&features);
        for t in 15..23 {
            let (a, b) = (after[t][joint::L_FOOT][1], before[t][joint::L_FOOT][1]);
            assert!((a - b).abs() < 1e-5, "frame {t}: toe at {a} m, was {b} m");
        }
    }

    #[test]
    fn cleaning_is_deterministic_and_a_clean_motion_stays_nearly_as_it_is() {
        let features = sliding_left_foot();
        let once = plant_feet(&features, &[]);
        assert_eq!(once, plant_feet(&features, &[]));
        let twice = plant_feet(&once, &[]);
        let (a, b) = (features_to_joints(&once), features_to_joints(&twice));
        assert!(crate::skeleton::max_joint_distance(&a, &b) < 0.01);
        let still = features_of(&standing(30));
        let kept = plant_feet(&still, &[]);
        let moved = crate::skeleton::max_joint_distance(
            &features_to_joints(&still),
            &features_to_joints(&kept),
        );
        assert!(moved < 1e-5, "a still pose moved {moved} m");
    }

    #[test]
    fn odd_input_comes_back_unchanged() {
        assert!(plant_feet(&[], &[]).is_empty());
        let one = [[0.0f32; 263]];
        assert_eq!(plant_feet(&one, &[]), one.to_vec());
        let mut bad = sliding_left_foot();
        bad[3][ROOT_HEIGHT.start] = f32::NAN;
        let out = plant_feet(&bad, &[]);
        assert_eq!(out.len(), bad.len());
        assert!(out[3][ROOT_HEIGHT.start].is_nan());
    }

    #[test]
    fn turned_leg_rotations_still_describe_the_legs() {
        // The rewritten 6D rotations of the sliding leg match the rotations computed from the
        // cleaned joints as the dataset would, within the model-to-IK gap of the input.
        let features = sliding_left_foot();
        let cleaned = plant_feet(&features, &[]);
        let ik = inverse_kinematics(
            &crate::features::features_to_joints_with_final(&cleaned),
            true,
        );
        for (t, row) in cleaned.iter().enumerate() {
            for j in [joint::L_HIP, joint::L_KNEE] {
                let q = rotation_6d(row, j);
                let d = q.mul(ik[t][j].inv()).normalized();
                let angle = 2.0 * d.0[0].abs().min(1.0).acos();
                assert!(angle < 0.05, "frame {t} joint {j}: {angle} rad off");
            }
        }
    }
}
