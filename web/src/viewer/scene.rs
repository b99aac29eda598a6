//! What the viewer draws, as plain coloured vertices: the figure of one frame (a shaded body,
//! coma's figure mesh, or on a toggle the skeleton: bones as ribbons facing the camera, joints
//! as small squares; the four limbs in their colours), soft contact shadows
//! under the feet and the pelvis, the ground grid and the root's path; the light that shades
//! the body; and the orbit camera that looks at it all. No GPU here, so it is tested natively.
//!
//! World space is the motion's: metres, Y up, the character starting at the origin facing +Z.

use coma::render::{bone_color, joint_color};
use coma::skeleton::PARENTS;

type V3 = [f32; 3];

/// One vertex: position in metres, the surface normal (all zero: not lit, as lines, shadows
/// and the skeleton's ribbons are) and an sRGB colour with alpha.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vertex {
    pub position: V3,
    pub normal: V3,
    pub color: [f32; 4],
}

/// Bytes per vertex on the GPU (3 + 3 + 4 floats).
pub const VERTEX_BYTES: usize = 40;

/// Vertices as the little-endian bytes a vertex buffer takes.
pub fn vertex_bytes(vertices: &[Vertex]) -> Vec<u8> {
    let mut out = Vec::with_capacity(vertices.len() * VERTEX_BYTES);
    for v in vertices {
        for x in v.position.iter().chain(&v.normal).chain(&v.color) {
            out.extend_from_slice(&x.to_le_bytes());
        }
    }
    out
}

/// The direction towards the light (unit, world space): from above, in front of the
/// character and to its left, so a figure facing the default camera is lit on its front.
/// The GPU renderers hand these numbers to `shaders/viewer.wgsl`.
pub const LIGHT: V3 = [0.381_385, 0.808_536, 0.448_123];
/// Light every surface gets, whichever way it faces.
pub const AMBIENT: f32 = 0.38;
/// Light from the sky: full on surfaces facing up, none on those facing down, so the parts
/// the light does not reach still show their shape.
pub const SKY: f32 = 0.17;
/// The directional light's strength on a surface facing it.
pub const DIFFUSE: f32 = 0.6;

/// How bright a surface with `normal` is (1: its colour as it is; above 1 brightens, the
/// colour is clamped later): ambient + sky + directional light. A zero normal means "not
/// lit" and gives 1. The shader computes the same per pixel; the 2D renderer per triangle.
pub fn shade(normal: V3) -> f32 {
    let n = normalize(normal);
    if n == [0.0, 0.0, 0.0] {
        return 1.0;
    }
    AMBIENT + SKY * (0.5 + 0.5 * n[1]) + DIFFUSE * dot(n, LIGHT).max(0.0)
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

    /// Back to the default angle and distance, looking at `target_xz` (x, z metres) at the
    /// default height (the "Reset view" button).
    pub fn reset(&mut self, target_xz: [f32; 2]) {
        let fov = self.fov;
        *self = OrbitCamera {
            fov,
            ..OrbitCamera::default()
        };
        if target_xz.iter().all(|v| v.is_finite()) {
            self.target[0] = target_xz[0];
            self.target[2] = target_xz[1];
        }
    }

    /// Moves the target over the ground towards `xz` (the root), a share `amount` (0..1) of
    /// the way, so the camera follows the character smoothly.
    pub fn follow(&mut self, xz: [f32; 2], amount: f32) {
        let amount = if amount.is_finite() {
            amount.clamp(0.0, 1.0)
        } else {
            0.0
        };
        if xz.iter().all(|v| v.is_finite()) {
            self.target[0] += (xz[0] - self.target[0]) * amount;
            self.target[2] += (xz[1] - self.target[2]) * amount;
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

/// The page's background behind the scene (linear 0–1 sRGB values as the canvas shows them).
pub const BACKGROUND: [f32; 3] = [0.93, 0.945, 0.965];

/// What one frame draws, in the order it is drawn: the lines (grid, the root's path, a
/// stroke being drawn), the contact shadows, then the figure's triangles.
pub struct Frame<'a> {
    pub view_projection: Mat4,
    /// Where the camera is, for the 2D renderer's back-face test.
    pub eye: V3,
    pub lines: &'a [Vertex],
    pub shadows: &'a [Shadow],
    pub body: &'a [Vertex],
    /// The part of each body triangle (see [`figure`]) for the 2D renderer's sort; empty when
    /// the body has no parts.
    pub body_parts: &'a [u16],
}

/// The normal of what is not lit.
pub const UNLIT: V3 = [0.0, 0.0, 0.0];

/// Where `p` shows on a picture `size` = [width, height] pixels (x from the left edge, y down
/// from the top), or `None` when it is behind the camera (or not a number).
pub fn screen_point(m: &Mat4, p: V3, size: [f32; 2]) -> Option<[f32; 2]> {
    let c = project(m, p);
    if c[3].is_nan() || c[3] <= NEAR_W {
        return None;
    }
    let out = [
        (c[0] / c[3] + 1.0) * 0.5 * size[0],
        (1.0 - c[1] / c[3]) * 0.5 * size[1],
    ];
    out.iter().all(|v| v.is_finite()).then_some(out)
}

/// Points nearer the camera than this (clip w, metres along the view) are not drawn by the
/// 2D renderer: the projection's near plane.
pub const NEAR_W: f32 = 0.05;

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
            normal: UNLIT,
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
                normal: UNLIT,
                color,
            });
        }
    }
    out
}

/// A body-part colour as the shaded figure's tint: the limbs' colours lightened a little and
/// the torso's dark grey a lot, so shading shows on every part.
pub fn tint(c: [u8; 3], torso: bool) -> [f32; 4] {
    let (towards, share) = if torso {
        ([200.0, 196.0, 190.0], 0.55)
    } else {
        ([245.0, 240.0, 232.0], 0.2)
    };
    let mix = |i: usize| (c[i] as f32 * (1.0 - share) + towards[i] * share) / 255.0;
    [mix(0), mix(1), mix(2), 1.0]
}

fn is_limb_color(c: [u8; 3]) -> bool {
    coma::render::PART_COLORS.iter().any(|(_, p)| *p == c)
}

/// Triangles of the shaded figure of one pose (22 joints, metres): the body mesh of
/// [`coma::figure::figure_mesh`] (capsules around the bones, a head, hands and feet), lit (every
/// vertex has its normal), each vertex tinted ([`tint`]) with the colour of the body part its
/// joint belongs to. Triangles with a corner that is not a number (from joints that are not)
/// are left out.
pub fn figure_triangles(pose: &[V3; 22]) -> Vec<Vertex> {
    figure(pose).0
}

/// [`figure_triangles`] with the part of each triangle: the figure's capsules are laid out one
/// after another, each carried by one joint, so a new part starts wherever the joint changes.
pub fn figure(pose: &[V3; 22]) -> (Vec<Vertex>, Vec<u16>) {
    let mesh = coma::figure::figure_mesh(pose);
    let vertex = |i: u32| {
        let i = i as usize;
        let (position, normal, joint) = (
            *mesh.positions.get(i)?,
            *mesh.normals.get(i)?,
            *mesh.joints.get(i)? as usize,
        );
        let c = joint_color(joint);
        position
            .iter()
            .chain(&normal)
            .all(|v| v.is_finite())
            .then(|| Vertex {
                position,
                normal,
                color: tint(c, !is_limb_color(c)),
            })
    };
    let mut out = Vec::with_capacity(mesh.indices.len());
    let mut parts = Vec::with_capacity(mesh.indices.len() / 3);
    let (mut part, mut joint) = (0u16, None);
    for tri in mesh.indices.chunks_exact(3) {
        let carrier = mesh.joints.get(tri[0] as usize).copied();
        if joint.is_some() && carrier != joint {
            part = part.saturating_add(1);
        }
        joint = carrier;
        if let (Some(a), Some(b), Some(c)) = (vertex(tri[0]), vertex(tri[1]), vertex(tri[2])) {
            out.extend([a, b, c]);
            parts.push(part);
        }
    }
    (out, parts)
}

/// The figure of one pose as the view shows it: the shaded body with the part of each
/// triangle ([`figure`]), or with `skeleton` the skeleton's ribbons and squares (unlit, turned
/// to `camera`; no parts).
pub fn body_triangles(
    pose: &[V3; 22],
    skeleton: bool,
    camera: &OrbitCamera,
) -> (Vec<Vertex>, Vec<u16>) {
    if skeleton {
        (skeleton_triangles(pose, camera), Vec::new())
    } else {
        figure(pose)
    }
}

/// A soft dark ellipse on the ground: where a foot (or the pelvis) is near the floor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shadow {
    /// Centre on the ground, `[x, z]` metres.
    pub center: [f32; 2],
    /// Unit direction of the long axis on the ground, `[x, z]`.
    pub axis: [f32; 2],
    /// Half the length along `axis` and half the width across it, metres.
    pub radii: [f32; 2],
    /// Opacity at the centre (fading to nothing at the rim).
    pub alpha: f32,
}

/// Height above the floor (metres) at which a foot's shadow has faded away.
pub const SHADOW_FADE_M: f32 = 0.45;
/// Opacity of a planted foot's shadow at its centre.
const FOOT_SHADOW_ALPHA: f32 = 0.55;
/// Opacity of the faint shadow under the pelvis.
const PELVIS_SHADOW_ALPHA: f32 = 0.16;

/// The contact shadows of a pose: one under each foot (along the foot, fading and widening
/// as the foot rises, gone at [`SHADOW_FADE_M`]) and a faint round one under the pelvis.
/// Joints that are not numbers cast none.
pub fn contact_shadows(pose: &[V3; 22]) -> Vec<Shadow> {
    let finite = |p: &V3| p.iter().all(|v| v.is_finite());
    let mut out = Vec::with_capacity(3);
    for (ankle, foot) in [(7, 10), (8, 11)] {
        let (a, f) = (pose[ankle], pose[foot]);
        if !finite(&a) || !finite(&f) {
            continue;
        }
        let height = a[1].min(f[1]).max(0.0);
        let fade = (1.0 - height / SHADOW_FADE_M).clamp(0.0, 1.0);
        if fade <= 0.0 {
            continue;
        }
        let d = [f[0] - a[0], f[2] - a[2]];
        let n = (d[0] * d[0] + d[1] * d[1]).sqrt();
        let axis = if n > 1e-4 {
            [d[0] / n, d[1] / n]
        } else {
            [0.0, 1.0]
        };
        let spread = 1.0 + height * 1.5;
        out.push(Shadow {
            center: [(a[0] + f[0]) * 0.5, (a[2] + f[2]) * 0.5],
            axis,
            radii: [(0.5 * n + 0.07) * spread, 0.075 * spread],
            alpha: FOOT_SHADOW_ALPHA * fade,
        });
    }
    let pelvis = pose[0];
    if finite(&pelvis) {
        out.push(Shadow {
            center: [pelvis[0], pelvis[2]],
            axis: [1.0, 0.0],
            radii: [0.24, 0.24],
            alpha: PELVIS_SHADOW_ALPHA,
        });
    }
    out
}

/// Height of the shadows over the ground (metres): above the grid so they darken it, below
/// the paths so those stay clear.
const SHADOW_Y: f32 = 0.001;
/// Points around a shadow's rim.
const SHADOW_POINTS: usize = 24;

impl Shadow {
    /// The ground point at angle `t` (radians) on the ellipse scaled by `k` (1: the rim).
    pub fn rim_point(&self, t: f32, k: f32) -> V3 {
        let [ax, az] = self.axis;
        let (a, b) = (self.radii[0] * k * t.cos(), self.radii[1] * k * t.sin());
        [
            self.center[0] + a * ax - b * az,
            SHADOW_Y,
            self.center[1] + a * az + b * ax,
        ]
    }

    /// The ellipse scaled by `k` as a closed outline of points (for the 2D renderer).
    pub fn outline(&self, k: f32) -> Vec<V3> {
        (0..SHADOW_POINTS)
            .map(|i| self.rim_point(i as f32 / SHADOW_POINTS as f32 * std::f32::consts::TAU, k))
            .collect()
    }
}

/// The shadows as triangle fans, black at each centre with the shadow's opacity and clear
/// at the rim, so the GPU's blending makes the edge soft. Not lit.
pub fn shadow_triangles(shadows: &[Shadow]) -> Vec<Vertex> {
    let mut out = Vec::with_capacity(shadows.len() * SHADOW_POINTS * 3);
    for s in shadows {
        let centre = Vertex {
            position: [s.center[0], SHADOW_Y, s.center[1]],
            normal: UNLIT,
            color: [0.0, 0.0, 0.0, s.alpha],
        };
        let rim = s.outline(1.0);
        for i in 0..rim.len() {
            out.push(centre);
            for p in [rim[i], rim[(i + 1) % rim.len()]] {
                out.push(Vertex {
                    position: p,
                    normal: UNLIT,
                    color: [0.0, 0.0, 0.0, 0.0],
                });
            }
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
            out.push(Vertex {
                position: a,
                normal: UNLIT,
                color,
            });
            out.push(Vertex {
                position: b,
                normal: UNLIT,
                color,
            });
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
                normal: UNLIT,
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
                normal: UNLIT,
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
    #[test]
    fn light_falls_on_surfaces_facing_it_and_unlit_ones_keep_their_colour() {
        assert_eq!(shade(UNLIT), 1.0);
        let towards = shade(LIGHT);
        let away = shade(scale(LIGHT, -1.0));
        assert!((towards - (AMBIENT + SKY * (0.5 + 0.5 * LIGHT[1]) + DIFFUSE)).abs() < 1e-5);
        assert!((AMBIENT..0.45).contains(&away), "{away}");
        assert!(shade([0.0, 1.0, 0.0]) > shade([0.0, -1.0, 0.0]));
        // Lengths do not matter, only directions.
        assert!((shade([0.0, 0.0, 3.0]) - shade([0.0, 0.0, 1.0])).abs() < 1e-6);
        assert!((dot(LIGHT, LIGHT) - 1.0).abs() < 1e-5);
    }

    /// A person standing at `at` (x, z) with the feet on the floor and the arms held out
    /// sideways (a T-pose), joints roughly placed.
    fn standing(at: [f32; 2]) -> [V3; 22] {
        // x (left is +X: the character faces +Z), y per joint.
        let xy: [[f32; 2]; 22] = [
            [0.0, 0.93],
            [0.1, 0.88],
            [-0.1, 0.88],
            [0.0, 1.05],
            [0.1, 0.5],
            [-0.1, 0.5],
            [0.0, 1.2],
            [0.1, 0.08],
            [-0.1, 0.08],
            [0.0, 1.3],
            [0.1, 0.02],
            [-0.1, 0.02],
            [0.0, 1.5],
            [0.08, 1.42],
            [-0.08, 1.42],
            [0.0, 1.6],
            [0.2, 1.4],
            [-0.2, 1.4],
            [0.45, 1.4],
            [-0.45, 1.4],
            [0.7, 1.4],
            [-0.7, 1.4],
        ];
        std::array::from_fn(|j| {
            // The feet's toe joints in front of the ankles.
            let forward = if j == 10 || j == 11 { 0.12 } else { 0.0 };
            [at[0] + xy[j][0], xy[j][1], at[1] + forward]
        })
    }

    #[test]
    fn planted_feet_cast_dark_shadows_that_fade_and_spread_as_they_rise() {
        let mut pose = standing([1.0, 2.0]);
        let planted = contact_shadows(&pose);
        assert_eq!(planted.len(), 3, "{planted:?}");
        // The left foot's shadow: under it, along it (+Z), nearly the full opacity.
        let left = planted[0];
        assert!((left.center[0] - 1.1).abs() < 1e-5 && (left.center[1] - 2.06).abs() < 1e-5);
        assert!((left.axis[1] - 1.0).abs() < 1e-5);
        assert!(left.alpha > 0.9 * FOOT_SHADOW_ALPHA);
        // The pelvis's: faint and round.
        assert_eq!(planted[2].alpha, PELVIS_SHADOW_ALPHA);
        assert_eq!(planted[2].radii[0], planted[2].radii[1]);
        // The left foot 20 cm up: fainter and wider; at the fade height, gone.
        for j in [7, 10] {
            pose[j][1] += 0.2;
        }
        let raised = contact_shadows(&pose);
        assert!(raised[0].alpha < 0.7 * left.alpha && raised[0].radii[1] > left.radii[1]);
        assert_eq!(raised[1], planted[1], "the right foot did not move");
        for j in [7, 10] {
            pose[j][1] = SHADOW_FADE_M + 0.1;
        }
        assert_eq!(contact_shadows(&pose).len(), 2);
    }

    #[test]
    fn shadow_fans_are_dark_in_the_middle_and_clear_at_the_rim() {
        let shadows = contact_shadows(&standing([0.0, 0.0]));
        let tris = shadow_triangles(&shadows);
        assert_eq!(tris.len(), shadows.len() * SHADOW_POINTS * 3);
        for (fan, s) in tris.chunks(SHADOW_POINTS * 3).zip(&shadows) {
            assert_eq!(fan[0].color, [0.0, 0.0, 0.0, s.alpha]);
            assert_eq!(fan[1].color[3], 0.0);
            assert!(fan
                .iter()
                .all(|v| v.position[1] == SHADOW_Y && v.normal == UNLIT));
            // Rim points lie on the ellipse: along the axis at the long radius.
            let p = s.rim_point(0.0, 1.0);
            let d = [p[0] - s.center[0], p[2] - s.center[1]];
            assert!(((d[0] * d[0] + d[1] * d[1]).sqrt() - s.radii[0]).abs() < 1e-5);
        }
    }

    #[test]
    fn the_figure_has_outward_normals_and_part_tints() {
        let pose = standing([0.0, 0.0]);
        let body = figure_triangles(&pose);
        assert_eq!(body.len() % 3, 0);
        assert!(body.len() > 3000, "{}", body.len());
        for v in &body {
            assert!((dot(v.normal, v.normal) - 1.0).abs() < 1e-3, "{v:?}");
            assert!(v.position.iter().all(|c| c.is_finite()));
        }
        // Every vertex's normal points away from the body's nearest joint or bone axis:
        // the skull's top faces up, the left hand's outside faces +X.
        let top = body
            .iter()
            .max_by(|a, b| a.position[1].total_cmp(&b.position[1]))
            .unwrap();
        assert!(top.normal[1] > 0.9, "{top:?}");
        let outer = body
            .iter()
            .max_by(|a, b| a.position[0].total_cmp(&b.position[0]))
            .unwrap();
        assert!(outer.normal[0] > 0.5, "{outer:?}");
        // The left arm's vertices carry its orange, lightened.
        assert_eq!(outer.color, tint([238, 128, 16], false));
        // The torso's grey is lightened more than a limb's colour.
        let torso = tint(coma::render::TORSO_COLOR, true);
        assert!(torso[0] > 0.5 && torso[0] < 0.65, "{torso:?}");
        // The skeleton toggle: unlit ribbons instead.
        let camera = OrbitCamera::default();
        let (sticks, no_parts) = body_triangles(&pose, true, &camera);
        assert!(sticks.iter().all(|v| v.normal == UNLIT) && no_parts.is_empty());
        let (shaded, parts) = body_triangles(&pose, false, &camera);
        assert_eq!(shaded, body);
        // One part per capsule of the mesh, numbered in order.
        assert_eq!(parts.len(), body.len() / 3);
        assert_eq!(parts.first(), Some(&0));
        assert!(parts.windows(2).all(|w| w[1] == w[0] || w[1] == w[0] + 1));
        assert!(*parts.last().unwrap() >= 20, "{:?}", parts.last());
    }

    #[test]
    fn reset_and_follow_move_the_camera_to_the_character() {
        let mut c = OrbitCamera::default();
        c.orbit(1.0, 0.5);
        c.zoom(3.0);
        c.reset([2.0, -1.0]);
        assert_eq!(
            c,
            OrbitCamera {
                target: [2.0, 0.9, -1.0],
                ..OrbitCamera::default()
            }
        );
        c.follow([4.0, 1.0], 0.5);
        assert_eq!(c.target, [3.0, 0.9, 0.0]);
        c.follow([f32::NAN, 0.0], 1.0);
        c.follow([9.0, 9.0], f32::NAN);
        assert_eq!(c.target, [3.0, 0.9, 0.0]);
        c.follow([5.0, 2.0], 7.0);
        assert_eq!(c.target, [5.0, 0.9, 2.0]);
    }

    #[test]
    fn screen_points_follow_the_camera_and_skip_what_is_behind_it() {
        let camera = OrbitCamera::default();
        let m = camera.view_projection(2.0);
        let centre = screen_point(&m, camera.target, [800.0, 400.0]).unwrap();
        assert!((centre[0] - 400.0).abs() < 1e-3 && (centre[1] - 200.0).abs() < 1e-3);
        let above = screen_point(&m, add(camera.target, [0.0, 0.5, 0.0]), [800.0, 400.0]);
        assert!(above.unwrap()[1] < 200.0);
        let behind = add(camera.eye(), sub(camera.eye(), camera.target));
        assert_eq!(screen_point(&m, behind, [800.0, 400.0]), None);
        assert_eq!(screen_point(&m, [f32::NAN; 3], [800.0, 400.0]), None);
    }
}
