//! What the Canvas 2D renderer paints, as plain data: the scene's triangles projected with the
//! same camera as the GPU renderers, the ones facing away dropped, the rest sorted back to
//! front (the painter's algorithm stands in for a depth buffer) and flat-shaded per triangle
//! with the same light ([`shade`]); lines projected and cut where they pass behind the camera.
//! No browser here, so it is tested natively; `canvas2d` only fills what this returns.

use super::scene::{project, screen_point, shade, Mat4, Shadow, Vertex, NEAR_W};

type V3 = [f32; 3];

/// One triangle to fill, in picture pixels (x right, y down).
#[derive(Clone, Debug, PartialEq)]
pub struct FlatTriangle {
    pub points: [[f32; 2]; 3],
    /// Mean distance from the camera along its view (clip w), for the sort.
    pub depth: f32,
    /// sRGB colour after shading, 0–255, and opacity 0–1.
    pub rgb: [u8; 3],
    pub alpha: f32,
}

/// One line to stroke, in picture pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct FlatLine {
    pub from: [f32; 2],
    pub to: [f32; 2],
    pub rgb: [u8; 3],
}

fn to_u8(c: f32) -> u8 {
    (c.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// The triangles of `vertices` (a triangle list) as the picture shows them, back to front:
/// each is skipped when a corner is behind the camera's near plane or not a number, or when
/// it is lit (non-zero normals) and its mean normal faces away from the camera at `eye`;
/// its colour is the corners' mean colour times [`shade`] of their mean normal.
pub fn flat_triangles(vertices: &[Vertex], m: &Mat4, eye: V3, size: [f32; 2]) -> Vec<FlatTriangle> {
    flat_parts(vertices, &[], m, eye, size)
}

/// [`flat_triangles`] of a body made of parts (`parts`: one number per triangle, the same for
/// the triangles of one closed part, such as one capsule of the figure): whole parts are
/// painted back to front by the mean depth of their visible triangles, and each part's
/// triangles back to front within it. Parts that pass into each other (a thigh into the
/// pelvis) then paint as wholes, instead of the inner triangles of one showing through the
/// other where a triangle-by-triangle sort misorders them. With fewer numbers than triangles,
/// each triangle is its own part.
pub fn flat_parts(
    vertices: &[Vertex],
    parts: &[u16],
    m: &Mat4,
    eye: V3,
    size: [f32; 2],
) -> Vec<FlatTriangle> {
    let grouped = parts.len() == vertices.len() / 3;
    let mut out = Vec::with_capacity(vertices.len() / 3);
    let mut part_of = Vec::with_capacity(vertices.len() / 3);
    for (i, tri) in vertices.chunks_exact(3).enumerate() {
        let normal = sum(tri.iter().map(|v| v.normal));
        if normal != [0.0, 0.0, 0.0] {
            let centre = scale(sum(tri.iter().map(|v| v.position)), 1.0 / 3.0);
            let to_eye = [eye[0] - centre[0], eye[1] - centre[1], eye[2] - centre[2]];
            if dot(normal, to_eye) < 0.0 {
                continue;
            }
        }
        let mut points = [[0.0f32; 2]; 3];
        let mut depth = 0.0;
        let mut visible = true;
        for (point, v) in points.iter_mut().zip(tri) {
            match screen_point(m, v.position, size) {
                Some(p) => {
                    *point = p;
                    depth += project(m, v.position)[3] / 3.0;
                }
                None => visible = false,
            }
        }
        if !visible {
            continue;
        }
        part_of.push(if grouped { Some(parts[i]) } else { None });
        let k = shade(normal);
        let color: [f32; 4] =
            std::array::from_fn(|i| tri.iter().map(|v| v.color[i]).sum::<f32>() / 3.0);
        out.push(FlatTriangle {
            points,
            depth,
            rgb: [
                to_u8(color[0] * k),
                to_u8(color[1] * k),
                to_u8(color[2] * k),
            ],
            alpha: color[3].clamp(0.0, 1.0),
        });
    }
    // Each triangle's sort key: its part's mean depth (its own without parts), then its own.
    let mut sums = std::collections::HashMap::<u16, (f32, u32)>::new();
    for (t, part) in out.iter().zip(&part_of) {
        if let Some(p) = part {
            let e = sums.entry(*p).or_insert((0.0, 0));
            *e = (e.0 + t.depth, e.1 + 1);
        }
    }
    let mut keyed: Vec<(f32, FlatTriangle)> = out
        .into_iter()
        .zip(part_of)
        .map(|(t, part)| {
            let key = part
                .and_then(|p| sums.get(&p))
                .map_or(t.depth, |(sum, n)| sum / *n as f32);
            (key, t)
        })
        .collect();
    // Far first, so nearer ones paint over them. total_cmp: no NaN reaches here (the corners
    // are finite), and it keeps the sort from panicking if one did.
    keyed.sort_by(|a, b| b.0.total_cmp(&a.0).then(b.1.depth.total_cmp(&a.1.depth)));
    keyed.into_iter().map(|(_, t)| t).collect()
}

/// The segments of `vertices` (a line list) as the picture shows them; a segment that passes
/// behind the camera is cut at the near plane, one wholly behind it is dropped.
pub fn flat_lines(vertices: &[Vertex], m: &Mat4, size: [f32; 2]) -> Vec<FlatLine> {
    let mut out = Vec::with_capacity(vertices.len() / 2);
    for pair in vertices.chunks_exact(2) {
        let (a, b) = (project(m, pair[0].position), project(m, pair[1].position));
        let ahead = |w: f32| w > NEAR_W;
        if !ahead(a[3]) && !ahead(b[3]) {
            continue;
        }
        // Cut at w = NEAR_W, in clip space, where the projection is still linear.
        let cut = |inside: [f32; 4], outside: [f32; 4]| {
            let t = (inside[3] - NEAR_W) / (inside[3] - outside[3]);
            std::array::from_fn::<f32, 4, _>(|i| inside[i] + (outside[i] - inside[i]) * t)
        };
        let (a, b) = if !ahead(a[3]) {
            (cut(b, a), b)
        } else if !ahead(b[3]) {
            (a, cut(a, b))
        } else {
            (a, b)
        };
        let pixel = |c: [f32; 4]| {
            [
                (c[0] / c[3] + 1.0) * 0.5 * size[0],
                (1.0 - c[1] / c[3]) * 0.5 * size[1],
            ]
        };
        let (from, to) = (pixel(a), pixel(b));
        if from.iter().chain(&to).all(|v| v.is_finite()) {
            let c = pair[0].color;
            out.push(FlatLine {
                from,
                to,
                rgb: [to_u8(c[0]), to_u8(c[1]), to_u8(c[2])],
            });
        }
    }
    out
}

/// Rings of one shadow for the 2D renderer: the ellipse at a few shrinking sizes, each filled
/// with a share of the shadow's opacity, so stacked they darken towards the centre and the
/// edge is soft, as the GPU's fans are. Each ring is its outline in picture pixels and its
/// opacity; rings with a point behind the camera are left out.
pub fn shadow_rings(shadow: &Shadow, m: &Mat4, size: [f32; 2]) -> Vec<(Vec<[f32; 2]>, f32)> {
    const RINGS: usize = 4;
    (0..RINGS)
        .filter_map(|i| {
            let k = 1.0 - i as f32 / RINGS as f32;
            let outline: Option<Vec<[f32; 2]>> = shadow
                .outline(k)
                .into_iter()
                .map(|p| screen_point(m, p, size))
                .collect();
            outline.map(|o| (o, shadow.alpha / RINGS as f32))
        })
        .collect()
}

fn sum(vs: impl Iterator<Item = V3>) -> V3 {
    vs.fold([0.0; 3], |a, v| [a[0] + v[0], a[1] + v[1], a[2] + v[2]])
}
fn scale(a: V3, s: f32) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::viewer::scene::{contact_shadows, figure_triangles, OrbitCamera, UNLIT};

    fn lit(position: V3, normal: V3) -> Vertex {
        Vertex {
            position,
            normal,
            color: [0.5, 0.5, 0.5, 1.0],
        }
    }

    /// The default camera turned to look at the character's face, level (from +Z).
    fn facing_camera() -> OrbitCamera {
        OrbitCamera {
            yaw: 0.0,
            pitch: 0.0,
            ..OrbitCamera::default()
        }
    }

    /// A small unlit triangle around `target`, `z` metres towards the facing camera.
    fn unlit_triangle(target: V3, z: f32) -> [Vertex; 3] {
        [[-0.1, -0.1, z], [0.1, -0.1, z], [0.0, 0.1, z]].map(|d| {
            lit(
                [target[0] + d[0], target[1] + d[1], target[2] + d[2]],
                UNLIT,
            )
        })
    }

    #[test]
    fn nearer_triangles_come_last_and_the_target_lands_in_the_middle() {
        let camera = facing_camera();
        let m = camera.view_projection(1.0);
        let t = camera.target;
        // Two unlit triangles around the target, one 1 m nearer the camera (+Z).
        let tri = |z: f32| unlit_triangle(t, z);
        let mut vertices = tri(1.0).to_vec();
        vertices.extend(tri(0.0));
        let flat = flat_triangles(&vertices, &m, camera.eye(), [200.0, 100.0]);
        assert_eq!(flat.len(), 2);
        assert!(flat[0].depth > flat[1].depth, "{flat:?}");
        // The nearer one (z = 1) is painted last and looks larger.
        let width = |f: &FlatTriangle| f.points[1][0] - f.points[0][0];
        assert!(width(&flat[1]) > width(&flat[0]));
        let centre = screen_point(&m, t, [200.0, 100.0]).unwrap();
        assert!((centre[0] - 100.0).abs() < 1e-3 && (centre[1] - 50.0).abs() < 1e-3);
    }

    #[test]
    fn faces_turned_away_are_dropped_and_lit_faces_are_shaded() {
        let camera = facing_camera();
        let m = camera.view_projection(1.0);
        let t = camera.target;
        let tri = |normal: V3| {
            [[-0.1, -0.1], [0.1, -0.1], [0.0, 0.1]]
                .map(|d| lit([t[0] + d[0], t[1] + d[1], t[2]], normal))
        };
        // The camera looks from +Z: a face whose normal is -Z faces away.
        assert!(
            flat_triangles(&tri([0.0, 0.0, -1.0]), &m, camera.eye(), [100.0, 100.0]).is_empty()
        );
        let front = flat_triangles(&tri([0.0, 0.0, 1.0]), &m, camera.eye(), [100.0, 100.0]);
        let up = flat_triangles(&tri([0.0, 1.0, 0.1]), &m, camera.eye(), [100.0, 100.0]);
        assert_eq!((front.len(), up.len()), (1, 1));
        let expect = |n: V3| to_u8(0.5 * shade(n));
        assert_eq!(front[0].rgb[0], expect([0.0, 0.0, 1.0]));
        // The light comes from above: a face turned up is brighter than one facing front.
        assert!(up[0].rgb[0] > front[0].rgb[0], "{up:?} {front:?}");
    }

    #[test]
    fn a_triangle_behind_the_camera_is_skipped_and_a_line_through_it_is_cut() {
        let camera = OrbitCamera::default();
        let m = camera.view_projection(1.5);
        let eye = camera.eye();
        let behind = [eye[0] * 2.0, eye[1], eye[2] * 2.0];
        let tri = [
            lit(behind, UNLIT),
            lit(camera.target, UNLIT),
            lit([0.0, 0.0, 0.0], UNLIT),
        ];
        assert!(flat_triangles(&tri, &m, eye, [300.0, 200.0]).is_empty());
        let line = [lit(behind, UNLIT), lit(camera.target, UNLIT)];
        let flat = flat_lines(&line, &m, [300.0, 200.0]);
        assert_eq!(flat.len(), 1);
        assert!((flat[0].to[0] - 150.0).abs() < 1e-2 && (flat[0].to[1] - 100.0).abs() < 1e-2);
        assert!(flat[0].from.iter().all(|v| v.is_finite()));
        assert!(flat_lines(
            &[lit(behind, UNLIT), lit(behind, UNLIT)],
            &m,
            [300.0, 200.0]
        )
        .is_empty());
    }

    #[test]
    fn the_figure_paints_around_its_root_and_bad_joints_paint_nothing() {
        let camera = OrbitCamera::default();
        let m = camera.view_projection(1.0);
        let mut pose = [[0.0f32; 3]; 22];
        for (j, p) in pose.iter_mut().enumerate() {
            *p = [(j % 3) as f32 * 0.1 - 0.1, 0.1 + j as f32 * 0.07, 0.0];
        }
        let flat = flat_triangles(&figure_triangles(&pose), &m, camera.eye(), [400.0, 400.0]);
        assert!(flat.len() > 500, "{}", flat.len());
        let root = screen_point(&m, pose[0], [400.0, 400.0]).unwrap();
        assert!(flat.iter().any(|f| f
            .points
            .iter()
            .all(|p| (p[0] - root[0]).abs() < 40.0 && (p[1] - root[1]).abs() < 40.0)));
        let broken = [[f32::NAN; 3]; 22];
        assert!(figure_triangles(&broken).is_empty());
        assert!(contact_shadows(&broken).is_empty());
    }

    #[test]
    fn shadow_rings_stack_to_the_shadows_opacity() {
        let camera = OrbitCamera::default();
        let m = camera.view_projection(1.0);
        let shadow = Shadow {
            center: [0.0, 0.0],
            axis: [0.0, 1.0],
            radii: [0.2, 0.1],
            alpha: 0.4,
        };
        let rings = shadow_rings(&shadow, &m, [100.0, 100.0]);
        assert_eq!(rings.len(), 4);
        let total: f32 = rings.iter().map(|r| r.1).sum();
        assert!((total - 0.4).abs() < 1e-6);
        // Each ring is inside the one before it: its leftmost point is further right.
        let left = |o: &Vec<[f32; 2]>| o.iter().map(|p| p[0]).fold(f32::INFINITY, f32::min);
        assert!(rings.windows(2).all(|w| left(&w[1].0) > left(&w[0].0)));
    }

    #[test]
    fn whole_parts_paint_back_to_front() {
        let camera = facing_camera();
        let m = camera.view_projection(1.0);
        let t = camera.target;
        let tri = |z: f32| unlit_triangle(t, z);
        // Part 0: triangles at z = 0 and z = 0.6 (mean 0.3); part 1: one at z = 0.4, whose own
        // depth lies between part 0's two.
        let vertices: Vec<Vertex> = [tri(0.0), tri(0.6), tri(0.4)].concat();
        let eye = camera.eye();
        let by_triangle = flat_triangles(&vertices, &m, eye, [100.0, 100.0]);
        let by_part = flat_parts(&vertices, &[0, 0, 1], &m, eye, [100.0, 100.0]);
        let order = |f: &[FlatTriangle]| f.iter().map(|t| t.depth).collect::<Vec<_>>();
        let d = |z: f32| camera.distance - z;
        let close = |a: Vec<f32>, b: [f32; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-3);
        assert!(close(order(&by_triangle), [d(0.0), d(0.4), d(0.6)]));
        // Part 0 (further on average) first, whole, far to near; then part 1.
        assert!(
            close(order(&by_part), [d(0.0), d(0.6), d(0.4)]),
            "{by_part:?}"
        );
        // Parts that do not match the triangles are ignored.
        assert_eq!(
            flat_parts(&vertices, &[0], &m, eye, [100.0, 100.0]),
            by_triangle
        );
    }
}
