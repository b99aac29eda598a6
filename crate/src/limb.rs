//! Two-bone inverse kinematics of a limb (hip–knee–ankle, shoulder–elbow–wrist): where the
//! middle and end joints go for the end to reach a target, keeping both bone lengths exactly.
//! The key-pose go stage and the feet planting of every decoded motion both bend legs with it.

use crate::geom::{self, Vec3};

/// How strongly a straight limb prefers its hint direction when it must bend: as much as a
/// bend of this many metres.
pub const HINT_WEIGHT: f64 = 0.01;
/// Width (metres) of the band below full reach in which a lifted limb approaches its reach
/// softly (see [`two_bone`]).
pub const SOFT_REACH: f64 = 0.03;

/// Two-bone IK: the middle and end joints that put the end on `target` (or as near as the bones
/// reach) with the root fixed. The limb bends the way it is bent now (the middle joint's offset
/// from the line root → `end`); a (nearly) straight limb bends towards `hint`. Both bone lengths
/// are kept exactly.
pub fn two_bone(
    [root, mid, end]: [Vec3; 3],
    target: Vec3,
    [l1, l2]: [f64; 2],
    hint: Vec3,
    soft: f64,
) -> (Vec3, Vec3) {
    let to = geom::sub(target, root);
    let length = geom::norm(to);
    let dir = if length > 1e-9 {
        geom::scale(to, 1.0 / length)
    } else {
        let d = geom::normalize(geom::sub(mid, root));
        if geom::norm(d) > 0.0 {
            d
        } else {
            [0.0, -1.0, 0.0]
        }
    };
    // Near full reach the middle joint's offset grows like √(reach − distance): a limb that
    // straightens or starts to bend there at any speed swings its knee or elbow infinitely
    // fast. A lifted limb may instead approach its reach exponentially (and fall short of the
    // target by at most SOFT_REACH / e), faded in and out with its lift so that a limb that
    // carries weight reaches its target exactly.
    let zone = l1 + l2 - SOFT_REACH;
    let softened = if length > zone {
        zone + SOFT_REACH * (1.0 - (-(length - zone) / SOFT_REACH).exp())
    } else {
        length
    };
    let length = length - soft.clamp(0.0, 1.0) * (length - softened);
    let d = length.clamp((l1 - l2).abs() + 1e-9, l1 + l2);
    let along = (l1 * l1 - l2 * l2 + d * d) / (2.0 * d);
    let out = (l1 * l1 - along * along).max(0.0).sqrt();
    let perp_to = |v: Vec3, axis: Vec3| geom::sub(v, geom::scale(axis, geom::dot(v, axis)));
    // The bend is measured against the limb's own line, not the target's: a straight limb whose
    // root has moved relative to the target has no bend, and its direction would be noise.
    let bend = perp_to(geom::sub(mid, root), geom::normalize(geom::sub(end, root)));
    // The hint decides only for a (nearly) straight limb; its small weight keeps the choice
    // continuous as the limb starts to bend on its own.
    let mut pole = perp_to(geom::add(bend, geom::scale(hint, HINT_WEIGHT)), dir);
    for fallback in [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]] {
        if geom::norm(pole) > 1e-12 {
            break;
        }
        pole = perp_to(fallback, dir);
    }
    let pole = geom::normalize(pole);
    let mid = geom::add(
        root,
        geom::add(geom::scale(dir, along), geom::scale(pole, out)),
    );
    (mid, geom::add(root, geom::scale(dir, d)))
}
