//! The shaded figure: a triangle mesh of a body built from one pose of the 22 joints, for the
//! 3D viewer (and its Canvas 2D fallback, which draws it every frame, hence the modest size:
//! [`MAX_TRIANGLES`]) and for the skinned mesh of the glTF export.
//!
//! Every part of the body is a capsule around a segment: two half-ellipsoid caps joined by a
//! tapered tube, with an elliptical cross-section on the torso, head and feet (wider left to
//! right than front to back). One part per bone (thighs, upper arms and torso thicker than
//! shins and forearms), a head around the head joint, a hand beyond each wrist along the
//! forearm, and each foot from the ankle to the toe joint and a little past it. Every vertex
//! rides rigidly on one joint: the joint at the start of its part's bone, whose rotation turns
//! that bone (the same joint a BVH or glTF rotation of that bone belongs to), so skinning with
//! weight 1 reproduces the figure and the joint also picks the body part's tint.
//!
//! Units are metres in the pose's own frame (the product's: Y up, facing +Z, left is +X).
//! Triangles wind counter-clockwise seen from outside (glTF's and wgpu's default front face).

use crate::geom::{add, cross, dot, norm, scale, sub, Vec3};
use crate::skeleton::{joint, NUM_JOINTS};

/// Vertices around every ring of a part.
const SIDES: usize = 12;
/// Latitude rings per cap, its equator included (at 30°, 60° and 90° from the pole).
const CAP_RINGS: usize = 3;
/// Triangles per part: two pole fans and the bands between the 2 × [`CAP_RINGS`] rings.
const PART_TRIANGLES: usize = 2 * SIDES + 2 * SIDES * (2 * CAP_RINGS - 1);

/// The figure as an indexed triangle list.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FigureMesh {
    /// Vertex positions, metres, in the pose's frame.
    pub positions: Vec<[f32; 3]>,
    /// Unit outward normal of each vertex, same frame.
    pub normals: Vec<[f32; 3]>,
    /// For each vertex, the joint (0..22, [`crate::skeleton::JOINT_NAMES`] order) whose bone
    /// carries it rigidly.
    pub joints: Vec<u8>,
    /// Three vertex indices per triangle, counter-clockwise seen from outside.
    pub indices: Vec<u32>,
}

impl FigureMesh {
    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }
}

/// One capsule of the body.
#[derive(Clone, Copy, Debug)]
struct Part {
    /// The joint that carries it.
    joint: usize,
    /// Axis ends (metres): the caps' centres.
    a: Vec3,
    b: Vec3,
    /// Radii of the caps at `a` and `b` (metres), along the axis.
    ra: f64,
    rb: f64,
    /// Direction of the cross-section's first semi-axis (made perpendicular to the axis).
    side: Vec3,
    /// Cross-section scale along `side` and along axis × side (1, 1: round).
    aspect: [f64; 2],
}

/// Most triangles a figure has (the parts are fixed: 26 capsules).
pub const MAX_TRIANGLES: usize = 26 * PART_TRIANGLES;

/// `a` scaled to unit length, or `fallback` when `a` is (nearly) zero.
fn unit_or(a: Vec3, fallback: Vec3) -> Vec3 {
    let n = norm(a);
    if n > 1e-6 {
        scale(a, 1.0 / n)
    } else {
        fallback
    }
}

/// The parts of the body in a pose (metres). Radii are those of an adult of the reference
/// skeleton's size (1.7 m or so).
fn parts(pose: &[[f32; 3]; NUM_JOINTS]) -> Vec<Part> {
    use joint::*;
    let pose = pose.map(|v| v.map(f64::from));
    let p = |j: usize| pose[j];
    // Left-right directions of the hips and shoulders: the flat sides of the torso, head and
    // feet face them.
    let hips = sub(p(L_HIP), p(R_HIP));
    let shoulders = sub(p(L_COLLAR), p(R_COLLAR));
    let round = [1.0, 1.0];
    let flat = [1.3, 0.8];
    let bone = |j: usize, from: usize, to: usize, ra: f64, rb: f64, side: Vec3, aspect| Part {
        joint: j,
        a: p(from),
        b: p(to),
        ra,
        rb,
        side,
        aspect,
    };
    // A part that starts at joint `from` and runs `len` metres past it along the bone
    // `back`→`from` (hands beyond the wrists, toes beyond the foot joints).
    let beyond = |from: usize, back: usize, start: f64, len: f64| {
        let d = unit_or(sub(p(from), p(back)), [0.0, -1.0, 0.0]);
        (add(p(from), scale(d, start)), add(p(from), scale(d, len)))
    };
    let mut out = vec![
        // Torso: pelvis to neck, widest at the chest.
        bone(PELVIS, PELVIS, SPINE1, 0.11, 0.105, hips, flat),
        bone(SPINE1, SPINE1, SPINE2, 0.105, 0.11, hips, flat),
        bone(SPINE2, SPINE2, SPINE3, 0.11, 0.12, shoulders, flat),
        bone(SPINE3, SPINE3, NECK, 0.12, 0.06, shoulders, flat),
        bone(NECK, NECK, HEAD, 0.055, 0.055, shoulders, round),
    ];
    // Head: an ellipsoid a little above the head joint, along the neck.
    let (ha, hb) = beyond(HEAD, NECK, 0.06, 0.09);
    out.push(Part {
        joint: HEAD,
        a: ha,
        b: hb,
        ra: 0.1,
        rb: 0.1,
        side: shoulders,
        aspect: [0.85, 1.0],
    });
    for (hip, knee, ankle, foot) in [
        (L_HIP, L_KNEE, L_ANKLE, L_FOOT),
        (R_HIP, R_KNEE, R_ANKLE, R_FOOT),
    ] {
        out.push(bone(PELVIS, PELVIS, hip, 0.1, 0.09, hips, round));
        out.push(bone(hip, hip, knee, 0.085, 0.055, hips, round));
        out.push(bone(knee, knee, ankle, 0.055, 0.04, hips, round));
        out.push(bone(ankle, ankle, foot, 0.045, 0.04, hips, [1.15, 0.75]));
        let (ta, tb) = beyond(foot, ankle, 0.0, 0.06);
        out.push(Part {
            joint: foot,
            a: ta,
            b: tb,
            ra: 0.04,
            rb: 0.03,
            side: hips,
            aspect: [1.15, 0.75],
        });
    }
    for (collar, shoulder, elbow, wrist) in [
        (L_COLLAR, L_SHOULDER, L_ELBOW, L_WRIST),
        (R_COLLAR, R_SHOULDER, R_ELBOW, R_WRIST),
    ] {
        out.push(bone(SPINE3, SPINE3, collar, 0.07, 0.065, shoulders, round));
        out.push(bone(
            collar, collar, shoulder, 0.065, 0.06, shoulders, round,
        ));
        out.push(bone(
            shoulder, shoulder, elbow, 0.055, 0.045, shoulders, round,
        ));
        out.push(bone(elbow, elbow, wrist, 0.045, 0.035, shoulders, round));
        let (ha, hb) = beyond(wrist, elbow, 0.04, 0.12);
        out.push(Part {
            joint: wrist,
            a: ha,
            b: hb,
            ra: 0.04,
            rb: 0.032,
            side: shoulders,
            aspect: round,
        });
    }
    out
}

/// Appends one part's capsule to the mesh.
fn push_part(mesh: &mut FigureMesh, part: &Part) {
    // A part shorter than the difference of its radii (a wrist inside its elbow) would turn
    // its tube inside out: it becomes a ball of the larger radius.
    let mut part = *part;
    if norm(sub(part.b, part.a)) < (part.ra - part.rb).abs() {
        part.ra = part.ra.max(part.rb);
        part.rb = part.ra;
    }
    let d = unit_or(sub(part.b, part.a), [0.0, 1.0, 0.0]);
    // The side made perpendicular to the axis; when it runs along the axis, the world axis
    // least aligned with it keeps the mesh defined and deterministic.
    let side = {
        let s = sub(part.side, scale(d, dot(part.side, d)));
        if norm(s) > 1e-4 * norm(part.side).max(1e-6) && norm(s) > 1e-7 {
            unit_or(s, [1.0, 0.0, 0.0])
        } else {
            let e = if d[0].abs() < 0.6 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 0.0, 1.0]
            };
            unit_or(sub(e, scale(d, dot(e, d))), [1.0, 0.0, 0.0])
        }
    };
    let w = cross(d, side);
    let [sx, sw] = part.aspect;
    let base = mesh.positions.len() as u32;
    let joint = part.joint as u8;
    let mut push = |position: Vec3, normal: Vec3| {
        mesh.positions.push(position.map(|v| v as f32));
        mesh.normals.push(unit_or(normal, d).map(|v| v as f32));
        mesh.joints.push(joint);
    };
    // Pole at `a`, the rings of cap a (pole to equator), of cap b (equator to pole), pole at b.
    push(sub(part.a, scale(d, part.ra)), scale(d, -1.0));
    let rings: Vec<(Vec3, f64, f64, f64)> = (1..=CAP_RINGS)
        .map(|i| (part.a, part.ra, -1.0, i))
        .chain((1..=CAP_RINGS).rev().map(|i| (part.b, part.rb, 1.0, i)))
        .map(|(c, r, sign, i)| {
            let phi = std::f64::consts::FRAC_PI_2 * i as f64 / CAP_RINGS as f64;
            (c, r, sign * phi.cos(), phi.sin())
        })
        .collect();
    for &(c, r, along, around) in &rings {
        for k in 0..SIDES {
            let theta = std::f64::consts::TAU * k as f64 / SIDES as f64;
            let (sin, cos) = theta.sin_cos();
            let radial = add(scale(side, sx * cos), scale(w, sw * sin));
            let position = add(add(c, scale(d, r * along)), scale(radial, r * around));
            // The ellipsoid's gradient: axis term and the cross-section's semi-axes inverted.
            let normal = add(
                scale(d, along),
                scale(add(scale(side, cos / sx), scale(w, sin / sw)), around),
            );
            push(position, normal);
        }
    }
    push(add(part.b, scale(d, part.rb)), d);
    let ring = |i: usize, k: usize| base + 1 + (i * SIDES + k % SIDES) as u32;
    let last_pole = base + 1 + (rings.len() * SIDES) as u32;
    for k in 0..SIDES {
        mesh.indices.extend([base, ring(0, k + 1), ring(0, k)]);
        for i in 0..rings.len() - 1 {
            let (p00, p01, p10, p11) = (
                ring(i, k),
                ring(i, k + 1),
                ring(i + 1, k),
                ring(i + 1, k + 1),
            );
            mesh.indices.extend([p00, p01, p10, p01, p11, p10]);
        }
        let l = rings.len() - 1;
        mesh.indices.extend([ring(l, k), ring(l, k + 1), last_pole]);
    }
}

/// The figure of one pose: joint positions in metres (Y up), the 22 joints in
/// [`crate::skeleton::JOINT_NAMES`] order. The mesh is in the same frame and units, posed
/// (world space when the pose is). The same pose always gives the same mesh; a pose with
/// non-finite joints gives non-finite vertices.
pub fn figure_mesh(pose: &[[f32; 3]; NUM_JOINTS]) -> FigureMesh {
    let parts = parts(pose);
    let vertices = parts.len() * (2 + 2 * CAP_RINGS * SIDES);
    let mut mesh = FigureMesh {
        positions: Vec::with_capacity(vertices),
        normals: Vec::with_capacity(vertices),
        joints: Vec::with_capacity(vertices),
        indices: Vec::with_capacity(parts.len() * PART_TRIANGLES * 3),
    };
    for part in &parts {
        push_part(&mut mesh, part);
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::{Offsets, Pose, PARENTS};

    /// The reference skeleton standing, pelvis 0.93 m up.
    fn rest_pose() -> [[f32; 3]; NUM_JOINTS] {
        as_f32(&rest_pose_f64())
    }

    fn rest_pose_f64() -> Pose {
        let offsets = Offsets::reference().0;
        let mut pose = [[0.0f64; 3]; NUM_JOINTS];
        pose[0] = [0.0, 0.93, 0.0];
        for j in 1..NUM_JOINTS {
            let p = PARENTS[j].unwrap();
            pose[j] = add(pose[p], offsets[j]);
        }
        // The head up, as people stand (the reference skeleton's head bone points forward).
        pose[joint::HEAD] = add(pose[joint::NECK], [0.0, 0.103, 0.0]);
        pose
    }

    fn as_f32(pose: &Pose) -> [[f32; 3]; NUM_JOINTS] {
        pose.map(|v| v.map(|x| x as f32))
    }

    /// Vertex positions or normals in f64.
    fn f64s(v: &[[f32; 3]]) -> Vec<Vec3> {
        v.iter().map(|p| p.map(f64::from)).collect()
    }

    /// A pose with bent limbs, a leaning trunk and the wrists inside the elbows (a
    /// zero-length forearm, to check degenerate bones).
    fn bent_pose() -> [[f32; 3]; NUM_JOINTS] {
        let mut pose = rest_pose_f64();
        pose[joint::L_ELBOW] = add(pose[joint::L_SHOULDER], [0.2, 0.1, 0.1]);
        pose[joint::L_WRIST] = add(pose[joint::L_ELBOW], [0.0, 0.25, 0.05]);
        pose[joint::R_WRIST] = pose[joint::R_ELBOW];
        pose[joint::L_ANKLE] = add(pose[joint::L_KNEE], [0.0, -0.2, -0.35]);
        pose[joint::HEAD] = add(pose[joint::NECK], [0.0, 0.05, 0.09]);
        as_f32(&pose)
    }

    /// The largest distance of a part's surface from its axis segment (metres).
    fn max_radius(part: &Part) -> f64 {
        part.ra.max(part.rb) * part.aspect[0].max(part.aspect[1]).max(1.0)
    }

    fn distance_to_segment(p: Vec3, a: Vec3, b: Vec3) -> (f64, Vec3) {
        let ab = sub(b, a);
        let t = if dot(ab, ab) > 0.0 {
            (dot(sub(p, a), ab) / dot(ab, ab)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = add(a, scale(ab, t));
        (norm(sub(p, q)), q)
    }

    /// The part each vertex belongs to (parts are laid out one after another).
    fn part_of_vertices(pose: &[[f32; 3]; NUM_JOINTS]) -> Vec<Part> {
        let per_part = 2 + 2 * CAP_RINGS * SIDES;
        parts(pose)
            .into_iter()
            .flat_map(|p| std::iter::repeat_n(p, per_part))
            .collect()
    }

    #[test]
    fn mesh_is_finite_bounded_and_indexed() {
        for pose in [rest_pose(), bent_pose()] {
            let mesh = figure_mesh(&pose);
            let n = mesh.positions.len();
            assert_eq!(mesh.normals.len(), n);
            assert_eq!(mesh.joints.len(), n);
            assert_eq!(mesh.indices.len() % 3, 0);
            assert!(mesh.triangle_count() <= MAX_TRIANGLES);
            assert!((2000..=4000).contains(&mesh.triangle_count()));
            assert!(mesh.indices.iter().all(|&i| (i as usize) < n));
            assert!(mesh.joints.iter().all(|&j| (j as usize) < NUM_JOINTS));
            assert!(mesh
                .positions
                .iter()
                .chain(&mesh.normals)
                .flatten()
                .all(|v| v.is_finite()));
            // No degenerate triangles: every triangle has three distinct corners.
            for t in mesh.indices.chunks(3) {
                assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
            }
            // Every joint carries part of the body.
            for j in 0..NUM_JOINTS {
                assert!(
                    mesh.joints.contains(&(j as u8)),
                    "joint {j} has no vertices"
                );
            }
        }
    }

    #[test]
    fn normals_are_unit_and_point_outward() {
        for pose in [rest_pose(), bent_pose()] {
            let mesh = figure_mesh(&pose);
            let owners = part_of_vertices(&pose);
            assert_eq!(owners.len(), mesh.positions.len());
            let (positions, normals) = (f64s(&mesh.positions), f64s(&mesh.normals));
            for ((p, n), part) in positions.iter().zip(&normals).zip(&owners) {
                assert!((norm(*n) - 1.0).abs() < 1e-5);
                let (_, q) = distance_to_segment(*p, part.a, part.b);
                assert!(
                    dot(*n, sub(*p, q)) > 0.0,
                    "inward normal on joint {}",
                    part.joint
                );
            }
            // Winding: each triangle's face normal agrees with its corners' normals.
            for t in mesh.indices.chunks(3) {
                let [a, b, c] = [0, 1, 2].map(|i| positions[t[i] as usize]);
                let face = cross(sub(b, a), sub(c, a));
                if norm(face) < 1e-9 {
                    // The tube of a zero-length bone: no area, nothing to see.
                    continue;
                }
                let normal = t.iter().fold([0.0; 3], |s, &i| add(s, normals[i as usize]));
                assert!(dot(face, normal) > 0.0, "triangle {t:?} winds inward");
            }
        }
    }

    #[test]
    fn vertices_stay_within_their_capsule() {
        let pose = bent_pose();
        let mesh = figure_mesh(&pose);
        for (p, part) in f64s(&mesh.positions).iter().zip(part_of_vertices(&pose)) {
            let (dist, _) = distance_to_segment(*p, part.a, part.b);
            assert!(dist <= max_radius(&part) + 1e-5, "{dist} from the axis");
            assert!(max_radius(&part) <= 0.16);
        }
        // Each bone part's axis is the bone itself: the joint's own position starts it.
        for part in parts(&pose) {
            let start = pose[part.joint].map(f64::from);
            let (dist, _) = distance_to_segment(start, part.a, part.b);
            assert!(dist < 0.1, "joint {} is {dist} m from its part", part.joint);
        }
    }

    #[test]
    fn mesh_follows_the_pose() {
        let pose = rest_pose_f64();
        let before = figure_mesh(&as_f32(&pose));
        assert_eq!(before, figure_mesh(&as_f32(&pose)), "deterministic");
        // Bend the left knee: the shin and the foot move, nothing else does.
        let mut bent = pose;
        let shift = [0.0, 0.1, -0.2];
        for j in [joint::L_ANKLE, joint::L_FOOT] {
            bent[j] = add(bent[j], shift);
        }
        let after = f64s(&figure_mesh(&as_f32(&bent)).positions);
        let positions = f64s(&before.positions);
        let moved: Vec<u8> = (0..positions.len())
            .filter(|&i| norm(sub(positions[i], after[i])) > 1e-6)
            .map(|i| before.joints[i])
            .collect();
        for j in [joint::L_KNEE, joint::L_ANKLE, joint::L_FOOT] {
            assert!(moved.contains(&(j as u8)), "joint {j} did not move");
        }
        assert!(moved
            .iter()
            .all(|&j| [joint::L_KNEE, joint::L_ANKLE, joint::L_FOOT].contains(&(j as usize))));
        // A whole-body translation moves every vertex by the same amount.
        let moved_pose = pose.map(|v| add(v, [1.0, 0.0, -2.0]));
        let shifted = figure_mesh(&as_f32(&moved_pose));
        for (a, b) in positions.iter().zip(&f64s(&shifted.positions)) {
            assert!(norm(sub(add(*a, [1.0, 0.0, -2.0]), *b)) < 1e-5);
        }
        assert_eq!(before.normals.len(), shifted.normals.len());
    }

    #[test]
    fn figure_has_a_body_size() {
        let pose = rest_pose();
        let mesh = figure_mesh(&pose);
        let (lo, hi) = mesh
            .positions
            .iter()
            .fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), p| {
                (
                    [0, 1, 2].map(|i| lo[i].min(p[i])),
                    [0, 1, 2].map(|i| hi[i].max(p[i])),
                )
            });
        let height = hi[1] - lo[1];
        assert!((1.5..2.0).contains(&height), "height {height} m");
        // The head's top is above the head joint, the soles near the ankles' floor.
        assert!(hi[1] > pose[joint::HEAD][1] + 0.1);
        assert!(lo[1] < pose[joint::L_FOOT][1]);
    }
}
