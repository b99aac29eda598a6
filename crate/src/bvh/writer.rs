//! Writes a 22-joint motion as BVH with rotations solved from joint positions, so animation
//! tools (Blender's importer among them) can retarget it.
//!
//! The file's skeleton:
//! - joints named as in [`JOINT_NAMES`], in metres, Y up, at the motion's frame rate;
//! - the pelvis has six channels (`Xposition Yposition Zposition Zrotation Yrotation
//!   Xrotation`), every other joint three rotations in the same `Z Y X` order (degrees);
//! - rest pose: legs and arms hang straight down, feet point forward (+Z), spine, neck and head
//!   point up; the hips and collars sit where the motion has them on average, relative to the
//!   pelvis and the upper spine.
//!
//! Rotations: the pelvis and the upper spine (spine3), which carry three bones each, get the
//! rotation of the frame spanned by their left–right bone pair and their upward bone; every
//! other joint gets the shortest rotation that points its bone at its child (no twist), relative
//! to its parent. Reading the file back gives the input joints exactly when the motion's bone
//! lengths are constant and its hip and collar triangles rigid (true of motions built from
//! features); otherwise bones take their mean lengths.

use super::BvhError;
use crate::geom::{self, Quat, Vec3};
use crate::skeleton::{joint, Pose, JOINT_NAMES, NUM_JOINTS, PARENTS, RAW_OFFSETS};
use std::fmt::Write;

/// Rest direction of each bone in the written skeleton (HumanML3D's, but with the head
/// pointing up so the rest pose looks like a person).
fn rest_direction(j: usize) -> Vec3 {
    if j == joint::HEAD {
        [0.0, 1.0, 0.0]
    } else {
        RAW_OFFSETS[j]
    }
}

/// End-site offsets of the leaf joints (metres): the top of the head, the toes, the hands.
fn end_site(j: usize) -> Vec3 {
    match j {
        joint::HEAD => [0.0, 0.1, 0.0],
        joint::L_FOOT | joint::R_FOOT => [0.0, 0.0, 0.05],
        _ => [0.0, -0.08, 0.0],
    }
}

/// The joints whose parent is `j`, in index order.
pub(crate) fn children(j: usize) -> Vec<usize> {
    (0..NUM_JOINTS).filter(|&c| PARENTS[c] == Some(j)).collect()
}

/// The rotation of the frame whose X axis runs from `right` to `left` and whose Y axis is
/// `up` made orthogonal to X.
fn triad(left: Vec3, right: Vec3, up: Vec3) -> Quat {
    let x = geom::normalize(geom::sub(left, right));
    let z = geom::normalize(geom::cross(x, up));
    let y = geom::cross(z, x);
    Quat::from_columns(x, y, z)
}

/// The rigid skeleton a motion is exported on (BVH here, glTF in [`crate::gltf`]) and the
/// rotations that pose it: rest offsets fitted to the motion, and per frame the joint
/// rotations solved from the joint positions (see the module's documentation). In the rest
/// pose every rotation is the identity; posing joint `j` with its rotations puts each child
/// `c` at `pose[j] + global[j] · offsets[c]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Rig {
    /// Each joint's offset from its parent in the rest pose (metres, Y up); the pelvis's is
    /// zero.
    pub offsets: [Vec3; NUM_JOINTS],
}

impl Rig {
    /// The skeleton that best fits the motion: mean bone lengths along the rest directions,
    /// the hips and collars at their mean placement relative to the pelvis and upper spine.
    /// `poses` must not be empty.
    pub fn fit(poses: &[Pose]) -> Rig {
        let n = poses.len() as f64;
        let mut rig = Rig {
            offsets: [[0.0; 3]; NUM_JOINTS],
        };
        for c in 1..NUM_JOINTS {
            let p = PARENTS[c].expect("non-root joint");
            let length = poses
                .iter()
                .map(|pose| geom::dist(pose[c], pose[p]))
                .sum::<f64>()
                / n;
            rig.offsets[c] = geom::scale(rest_direction(c), length);
        }
        // Bones hanging off the pelvis and the upper spine keep their average placement in
        // the parent's frame; the parent's frame itself does not depend on these offsets.
        for parent in [joint::PELVIS, joint::SPINE3] {
            let mut sums = [[0.0; 3]; NUM_JOINTS];
            for pose in poses {
                let g = rig.global_rotations(pose)[parent].inv();
                for c in children(parent) {
                    sums[c] = geom::add(sums[c], g.rotate(geom::sub(pose[c], pose[parent])));
                }
            }
            for c in children(parent) {
                rig.offsets[c] = geom::scale(sums[c], 1.0 / n);
            }
        }
        rig
    }

    /// World rotation of every joint in one pose (from the rest pose). The pelvis and the
    /// upper spine turn with the triangle of their three bones; every other joint with
    /// a single child takes the shortest rotation from its parent's that points its bone at
    /// the child; leaves (head, wrists, toes) keep their parent's.
    pub fn global_rotations(&self, pose: &Pose) -> [Quat; NUM_JOINTS] {
        let mut g = [Quat::IDENTITY; NUM_JOINTS];
        for j in 0..NUM_JOINTS {
            g[j] = match j {
                joint::PELVIS => triad(
                    pose[joint::L_HIP],
                    pose[joint::R_HIP],
                    geom::sub(pose[joint::SPINE1], pose[0]),
                ),
                joint::SPINE3 => triad(
                    pose[joint::L_COLLAR],
                    pose[joint::R_COLLAR],
                    geom::sub(pose[joint::NECK], pose[joint::SPINE3]),
                ),
                _ => {
                    let parent = g[PARENTS[j].expect("non-root joint")];
                    match children(j).as_slice() {
                        [c] => {
                            let local_dir = parent.inv().rotate(geom::sub(pose[*c], pose[j]));
                            parent.mul(Quat::between(self.offsets[*c], local_dir))
                        }
                        _ => parent,
                    }
                }
            };
        }
        g
    }

    /// Each joint's rotation relative to its parent's (the pelvis's is its world rotation),
    /// as BVH channels and glTF nodes carry them.
    pub fn local_rotations(&self, pose: &Pose) -> [Quat; NUM_JOINTS] {
        let g = self.global_rotations(pose);
        std::array::from_fn(|j| match PARENTS[j] {
            None => g[j],
            Some(p) => g[p].inv().mul(g[j]),
        })
    }

    /// The joints of the rest pose (metres) with the pelvis at `root`.
    pub fn rest_pose(&self, root: Vec3) -> Pose {
        let mut pose = [root; NUM_JOINTS];
        for j in 1..NUM_JOINTS {
            let p = PARENTS[j].expect("non-root joint");
            pose[j] = geom::add(pose[p], self.offsets[j]);
        }
        pose
    }
}

/// `Z Y X` Euler angles in degrees of a rotation: `R = Rz(z) · Ry(y) · Rx(x)`.
fn euler_zyx_degrees(q: Quat) -> [f64; 3] {
    let m = q.to_matrix();
    let y = (-m[2][0]).clamp(-1.0, 1.0).asin();
    let (z, x) = if m[2][0].abs() < 1.0 - 1e-12 {
        (m[1][0].atan2(m[0][0]), m[2][1].atan2(m[2][2]))
    } else {
        // Gimbal lock: only z − x (or z + x) is defined; put it all in z.
        ((-m[0][1]).atan2(m[1][1]), 0.0)
    };
    [z.to_degrees(), y.to_degrees(), x.to_degrees()]
}

/// The motion as BVH text. `fps` is the motion's frame rate (20 for our motions).
pub fn write_bvh(poses: &[Pose], fps: f64) -> Result<String, BvhError> {
    if poses.is_empty() {
        return Err(BvhError::Empty);
    }
    if let Some(t) = poses
        .iter()
        .position(|p| p.iter().flatten().any(|v| !v.is_finite()))
    {
        return Err(BvhError::Syntax {
            line: 0,
            message: format!("frame {t} has a non-finite joint position"),
        });
    }
    let rig = Rig::fit(poses);
    let mut order = Vec::with_capacity(NUM_JOINTS);
    let mut out = String::from("HIERARCHY\n");
    write_joint(&mut out, 0, 0, &rig.offsets, &mut order);
    let _ = writeln!(
        out,
        "MOTION\nFrames: {}\nFrame Time: {:.8}",
        poses.len(),
        1.0 / fps
    );
    for pose in poses {
        let local = rig.local_rotations(pose);
        let mut line = format!("{:.6} {:.6} {:.6}", pose[0][0], pose[0][1], pose[0][2]);
        for &j in &order {
            let [z, y, x] = euler_zyx_degrees(local[j]);
            let _ = write!(line, " {z:.6} {y:.6} {x:.6}");
        }
        out.push_str(&line);
        out.push('\n');
    }
    Ok(out)
}

fn write_joint(
    out: &mut String,
    j: usize,
    depth: usize,
    offsets: &[Vec3; NUM_JOINTS],
    order: &mut Vec<usize>,
) {
    let pad = "\t".repeat(depth);
    let o = offsets[j];
    order.push(j);
    if j == 0 {
        let _ = writeln!(
            out,
            "ROOT {}\n{{\n{pad}\tOFFSET 0.000000 0.000000 0.000000",
            JOINT_NAMES[j]
        );
        let _ = writeln!(
            out,
            "{pad}\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation"
        );
    } else {
        let _ = writeln!(out, "{pad}JOINT {}\n{pad}{{", JOINT_NAMES[j]);
        let _ = writeln!(out, "{pad}\tOFFSET {:.6} {:.6} {:.6}", o[0], o[1], o[2]);
        let _ = writeln!(out, "{pad}\tCHANNELS 3 Zrotation Yrotation Xrotation");
    }
    let kids = children(j);
    if kids.is_empty() {
        let e = end_site(j);
        let _ = writeln!(
            out,
            "{pad}\tEnd Site\n{pad}\t{{\n{pad}\t\tOFFSET {:.6} {:.6} {:.6}\n{pad}\t}}",
            e[0], e[1], e[2]
        );
    }
    for c in kids {
        write_joint(out, c, depth + 1, offsets, order);
    }
    let _ = writeln!(out, "{pad}}}");
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{to_smpl_motion, Bvh};
    use crate::skeleton::{forward_kinematics, Offsets};

    /// A motion whose hip and collar triangles are rigid: only limb bones rotate.
    fn rigid_motion(frames: usize) -> Vec<Pose> {
        let mut lengths = RAW_OFFSETS.map(|d| geom::scale(d, 0.2));
        lengths[joint::L_HIP] = [0.1, -0.05, 0.0];
        lengths[joint::R_HIP] = [-0.1, -0.05, 0.0];
        let offsets = Offsets(lengths);
        let rots: Vec<_> = (0..frames)
            .map(|t| {
                let s = (t as f64 * 0.25).sin();
                let mut r = [Quat::IDENTITY; NUM_JOINTS];
                r[0] = Quat::from_yaw(0.05 * t as f64)
                    .mul(Quat::from_axis_angle([1.0, 0.0, 0.0], 0.1 * s));
                r[joint::L_KNEE] = Quat::from_axis_angle([1.0, 0.0, 0.0], -0.5 * s);
                r[joint::R_ANKLE] = Quat::from_axis_angle([1.0, 0.0, 0.0], 0.7 * s);
                r[joint::L_ELBOW] = Quat::from_axis_angle([0.0, 0.3, 1.0], 1.5 + s);
                r[joint::R_WRIST] = Quat::from_axis_angle([1.0, 0.0, 0.0], -1.2);
                r[joint::HEAD] = Quat::from_axis_angle([1.0, 0.0, 0.0], -1.3);
                r
            })
            .collect();
        let root: Vec<Vec3> = (0..frames)
            .map(|t| [0.02 * t as f64, 0.95, 0.04 * t as f64])
            .collect();
        forward_kinematics(&rots, &offsets, &root)
    }

    #[test]
    fn write_then_read_gives_same_joints() {
        let poses = rigid_motion(50);
        let text = write_bvh(&poses, 20.0).unwrap();
        let back = to_smpl_motion(&Bvh::parse(&text).unwrap()).unwrap();
        assert_eq!(back.len(), poses.len());
        let worst = crate::skeleton::max_joint_distance(&poses, &back);
        assert!(worst < 1e-4, "worst joint error {worst} m");
    }

    #[test]
    fn euler_decomposition_round_trips() {
        for (axis, angle) in [
            ([0.2, 1.0, -0.4], 2.0),
            ([1.0, 0.0, 0.0], 0.3),
            ([0.0, 0.0, 1.0], -2.9),
        ] {
            let q = Quat::from_axis_angle(axis, angle);
            let [z, y, x] = euler_zyx_degrees(q);
            let r = Quat::from_axis_angle([0.0, 0.0, 1.0], z.to_radians())
                .mul(Quat::from_axis_angle([0.0, 1.0, 0.0], y.to_radians()))
                .mul(Quat::from_axis_angle([1.0, 0.0, 0.0], x.to_radians()));
            let v = [0.3, -0.2, 0.9];
            assert!(geom::dist(q.rotate(v), r.rotate(v)) < 1e-9);
        }
    }

    #[test]
    fn refuses_empty_and_non_finite() {
        assert_eq!(write_bvh(&[], 20.0), Err(BvhError::Empty));
        let mut poses = rigid_motion(3);
        poses[1][5][0] = f64::NAN;
        assert!(write_bvh(&poses, 20.0)
            .unwrap_err()
            .to_string()
            .contains("frame 1"));
    }
}
