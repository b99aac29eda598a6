//! Filmstrips: a motion drawn as a grid of stick-figure snapshots in one PNG, so that anyone can
//! look at what the data and the models produce.
//!
//! Every cell shows one frame, sampled evenly over the motion (first and last frame included),
//! with an orthographic projection of the chosen [`View`]. Limbs have their own colours
//! ([`PART_COLORS`]: warm colours on the character's left, cool ones on its right), the torso
//! is dark grey, the head a light circle with eyes on the side it faces, the ground is a faint grid (or a line when the camera is level) and
//! the pelvis's path over the whole motion is drawn on the ground. Each cell is centred on that
//! frame's pelvis so a walking figure stays in view, while the scale is shared by all cells so
//! that sizes can be compared.
//!
//! Projection: the image shows what a person standing where the camera is would see. In
//! [`View::Front`] the viewer stands on +Z looking towards -Z, face to face with a character
//! that faces +Z; the character's left (+X) is then on the viewer's right, so world +X goes to
//! the image's right, exactly as your friend's left hand is on your right when you face them.

mod draw;
pub(crate) mod font;
pub mod plot;

use std::path::{Path, PathBuf};

use tiny_skia::{PathBuilder, Pixmap, PixmapPaint, Rect, Stroke, Transform};

use crate::geom::{self, Vec3};
use crate::skeleton::{joint, BodyPart, Pose, JOINT_NAMES, PARENTS};

use crate::timing::FPS;

use draw::{color, draw_text, fill_circle, paint, stroke_circle, stroke_line, stroke_polyline};

/// Colour of each limb (sRGB). Warm colours are on the character's left and cool ones on its
/// right, so sides can be told apart at a glance even where the colours are hard to name.
pub const PART_COLORS: [(BodyPart, [u8; 3]); 4] = [
    (BodyPart::LeftArm, [238, 128, 16]),
    (BodyPart::RightArm, [36, 104, 214]),
    (BodyPart::LeftLeg, [206, 30, 52]),
    (BodyPart::RightLeg, [30, 150, 70]),
];

/// Colour of the torso, neck and head outline (sRGB): neutral, so the limbs stand out.
pub const TORSO_COLOR: [u8; 3] = [70, 70, 76];

const HEAD_FILL: [u8; 3] = [234, 230, 222];
const PAGE_BACKGROUND: [u8; 3] = [255, 255, 255];
const CELL_BACKGROUND: [u8; 3] = [250, 250, 247];
const CELL_BORDER: [u8; 3] = [214, 214, 208];
const GROUND_COLOR: [u8; 3] = [110, 110, 104];
const PATH_COLOR: [u8; 3] = [70, 110, 170];
const TITLE_COLOR: [u8; 3] = [30, 30, 30];
const LABEL_COLOR: [u8; 3] = [100, 100, 100];

/// Head radius in metres; the head joint of SMPL sits low in the skull, so the circle's centre
/// is moved up from it by [`HEAD_LIFT`] along the neck.
const HEAD_RADIUS: f64 = 0.1;
const HEAD_LIFT: f64 = 0.06;

/// Spacing of the ground grid and how far from the pelvis it is drawn (metres). The grid is
/// finite because an orthographic view of an endless floor would fill the whole cell.
const GRID_STEP: f64 = 0.5;
const GRID_RADIUS: f64 = 2.5;

/// Coordinates beyond this many metres are not a plausible motion; rejecting them keeps the
/// arithmetic far from overflow.
const MAX_COORDINATE: f64 = 1.0e4;

/// Allowed cell sizes in pixels: smaller cells cannot hold a legible label, larger ones are
/// surely a mistake.
const MIN_CELL: u32 = 32;
const MAX_CELL: u32 = 4096;

/// Largest image in pixels (256 MiB of RGBA), so a typo cannot exhaust memory.
const MAX_PIXELS: u64 = 1 << 26;

/// The direction the camera looks at the character from. All views are orthographic and
/// described for a character facing +Z (the start of every motion).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum View {
    /// From +Z towards -Z, level: face to face with the character, whose left arm appears on
    /// the image's right.
    Front,
    /// From +X towards -X, level: the character's left side; a character facing +Z faces the
    /// image's left.
    Side,
    /// From in front of the character and to its left (35° round from the front), raised by
    /// 15° and looking slightly down: the face side, depth and the ground are all visible.
    #[default]
    ThreeQuarter,
}

impl View {
    /// All views.
    pub const ALL: [View; 3] = [View::Front, View::Side, View::ThreeQuarter];

    /// The view's name as a user types it ("front", "side", "three-quarter").
    pub fn name(self) -> &'static str {
        match self {
            View::Front => "front",
            View::Side => "side",
            View::ThreeQuarter => "three-quarter",
        }
    }

    /// Parses a view name, case-insensitively; `_`, spaces and a missing hyphen are accepted
    /// ("three_quarter", "ThreeQuarter"), and so is "3/4".
    pub fn parse(text: &str) -> Option<View> {
        let t: String = text
            .trim()
            .to_ascii_lowercase()
            .chars()
            .filter(|c| !matches!(c, '-' | '_' | ' '))
            .collect();
        match t.as_str() {
            "front" => Some(View::Front),
            "side" => Some(View::Side),
            "threequarter" | "3/4" => Some(View::ThreeQuarter),
            _ => None,
        }
    }

    /// Camera azimuth (radians round from +Z towards +X, the character's left) and elevation.
    fn angles(self) -> (f64, f64) {
        match self {
            View::Front => (0.0, 0.0),
            View::Side => (std::f64::consts::FRAC_PI_2, 0.0),
            View::ThreeQuarter => (35f64.to_radians(), 15f64.to_radians()),
        }
    }
}

/// How to draw a filmstrip.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FilmstripOptions {
    /// Number of cells (frames shown); a motion with fewer frames shows each frame once.
    /// Default 8.
    pub frames: usize,
    /// Cells per row. Default 4.
    pub columns: usize,
    /// Side of a square cell in pixels, 32 to 4096. Default 256.
    pub cell_size: u32,
    /// Text drawn above the grid, wrapped onto at most three lines; characters outside
    /// printable ASCII are drawn as `?`.
    pub title: Option<String>,
    /// The camera direction. Default [`View::ThreeQuarter`].
    pub view: View,
}

impl Default for FilmstripOptions {
    fn default() -> Self {
        FilmstripOptions {
            frames: 8,
            columns: 4,
            cell_size: 256,
            title: None,
            view: View::default(),
        }
    }
}

impl FilmstripOptions {
    /// Width and height in pixels of the filmstrip of a motion of `num_frames` frames.
    pub fn image_size(&self, num_frames: usize) -> Result<(u32, u32), RenderError> {
        if num_frames == 0 {
            return Err(RenderError::EmptyMotion);
        }
        let layout = Layout::new(self, num_frames)?;
        Ok((layout.width, layout.height))
    }
}

/// Why a filmstrip could not be made.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The motion has no frames.
    #[error("cannot draw an empty motion: it has no frames")]
    EmptyMotion,
    /// A coordinate is NaN or infinite.
    #[error("frame {frame}, joint {joint} ({name}) has a non-finite coordinate ({value})")]
    NonFinite {
        /// Frame index.
        frame: usize,
        /// Joint index.
        joint: usize,
        /// Joint name.
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A coordinate is implausibly far from the origin.
    #[error(
        "frame {frame}, joint {joint} ({name}) has a coordinate of {value} m, beyond the \
         plausible range of ±{MAX_COORDINATE} m"
    )]
    OutOfRange {
        /// Frame index.
        frame: usize,
        /// Joint index.
        joint: usize,
        /// Joint name.
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// The options cannot give an image.
    #[error("invalid filmstrip options: {0}")]
    InvalidOptions(String),
    /// The image would be too large to allocate.
    #[error("a {width}×{height} pixel filmstrip is too large (at most {MAX_PIXELS} pixels)")]
    TooLarge {
        /// Width in pixels.
        width: u64,
        /// Height in pixels.
        height: u64,
    },
    /// The PNG encoder failed.
    #[error("PNG encoding failed: {0}")]
    Png(String),
    /// The PNG file could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The file that could not be written.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
}

/// Draws a filmstrip of `poses` (metres, Y up, 20 fps) and returns it as PNG bytes.
pub fn filmstrip_png(poses: &[Pose], options: &FilmstripOptions) -> Result<Vec<u8>, RenderError> {
    validate_poses(poses)?;
    let layout = Layout::new(options, poses.len())?;
    let mut page = Pixmap::new(layout.width, layout.height).ok_or(RenderError::TooLarge {
        width: layout.width.into(),
        height: layout.height.into(),
    })?;
    page.fill(color(PAGE_BACKGROUND, 255));
    draw_header(&mut page, &layout);

    let camera = Camera::new(options.view);
    let cells = CellStyle::new(layout.cell, layout.text_scale);
    let fit = Fit::new(poses, &camera, &cells);
    let ground_path: Vec<Vec3> = poses
        .iter()
        .map(|p| [p[joint::PELVIS][0], 0.0, p[joint::PELVIS][2]])
        .collect();
    for (k, &t) in sample_frames(poses.len(), layout.cells).iter().enumerate() {
        let cell = draw_cell(&poses[t], t, &ground_path, &camera, &fit, &cells)?;
        // Sizes were bounded by MAX_PIXELS, so the offsets fit an i32.
        let x = (k % layout.columns) as u32 * layout.cell;
        let y = layout.header + (k / layout.columns) as u32 * layout.cell;
        page.draw_pixmap(
            x as i32,
            y as i32,
            cell.as_ref(),
            &PixmapPaint::default(),
            Transform::identity(),
            None,
        );
    }
    page.encode_png()
        .map_err(|e| RenderError::Png(e.to_string()))
}

/// Draws a filmstrip of `poses` and writes it to `path` as a PNG file.
pub fn write_filmstrip(
    path: &Path,
    poses: &[Pose],
    options: &FilmstripOptions,
) -> Result<(), RenderError> {
    let png = filmstrip_png(poses, options)?;
    std::fs::write(path, png).map_err(|source| RenderError::Io {
        path: path.to_path_buf(),
        source,
    })
}

fn validate_poses(poses: &[Pose]) -> Result<(), RenderError> {
    if poses.is_empty() {
        return Err(RenderError::EmptyMotion);
    }
    for (frame, pose) in poses.iter().enumerate() {
        for (j, p) in pose.iter().enumerate() {
            for &value in p {
                let name = JOINT_NAMES[j];
                if !value.is_finite() {
                    return Err(RenderError::NonFinite {
                        frame,
                        joint: j,
                        name,
                        value,
                    });
                }
                if value.abs() > MAX_COORDINATE {
                    return Err(RenderError::OutOfRange {
                        frame,
                        joint: j,
                        name,
                        value,
                    });
                }
            }
        }
    }
    Ok(())
}

/// `cells` frame indices spread evenly over `n` frames, first and last included; distinct
/// whenever `cells <= n`, because consecutive ideal positions are at least one frame apart.
fn sample_frames(n: usize, cells: usize) -> Vec<usize> {
    if cells <= 1 || n <= 1 {
        return vec![0; cells.min(1)];
    }
    let span = cells - 1;
    (0..cells)
        .map(|i| (i * (n - 1) + span / 2) / span)
        .collect()
}

/// An orthographic camera: screen axes in world coordinates.
#[derive(Clone, Copy, Debug)]
struct Camera {
    right: Vec3,
    up: Vec3,
    /// Viewing direction, from the camera into the scene: larger depth is farther away.
    forward: Vec3,
}

impl Camera {
    fn new(view: View) -> Camera {
        let (azimuth, elevation) = view.angles();
        let eye = [
            azimuth.sin() * elevation.cos(),
            elevation.sin(),
            azimuth.cos() * elevation.cos(),
        ];
        let forward = geom::scale(eye, -1.0);
        // forward × up is the viewer's right in a right-handed, Y-up world: looking along -Z
        // it is +X, which is what a person facing -Z has on their right.
        let right = geom::normalize(geom::cross(forward, [0.0, 1.0, 0.0]));
        let up = geom::cross(right, forward);
        Camera { right, up, forward }
    }

    /// `[u, v, depth]`: metres to the right of and above the world origin on screen, and
    /// along the viewing direction.
    fn project(&self, p: Vec3) -> Vec3 {
        [
            geom::dot(p, self.right),
            geom::dot(p, self.up),
            geom::dot(p, self.forward),
        ]
    }

    /// Whether the camera looks horizontally, so the ground plane is seen edge-on.
    fn is_level(&self) -> bool {
        self.forward[1].abs() < 1e-9
    }
}

/// Pixel metrics of a cell, all derived from its size.
struct CellStyle {
    size: u32,
    /// Font pixel size in image pixels.
    text_scale: u32,
    /// Rows reserved at the top for the frame label.
    label_band: f64,
    /// Margin around the figure.
    pad: f64,
}

impl CellStyle {
    fn new(size: u32, text_scale: u32) -> CellStyle {
        let pad = f64::from(3 * text_scale);
        CellStyle {
            size,
            text_scale,
            label_band: 2.0 * pad + f64::from(font::CAP_ROWS * text_scale),
            pad,
        }
    }
}

/// The centre of the head circle: above the head joint along the neck.
fn head_centre(pose: &Pose) -> Vec3 {
    let neck_dir = geom::normalize(geom::sub(pose[joint::HEAD], pose[joint::NECK]));
    let neck_dir = if geom::norm(neck_dir) > 0.0 {
        neck_dir
    } else {
        [0.0, 1.0, 0.0]
    };
    geom::add(pose[joint::HEAD], geom::scale(neck_dir, HEAD_LIFT))
}

/// The point on the ground under the pelvis, which each cell is centred on.
fn anchor(pose: &Pose) -> Vec3 {
    [pose[joint::PELVIS][0], 0.0, pose[joint::PELVIS][2]]
}

/// The scale shared by every cell and where the anchor goes in a cell.
struct Fit {
    /// Pixels per metre.
    scale: f64,
    /// Pixel column of the anchor.
    anchor_x: f64,
    /// Pixel row of the anchor.
    anchor_y: f64,
}

impl Fit {
    /// Fits the extent of the whole motion around its anchors (the tallest and widest poses,
    /// the head circle and the ground) into the cell below its label.
    fn new(poses: &[Pose], camera: &Camera, cells: &CellStyle) -> Fit {
        // Floors keep a degenerate motion (every joint at one point) at a sane scale, and
        // some floor stays visible in front of the feet.
        let (mut half_width, mut top, mut bottom) = (0.3f64, 0.0f64, -0.15f64);
        for pose in poses {
            let a = camera.project(anchor(pose));
            let mut extend = |p: Vec3, radius: f64| {
                let q = camera.project(p);
                half_width = half_width.max((q[0] - a[0]).abs() + radius);
                top = top.max(q[1] - a[1] + radius);
                bottom = bottom.min(q[1] - a[1] - radius);
            };
            for &p in pose {
                extend(p, 0.0);
            }
            extend(head_centre(pose), HEAD_RADIUS);
        }
        let height = top - bottom;
        let size = f64::from(cells.size);
        let avail_h = size - cells.label_band - 2.0 * cells.pad;
        let avail_w = size - 4.0 * cells.pad;
        let scale = (avail_h / height.max(1.0)).min(avail_w / (2.0 * half_width));
        Fit {
            scale,
            anchor_x: size / 2.0,
            anchor_y: cells.label_band + (avail_h - height * scale) / 2.0 + top * scale,
        }
    }
}

/// World to cell pixels for one frame.
struct Screen<'a> {
    camera: &'a Camera,
    fit: &'a Fit,
    anchor: Vec3,
}

impl Screen<'_> {
    /// `(x, y, depth)`: pixel position (y down) and depth in metres (larger is farther).
    fn to_px(&self, p: Vec3) -> (f32, f32, f64) {
        let q = self.camera.project(p);
        let x = self.fit.anchor_x + (q[0] - self.anchor[0]) * self.fit.scale;
        let y = self.fit.anchor_y - (q[1] - self.anchor[1]) * self.fit.scale;
        (x as f32, y as f32, q[2])
    }

    fn xy(&self, p: Vec3) -> (f32, f32) {
        let (x, y, _) = self.to_px(p);
        (x, y)
    }
}

/// The colour of a joint's dot: its limb's, or the torso's.
pub fn joint_color(j: usize) -> [u8; 3] {
    PART_COLORS
        .iter()
        .find(|(part, _)| part.limb_joints().contains(&j))
        .map_or(TORSO_COLOR, |&(_, c)| c)
}

/// The colour of the bone from `parent` to `child`: a limb's only when both ends are in the
/// limb, so the pelvis→hip and spine3→collar bones stay with the torso.
pub fn bone_color(parent: usize, child: usize) -> [u8; 3] {
    PART_COLORS
        .iter()
        .find(|(part, _)| {
            let limb = part.limb_joints();
            limb.contains(&parent) && limb.contains(&child)
        })
        .map_or(TORSO_COLOR, |&(_, c)| c)
}

fn draw_cell(
    pose: &Pose,
    frame: usize,
    ground_path: &[Vec3],
    camera: &Camera,
    fit: &Fit,
    style: &CellStyle,
) -> Result<Pixmap, RenderError> {
    let size = style.size;
    let mut pm = Pixmap::new(size, size).ok_or(RenderError::TooLarge {
        width: size.into(),
        height: size.into(),
    })?;
    pm.fill(color(CELL_BACKGROUND, 255));
    let screen = Screen {
        camera,
        fit,
        anchor: camera.project(anchor(pose)),
    };
    let s = style.text_scale as f32;
    // Limbs get thicker with the figure but stay legible in small cells and tidy in big ones.
    let bone_width = ((fit.scale * 0.035) as f32).clamp(1.5 * s, 4.0 * s);

    draw_ground(&mut pm, &screen, anchor(pose), s);
    stroke_polyline(
        &mut pm,
        ground_path.iter().map(|&p| screen.xy(p)),
        s.max(1.5),
        PATH_COLOR,
        110,
    );
    fill_circle(&mut pm, screen.xy(anchor(pose)), 2.0 * s, PATH_COLOR, 200);

    draw_figure(&mut pm, pose, &screen, bone_width);

    let label = format!("#{frame}  {:.2}s", frame as f64 / FPS);
    let pad = style.pad as f32;
    draw_text(&mut pm, &label, pad, pad, style.text_scale, LABEL_COLOR);
    if let Some(rect) = Rect::from_xywh(0.5, 0.5, size as f32 - 1.0, size as f32 - 1.0) {
        let path = PathBuilder::from_rect(rect);
        let stroke = Stroke {
            width: 1.0,
            ..Stroke::default()
        };
        pm.stroke_path(
            &path,
            &paint(CELL_BORDER, 255),
            &stroke,
            Transform::identity(),
            None,
        );
    }
    Ok(pm)
}

/// The ground: a grid fading with distance from the pelvis, or, for a level camera that sees
/// the floor edge-on, a line with ticks at the grid spacing so that travel stays visible.
fn draw_ground(pm: &mut Pixmap, screen: &Screen, centre: Vec3, s: f32) {
    let fade = |d: f64| {
        let f = (1.0 - d / GRID_RADIUS).max(0.0);
        (f * f * 90.0) as u8
    };
    let steps = (GRID_RADIUS / GRID_STEP).ceil() as i64;
    if screen.camera.is_level() {
        let (_, y) = screen.xy(centre);
        let width = pm.width() as f32;
        stroke_line(pm, (0.0, y), (width, y), s.max(1.0), GROUND_COLOR, 90);
        let u0 = screen.camera.project(centre)[0];
        let first = (u0 / GRID_STEP).round() as i64;
        for k in first - 2 * steps..=first + 2 * steps {
            let u = k as f64 * GRID_STEP;
            let x = (screen.fit.anchor_x + (u - u0) * screen.fit.scale) as f32;
            let alpha = fade((u - u0).abs() / 2.0);
            if alpha > 0 {
                stroke_line(
                    pm,
                    (x, y),
                    (x, y + 3.0 * s),
                    s.max(1.0),
                    GROUND_COLOR,
                    alpha,
                );
            }
        }
        return;
    }
    let (ix, iz) = (
        (centre[0] / GRID_STEP).round() as i64,
        (centre[2] / GRID_STEP).round() as i64,
    );
    let width = (0.5 * s).max(1.0);
    // Short segments, each with its own alpha, give the fade without a gradient shader.
    for i in -steps..=steps {
        for j in -steps..steps {
            let a = (i + ix) as f64 * GRID_STEP;
            let (b0, b1) = ((j + iz) as f64 * GRID_STEP, (j + iz + 1) as f64 * GRID_STEP);
            let (c0, c1) = ((j + ix) as f64 * GRID_STEP, (j + ix + 1) as f64 * GRID_STEP);
            let z = (i + iz) as f64 * GRID_STEP;
            for (p, q) in [([a, 0.0, b0], [a, 0.0, b1]), ([c0, 0.0, z], [c1, 0.0, z])] {
                let mid = geom::lerp(p, q, 0.5);
                let alpha = fade(geom::dist(mid, centre));
                if alpha > 0 {
                    stroke_line(pm, screen.xy(p), screen.xy(q), width, GROUND_COLOR, alpha);
                }
            }
        }
    }
}

/// Bones, joints and the head, far to near so that near limbs cover far ones.
fn draw_figure(pm: &mut Pixmap, pose: &Pose, screen: &Screen, bone_width: f32) {
    let dot_radius = 0.8 * bone_width;
    let mut items: Vec<(f64, usize)> = (0..PARENTS.len())
        .map(|j| {
            let point = match PARENTS[j] {
                Some(parent) => geom::lerp(pose[parent], pose[j], 0.5),
                None => pose[j],
            };
            (screen.to_px(point).2, j)
        })
        .collect();
    items.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (_, j) in items {
        if let Some(parent) = PARENTS[j] {
            stroke_line(
                pm,
                screen.xy(pose[parent]),
                screen.xy(pose[j]),
                bone_width,
                bone_color(parent, j),
                255,
            );
        }
        fill_circle(
            pm,
            screen.xy(pose[j]),
            dot_radius,
            shade(joint_color(j), 0.75),
            255,
        );
        if j == joint::HEAD {
            draw_head(pm, pose, screen, bone_width);
        }
    }
}

/// The head as a circle, with eyes on the side that faces the camera so that the facing
/// direction reads at a glance. Joint positions carry no head orientation, so the eyes follow
/// the body's facing (hips and shoulders).
fn draw_head(pm: &mut Pixmap, pose: &Pose, screen: &Screen, bone_width: f32) {
    let centre = head_centre(pose);
    let radius = (HEAD_RADIUS * screen.fit.scale) as f32;
    let c = screen.xy(centre);
    fill_circle(pm, c, radius, HEAD_FILL, 255);
    stroke_circle(pm, c, radius, 0.7 * bone_width, TORSO_COLOR);

    let across = geom::add(
        geom::sub(pose[joint::R_HIP], pose[joint::L_HIP]),
        geom::sub(pose[joint::R_SHOULDER], pose[joint::L_SHOULDER]),
    );
    let forward = geom::normalize([across[2], 0.0, -across[0]]);
    let left = geom::cross([0.0, 1.0, 0.0], forward);
    let up = geom::normalize(geom::sub(centre, pose[joint::NECK]));
    let centre_depth = screen.to_px(centre).2;
    for side in [1.0, -1.0] {
        let eye = geom::add(
            centre,
            geom::add(
                geom::scale(forward, 0.78 * HEAD_RADIUS),
                geom::add(
                    geom::scale(left, side * 0.38 * HEAD_RADIUS),
                    geom::scale(up, 0.12 * HEAD_RADIUS),
                ),
            ),
        );
        let (x, y, depth) = screen.to_px(eye);
        // Only eyes clearly on the camera's side of the head are drawn.
        if depth < centre_depth - 0.1 * HEAD_RADIUS {
            fill_circle(pm, (x, y), (0.4 * bone_width).max(1.2), TORSO_COLOR, 255);
        }
    }
}

/// The header: title lines, then the colour legend and the motion's length.
fn draw_header(pm: &mut Pixmap, layout: &Layout) {
    for (line, y) in &layout.title_lines {
        draw_text(
            pm,
            line,
            layout.pad as f32,
            *y as f32,
            layout.title_scale,
            TITLE_COLOR,
        );
    }
    let s = layout.text_scale as f32;
    for item in &layout.legend {
        let (x, y) = (item.x as f32, item.y as f32);
        let text_x = match item.swatch {
            Some(c) => {
                let mid = y + 0.5 * (font::CAP_ROWS as f32) * s;
                let w = 3.0 * s;
                stroke_line(
                    pm,
                    (x + 0.5 * w, mid),
                    (x + 10.0 * s - 0.5 * w, mid),
                    w,
                    c,
                    255,
                );
                x + 13.0 * s
            }
            None => x,
        };
        draw_text(pm, &item.text, text_x, y, layout.text_scale, LABEL_COLOR);
    }
}

/// A legend entry: an optional colour swatch followed by text, at pixel `(x, y)` (top-left).
struct LegendItem {
    x: u32,
    y: u32,
    swatch: Option<[u8; 3]>,
    text: String,
}

/// Where everything goes on the page; computed before drawing so the size is known.
struct Layout {
    width: u32,
    height: u32,
    /// Height of the header band above the grid.
    header: u32,
    cells: usize,
    columns: usize,
    cell: u32,
    pad: u32,
    text_scale: u32,
    title_scale: u32,
    title_lines: Vec<(String, u32)>,
    legend: Vec<LegendItem>,
}

impl Layout {
    fn new(options: &FilmstripOptions, num_frames: usize) -> Result<Layout, RenderError> {
        if options.frames == 0 {
            return Err(RenderError::InvalidOptions(
                "frames must be at least 1".into(),
            ));
        }
        if options.columns == 0 {
            return Err(RenderError::InvalidOptions(
                "columns must be at least 1".into(),
            ));
        }
        if !(MIN_CELL..=MAX_CELL).contains(&options.cell_size) {
            return Err(RenderError::InvalidOptions(format!(
                "cell size must be {MIN_CELL} to {MAX_CELL} pixels, not {}",
                options.cell_size
            )));
        }
        let cell = options.cell_size;
        // Never repeat a frame: short motions get fewer cells, and the page no more columns
        // than cells.
        let cells = options.frames.min(num_frames.max(1));
        let columns = options.columns.min(cells);
        let rows = cells.div_ceil(columns);
        let width = columns as u64 * u64::from(cell);
        let grid_height = rows as u64 * u64::from(cell);
        if width * grid_height > MAX_PIXELS {
            return Err(RenderError::TooLarge {
                width,
                height: grid_height,
            });
        }
        let width = width as u32;

        let text_scale = ((cell + 64) / 128).max(1);
        let title_scale = text_scale + 1;
        let pad = 4 * text_scale;
        let usable = width.saturating_sub(2 * pad);
        let mut y = pad;
        let mut title_lines = Vec::new();
        if let Some(title) = &options.title {
            for line in wrap(title, usable / title_scale, 3) {
                title_lines.push((line, y));
                y += font::LINE_ROWS * title_scale;
            }
            if !title_lines.is_empty() {
                y += 2 * text_scale;
            }
        }

        let line_height = font::LINE_ROWS * text_scale;
        let mut legend = Vec::new();
        let mut x = pad;
        let right = pad + usable;
        for (part, c) in PART_COLORS {
            let text = short_name(part).to_string();
            let w = 13 * text_scale + font::text_width(&text) * text_scale;
            if x > pad && x + w > right {
                x = pad;
                y += line_height;
            }
            legend.push(LegendItem {
                x,
                y,
                swatch: Some(c),
                text,
            });
            x += w + 9 * text_scale;
        }
        let info = format!(
            "{num_frames} frames, {:.2} s at {FPS} fps",
            num_frames as f64 / FPS
        );
        let info_w = font::text_width(&info) * text_scale;
        let (info_x, info_y) = if x + 3 * text_scale + info_w <= right {
            (right - info_w, y)
        } else {
            (pad, y + line_height)
        };
        legend.push(LegendItem {
            x: info_x,
            y: info_y,
            swatch: None,
            text: info,
        });
        let header = info_y + line_height + pad - text_scale;

        let height = u64::from(header) + grid_height;
        if u64::from(width) * height > MAX_PIXELS {
            return Err(RenderError::TooLarge {
                width: width.into(),
                height,
            });
        }
        Ok(Layout {
            width,
            height: height as u32,
            header,
            cells,
            columns,
            cell,
            pad,
            text_scale,
            title_scale,
            title_lines,
            legend,
        })
    }
}

/// The legend's words for a part.
fn short_name(part: BodyPart) -> &'static str {
    match part {
        BodyPart::LeftArm => "L arm",
        BodyPart::RightArm => "R arm",
        BodyPart::LeftLeg => "L leg",
        BodyPart::RightLeg => "R leg",
    }
}

/// Word-wraps `text` into lines at most `max_width` font pixels wide, breaking words that are
/// too long on their own; past `max_lines` the last line ends in "...".
fn wrap(text: &str, max_width: u32, max_lines: usize) -> Vec<String> {
    let fits = |s: &str| font::text_width(s) <= max_width;
    let mut lines: Vec<String> = Vec::new();
    let mut current = String::new();
    for word in text.split_whitespace() {
        let joined = if current.is_empty() {
            word.to_string()
        } else {
            format!("{current} {word}")
        };
        if fits(&joined) {
            current = joined;
            continue;
        }
        if !current.is_empty() {
            lines.push(std::mem::take(&mut current));
        }
        for c in word.chars() {
            current.push(c);
            if !fits(&current) && current.chars().count() > 1 {
                current.pop();
                lines.push(std::mem::take(&mut current));
                current.push(c);
            }
        }
    }
    if !current.is_empty() {
        lines.push(current);
    }
    if lines.len() > max_lines {
        lines.truncate(max_lines);
        let last = lines.last_mut().expect("max_lines lines were kept");
        while !last.is_empty() && !fits(&format!("{last}...")) {
            last.pop();
        }
        let trimmed = last.trim_end().len();
        last.truncate(trimmed);
        last.push_str("...");
    }
    lines
}

/// A darker version of `c` (`factor` < 1), for joint dots on their own bones.
fn shade(c: [u8; 3], factor: f32) -> [u8; 3] {
    c.map(|v| (f32::from(v) * factor).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Quat;
    use crate::skeleton::{forward_kinematics, Offsets, Rotations, NUM_JOINTS, RAW_OFFSETS};
    use std::f64::consts::{FRAC_PI_2, PI};

    /// A human-sized skeleton along the rest directions: arms hang, feet point +Z. The rest
    /// directions put the shoulder under the collar, so the collar bone carries the width.
    fn offsets() -> Offsets {
        let lengths = [
            0.0, 0.09, 0.09, 0.12, 0.4, 0.4, 0.14, 0.42, 0.42, 0.06, 0.12, 0.12, 0.15, 0.2, 0.2,
            0.08, 0.04, 0.04, 0.27, 0.27, 0.25, 0.25,
        ];
        Offsets(std::array::from_fn(|j| {
            geom::scale(RAW_OFFSETS[j], lengths[j])
        }))
    }

    /// Rest rotations, except that the head bone (rest direction +Z) is turned to point up
    /// and the collar bones slope up to the shoulders (the arms turned back to hang).
    fn rest_rotations() -> Rotations {
        let z_axis = [0.0, 0.0, 1.0];
        let mut rots = [Quat::IDENTITY; NUM_JOINTS];
        rots[joint::HEAD] = Quat::from_axis_angle([1.0, 0.0, 0.0], -FRAC_PI_2);
        rots[joint::L_COLLAR] = Quat::from_axis_angle(z_axis, 0.5);
        rots[joint::L_SHOULDER] = Quat::from_axis_angle(z_axis, -0.5);
        rots[joint::R_COLLAR] = Quat::from_axis_angle(z_axis, -0.5);
        rots[joint::R_SHOULDER] = Quat::from_axis_angle(z_axis, 0.5);
        rots
    }

    fn pose(rots: Rotations, root: Vec3) -> Pose {
        forward_kinematics(&[rots], &offsets(), &[root])[0]
    }

    fn rest_pose() -> Pose {
        pose(rest_rotations(), [0.0, 0.9, 0.0])
    }

    fn left_arm_raised() -> Pose {
        let mut rots = rest_rotations();
        // Rotating the hanging upper arm by 160° about +Z swings it out to +X and up.
        rots[joint::L_ELBOW] = Quat::from_axis_angle([0.0, 0.0, 1.0], 160f64.to_radians());
        pose(rots, [0.0, 0.9, 0.0])
    }

    /// A walk along the facing direction that turns slowly to the left, raising the left arm
    /// over its last quarter.
    fn walking(n: usize) -> Vec<Pose> {
        let x_axis = [1.0, 0.0, 0.0];
        let z_axis = [0.0, 0.0, 1.0];
        let mut root = [0.0, 0.9, 0.0];
        (0..n)
            .map(|t| {
                let phase = 2.0 * PI * t as f64 / 20.0;
                let yaw = 0.8 * t as f64 / n as f64;
                let swing = 0.45 * phase.sin();
                let mut rots = rest_rotations();
                rots[0] = Quat::from_yaw(yaw);
                // Positive rotation about +X swings a hanging bone backwards (-Z).
                rots[joint::L_KNEE] = Quat::from_axis_angle(x_axis, -swing);
                rots[joint::R_KNEE] = Quat::from_axis_angle(x_axis, swing);
                rots[joint::L_ANKLE] = Quat::from_axis_angle(x_axis, 0.8 * phase.cos().max(0.0));
                rots[joint::R_ANKLE] = Quat::from_axis_angle(x_axis, 0.8 * (-phase.cos()).max(0.0));
                let raise = ((t as f64 / n as f64 - 0.75) * 4.0).clamp(0.0, 1.0);
                rots[joint::L_ELBOW] = Quat::from_axis_angle(z_axis, 0.1 + 2.6 * raise)
                    .mul(Quat::from_axis_angle(x_axis, 0.6 * swing * (1.0 - raise)));
                rots[joint::R_ELBOW] = Quat::from_axis_angle(z_axis, -0.1)
                    .mul(Quat::from_axis_angle(x_axis, -0.6 * swing));
                rots[joint::L_WRIST] = Quat::from_axis_angle(x_axis, -0.3 * (1.0 - raise));
                rots[joint::R_WRIST] = Quat::from_axis_angle(x_axis, -0.3);
                let heading = Quat::from_yaw(yaw).rotate(z_axis);
                root = geom::add(root, geom::scale(heading, 1.2 / FPS));
                root[1] = 0.9 + 0.02 * (2.0 * phase).cos();
                pose(rots, root)
            })
            .collect()
    }

    fn decode(png: &[u8]) -> Pixmap {
        Pixmap::decode_png(png).expect("valid PNG")
    }

    fn near(px: tiny_skia::PremultipliedColorU8, c: [u8; 3]) -> bool {
        px.alpha() == 255
            && [px.red(), px.green(), px.blue()]
                .iter()
                .zip(c)
                .all(|(&a, b)| a.abs_diff(b) <= 6)
    }

    /// Pixels of colour `c` in the grid (below the header, whose legend repeats the colours).
    fn pixels_of(pm: &Pixmap, header: u32, c: [u8; 3]) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        for y in header..pm.height() {
            for x in 0..pm.width() {
                if near(pm.pixel(x, y).expect("in bounds"), c) {
                    out.push((x, y));
                }
            }
        }
        out
    }

    fn part_color(part: BodyPart) -> [u8; 3] {
        PART_COLORS.iter().find(|(p, _)| *p == part).unwrap().1
    }

    fn single_cell(view: View) -> (FilmstripOptions, u32) {
        let options = FilmstripOptions {
            frames: 1,
            columns: 1,
            cell_size: 256,
            title: None,
            view,
        };
        let header = Layout::new(&options, 1).unwrap().header;
        (options, header)
    }

    #[test]
    fn png_has_the_expected_size() {
        let poses = walking(30);
        for (frames, columns, cell, rows) in [(8, 4, 128, 2), (5, 2, 96, 3), (3, 5, 64, 1)] {
            let options = FilmstripOptions {
                frames,
                columns,
                cell_size: cell,
                title: Some("size check".into()),
                view: View::Front,
            };
            let pm = decode(&filmstrip_png(&poses, &options).unwrap());
            let header = Layout::new(&options, poses.len()).unwrap().header;
            assert_eq!(pm.width(), columns.min(frames) as u32 * cell);
            assert_eq!(pm.height(), header + rows * cell);
            assert_eq!(
                options.image_size(poses.len()).unwrap(),
                (pm.width(), pm.height())
            );
        }
    }

    #[test]
    fn short_motions_get_one_cell_per_frame() {
        let poses = walking(3);
        let options = FilmstripOptions::default();
        let (w, _) = options.image_size(3).unwrap();
        assert_eq!(w, 3 * options.cell_size);
        assert_eq!(decode(&filmstrip_png(&poses, &options).unwrap()).width(), w);
    }

    #[test]
    fn sampled_frames_include_first_and_last() {
        assert_eq!(sample_frames(100, 8).first(), Some(&0));
        assert_eq!(sample_frames(100, 8).last(), Some(&99));
        assert_eq!(sample_frames(9, 5), vec![0, 2, 4, 6, 8]);
        assert_eq!(sample_frames(4, 4), vec![0, 1, 2, 3]);
        assert_eq!(sample_frames(1, 1), vec![0]);
        assert_eq!(sample_frames(50, 1), vec![0]);
        let frames = sample_frames(13, 12);
        assert!(frames.windows(2).all(|w| w[0] < w[1]), "{frames:?}");
    }

    #[test]
    fn projection_follows_the_documented_views() {
        let front = Camera::new(View::Front);
        // Face to face: the character's left (+X) is on the image's right, up is up, and its
        // front (+Z) is nearer to the camera.
        assert!(front.project([1.0, 0.0, 0.0])[0] > 0.99);
        assert!(front.project([0.0, 1.0, 0.0])[1] > 0.99);
        assert!(front.project([0.0, 0.0, 1.0])[2] < -0.99);
        assert!(front.is_level());

        let side = Camera::new(View::Side);
        // From the character's left: its left side is nearest and it faces the image's left.
        assert!(side.project([1.0, 0.0, 0.0])[2] < -0.99);
        assert!(side.project([0.0, 0.0, 1.0])[0] < -0.99);
        assert!(side.is_level());

        let three = Camera::new(View::ThreeQuarter);
        let pose = rest_pose();
        let depth = |j: usize| three.project(pose[j])[2];
        assert!(depth(joint::L_SHOULDER) < depth(joint::R_SHOULDER));
        assert!(three.project([0.0, 0.0, 1.0])[2] < 0.0, "sees the front");
        assert!(
            three.project([1.0, 0.0, 0.0])[0] > 0.0,
            "left stays on the right"
        );
        assert!(three.forward[1] < 0.0, "looks down");
        assert!(!three.is_level());
        assert!(three.project([0.0, 1.0, 0.0])[1] > 0.9, "upright");
    }

    #[test]
    fn raised_left_arm_is_above_the_head_in_front_view() {
        let (options, header) = single_cell(View::Front);
        let top = |pose: Pose, c: [u8; 3]| {
            let pm = decode(&filmstrip_png(&[pose], &options).unwrap());
            let ys: Vec<u32> = pixels_of(&pm, header, c).iter().map(|p| p.1).collect();
            *ys.iter().min().expect("colour is drawn")
        };
        let arm = part_color(BodyPart::LeftArm);
        // The head outline is the topmost torso-coloured pixel.
        assert!(top(left_arm_raised(), arm) < top(left_arm_raised(), TORSO_COLOR));
        assert!(top(rest_pose(), arm) > top(rest_pose(), TORSO_COLOR));
    }

    #[test]
    fn front_view_shows_the_left_side_on_the_image_right() {
        let (options, header) = single_cell(View::Front);
        let pm = decode(&filmstrip_png(&[rest_pose()], &options).unwrap());
        let mean_x = |part: BodyPart| {
            let px = pixels_of(&pm, header, part_color(part));
            assert!(!px.is_empty(), "{part:?} is drawn");
            px.iter().map(|p| f64::from(p.0)).sum::<f64>() / px.len() as f64
        };
        let centre = f64::from(options.cell_size) / 2.0;
        assert!(mean_x(BodyPart::LeftArm) > centre + 10.0);
        assert!(mean_x(BodyPart::RightArm) < centre - 10.0);
        assert!(mean_x(BodyPart::LeftLeg) > centre);
        assert!(mean_x(BodyPart::RightLeg) < centre);
    }

    #[test]
    fn figure_stands_upright_on_the_ground() {
        let (options, header) = single_cell(View::ThreeQuarter);
        let pm = decode(&filmstrip_png(&[rest_pose()], &options).unwrap());
        let ys = |c| -> Vec<u32> { pixels_of(&pm, header, c).iter().map(|p| p.1).collect() };
        let leg_bottom = *ys(part_color(BodyPart::LeftLeg)).iter().max().unwrap();
        let arm_top = *ys(part_color(BodyPart::LeftArm)).iter().min().unwrap();
        assert!(leg_bottom > arm_top + 50, "legs below arms");
        assert!(
            leg_bottom < header + options.cell_size,
            "feet inside the cell"
        );
    }

    #[test]
    fn part_colours_are_distinct() {
        let mut all: Vec<[u8; 3]> = PART_COLORS.iter().map(|p| p.1).collect();
        all.push(TORSO_COLOR);
        all.push(HEAD_FILL);
        for (i, a) in all.iter().enumerate() {
            for b in &all[i + 1..] {
                let d: u32 = a
                    .iter()
                    .zip(b)
                    .map(|(x, y)| u32::from(x.abs_diff(*y)))
                    .sum();
                assert!(d > 120, "{a:?} vs {b:?}");
            }
        }
        let parts: Vec<BodyPart> = PART_COLORS.iter().map(|p| p.0).collect();
        assert_eq!(parts, BodyPart::ALL);
    }

    #[test]
    fn bad_motions_are_errors() {
        let options = FilmstripOptions::default();
        assert!(matches!(
            filmstrip_png(&[], &options),
            Err(RenderError::EmptyMotion)
        ));
        let mut poses = walking(5);
        poses[3][joint::L_WRIST][1] = f64::NAN;
        let err = filmstrip_png(&poses, &options).unwrap_err();
        assert!(matches!(
            err,
            RenderError::NonFinite {
                frame: 3,
                joint: joint::L_WRIST,
                ..
            }
        ));
        assert!(err.to_string().contains("l_wrist"), "{err}");
        poses[3][joint::L_WRIST][1] = f64::INFINITY;
        assert!(matches!(
            filmstrip_png(&poses, &options),
            Err(RenderError::NonFinite { .. })
        ));
        poses[3][joint::L_WRIST][1] = 1e300;
        assert!(matches!(
            filmstrip_png(&poses, &options),
            Err(RenderError::OutOfRange { .. })
        ));
        assert!(matches!(
            options.image_size(0),
            Err(RenderError::EmptyMotion)
        ));
    }

    #[test]
    fn bad_options_are_errors() {
        let poses = walking(5);
        let bad = [
            FilmstripOptions {
                frames: 0,
                ..FilmstripOptions::default()
            },
            FilmstripOptions {
                columns: 0,
                ..FilmstripOptions::default()
            },
            FilmstripOptions {
                cell_size: 8,
                ..FilmstripOptions::default()
            },
            FilmstripOptions {
                cell_size: 1 << 20,
                ..FilmstripOptions::default()
            },
        ];
        for options in bad {
            assert!(matches!(
                filmstrip_png(&poses, &options),
                Err(RenderError::InvalidOptions(_))
            ));
        }
        let huge = FilmstripOptions {
            frames: usize::MAX,
            columns: usize::MAX,
            cell_size: MAX_CELL,
            ..FilmstripOptions::default()
        };
        let many: Vec<Pose> = vec![rest_pose(); 100];
        assert!(matches!(
            filmstrip_png(&many, &huge),
            Err(RenderError::TooLarge { .. })
        ));
    }

    #[test]
    fn degenerate_but_finite_motions_still_render() {
        let options = FilmstripOptions {
            title: Some("ünïcödé\ttitle\nwith a verylongwordthatmustbebrokensomewhere".into()),
            ..FilmstripOptions::default()
        };
        for poses in [
            vec![[[0.0; 3]; NUM_JOINTS]; 4],
            vec![[[5e3; 3]; NUM_JOINTS]],
        ] {
            let png = filmstrip_png(&poses, &options).unwrap();
            decode(&png);
        }
    }

    #[test]
    fn titles_wrap_and_truncate() {
        let lines = wrap("a person walks forward and waves", 60, 10);
        assert!(lines.len() > 1);
        assert!(lines.iter().all(|l| font::text_width(l) <= 60), "{lines:?}");
        assert_eq!(lines.join(" "), "a person walks forward and waves");
        let long = wrap(&"word ".repeat(100), 60, 3);
        assert_eq!(long.len(), 3);
        assert!(long[2].ends_with("..."));
        assert!(font::text_width(&long[2]) <= 60);
        let broken = wrap("abcdefghijklmnopqrstuvwxyz", 30, 10);
        assert!(broken.len() > 1);
        assert_eq!(broken.concat(), "abcdefghijklmnopqrstuvwxyz");
        assert!(wrap("   ", 30, 3).is_empty());
    }

    #[test]
    fn view_names_parse() {
        for v in View::ALL {
            assert_eq!(View::parse(v.name()), Some(v));
        }
        assert_eq!(View::parse("Three_Quarter"), Some(View::ThreeQuarter));
        assert_eq!(View::parse("3/4"), Some(View::ThreeQuarter));
        assert_eq!(View::parse("top"), None);
    }

    #[test]
    fn write_filmstrip_writes_a_png_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("strip.png");
        write_filmstrip(&path, &walking(10), &FilmstripOptions::default()).unwrap();
        decode(&std::fs::read(&path).unwrap());
        let missing = dir.path().join("no/such/dir/strip.png");
        let err = write_filmstrip(&missing, &walking(10), &FilmstripOptions::default());
        assert!(matches!(err, Err(RenderError::Io { .. })));
    }

    /// Writes example filmstrips to the temporary directory (`/tmp/render-example*.png`) for
    /// a person to look at.
    #[test]
    fn write_example_pngs() {
        let poses = walking(60);
        let dir = std::env::temp_dir();
        for (view, name) in [
            (View::ThreeQuarter, "render-example.png"),
            (View::Front, "render-example-front.png"),
            (View::Side, "render-example-side.png"),
        ] {
            let options = FilmstripOptions {
                title: Some(format!(
                    "Example ({}): a person walks forward, turns left and raises the left arm",
                    view.name()
                )),
                view,
                ..FilmstripOptions::default()
            };
            write_filmstrip(&dir.join(name), &poses, &options).unwrap();
        }
    }
}
