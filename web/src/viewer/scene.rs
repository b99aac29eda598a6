//! What the viewer draws, as plain coloured vertices: the skeleton of one frame (bones as
//! ribbons facing the camera, joints as small squares, the four limbs in their colours), the
//! ground grid and the root's path; and the orbit camera that looks at it. No GPU here, so
//! it is tested natively.
//!
//! World space is the motion's: metres, Y up, the character starting at the origin facing +Z.

use coma::render::{bone_color, joint_color};
use coma::skeleton::PARENTS;

type V3 = [f32; 3];

/// One vertex: position in metres and an sRGB colour with alpha.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vertex {
    pub position: V3,
    pub color: [f32; 4],
}

/// Bytes per vertex on the GPU (3 + 4 floats).
pub const VERTEX_BYTES: usize = 28;

/// Vertices as the little-endian bytes a vertex buffer takes.
pub fn vertex_bytes(vertices: &[Vertex]) -> Vec<u8> {
    let mut out = Vec::with_capacity(vertices.len() * VERTEX_BYTES);
    for v in vertices {
        for x in v.position.iter().chain(&v.color) {
            out.extend_from_slice(&x.to_le_bytes());
        }
    }
    out
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn scale(a: V3, s: f32) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn normalize(a: V3) -> V3 {
    let n = dot(a, a).sqrt();
    if n > 1e-9 {
        scale(a, 1.0 / n)
    } else {
        [0.0, 0.0, 0.0]
    }
}

/// A camera orbiting a target point: yaw about +Y (0 looks at the character's face from
/// +Z), pitch above the ground, distance in metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitCamera {
    pub target: V3,
    pub yaw: f32,
    pub pitch: f32,
    pub distance: f32,
    /// Vertical field of view, radians.
    pub fov: f32,
}

impl Default for OrbitCamera {
    fn default() -> Self {
        OrbitCamera {
            target: [0.0, 0.9, 0.0],
            yaw: 0.6,
            pitch: 0.3,
            distance: 4.5,
            fov: 0.8,
        }
    }
}

/// Column-major 4×4 matrix, as WGSL's `mat4x4<f32>` is laid out.
pub type Mat4 = [[f32; 4]; 4];

impl OrbitCamera {
    /// Where the camera is.
    pub fn eye(&self) -> V3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        add(self.target, scale([sy * cp, sp, cy * cp], self.distance))
    }

    /// Turns the camera by pointer movement (radians); the pitch stays between just above
    /// the ground and just below straight down.
    pub fn orbit(&mut self, dyaw: f32, dpitch: f32) {
        self.yaw = (self.yaw + dyaw).rem_euclid(std::f32::consts::TAU);
        self.pitch = (self.pitch + dpitch).clamp(-0.1, 1.5);
    }

    /// Moves closer (`factor` < 1) or further, within 0.5–30 m.
    pub fn zoom(&mut self, factor: f32) {
        if factor.is_finite() && factor > 0.0 {
            self.distance = (self.distance * factor).clamp(0.5, 30.0);
        }
    }

    /// View-projection for WebGPU clip space (depth 0..1), `aspect` = width / height.
    pub fn view_projection(&self, aspect: f32) -> Mat4 {
        let eye = self.eye();
        let f = normalize(sub(self.target, eye));
        let s = normalize(cross(f, [0.0, 1.0, 0.0]));
        let u = cross(s, f);
        let view: Mat4 = [
            [s[0], u[0], -f[0], 0.0],
            [s[1], u[1], -f[1], 0.0],
            [s[2], u[2], -f[2], 0.0],
            [-dot(s, eye), -dot(u, eye), dot(f, eye), 1.0],
        ];
        let (near, far) = (0.05f32, 100.0f32);
        let t = 1.0 / (self.fov / 2.0).tan();
        let aspect = if aspect.is_finite() && aspect > 0.0 {
            aspect
        } else {
            1.0
        };
        let projection: Mat4 = [
            [t / aspect, 0.0, 0.0, 0.0],
            [0.0, t, 0.0, 0.0],
            [0.0, 0.0, far / (near - far), -1.0],
            [0.0, 0.0, near * far / (near - far), 0.0],
        ];
        multiply(&projection, &view)
    }

    /// The point of the ground (the plane y = 0) under a point of the picture, as `[x, z]`
    /// metres, or `None` where the picture shows sky (or ground beyond the far plane).
    /// `ndc` is the picture point in normalised device coordinates: x from −1 (left edge) to
    /// 1 (right), y from −1 (bottom) to 1 (top); `aspect` = width / height as given to
    /// [`OrbitCamera::view_projection`], whose inverse this is on that plane.
    pub fn ground_point(&self, ndc: [f32; 2], aspect: f32) -> Option<[f32; 2]> {
        let aspect = if aspect.is_finite() && aspect > 0.0 {
            aspect
        } else {
            1.0
        };
        let eye = self.eye();
        let f = normalize(sub(self.target, eye));
        let (s, u) = self.axes();
        // A picture point at NDC (x, y) lies along f + x·tan(fov/2)·aspect·s + y·tan(fov/2)·u
        // (the projection's t = 1/tan(fov/2) divides them back out).
        let h = (self.fov / 2.0).tan();
        let ray = add(f, add(scale(s, ndc[0] * h * aspect), scale(u, ndc[1] * h)));
        // Rays level with the horizon or above it (or NaN) never meet the ground in front.
        if ray[1].is_nan() || ray[1] >= -1e-6 {
            return None;
        }
        let t = -eye[1] / ray[1];
        let hit = add(eye, scale(ray, t));
        // Beyond the far plane the picture shows nothing, so nothing can be pointed at there.
        let along = t * dot(ray, f);
        (t > 0.0 && along < 100.0 && hit[0].is_finite() && hit[2].is_finite())
            .then_some([hit[0], hit[2]])
    }

    /// The camera's right and up directions in world space (for billboards).
    fn axes(&self) -> (V3, V3) {
        let f = normalize(sub(self.target, self.eye()));
        let s = normalize(cross(f, [0.0, 1.0, 0.0]));
        (s, cross(s, f))
    }
}

/// `a · b` of column-major matrices.
pub fn multiply(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut out = [[0.0; 4]; 4];
    for (c, col) in out.iter_mut().enumerate() {
        for (r, cell) in col.iter_mut().enumerate() {
            *cell = (0..4).map(|k| a[k][r] * b[c][k]).sum();
        }
    }
    out
}

/// Clip-space position of a point.
pub fn project(m: &Mat4, p: V3) -> [f32; 4] {
    let v = [p[0], p[1], p[2], 1.0];
    std::array::from_fn(|r| (0..4).map(|k| m[k][r] * v[k]).sum())
}

fn rgba(c: [u8; 3], alpha: f32) -> [f32; 4] {
    [
        c[0] as f32 / 255.0,
        c[1] as f32 / 255.0,
        c[2] as f32 / 255.0,
        alpha,
    ]
}

/// Two triangles spanning `a`–`b` with half-width `w`, turned to face the camera.
fn ribbon(out: &mut Vec<Vertex>, a: V3, b: V3, w: f32, eye: V3, color: [f32; 4]) {
    let along = sub(b, a);
    let to_eye = sub(eye, scale(add(a, b), 0.5));
    let mut side = normalize(cross(along, to_eye));
    if side == [0.0, 0.0, 0.0] {
        side = [w, 0.0, 0.0];
    } else {
        side = scale(side, w);
    }
    let corners = [sub(a, side), add(a, side), add(b, side), sub(b, side)];
    for i in [0, 1, 2, 0, 2, 3] {
        out.push(Vertex {
            position: corners[i],
            color,
        });
    }
}

/// Triangles of one pose (22 joints, metres): bones 2.2 cm wide, joints 4 cm squares.
pub fn skeleton_triangles(pose: &[V3; 22], camera: &OrbitCamera) -> Vec<Vertex> {
    let eye = camera.eye();
    let mut out = Vec::with_capacity(21 * 6 + 22 * 6);
    for (child, parent) in PARENTS.iter().enumerate() {
        if let Some(p) = parent {
            let color = rgba(bone_color(*p, child), 1.0);
            ribbon(&mut out, pose[*p], pose[child], 0.011, eye, color);
        }
    }
    let (right, up) = camera.axes();
    let r = 0.02;
    for (j, p) in pose.iter().enumerate() {
        let color = rgba(joint_color(j), 1.0);
        let (dx, dy) = (scale(right, r), scale(up, r));
        let corners = [
            sub(sub(*p, dx), dy),
            sub(add(*p, dx), dy),
            add(add(*p, dx), dy),
            add(sub(*p, dx), dy),
        ];
        for i in [0, 1, 2, 0, 2, 3] {
            out.push(Vertex {
                position: corners[i],
                color,
            });
        }
    }
    out
}

/// Line segments of a square ground grid around `center` (x, z), every `step` metres out
/// to `radius`.
pub fn grid_lines(center: [f32; 2], radius: f32, step: f32) -> Vec<Vertex> {
    let color = [0.55, 0.55, 0.52, 1.0];
    let snap = |v: f32| (v / step).round() * step;
    let (cx, cz) = (snap(center[0]), snap(center[1]));
    let n = (radius / step).round() as i32;
    let mut out = Vec::with_capacity((2 * n as usize + 1) * 4);
    for i in -n..=n {
        let o = i as f32 * step;
        for (a, b) in [
            ([cx + o, 0.0, cz - radius], [cx + o, 0.0, cz + radius]),
            ([cx - radius, 0.0, cz + o], [cx + radius, 0.0, cz + o]),
        ] {
            out.push(Vertex { position: a, color });
            out.push(Vertex { position: b, color });
        }
    }
    out
}

/// Line segments of the root's path on the ground, from the first frame to the last.
pub fn path_lines(poses: &[[V3; 22]]) -> Vec<Vertex> {
    let color = [0.27, 0.43, 0.67, 1.0];
    poses
        .windows(2)
        .flat_map(|w| {
            [w[0][0], w[1][0]].map(|p| Vertex {
                position: [p[0], 0.002, p[2]],
                color,
            })
        })
        .collect()
}

/// Line segments of a path being drawn on the ground (`[x, z]` metres), just above the root's
/// path so it shows over it, in a warm colour apart from the path's blue.
pub fn stroke_lines(points: &[[f64; 2]]) -> Vec<Vertex> {
    let color = [0.85, 0.33, 0.1, 1.0];
    points
        .windows(2)
        .flat_map(|w| {
            [w[0], w[1]].map(|p| Vertex {
                position: [p[0] as f32, 0.006, p[1] as f32],
                color,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clip_to_ndc(c: [f32; 4]) -> V3 {
        [c[0] / c[3], c[1] / c[3], c[2] / c[3]]
    }

    #[test]
    fn the_target_is_in_the_middle_of_the_picture_and_up_is_up() {
        let camera = OrbitCamera::default();
        let m = camera.view_projection(16.0 / 9.0);
        let centre = clip_to_ndc(project(&m, camera.target));
        assert!(
            centre[0].abs() < 1e-5 && centre[1].abs() < 1e-5,
            "{centre:?}"
        );
        assert!((0.0..1.0).contains(&centre[2]), "depth {}", centre[2]);
        let above = clip_to_ndc(project(&m, add(camera.target, [0.0, 0.5, 0.0])));
        assert!(above[1] > 0.1, "{above:?}");
        // Nearer points have smaller depth.
        let near = clip_to_ndc(project(
            &m,
            add(
                camera.target,
                scale(normalize(sub(camera.eye(), camera.target)), 1.0),
            ),
        ));
        assert!(near[2] < centre[2]);
    }

    #[test]
    fn from_the_front_the_characters_left_is_on_the_right_of_the_picture() {
        let camera = OrbitCamera {
            yaw: 0.0,
            pitch: 0.0,
            ..OrbitCamera::default()
        };
        let m = camera.view_projection(1.0);
        // The character faces +Z, so its left hand is at +X.
        let left_hand = clip_to_ndc(project(&m, [0.5, 0.9, 0.0]));
        assert!(left_hand[0] > 0.0, "{left_hand:?}");
    }

    #[test]
    fn orbit_and_zoom_stay_in_range() {
        let mut c = OrbitCamera::default();
        c.orbit(100.0, 100.0);
        assert!(c.pitch <= 1.5 && (0.0..std::f32::consts::TAU).contains(&c.yaw));
        c.zoom(1e-9);
        assert_eq!(c.distance, 0.5);
        c.zoom(f32::NAN);
        assert_eq!(c.distance, 0.5);
    }

    #[test]
    fn a_pose_makes_one_ribbon_per_bone_and_one_square_per_joint() {
        let mut pose = [[0.0f32; 3]; 22];
        for (j, p) in pose.iter_mut().enumerate() {
            *p = [j as f32 * 0.01, 1.0 + j as f32 * 0.02, 0.0];
        }
        let v = skeleton_triangles(&pose, &OrbitCamera::default());
        assert_eq!(v.len(), 21 * 6 + 22 * 6);
        assert!(v.iter().all(|x| x.position.iter().all(|c| c.is_finite())));
        // The left wrist's square has the left arm's orange.
        let wrist = &v[21 * 6 + 20 * 6];
        assert!((wrist.color[0] - 238.0 / 255.0).abs() < 1e-6);
        assert_eq!(vertex_bytes(&v).len(), v.len() * VERTEX_BYTES);
    }

    #[test]
    fn a_picked_ground_point_projects_back_to_where_it_was_picked() {
        for camera in [
            OrbitCamera::default(),
            OrbitCamera {
                target: [1.5, 0.9, -2.0],
                yaw: 2.4,
                pitch: 1.2,
                distance: 7.0,
                ..OrbitCamera::default()
            },
        ] {
            let aspect = 16.0 / 10.0;
            let m = camera.view_projection(aspect);
            for ground in [[0.0, 0.0], [0.7, -0.4], [1.5, -2.0], [2.0, 1.0]] {
                let ndc = clip_to_ndc(project(&m, [ground[0], 0.0, ground[1]]));
                let picked = camera.ground_point([ndc[0], ndc[1]], aspect).unwrap();
                assert!(
                    (picked[0] - ground[0]).abs() < 1e-3 && (picked[1] - ground[1]).abs() < 1e-3,
                    "{camera:?}: {ground:?} picked as {picked:?}"
                );
            }
        }
        // Level with the camera, from just above the ground: the top of the picture is sky.
        let low = OrbitCamera {
            pitch: 0.0,
            ..OrbitCamera::default()
        };
        assert_eq!(low.ground_point([0.0, 0.9], 1.0), None);
        // The bottom of the default view is ground in front of the character, towards the
        // camera (which looks from +X, +Z).
        let below = OrbitCamera::default()
            .ground_point([0.0, -0.9], 1.0)
            .unwrap();
        assert!(below[0] > 0.0 && below[1] > 0.0, "{below:?}");
    }

    #[test]
    fn grid_and_path() {
        assert_eq!(grid_lines([0.0, 0.0], 2.0, 0.5).len(), 9 * 4);
        let poses = vec![[[0.0f32; 3]; 22]; 5];
        assert_eq!(path_lines(&poses).len(), 8);
        assert!(path_lines(&poses[..1]).is_empty());
        let stroke = stroke_lines(&[[0.0, 0.0], [0.0, 1.0], [1.0, 1.0]]);
        assert_eq!(stroke.len(), 4);
        assert_eq!(stroke[3].position, [1.0, 0.006, 1.0]);
        assert!(stroke_lines(&[[0.0, 0.0]]).is_empty());
    }
}
