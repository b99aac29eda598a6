//! Acclaim ASF/AMC motion capture (the HDM05 subset) and its retarget onto our 22 SMPL joints.
//!
//! An ASF file is one performer's skeleton: bones with a rest `direction` (a unit vector in
//! the world frame of the rest pose), a `length`, a local frame `axis` (three Euler angles)
//! and the rotational degrees of freedom (`dof`) the motion animates. An AMC file is the
//! motion: per frame its number and one line per animated bone with that bone's dof values.
//! HDM05 was written by Vicon BodyBuilder: lengths in ASF units (`:units length 0.45`, so one
//! unit is 0.0254 / 0.45 m = 5.644 cm), angles in degrees, Y up, 120 Hz, and `l…` bones are the
//! performer's left (+X at rest, toes towards +Z).
//!
//! Forward kinematics, as checked against HDM05's figures (root at 0.97 m standing in
//! `HDM_bd_squat1Reps_001`): a bone's rest frame `C` comes from its `axis` angles composed in
//! the listed order (`XYZ` gives `C = Rz·Ry·Rx`), its motion `M` from its dof values composed in
//! the listed order (`rx ry rz` gives `M = Rz·Ry·Rx`), its local rotation is `L = C·M·Cᵀ`, its
//! world rotation `R = R_parent·L`, and its end is `end_parent + R·(direction × length)`. The
//! root's rotation is its `RX RY RZ` values composed in the root's `axis` order, its position
//! the `TX TY TZ` values; a child of the root starts at the root position. The `:root`
//! `position` and `orientation` (the rest pose's) are checked but not used: every AMC frame
//! gives the root's place and rotation in full.
//!
//! We take world positions of bone ends, not rotations, because the two skeletons' rest
//! poses and local axes differ while their joints correspond. Which bone end drives which SMPL
//! joint ("end of X" is where bone X ends, i.e. where its children start):
//!
//! | SMPL joint              | from                                                        |
//! |-------------------------|-------------------------------------------------------------|
//! | pelvis                  | root position                                               |
//! | l_hip / r_hip           | end of lhipjoint / rhipjoint                                |
//! | l_knee / r_knee         | end of lfemur / rfemur                                      |
//! | l_ankle / r_ankle       | end of ltibia / rtibia                                      |
//! | l_foot / r_foot         | end of lfoot / rfoot (the ball of the foot, where the toes start) |
//! | spine1                  | end of lowerback                                            |
//! | spine2                  | end of upperback                                            |
//! | spine3                  | end of thorax (where the clavicles and the neck start)      |
//! | neck                    | end of lowerneck                                            |
//! | head                    | end of upperneck (the base of the head bone, not the crown)  |
//! | l_collar / r_collar     | synthesised: ⅓ of the way along l/rclavicle (no ASF joint there) |
//! | l_shoulder / r_shoulder | end of lclavicle / rclavicle                                |
//! | l_elbow / r_elbow       | end of lhumerus / rhumerus                                  |
//! | l_wrist / r_wrist       | end of lradius / rradius                                    |
//!
//! The collar's place along the clavicle changes only the raw positions: spine3, collar and
//! shoulder lie on one line, so the bone directions that [`crate::features::joints_to_features`]
//! keeps are the same for any fraction. Bone lengths are made uniform there too.
//!
//! Positions are converted to metres and taken every 6th frame (120 Hz → 20 fps,
//! [`crate::timing::FPS`]); 20 divides 120, so no interpolation is needed.

use super::{read_files, Source, Take};
use crate::geom::{self, Vec3};
use crate::skeleton::{Pose, NUM_JOINTS};
use anyhow::{bail, Context, Result};
use rayon::prelude::*;
use std::borrow::Cow;
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// Frames per second of HDM05's AMC files (the files do not say; HDM05's documentation does).
pub const SOURCE_FPS: f64 = 120.0;

/// Every how many source frames one is kept: 120 Hz / 20 fps.
pub const FRAME_STEP: usize = 6;

/// Metres per inch: ASF lengths are inches divided by the `:units length` factor.
const INCH: f64 = 0.0254;

/// Most bones an ASF may declare, so a hostile file cannot make us allocate without bound.
const MAX_BONES: usize = 1024;

/// Most dofs one bone may list (rx ry rz, each at most twice, is already unusual).
const MAX_DOFS: usize = 6;

/// Why an ASF or AMC file could not be read or converted. Line numbers count from 1; the file
/// name is added by the caller (see [`read_hdm05`]).
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum AcclaimError {
    /// A line that does not say what the format expects there.
    #[error("line {line}: {message}")]
    Syntax { line: usize, message: String },
    /// A skeleton that cannot be posed (a bone without a parent, a cycle, a missing bone), or
    /// a motion that does not fit the skeleton.
    #[error("skeleton: {0}")]
    Skeleton(String),
    /// An AMC file without a single frame.
    #[error("the motion has no frames")]
    Empty,
}

fn syntax(line: usize, message: impl Into<String>) -> AcclaimError {
    AcclaimError::Syntax {
        line,
        message: message.into(),
    }
}

/// A coordinate axis of the capture's world (Y up) or of a bone's local frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    /// At rest, the performer's left.
    X,
    /// Up.
    Y,
    /// At rest, the performer's front.
    Z,
}

impl Axis {
    fn parse(letter: char) -> Option<Axis> {
        match letter.to_ascii_uppercase() {
            'X' => Some(Axis::X),
            'Y' => Some(Axis::Y),
            'Z' => Some(Axis::Z),
            _ => None,
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// One value of the root's line in an AMC frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RootChannel {
    /// Position along an axis, ASF length units.
    Translation(Axis),
    /// Rotation about an axis, in the AMC's angle unit.
    Rotation(Axis),
}

/// One bone of an ASF skeleton.
#[derive(Clone, Debug, PartialEq)]
pub struct Bone {
    /// Name as written (`lfemur`); unique within the skeleton.
    pub name: String,
    /// Rest direction from the bone's start to its end, world frame of the rest pose (Y up,
    /// +X the performer's left, +Z forward).
    pub direction: Vec3,
    /// Length in ASF units (metres = length × [`Asf::metres_per_unit`]).
    pub length: f64,
    /// The bone's local frame: Euler angles in radians, `axis_angles[k]` about
    /// `axis_order[k]`, applied in that order.
    pub axis_angles: Vec3,
    /// Order of the `axis` angles (`XYZ` in HDM05).
    pub axis_order: [Axis; 3],
    /// Rotational degrees of freedom, in the order their values appear in the AMC line and
    /// are applied.
    pub dofs: Vec<Axis>,
    /// Index of the parent bone in [`Asf::bones`]; `None` when the parent is the root.
    pub parent: Option<usize>,
}

/// A parsed ASF skeleton.
#[derive(Clone, Debug, PartialEq)]
pub struct Asf {
    /// The `:units length` factor: metres = ASF units × 0.0254 / `length_unit`.
    pub length_unit: f64,
    /// Whether the `axis` angles were given in degrees (`:units angle deg`); they are stored
    /// in radians either way.
    pub axis_in_degrees: bool,
    /// The values of the root's AMC line, in order (`TX TY TZ RX RY RZ`).
    pub root_order: Vec<RootChannel>,
    /// The order the root's rotation values are applied in (`XYZ`: `R = Rz·Ry·Rx`).
    pub root_axis: [Axis; 3],
    /// Bones in file order.
    pub bones: Vec<Bone>,
    /// Bone indices with every parent before its children.
    order: Vec<usize>,
    /// Index of each bone's first value in a flattened AMC frame (after the root's values).
    first_value: Vec<usize>,
    /// Each bone's rest frame `C` as a matrix.
    rest: Vec<Mat3>,
}

/// A parsed AMC motion, bound to the [`Asf`] it was parsed against.
#[derive(Clone, Debug, PartialEq)]
pub struct Amc {
    /// Whether angles are in degrees (`:DEGREES`, the default) or radians (`:RADIANS`).
    pub degrees: bool,
    /// The number of the first frame as written (HDM05 starts at 1); frames are consecutive.
    pub first_frame: i64,
    /// Values per frame: the root's, in [`Asf::root_order`], then each bone's dof values in
    /// bone order.
    pub values_per_frame: usize,
    /// All frames' values, frame after frame (source rate, 120 Hz for HDM05).
    pub values: Vec<f64>,
}

impl Amc {
    /// Number of frames at the source rate (120 Hz for HDM05).
    pub fn num_frames(&self) -> usize {
        self.values
            .len()
            .checked_div(self.values_per_frame)
            .unwrap_or(0)
    }

    /// The values of frame `f` (0-based, source rate), laid out as [`Amc::values`] describes.
    /// Panics when `f` is not below [`Amc::num_frames`], as slice indexing does.
    pub fn frame(&self, f: usize) -> &[f64] {
        &self.values[f * self.values_per_frame..(f + 1) * self.values_per_frame]
    }
}

/// Lines of a file as text, numbered from 1, without their CR: Latin-1 bytes (HDM05's header
/// comments) are decoded as Latin-1 instead of failing as UTF-8.
fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, Cow<'_, str>)> {
    bytes.split(|&b| b == b'\n').enumerate().map(|(i, l)| {
        let l = l.strip_suffix(b"\r").unwrap_or(l);
        let text = match std::str::from_utf8(l) {
            Ok(s) => Cow::Borrowed(s),
            Err(_) => Cow::Owned(l.iter().map(|&b| b as char).collect()),
        };
        (i + 1, text)
    })
}

fn number(line: usize, word: Option<&str>, what: &str) -> Result<f64, AcclaimError> {
    let word =
        word.ok_or_else(|| syntax(line, format!("expected {what}, found the end of the line")))?;
    match word.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(syntax(
            line,
            format!("expected {what} (a number), found '{word}'"),
        )),
    }
}

fn vec3<'a>(
    line: usize,
    words: &mut impl Iterator<Item = &'a str>,
    what: &str,
) -> Result<Vec3, AcclaimError> {
    Ok([
        number(line, words.next(), what)?,
        number(line, words.next(), what)?,
        number(line, words.next(), what)?,
    ])
}

fn axis_order(line: usize, word: Option<&str>) -> Result<[Axis; 3], AcclaimError> {
    let word = word.unwrap_or("");
    let axes: Vec<Axis> = word.chars().filter_map(Axis::parse).collect();
    let is_permutation = word.chars().count() == 3
        && axes.len() == 3
        && axes[0] != axes[1]
        && axes[1] != axes[2]
        && axes[0] != axes[2];
    if !is_permutation {
        return Err(syntax(
            line,
            format!("expected an axis order such as XYZ, found '{word}'"),
        ));
    }
    Ok([axes[0], axes[1], axes[2]])
}

/// A bone between its `begin` and `end` in `:bonedata`.
struct BoneDraft {
    line: usize,
    name: Option<String>,
    direction: Option<Vec3>,
    length: Option<f64>,
    axis: Option<(Vec3, [Axis; 3])>,
    dofs: Vec<Axis>,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Section {
    Preamble,
    Units,
    Root,
    Bones,
    Hierarchy,
    Other,
}

impl Asf {
    /// Parses an ASF file (bytes: comments may be Latin-1). Lengths stay in ASF units; `axis`
    /// angles are converted to radians. Errors name the line and what was expected.
    pub fn parse(bytes: &[u8]) -> Result<Asf, AcclaimError> {
        let mut section = Section::Preamble;
        let mut length_unit = 1.0;
        let mut degrees = true;
        let mut root_order = vec![
            RootChannel::Translation(Axis::X),
            RootChannel::Translation(Axis::Y),
            RootChannel::Translation(Axis::Z),
            RootChannel::Rotation(Axis::X),
            RootChannel::Rotation(Axis::Y),
            RootChannel::Rotation(Axis::Z),
        ];
        let mut root_axis = [Axis::X, Axis::Y, Axis::Z];
        let mut drafts: Vec<BoneDraft> = Vec::new();
        let mut open: Option<BoneDraft> = None;
        // (line, parent, children) of `:hierarchy`, resolved once every bone is known.
        let mut links: Vec<(usize, String, Vec<String>)> = Vec::new();
        let mut hierarchy_open = false;

        for (ln, text) in lines(bytes) {
            let t = text.trim();
            if t.is_empty() || t.starts_with('#') {
                continue;
            }
            if let Some(keyword) = t.strip_prefix(':') {
                if let Some(bone) = &open {
                    return Err(syntax(
                        ln,
                        format!(
                            "section ':{keyword}' inside a bone (its 'begin' is on line {}, \
                             'end' is missing)",
                            bone.line
                        ),
                    ));
                }
                section = match keyword.split_whitespace().next().unwrap_or("") {
                    "units" => Section::Units,
                    "root" => Section::Root,
                    "bonedata" => Section::Bones,
                    "hierarchy" => Section::Hierarchy,
                    _ => Section::Other,
                };
                continue;
            }
            let mut words = t.split_whitespace();
            let key = words.next().unwrap_or("");
            match section {
                // Free text (`:documentation`) and sections we do not use.
                Section::Preamble | Section::Other => {}
                Section::Units => match key {
                    "length" => {
                        let v = number(ln, words.next(), "the length unit")?;
                        if v <= 0.0 {
                            return Err(syntax(
                                ln,
                                format!("the length unit must be positive, found {v}"),
                            ));
                        }
                        length_unit = v;
                    }
                    "angle" => {
                        degrees = match words.next().map(str::to_ascii_lowercase).as_deref() {
                            Some("deg") | Some("degree") | Some("degrees") => true,
                            Some("rad") | Some("radian") | Some("radians") => false,
                            other => {
                                return Err(syntax(
                                    ln,
                                    format!(
                                        "expected the angle unit 'deg' or 'rad', found '{}'",
                                        other.unwrap_or("")
                                    ),
                                ))
                            }
                        }
                    }
                    _ => {}
                },
                Section::Root => match key {
                    "order" => {
                        root_order = words
                            .map(|w| {
                                let mut c = w.chars();
                                let kind = c.next().map(|k| k.to_ascii_uppercase());
                                let axis = c.next().and_then(Axis::parse);
                                match (kind, axis, c.next()) {
                                    (Some('T'), Some(a), None) => Ok(RootChannel::Translation(a)),
                                    (Some('R'), Some(a), None) => Ok(RootChannel::Rotation(a)),
                                    _ => Err(syntax(
                                        ln,
                                        format!("unknown root channel '{w}' (expected TX … RZ)"),
                                    )),
                                }
                            })
                            .collect::<Result<_, _>>()?;
                        if root_order.len() > 6 {
                            return Err(syntax(ln, "the root has more than 6 channels"));
                        }
                    }
                    "axis" => root_axis = axis_order(ln, words.next())?,
                    // The rest pose's place and orientation: the AMC root line gives both in full.
                    "position" | "orientation" => {
                        vec3(ln, &mut words, &format!("the root {key}"))?;
                    }
                    _ => {}
                },
                Section::Bones => match key {
                    "begin" => {
                        if let Some(bone) = &open {
                            return Err(syntax(
                                ln,
                                format!(
                                    "'begin' inside a bone (its 'begin' is on line {})",
                                    bone.line
                                ),
                            ));
                        }
                        if drafts.len() >= MAX_BONES {
                            return Err(syntax(ln, format!("more than {MAX_BONES} bones")));
                        }
                        open = Some(BoneDraft {
                            line: ln,
                            name: None,
                            direction: None,
                            length: None,
                            axis: None,
                            dofs: Vec::new(),
                        });
                    }
                    "end" => drafts.push(
                        open.take()
                            .ok_or_else(|| syntax(ln, "'end' without 'begin'"))?,
                    ),
                    _ => {
                        let bone = open.as_mut().ok_or_else(|| {
                            syntax(ln, format!("'{key}' outside a bone's begin … end"))
                        })?;
                        match key {
                            "name" => {
                                let name = words
                                    .next()
                                    .ok_or_else(|| syntax(ln, "a bone name is missing"))?;
                                bone.name = Some(name.to_string());
                            }
                            "direction" => {
                                bone.direction =
                                    Some(vec3(ln, &mut words, "a direction component")?)
                            }
                            "length" => {
                                let v = number(ln, words.next(), "the bone length")?;
                                if v < 0.0 {
                                    return Err(syntax(
                                        ln,
                                        format!("a bone length cannot be negative, found {v}"),
                                    ));
                                }
                                bone.length = Some(v);
                            }
                            "axis" => {
                                let angles = vec3(ln, &mut words, "an axis angle")?;
                                bone.axis = Some((angles, axis_order(ln, words.next())?));
                            }
                            "dof" => {
                                for w in words {
                                    let axis = match w.to_ascii_lowercase().as_str() {
                                        "rx" => Axis::X,
                                        "ry" => Axis::Y,
                                        "rz" => Axis::Z,
                                        "tx" | "ty" | "tz" | "l" => {
                                            return Err(syntax(
                                                ln,
                                                format!(
                                                    "dof '{w}' is not supported (only rx, ry, rz)"
                                                ),
                                            ))
                                        }
                                        _ => return Err(syntax(ln, format!("unknown dof '{w}'"))),
                                    };
                                    if bone.dofs.len() >= MAX_DOFS {
                                        return Err(syntax(
                                            ln,
                                            format!("more than {MAX_DOFS} dofs"),
                                        ));
                                    }
                                    bone.dofs.push(axis);
                                }
                            }
                            // `id`, `limits` (and its continuation lines), `bodymass`, …
                            // do not move joints.
                            _ => {}
                        }
                    }
                },
                Section::Hierarchy => match key {
                    "begin" => hierarchy_open = true,
                    "end" => hierarchy_open = false,
                    parent => {
                        if !hierarchy_open {
                            return Err(syntax(
                                ln,
                                format!("'{parent}' outside the hierarchy's begin … end"),
                            ));
                        }
                        links.push((ln, parent.to_string(), words.map(str::to_string).collect()));
                    }
                },
            }
        }
        if let Some(bone) = open {
            return Err(syntax(bone.line, "bone without 'end'"));
        }

        let angle = if degrees { 1f64.to_radians() } else { 1.0 };
        let mut bones = Vec::with_capacity(drafts.len());
        let mut index: HashMap<String, usize> = HashMap::new();
        for d in drafts {
            let missing =
                |what: &str| syntax(d.line, format!("the bone starting here has no {what}"));
            let name = d.name.clone().ok_or_else(|| missing("name"))?;
            if name == "root" || index.insert(name.clone(), bones.len()).is_some() {
                return Err(syntax(
                    d.line,
                    format!("bone name '{name}' is used twice (or is 'root')"),
                ));
            }
            let (axis, axis_order) = d.axis.unwrap_or(([0.0; 3], [Axis::X, Axis::Y, Axis::Z]));
            bones.push(Bone {
                name,
                direction: d.direction.ok_or_else(|| missing("direction"))?,
                length: d.length.ok_or_else(|| missing("length"))?,
                axis_angles: geom::scale(axis, angle),
                axis_order,
                dofs: d.dofs,
                parent: None,
            });
        }

        let mut has_parent = vec![false; bones.len()];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); bones.len() + 1];
        for (ln, parent, kids) in &links {
            let p = match parent.as_str() {
                "root" => None,
                name => Some(
                    *index
                        .get(name)
                        .ok_or_else(|| syntax(*ln, format!("unknown parent bone '{name}'")))?,
                ),
            };
            for kid in kids {
                let c = *index
                    .get(kid.as_str())
                    .ok_or_else(|| syntax(*ln, format!("unknown bone '{kid}'")))?;
                if std::mem::replace(&mut has_parent[c], true) {
                    return Err(syntax(*ln, format!("bone '{kid}' has a second parent")));
                }
                bones[c].parent = p;
                children[p.map_or(0, |p| p + 1)].push(c);
            }
        }
        if let Some(c) = has_parent.iter().position(|h| !h) {
            return Err(AcclaimError::Skeleton(format!(
                "bone '{}' has no parent in :hierarchy",
                bones[c].name
            )));
        }
        // Breadth first from the root: bones that are never reached sit on a cycle.
        let mut order: Vec<usize> = children[0].clone();
        let mut k = 0;
        while k < order.len() {
            order.extend_from_slice(&children[order[k] + 1]);
            k += 1;
        }
        if order.len() < bones.len() {
            let mut reached = vec![false; bones.len()];
            order.iter().for_each(|&b| reached[b] = true);
            let lost = reached.iter().position(|r| !r).unwrap_or(0);
            return Err(AcclaimError::Skeleton(format!(
                "bone '{}' is not connected to the root (a cycle in :hierarchy)",
                bones[lost].name
            )));
        }

        let root_values = root_order.len();
        let first_value = bones
            .iter()
            .scan(root_values, |next, b| {
                let first = *next;
                *next += b.dofs.len();
                Some(first)
            })
            .collect();
        let rest = bones
            .iter()
            .map(|b| compose(&b.axis_order, |k| b.axis_angles[k]))
            .collect();
        Ok(Asf {
            length_unit,
            axis_in_degrees: degrees,
            root_order,
            root_axis,
            bones,
            order,
            first_value,
            rest,
        })
    }

    /// Metres per ASF length unit (0.0254 / 0.45 = 0.05644 for HDM05).
    pub fn metres_per_unit(&self) -> f64 {
        INCH / self.length_unit
    }

    /// Values per AMC frame: the root's channels and every bone's dofs.
    pub fn values_per_frame(&self) -> usize {
        self.root_order.len() + self.bones.iter().map(|b| b.dofs.len()).sum::<usize>()
    }

    /// Index of a bone.
    pub fn bone_index(&self, name: &str) -> Option<usize> {
        self.bones.iter().position(|b| b.name == name)
    }

    /// Index into [`Asf::world_points`]' result: `root` is 0, bone `i`'s end is `i + 1`.
    pub fn point_index(&self, name: &str) -> Option<usize> {
        if name == "root" {
            Some(0)
        } else {
            self.bone_index(name).map(|i| i + 1)
        }
    }

    /// World positions in frame `f` of `amc` (parsed against this skeleton): the root first,
    /// then the end of every bone in bone order. ASF length units, Y up, the capture's place
    /// and facing.
    pub fn world_points(&self, amc: &Amc, f: usize) -> Result<Vec<Vec3>, AcclaimError> {
        if amc.values_per_frame != self.values_per_frame() {
            return Err(AcclaimError::Skeleton(format!(
                "the motion has {} values per frame, this skeleton needs {}",
                amc.values_per_frame,
                self.values_per_frame()
            )));
        }
        if f >= amc.num_frames() {
            return Err(AcclaimError::Skeleton(format!(
                "frame {f} asked for, the motion has {}",
                amc.num_frames()
            )));
        }
        Ok(self.forward(amc.frame(f), amc.degrees))
    }

    /// Forward kinematics of one frame's values (length checked by the caller).
    fn forward(&self, row: &[f64], degrees: bool) -> Vec<Vec3> {
        let angle = if degrees { 1f64.to_radians() } else { 1.0 };
        let mut root_pos = [0.0; 3];
        let mut root_rot = [0.0; 3];
        for (ch, v) in self.root_order.iter().zip(row) {
            match *ch {
                RootChannel::Translation(a) => root_pos[a.index()] = *v,
                RootChannel::Rotation(a) => root_rot[a.index()] = *v * angle,
            }
        }
        let root = compose(&self.root_axis, |k| root_rot[self.root_axis[k].index()]);
        let mut points = vec![root_pos; self.bones.len() + 1];
        let mut rotations = vec![root; self.bones.len()];
        for &b in &self.order {
            let bone = &self.bones[b];
            let values = &row[self.first_value[b]..self.first_value[b] + bone.dofs.len()];
            let motion = compose(&bone.dofs, |k| values[k] * angle);
            let c = self.rest[b];
            let local = mul(mul(c, motion), transpose(c));
            let (parent_rot, parent_end) = match bone.parent {
                None => (root, root_pos),
                Some(p) => (rotations[p], points[p + 1]),
            };
            rotations[b] = mul(parent_rot, local);
            let offset = geom::scale(bone.direction, bone.length);
            points[b + 1] = geom::add(parent_end, apply(rotations[b], offset));
        }
        points
    }
}

impl Amc {
    /// Parses an AMC file (bytes: HDM05's header comment has a Latin-1 byte) against the
    /// skeleton it animates. Every frame must give the root and every bone with dofs exactly
    /// once, with as many values as the skeleton says; frame numbers must be consecutive.
    pub fn parse(bytes: &[u8], asf: &Asf) -> Result<Amc, AcclaimError> {
        let stride = asf.values_per_frame();
        // Name → (first value, count); `None` for the root.
        let mut slots: HashMap<&str, (Option<usize>, usize, usize)> = HashMap::new();
        slots.insert("root", (None, 0, asf.root_order.len()));
        for (i, b) in asf.bones.iter().enumerate() {
            slots.insert(&b.name, (Some(i), asf.first_value[i], b.dofs.len()));
        }
        let needed = 1 + asf.bones.iter().filter(|b| !b.dofs.is_empty()).count();
        let mut degrees = true;
        let mut first_frame = None;
        let mut current: Option<(usize, i64)> = None; // (line, number) of the open frame
        let mut seen = vec![false; asf.bones.len() + 1];
        let mut seen_count = 0;
        let mut values: Vec<f64> = Vec::new();

        let close =
            |current: Option<(usize, i64)>, seen: &mut Vec<bool>, seen_count: &mut usize| {
                if let Some((line, n)) = current {
                    if *seen_count < needed {
                        let missing = if !seen[0] {
                            "root".to_string()
                        } else {
                            asf.bones
                                .iter()
                                .enumerate()
                                .find(|(i, b)| !b.dofs.is_empty() && !seen[i + 1])
                                .map_or_else(String::new, |(_, b)| b.name.clone())
                        };
                        return Err(syntax(
                            line,
                            format!("frame {n} has no line for '{missing}'"),
                        ));
                    }
                }
                seen.iter_mut().for_each(|s| *s = false);
                *seen_count = 0;
                Ok(())
            };

        for (ln, text) in lines(bytes) {
            let t = text.trim();
            if t.is_empty() || t.starts_with('#') {
                continue;
            }
            if let Some(keyword) = t.strip_prefix(':') {
                if current.is_some() {
                    return Err(syntax(ln, format!("':{keyword}' after the first frame")));
                }
                match keyword.trim().to_ascii_uppercase().as_str() {
                    "FULLY-SPECIFIED" => {}
                    "DEGREES" => degrees = true,
                    "RADIANS" => degrees = false,
                    other => return Err(syntax(ln, format!("unsupported AMC keyword ':{other}'"))),
                }
                continue;
            }
            let mut words = t.split_whitespace();
            let name = words.next().unwrap_or("");
            if name.bytes().all(|b| b.is_ascii_digit()) {
                if words.next().is_some() {
                    return Err(syntax(ln, "a frame number line has more than the number"));
                }
                let n: i64 = name
                    .parse()
                    .map_err(|_| syntax(ln, format!("frame number '{name}' is too large")))?;
                if let Some((_, previous)) = current {
                    if previous.checked_add(1) != Some(n) {
                        return Err(syntax(
                            ln,
                            format!(
                                "frame {n} follows frame {previous}; frames must be consecutive"
                            ),
                        ));
                    }
                }
                close(current, &mut seen, &mut seen_count)?;
                first_frame.get_or_insert(n);
                current = Some((ln, n));
                values.resize(values.len() + stride, 0.0);
                continue;
            }
            let Some((frame_line, _)) = current else {
                return Err(syntax(
                    ln,
                    format!("'{name}' before the first frame number"),
                ));
            };
            let &(bone, first, count) = slots.get(name).ok_or_else(|| {
                syntax(ln, format!("unknown bone '{name}' (not in the skeleton)"))
            })?;
            let s = bone.map_or(0, |b| b + 1);
            if std::mem::replace(&mut seen[s], true) {
                return Err(syntax(
                    ln,
                    format!("'{name}' appears twice in the frame starting on line {frame_line}"),
                ));
            }
            if count > 0 || bone.is_none() {
                seen_count += 1;
            }
            let row = values.len() - stride;
            for k in 0..count {
                values[row + first + k] =
                    number(ln, words.next(), &format!("{count} values for '{name}'"))?;
            }
            if words.next().is_some() {
                return Err(syntax(ln, format!("more than {count} values for '{name}'")));
            }
        }
        close(current, &mut seen, &mut seen_count)?;
        let Some(first_frame) = first_frame else {
            return Err(AcclaimError::Empty);
        };
        Ok(Amc {
            degrees,
            first_frame,
            values_per_frame: stride,
            values,
        })
    }
}

/// Where an SMPL joint comes from, in the skeleton's points (`root` or a bone's end).
#[derive(Clone, Copy, Debug)]
pub enum JointFrom {
    /// The root position or the end of one bone.
    End(&'static str),
    /// The point `t` of the way from the end of the first to the end of the second.
    Between(&'static str, &'static str, f64),
}

/// The source of each SMPL joint, in SMPL joint order (see the table in the module doc).
pub const MAPPING: [JointFrom; NUM_JOINTS] = [
    JointFrom::End("root"),
    JointFrom::End("lhipjoint"),
    JointFrom::End("rhipjoint"),
    JointFrom::End("lowerback"),
    JointFrom::End("lfemur"),
    JointFrom::End("rfemur"),
    JointFrom::End("upperback"),
    JointFrom::End("ltibia"),
    JointFrom::End("rtibia"),
    JointFrom::End("thorax"),
    JointFrom::End("lfoot"),
    JointFrom::End("rfoot"),
    JointFrom::End("lowerneck"),
    JointFrom::Between("thorax", "lclavicle", 1.0 / 3.0),
    JointFrom::Between("thorax", "rclavicle", 1.0 / 3.0),
    JointFrom::End("upperneck"),
    JointFrom::End("lclavicle"),
    JointFrom::End("rclavicle"),
    JointFrom::End("lhumerus"),
    JointFrom::End("rhumerus"),
    JointFrom::End("lradius"),
    JointFrom::End("rradius"),
];

/// The motion on our 22 joints: every [`FRAME_STEP`]th frame (120 Hz → 20 fps), metres, Y up,
/// place and facing as captured.
pub fn retarget(asf: &Asf, amc: &Amc) -> Result<Vec<Pose>, AcclaimError> {
    if amc.num_frames() == 0 {
        return Err(AcclaimError::Empty);
    }
    let index = |name: &str| {
        asf.point_index(name)
            .ok_or_else(|| AcclaimError::Skeleton(format!("HDM05 bone '{name}' is missing")))
    };
    let sources = MAPPING
        .iter()
        .map(|s| {
            Ok(match *s {
                JointFrom::End(a) => (index(a)?, index(a)?, 0.0),
                JointFrom::Between(a, b, t) => (index(a)?, index(b)?, t),
            })
        })
        .collect::<Result<Vec<_>, AcclaimError>>()?;
    let metres = asf.metres_per_unit();
    (0..amc.num_frames())
        .step_by(FRAME_STEP)
        .map(|f| {
            let points = asf.world_points(amc, f)?;
            Ok(std::array::from_fn(|j| {
                let (a, b, t) = sources[j];
                geom::scale(geom::lerp(points[a], points[b], t), metres)
            }))
        })
        .collect()
}

/// Stem, actor and class of a clip file named `HDM_<actor>_<class>_<NNN>_120.amc`.
fn clip_name(path: &str) -> Result<(String, String, String)> {
    let file = path.rsplit('/').next().unwrap_or(path);
    let stem = file
        .strip_suffix(".amc")
        .or_else(|| file.strip_suffix(".AMC"))
        .unwrap_or(file);
    let stem = stem.strip_suffix("_120").unwrap_or(stem);
    let parts: Vec<&str> = stem.split('_').collect();
    match parts.as_slice() {
        ["HDM", actor, class, number]
            if !actor.is_empty()
                && !class.is_empty()
                && number.bytes().all(|b| b.is_ascii_digit()) =>
        {
            Ok((stem.to_string(), actor.to_string(), class.to_string()))
        }
        _ => bail!("{path}: expected a clip named HDM_<actor>_<class>_<NNN>_120.amc"),
    }
}

/// One clip's poses from its skeleton and motion bytes.
fn read_clip(asf: &Asf, amc: &[u8]) -> Result<Vec<Pose>, AcclaimError> {
    retarget(asf, &Amc::parse(amc, asf)?)
}

/// Reads every clip of the HDM05 subset, from `hdm05-subset-amc.tar.xz` or from a folder
/// holding its files (`asf/HDM_<actor>.asf`, `amc/<class>/HDM_<actor>_<class>_<NNN>_120.amc`,
/// at any depth). Each clip is posed with its own actor's skeleton and returned on our 22
/// joints: 20 fps, metres, Y up, place and facing as captured. `stem` is the file stem without
/// `_120`, `actor` the performer (`bd`, `bk`, `dg`, `mm`, `tr`), `label` the HDM05 class
/// (`squat1Reps`). Sorted by stem. Errors name the file and line.
pub fn read_hdm05(source: &Path) -> Result<Vec<Take>> {
    let files = read_files(source, &|p: &str| {
        let p = p.to_ascii_lowercase();
        p.ends_with(".asf") || p.ends_with(".amc")
    })?;
    let mut skeletons: BTreeMap<String, (String, Asf)> = BTreeMap::new();
    let mut clips = Vec::new();
    for (path, bytes) in &files {
        let file = path.rsplit('/').next().unwrap_or(path);
        if file.to_ascii_lowercase().ends_with(".amc") {
            clips.push((path, bytes));
            continue;
        }
        let actor = file
            .strip_prefix("HDM_")
            .and_then(|f| f.get(..f.len().saturating_sub(4)))
            .filter(|a| !a.is_empty())
            .with_context(|| format!("{path}: expected a skeleton named HDM_<actor>.asf"))?;
        let asf = Asf::parse(bytes).with_context(|| format!("cannot read skeleton {path}"))?;
        if let Some((other, _)) = skeletons.insert(actor.to_string(), (path.clone(), asf)) {
            bail!("two skeletons for actor '{actor}': {other} and {path}");
        }
    }
    if clips.is_empty() {
        bail!("no HDM05 clips (.amc files) in {}", source.display());
    }
    let mut takes = clips
        .par_iter()
        .map(|(path, bytes)| {
            let (stem, actor, label) = clip_name(path)?;
            let (_, asf) = skeletons.get(&actor).with_context(|| {
                format!("{path}: no skeleton HDM_{actor}.asf for actor '{actor}'")
            })?;
            let poses =
                read_clip(asf, bytes).with_context(|| format!("cannot read clip {path}"))?;
            Ok(Take {
                source: Source::Hdm05,
                stem,
                actor,
                label,
                poses,
            })
        })
        .collect::<Result<Vec<Take>>>()?;
    takes.sort_by(|a, b| a.stem.cmp(&b.stem));
    if let Some(w) = takes.windows(2).find(|w| w[0].stem == w[1].stem) {
        bail!("clip {} appears twice in {}", w[0].stem, source.display());
    }
    Ok(takes)
}

/// A 3×3 matrix, rows first, acting on column vectors.
type Mat3 = [[f64; 3]; 3];

const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

fn mul(a: Mat3, b: Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn transpose(a: Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]))
}

fn apply(m: Mat3, v: Vec3) -> Vec3 {
    std::array::from_fn(|i| geom::dot(m[i], v))
}

/// Rotation of `angle` radians about an axis (right-hand rule).
fn rotation(axis: Axis, angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    match axis {
        Axis::X => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        Axis::Y => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
        Axis::Z => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
    }
}

/// Rotations about `axes[k]` by `angle(k)`, the first listed applied first (`X, Y, Z` gives
/// `Rz·Ry·Rx`).
fn compose(axes: &[Axis], angle: impl Fn(usize) -> f64) -> Mat3 {
    axes.iter()
        .enumerate()
        .fold(IDENTITY, |m, (k, &a)| mul(rotation(a, angle(k)), m))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::joints_to_features;
    use crate::skeleton::{joint, Offsets};
    use std::path::PathBuf;
    use std::sync::OnceLock;

    fn archive() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../shared/data/hdm05-subset/hdm05-subset-amc.tar.xz")
    }

    /// The archive's files, read once for all tests.
    fn files() -> &'static BTreeMap<String, Vec<u8>> {
        static FILES: OnceLock<BTreeMap<String, Vec<u8>>> = OnceLock::new();
        FILES.get_or_init(|| read_files(&archive(), &|_| true).expect("the HDM05 archive reads"))
    }

    /// Every take, read once for all tests.
    fn takes() -> &'static [Take] {
        static TAKES: OnceLock<Vec<Take>> = OnceLock::new();
        TAKES.get_or_init(|| read_hdm05(&archive()).expect("every HDM05 clip reads"))
    }

    fn take(stem: &str) -> &'static Take {
        takes()
            .iter()
            .find(|t| t.stem == stem)
            .expect("the clip exists")
    }

    fn file(name: &str) -> &'static [u8] {
        files()
            .iter()
            .find(|(p, _)| p.ends_with(name))
            .map(|(_, b)| b.as_slice())
            .expect("the file is in the archive")
    }

    fn skeleton(actor: &str) -> Asf {
        Asf::parse(file(&format!("HDM_{actor}.asf"))).unwrap()
    }

    /// Skeleton and motion of one clip, e.g. `HDM_bd_squat1Reps_001`.
    fn clip(stem: &str) -> (Asf, Amc) {
        let (_, actor, _) = clip_name(stem).unwrap();
        let asf = skeleton(&actor);
        let amc = Amc::parse(file(&format!("{stem}_120.amc")), &asf).unwrap();
        (asf, amc)
    }

    fn heights(poses: &[Pose], j: usize) -> Vec<f64> {
        poses.iter().map(|p| p[j][1]).collect()
    }

    fn max(v: impl IntoIterator<Item = f64>) -> f64 {
        v.into_iter().fold(f64::NEG_INFINITY, f64::max)
    }

    fn min(v: impl IntoIterator<Item = f64>) -> f64 {
        v.into_iter().fold(f64::INFINITY, f64::min)
    }

    fn ground(a: Vec3, b: Vec3) -> f64 {
        (a[0] - b[0]).hypot(a[2] - b[2])
    }

    /// Rows of clips.tsv: (file stem without `_120`, class, frames at 120 Hz, seconds).
    fn clips_tsv() -> Vec<(String, String, usize, f64)> {
        let text = std::fs::read_to_string(archive().with_file_name("clips.tsv")).unwrap();
        text.lines()
            .skip(1)
            .map(|l| {
                let c: Vec<&str> = l.split('\t').collect();
                let (stem, _, _) = clip_name(c[0]).unwrap();
                (
                    stem,
                    c[2].to_string(),
                    c[3].parse().unwrap(),
                    c[4].parse().unwrap(),
                )
            })
            .collect()
    }

    #[test]
    fn every_clip_reads_with_its_class_and_length() {
        let rows = clips_tsv();
        assert_eq!(rows.len(), 288);
        assert_eq!(takes().len(), 288);
        let mut per_class: BTreeMap<&str, (usize, usize)> = BTreeMap::new();
        for (stem, class, _, _) in &rows {
            per_class.entry(class).or_default().0 += 1;
            let t = take(stem);
            assert_eq!(&t.label, class);
            assert_eq!(t.source, Source::Hdm05);
            assert_eq!(
                t.stem,
                format!("HDM_{}_{}_{}", t.actor, t.label, &stem[stem.len() - 3..])
            );
        }
        for t in takes() {
            per_class.entry(&t.label).or_default().1 += 1;
        }
        for (class, (expected, read)) in per_class {
            assert_eq!(expected, read, "{class}");
        }
        assert!(takes().windows(2).all(|w| w[0].stem < w[1].stem));
        let actors: std::collections::BTreeSet<&str> =
            takes().iter().map(|t| t.actor.as_str()).collect();
        assert_eq!(
            actors.into_iter().collect::<Vec<_>>(),
            ["bd", "bk", "dg", "mm", "tr"]
        );
    }

    #[test]
    fn frame_counts_are_every_sixth_frame_at_20_fps() {
        for (stem, _, frames_120, seconds) in clips_tsv() {
            let n = take(&stem).poses.len();
            assert_eq!(n, (frames_120 - 1) / FRAME_STEP + 1, "{stem}");
            assert!(
                (n as f64 - seconds * crate::timing::FPS).abs() <= 1.0,
                "{stem}: {n} frames for {seconds} s"
            );
        }
        let (_, amc) = clip("HDM_bd_squat1Reps_001");
        assert_eq!(amc.first_frame, 1);
        assert!(amc.degrees);
        assert_eq!(amc.values_per_frame, 62);
    }

    #[test]
    fn squat_matches_the_checked_figures() {
        let p = &take("HDM_bd_squat1Reps_001").poses;
        let root = heights(p, joint::PELVIS);
        assert!((root[0] - 0.97).abs() < 0.02, "{}", root[0]);
        assert!(
            (min(root.clone()) - 0.49).abs() < 0.02,
            "{}",
            min(root.clone())
        );
        assert!((root[root.len() - 1] - 0.97).abs() < 0.02);
        // README's head figure is the end of the ASF head bone (the crown); our head joint is
        // the end of upperneck, a head bone's length (10 cm) below.
        let (asf, amc) = clip("HDM_bd_squat1Reps_001");
        let crown = asf.world_points(&amc, 0).unwrap()[asf.point_index("head").unwrap()][1]
            * asf.metres_per_unit();
        assert!((crown - 1.63).abs() < 0.02, "{crown}");
        assert!(
            (p[0][joint::HEAD][1] - 1.53).abs() < 0.03,
            "{}",
            p[0][joint::HEAD][1]
        );
    }

    #[test]
    fn lying_down_ends_on_the_floor() {
        let p = &take("HDM_bd_lieDownFloor_001").poses;
        let root = heights(p, joint::PELVIS);
        assert!((root[0] - 0.98).abs() < 0.02);
        assert!(root[root.len() - 1] < 0.1, "{}", root[root.len() - 1]);
        assert!(p[p.len() - 1][joint::HEAD][1] < 0.1);
        // Some end propped on an arm (HDM_bk_lieDownFloor_005 holds a hand 0.5 m up), but
        // every pelvis ends on the floor.
        for t in takes().iter().filter(|t| t.label == "lieDownFloor") {
            let last = t.poses[t.poses.len() - 1];
            assert!(
                last[joint::PELVIS][1] < 0.15,
                "{}: pelvis at {}",
                t.stem,
                last[0][1]
            );
            assert!(
                last[joint::HEAD][1] < 0.35,
                "{}: head at {}",
                t.stem,
                last[joint::HEAD][1]
            );
        }
    }

    #[test]
    fn a_hop_raises_the_root_and_moves_forward() {
        let p = &take("HDM_bd_hopBothLegs1hops_001").poses;
        let root = heights(p, joint::PELVIS);
        let rise = max(root.clone()) - root[0];
        assert!((rise - 0.27).abs() < 0.06, "{rise}");
        let moved = ground(p[0][joint::PELVIS], p[p.len() - 1][joint::PELVIS]);
        assert!((moved - 1.15).abs() < 0.15, "{moved}");
        for t in takes().iter().filter(|t| t.label == "hopBothLegs1hops") {
            let lowest_foot = |q: &Pose| min([7, 8, 10, 11].map(|j| q[j][1]));
            let airborne = max(t.poses.iter().map(lowest_foot));
            assert!(
                airborne > 0.1,
                "{}: both feet at most {airborne} m up",
                t.stem
            );
        }
    }

    #[test]
    fn bone_lengths_are_human() {
        for actor in ["bd", "bk", "dg", "mm", "tr"] {
            let t = takes().iter().find(|t| t.actor == actor).unwrap();
            let p = &t.poses[0];
            let len = |a: usize, b: usize| geom::dist(p[a], p[b]);
            for (name, a, b, lo, hi) in [
                ("thigh", joint::L_HIP, joint::L_KNEE, 0.35, 0.5),
                ("thigh", joint::R_HIP, joint::R_KNEE, 0.35, 0.5),
                ("shin", joint::L_KNEE, joint::L_ANKLE, 0.35, 0.5),
                ("shin", joint::R_KNEE, joint::R_ANKLE, 0.35, 0.5),
                ("upper arm", joint::L_SHOULDER, joint::L_ELBOW, 0.22, 0.34),
                ("upper arm", joint::R_SHOULDER, joint::R_ELBOW, 0.22, 0.34),
                ("forearm", joint::L_ELBOW, joint::L_WRIST, 0.15, 0.26),
                ("forearm", joint::R_ELBOW, joint::R_WRIST, 0.15, 0.26),
                ("hips apart", joint::L_HIP, joint::R_HIP, 0.1, 0.3),
                (
                    "shoulders apart",
                    joint::L_SHOULDER,
                    joint::R_SHOULDER,
                    0.3,
                    0.55,
                ),
            ] {
                let l = len(a, b);
                assert!((lo..hi).contains(&l), "{actor}: {name} {l} m");
            }
            let height = p[joint::HEAD][1] - min(p.iter().map(|v| v[1]));
            assert!((1.35..1.7).contains(&height), "{actor}: head at {height} m");
        }
    }

    #[test]
    fn standing_feet_are_on_the_floor() {
        for t in takes() {
            let lowest = min(t.poses[0].iter().map(|v| v[1]));
            if t.stem == "HDM_bk_hopBothLegs1hops_021" {
                // Cut in mid-air after the previous hop: the root starts at 1.31 m.
                assert!(lowest > 0.15, "{lowest}");
            } else {
                assert!(
                    (-0.04..0.08).contains(&lowest),
                    "{}: lowest joint at {lowest} m",
                    t.stem
                );
            }
            let lowest_ever = min(t.poses.iter().flat_map(|p| p.iter().map(|v| v[1])));
            if t.stem == "HDM_dg_lieDownFloor_014" {
                // A capture artefact, not the reader: around its frame 29 the left knee dips
                // 21 cm under the floor, with lfemur angles far beyond the ASF's own limits.
                assert!(lowest_ever > -0.25, "{lowest_ever}");
            } else {
                assert!(
                    (-0.08..0.06).contains(&lowest_ever),
                    "{}: lowest joint at {lowest_ever} m",
                    t.stem
                );
            }
        }
    }

    /// Left/right and facing: swapped sides would turn the body round and put the toes behind
    /// the ankles. Each foot alone may point a little sideways (the facing comes from hips and
    /// shoulders), so the two are averaged.
    #[test]
    fn features_face_forward_with_the_left_hip_at_plus_x() {
        for t in takes() {
            let (_, p) = joints_to_features(&t.poses, &Offsets::reference()).unwrap();
            let f = &p[0];
            let toes_ahead = [
                (joint::L_FOOT, joint::L_ANKLE),
                (joint::R_FOOT, joint::R_ANKLE),
            ]
            .map(|(toe, ankle)| f[toe][2] - f[ankle][2]);
            assert!(
                f[joint::L_HIP][0] > f[joint::PELVIS][0] + 0.02,
                "{}",
                t.stem
            );
            assert!(
                f[joint::R_HIP][0] < f[joint::PELVIS][0] - 0.02,
                "{}",
                t.stem
            );
            assert!(
                f[joint::L_SHOULDER][0] > f[joint::R_SHOULDER][0] + 0.2,
                "{}",
                t.stem
            );
            assert!(
                toes_ahead[0] + toes_ahead[1] > 0.05 && max(toes_ahead) > 0.08,
                "{}: toes ahead of ankles by {toes_ahead:?} m",
                t.stem
            );
            assert!(f[joint::HEAD][1] > f[joint::PELVIS][1] + 0.4, "{}", t.stem);
        }
    }

    #[test]
    fn jogging_is_faster_than_sneaking() {
        let speed = |t: &Take| {
            let p = &t.poses;
            let d: f64 = p.windows(2).map(|w| ground(w[0][0], w[1][0])).sum();
            d / crate::timing::seconds(p.len() - 1)
        };
        let mean = |label: &str| {
            let v: Vec<f64> = takes()
                .iter()
                .filter(|t| t.label == label)
                .map(speed)
                .collect();
            (
                v.iter().sum::<f64>() / v.len() as f64,
                min(v.iter().copied()),
                max(v.iter().copied()),
            )
        };
        let (jog, jog_min, jog_max) = mean("jogLeftCircle4StepsRstart");
        let (sneak, _, sneak_max) = mean("sneak2StepsLStart");
        let (squat, _, _) = mean("squat1Reps");
        assert!(
            (1.2..2.5).contains(&jog_min) && jog_max < 2.5,
            "jog {jog_min}–{jog_max} m/s"
        );
        assert!((1.4..2.0).contains(&jog), "jog {jog} m/s");
        assert!((0.4..1.0).contains(&sneak), "sneak {sneak} m/s");
        eprintln!(
            "root speed: jog {jog:.2} ({jog_min:.2}–{jog_max:.2}) m/s, \
             sneak {sneak:.2} (at most {sneak_max:.2}), squat {squat:.2}"
        );
        assert!(
            jog_min > sneak_max,
            "slowest jog {jog_min}, fastest sneak {sneak_max}"
        );
        assert!(squat < 0.25, "squat {squat} m/s");
    }

    #[test]
    fn left_front_kicks_lift_the_left_foot() {
        let kicks: Vec<&Take> = takes()
            .iter()
            .filter(|t| t.label == "kickLFront1Reps")
            .collect();
        assert_eq!(kicks.len(), 29);
        for t in kicks {
            let left = max(heights(&t.poses, joint::L_FOOT));
            let right = max(heights(&t.poses, joint::R_FOOT));
            assert!(
                left > 0.5 && left > right + 0.3,
                "{}: left {left}, right {right}",
                t.stem
            );
        }
    }

    #[test]
    fn reads_an_extracted_folder_like_the_archive() {
        let dir = tempfile::tempdir().unwrap();
        for (path, bytes) in files() {
            if path.ends_with("HDM_dg.asf") || path.contains("HDM_dg_grabHighR_") {
                let to = dir.path().join(path);
                std::fs::create_dir_all(to.parent().unwrap()).unwrap();
                std::fs::write(to, bytes).unwrap();
            }
        }
        let folder = read_hdm05(dir.path()).unwrap();
        let from_archive: Vec<&Take> = takes()
            .iter()
            .filter(|t| t.stem.starts_with("HDM_dg_grabHighR_"))
            .collect();
        assert!(!folder.is_empty());
        assert_eq!(folder.len(), from_archive.len());
        for (a, b) in folder.iter().zip(from_archive) {
            assert_eq!((&a.stem, &a.actor, &a.label), (&b.stem, &b.actor, &b.label));
            assert_eq!(a.poses, b.poses);
        }
    }

    /// A one-bone skeleton whose bone frame is turned 90° about Z.
    const TINY_ASF: &str = concat!(
        ":version 1.10\r\n",
        ":units\r\n",
        "  length 0.0254\r\n",
        "  angle deg\r\n",
        ":root\r\n",
        "   order TX TY TZ RX RY RZ\r\n",
        "   axis XYZ\r\n",
        "   position 0 0 0\r\n",
        "   orientation 0 0 0\r\n",
        ":bonedata\r\n",
        "  begin\r\n",
        "     id 1\r\n",
        "     name a\r\n",
        "     direction 1 0 0\r\n",
        "     length 2\r\n",
        "     axis 0 0 90 XYZ\r\n",
        "    dof rx\r\n",
        "    limits (-180.0 180.0)\r\n",
        "  end\r\n",
        ":hierarchy\r\n",
        "  begin\r\n",
        "    root a\r\n",
        "  end\r\n",
    );

    #[test]
    fn bone_rotations_turn_about_the_bone_frame() {
        let asf = Asf::parse(TINY_ASF.as_bytes()).unwrap();
        assert_eq!(asf.metres_per_unit(), 1.0);
        // rx in a frame turned 90° about Z is a turn about world +Y: +X goes to −Z.
        let amc = Amc::parse(
            b"#\xfc Latin-1\r\n:FULLY-SPECIFIED\r\n:DEGREES\r\n1\nroot 1 2 3 0 0 0\r\na 90\r\n",
            &asf,
        )
        .unwrap();
        let p = asf.world_points(&amc, 0).unwrap();
        assert_eq!(p[0], [1.0, 2.0, 3.0]);
        assert!(geom::dist(p[1], [1.0, 2.0, 1.0]) < 1e-12, "{:?}", p[1]);
        // The root turns its children; radians are honoured.
        let amc = Amc::parse(
            b":RADIANS\n1\nroot 0 0 0 0 0 1.5707963267948966\na 0\n",
            &asf,
        )
        .unwrap();
        let p = asf.world_points(&amc, 0).unwrap();
        assert!(geom::dist(p[1], [0.0, 2.0, 0.0]) < 1e-12, "{:?}", p[1]);
    }

    fn amc_error(text: &[u8]) -> AcclaimError {
        Amc::parse(text, &skeleton("bd")).unwrap_err()
    }

    fn asf_error(text: &str) -> AcclaimError {
        Asf::parse(text.as_bytes()).unwrap_err()
    }

    #[test]
    fn malformed_motions_are_errors() {
        let good = file("HDM_bd_squat1Reps_001_120.amc");
        let text = String::from_utf8_lossy(good).to_string();
        let first_frame = text.find("\n1\n").unwrap() + 1;
        let line_of = |at: usize| text[..at].matches('\n').count() + 1;

        let rtibia_line = line_of(text.find("rtibia 39.6435").unwrap());
        let bad = text.replacen("rtibia 39.6435", "rtibia 39.6x35", 1);
        let err = amc_error(bad.as_bytes());
        assert!(
            matches!(&err, AcclaimError::Syntax { line, message }
                if *line == rtibia_line && message.contains("rtibia")),
            "{err}"
        );
        let err = amc_error(
            text.replacen("rtibia 39.6435", "rtibia 39.6435 1", 1)
                .as_bytes(),
        );
        assert!(
            err.to_string().contains("more than 1 values for 'rtibia'"),
            "{err}"
        );
        let err = amc_error(text.replacen("rtibia 39.6435", "rtibia", 1).as_bytes());
        assert!(err.to_string().contains("rtibia"), "{err}");
        let err = amc_error(
            text.replacen("rtibia 39.6435", "rfibula 39.6435", 1)
                .as_bytes(),
        );
        assert!(err.to_string().contains("unknown bone 'rfibula'"), "{err}");
        let err = amc_error(text.replacen("rtibia 39.6435\r\n", "", 1).as_bytes());
        assert!(
            err.to_string().contains("frame 1 has no line for 'rtibia'"),
            "{err}"
        );
        let err = amc_error(
            text.replacen("rtibia 39.6435", "rtibia 39.6435\r\nrtibia 1", 1)
                .as_bytes(),
        );
        assert!(err.to_string().contains("twice"), "{err}");
        let err = amc_error(text.replacen("\n2\n", "\n3\n", 1).as_bytes());
        assert!(err.to_string().contains("consecutive"), "{err}");
        let err = amc_error(text.replacen(":DEGREES", ":PARTIAL", 1).as_bytes());
        assert!(err.to_string().contains(":PARTIAL"), "{err}");
        assert_eq!(amc_error(b""), AcclaimError::Empty);
        assert_eq!(
            amc_error(b":FULLY-SPECIFIED\r\n:DEGREES\r\n"),
            AcclaimError::Empty
        );
        assert!(amc_error(&text.as_bytes()[first_frame + 2..])
            .to_string()
            .contains("before the first frame"));
        assert!(amc_error(text.replacen("1.01587", "inf", 1).as_bytes())
            .to_string()
            .contains("'inf'"));
        assert!(amc_error(text.replacen("1.01587", "1e999", 1).as_bytes())
            .to_string()
            .contains("'1e999'"));

        // Cut anywhere in the first frames: an error or (at a frame's end) a motion, never a panic.
        let asf = skeleton("bd");
        for cut in 0..3000 {
            if let Ok(amc) = Amc::parse(&good[..cut], &asf) {
                assert!(amc.num_frames() >= 1);
                retarget(&asf, &amc).unwrap();
            }
        }
        // Garbage bytes, too.
        let mut noise = good[..4000].to_vec();
        for (k, b) in noise.iter_mut().enumerate().skip(200).step_by(97) {
            *b = (k * 31 % 256) as u8;
        }
        let _ = Amc::parse(&noise, &asf);
        // A motion of another skeleton's layout is refused by forward kinematics.
        let tiny = Asf::parse(TINY_ASF.as_bytes()).unwrap();
        let amc = Amc::parse(good, &asf).unwrap();
        assert!(tiny.world_points(&amc, 0).is_err());
        assert!(asf.world_points(&amc, amc.num_frames()).is_err());
    }

    #[test]
    fn malformed_skeletons_are_errors() {
        let good = String::from_utf8_lossy(file("HDM_bd.asf")).to_string();
        let err = asf_error(&good.replacen("length 7.34031", "length 7.3x", 1));
        assert!(
            matches!(&err, AcclaimError::Syntax { message, .. } if message.contains("'7.3x'")),
            "{err}"
        );
        let err = asf_error(&good.replacen("length 7.34031", "length -1", 1));
        assert!(err.to_string().contains("negative"), "{err}");
        let err =
            asf_error(&good.replacen("direction 0.34202 -0.939693 0", "direction 0.34202", 1));
        assert!(err.to_string().contains("direction"), "{err}");
        let err = asf_error(&good.replacen("dof rx ry rz", "dof rx ry tz", 1));
        assert!(err.to_string().contains("'tz' is not supported"), "{err}");
        let err = asf_error(&good.replacen("lfemur ltibia", "lfemur", 1));
        assert!(err.to_string().contains("'ltibia' has no parent"), "{err}");
        let err = asf_error(&good.replacen("lfemur ltibia", "lfemur ltibia lfemur", 1));
        assert!(err.to_string().contains("second parent"), "{err}");
        let err = asf_error(&good.replacen(
            "root lhipjoint rhipjoint lowerback",
            "root rhipjoint lowerback\r\nltoes lhipjoint",
            1,
        ));
        assert!(err.to_string().contains("cycle"), "{err}");
        let err = asf_error(&good.replacen("lfemur ltibia", "lfemur lshin", 1));
        assert!(err.to_string().contains("unknown bone 'lshin'"), "{err}");
        let err = asf_error(&good.replacen("name ltibia", "name lfemur", 1));
        assert!(err.to_string().contains("used twice"), "{err}");
        let err = asf_error(&good.replacen("axis 0 0 20  XYZ", "axis 0 0 20 XXY", 1));
        assert!(err.to_string().contains("'XXY'"), "{err}");
        let err = asf_error(&good.replacen("length 0.45", "length 0", 1));
        assert!(err.to_string().contains("positive"), "{err}");
        let err =
            asf_error(&good.replacen("order TX TY TZ RX RY RZ", "order TX TY TZ RX RY RW", 1));
        assert!(err.to_string().contains("'RW'"), "{err}");
        let cut = good.find("name lfemur").unwrap();
        assert!(asf_error(&good[..cut])
            .to_string()
            .contains("without 'end'"));
        for cut in (0..good.len()).step_by(7) {
            let _ = Asf::parse(&good.as_bytes()[..cut]);
        }
    }

    #[test]
    fn a_bad_file_names_itself_and_its_line() {
        let dir = tempfile::tempdir().unwrap();
        let asf = file("HDM_bk.asf");
        let amc = String::from_utf8_lossy(file("HDM_bk_squat1Reps_014_120.amc"))
            .replacen("ltoes ", "ltoes x", 1);
        std::fs::write(dir.path().join("HDM_bk.asf"), asf).unwrap();
        std::fs::write(dir.path().join("HDM_bk_squat1Reps_014_120.amc"), amc).unwrap();
        let err = format!("{:#}", read_hdm05(dir.path()).unwrap_err());
        assert!(
            err.contains("HDM_bk_squat1Reps_014_120.amc") && err.contains("line 33"),
            "{err}"
        );
        std::fs::remove_file(dir.path().join("HDM_bk.asf")).unwrap();
        let err = format!("{:#}", read_hdm05(dir.path()).unwrap_err());
        assert!(err.contains("no skeleton HDM_bk.asf"), "{err}");
        std::fs::write(dir.path().join("HDM_bk_squat1Reps_014_120.amc"), b"").unwrap();
        std::fs::write(dir.path().join("HDM_bk.asf"), asf).unwrap();
        let err = format!("{:#}", read_hdm05(dir.path()).unwrap_err());
        assert!(err.contains("no frames"), "{err}");
        let empty = tempfile::tempdir().unwrap();
        assert!(read_hdm05(empty.path()).is_err());
    }
}
