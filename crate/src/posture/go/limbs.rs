//! The limbs the go stage holds on targets (a foot planted, a hand on the floor): which
//! joints make each arm and leg, and the two-bone solve that puts their ends where they must
//! be in a frame.

use super::{dist_xz, lowest, shift_y, yawed, MAX_REACH_DROP};
use crate::geom::{self, Vec3};
use crate::limb::two_bone;
use crate::skeleton::{joint, Pose, REFERENCE_BONE_LENGTHS};

/// A limb that can be held to a target: root joint (kept), middle joint (bent by IK), end
/// joint (the target) and, for legs, the toe carried by the end.
pub(super) struct Limb {
    pub(super) root: usize,
    pub(super) mid: usize,
    pub(super) end: usize,
    pub(super) tip: Option<usize>,
    pub(super) leg: bool,
}

impl Limb {
    pub(super) fn effectors(&self) -> impl Iterator<Item = usize> {
        std::iter::once(self.end).chain(self.tip)
    }
}

pub(super) const LEFT_LEG: usize = 0;
pub(super) const RIGHT_LEG: usize = 1;
pub(super) const LEFT_ARM: usize = 2;
pub(super) const RIGHT_ARM: usize = 3;

pub(super) const LIMBS: [Limb; 4] = [
    Limb {
        root: joint::L_HIP,
        mid: joint::L_KNEE,
        end: joint::L_ANKLE,
        tip: Some(joint::L_FOOT),
        leg: true,
    },
    Limb {
        root: joint::R_HIP,
        mid: joint::R_KNEE,
        end: joint::R_ANKLE,
        tip: Some(joint::R_FOOT),
        leg: true,
    },
    Limb {
        root: joint::L_SHOULDER,
        mid: joint::L_ELBOW,
        end: joint::L_WRIST,
        tip: None,
        leg: false,
    },
    Limb {
        root: joint::R_SHOULDER,
        mid: joint::R_ELBOW,
        end: joint::R_WRIST,
        tip: None,
        leg: false,
    },
];

/// Where a limb's end (and toe) must be in one frame.
#[derive(Clone, Copy)]
pub(super) struct Target {
    pub(super) end: Vec3,
    pub(super) tip: Option<Vec3>,
    /// 0–1: how much the limb may fall short of a target near its full reach (see
    /// [`crate::limb::SOFT_REACH`]); 0 for a limb that carries weight.
    pub(super) soft: f64,
}

/// A target from pins on some of a limb's effectors; an unpinned end or toe keeps its place
/// relative to the pinned one in `pose`.
pub(super) fn pinned(
    limb: &Limb,
    end: Option<Vec3>,
    tip: Option<Vec3>,
    pose: &Pose,
) -> Option<Target> {
    match (end, limb.tip, tip) {
        (Some(end), _, Some(tip)) => Some(Target {
            end,
            tip: Some(tip),
            soft: 0.0,
        }),
        (Some(end), Some(t), None) => Some(Target {
            end,
            tip: Some(geom::add(end, geom::sub(pose[t], pose[limb.end]))),
            soft: 0.0,
        }),
        (Some(end), None, None) => Some(Target {
            end,
            tip: None,
            soft: 0.0,
        }),
        (None, Some(t), Some(tip)) => Some(Target {
            end: geom::add(tip, geom::sub(pose[limb.end], pose[t])),
            tip: Some(tip),
            soft: 0.0,
        }),
        _ => None,
    }
}

/// Holds the limbs on their targets: sinks the pelvis as far as needed (and allowed) for the
/// targets to be in reach, bends the limbs by two-bone IK, then lifts the body if any joint is
/// under the floor.
pub(super) fn solve_on_targets(pose: &mut Pose, targets: &[Option<Target>; 4], yaw: f64) {
    let bone = |j: usize| REFERENCE_BONE_LENGTHS[j];
    let mut drop = 0.0f64;
    for (limb, target) in LIMBS.iter().zip(targets) {
        let Some(target) = target else { continue };
        let reach = bone(limb.mid) + bone(limb.end);
        let root = pose[limb.root];
        let across = dist_xz(root, target.end);
        let allowed = (reach * reach - across * across).max(0.0).sqrt();
        drop = drop.max(root[1] - target.end[1] - allowed);
    }
    shift_y(pose, -drop.clamp(0.0, MAX_REACH_DROP));
    let forward = yawed(yaw, [0.0, 0.0, 1.0]);
    for (limb, target) in LIMBS.iter().zip(targets) {
        let Some(target) = target else { continue };
        // Knees bend over the toes (and forward when the foot gives no direction), elbows
        // backward.
        let hint = match (limb.tip, target.tip) {
            (Some(tip), Some(toe)) => {
                let foot = geom::sub(toe, target.end);
                let foot = geom::scale([foot[0], 0.0, foot[2]], 1.0 / bone(tip));
                geom::normalize(geom::add(foot, geom::scale(forward, 0.2)))
            }
            _ if limb.leg => forward,
            _ => geom::scale(forward, -1.0),
        };
        let (mid, end) = two_bone(
            [pose[limb.root], pose[limb.mid], pose[limb.end]],
            target.end,
            [bone(limb.mid), bone(limb.end)],
            hint,
            target.soft,
        );
        if let Some(tip) = limb.tip {
            let natural = geom::sub(pose[tip], pose[limb.end]);
            let aim = target
                .tip
                .map(|p| geom::sub(p, end))
                .filter(|d| geom::norm(*d) > 1e-9)
                .unwrap_or(natural);
            pose[tip] = geom::add(end, geom::scale(geom::normalize(aim), bone(tip)));
        }
        pose[limb.mid] = mid;
        pose[limb.end] = end;
    }
    let low = lowest(pose);
    if low < 0.0 {
        shift_y(pose, -low);
    }
}
