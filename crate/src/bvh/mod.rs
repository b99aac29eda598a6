//! BVH motion capture files: a reader for any hierarchy and channel layout, forward kinematics
//! to world positions, the retarget of the Bandai-Namco skeleton onto our 22 joints
//! ([`bandai`]) and a writer for the 22-joint skeleton ([`writer`]).
//!
//! Conventions of the format as read here:
//! - Any joint may have any subset of the six channels, in any order. Rotation channels
//!   compose in the order they are listed: `Zrotation Xrotation Yrotation` means
//!   `R = Rz · Rx · Ry`, angles in degrees, acting on column vectors.
//! - A joint with position channels takes the channel values as its local translation on those
//!   axes (they replace the OFFSET there, as Blender reads them); other axes keep the OFFSET.
//! - A joint's world position is `parent position + parent world rotation · local
//!   translation`; its world rotation is `parent world rotation · local rotation`.

pub mod bandai;
pub mod writer;

use crate::geom::{self, Quat, Vec3};
use crate::skeleton::{Pose, JOINT_NAMES, NUM_JOINTS};
use crate::timing::FPS;

/// Largest number of joints and of channel values per frame we accept, so a hostile file
/// cannot make us allocate without bound before its data is even read.
const MAX_JOINTS: usize = 4096;

/// One animation channel of a joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    Xposition,
    Yposition,
    Zposition,
    Xrotation,
    Yrotation,
    Zrotation,
}

impl Channel {
    fn parse(word: &str) -> Option<Channel> {
        Some(match word.to_ascii_lowercase().as_str() {
            "xposition" => Channel::Xposition,
            "yposition" => Channel::Yposition,
            "zposition" => Channel::Zposition,
            "xrotation" => Channel::Xrotation,
            "yrotation" => Channel::Yrotation,
            "zrotation" => Channel::Zrotation,
            _ => return None,
        })
    }

    /// The name used in files.
    pub fn name(self) -> &'static str {
        match self {
            Channel::Xposition => "Xposition",
            Channel::Yposition => "Yposition",
            Channel::Zposition => "Zposition",
            Channel::Xrotation => "Xrotation",
            Channel::Yrotation => "Yrotation",
            Channel::Zrotation => "Zrotation",
        }
    }
}

/// One joint of the hierarchy.
#[derive(Clone, Debug, PartialEq)]
pub struct BvhJoint {
    /// Name as written in the file.
    pub name: String,
    /// Index of the parent joint; `None` for the root.
    pub parent: Option<usize>,
    /// Rest offset from the parent, in the file's units.
    pub offset: Vec3,
    /// Animated channels, in file order.
    pub channels: Vec<Channel>,
    /// Offset of the end site, for joints that end a chain.
    pub end_site: Option<Vec3>,
    /// Index of this joint's first value in a frame's row.
    pub first_value: usize,
}

/// A parsed BVH file.
#[derive(Clone, Debug, PartialEq)]
pub struct Bvh {
    /// Joints in file order; parents come before their children.
    pub joints: Vec<BvhJoint>,
    /// Seconds per frame.
    pub frame_time: f64,
    /// One row of channel values per frame.
    pub frames: Vec<Vec<f64>>,
}

/// Why a BVH file could not be read or converted.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum BvhError {
    #[error("line {line}: {message}")]
    Syntax { line: usize, message: String },
    #[error("unexpected end of file: {0}")]
    Eof(String),
    #[error("skeleton not recognised: {0}")]
    UnknownSkeleton(String),
    #[error("the motion has no frames")]
    Empty,
}

struct Tokens<'a> {
    words: Vec<(usize, &'a str)>,
    pos: usize,
}

impl<'a> Tokens<'a> {
    fn new(text: &'a str) -> Tokens<'a> {
        let words = text
            .lines()
            .enumerate()
            .flat_map(|(i, l)| l.split_whitespace().map(move |w| (i + 1, w)))
            .collect();
        Tokens { words, pos: 0 }
    }

    fn next(&mut self, what: &str) -> Result<(usize, &'a str), BvhError> {
        let t = self
            .words
            .get(self.pos)
            .copied()
            .ok_or_else(|| BvhError::Eof(format!("expected {what}")))?;
        self.pos += 1;
        Ok(t)
    }

    fn peek(&self) -> Option<&'a str> {
        self.words.get(self.pos).map(|t| t.1)
    }

    fn expect(&mut self, word: &str) -> Result<usize, BvhError> {
        let (line, w) = self.next(word)?;
        if w.eq_ignore_ascii_case(word) {
            Ok(line)
        } else {
            Err(BvhError::Syntax {
                line,
                message: format!("expected '{word}', found '{w}'"),
            })
        }
    }

    fn number(&mut self, what: &str) -> Result<f64, BvhError> {
        let (line, w) = self.next(what)?;
        match w.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(BvhError::Syntax {
                line,
                message: format!("expected {what} (a number), found '{w}'"),
            }),
        }
    }

    fn vec3(&mut self, what: &str) -> Result<Vec3, BvhError> {
        Ok([self.number(what)?, self.number(what)?, self.number(what)?])
    }
}

impl Bvh {
    /// Parses BVH text. Errors name the line and what was expected.
    pub fn parse(text: &str) -> Result<Bvh, BvhError> {
        let mut tok = Tokens::new(text);
        tok.expect("HIERARCHY")?;
        let mut joints = Vec::new();
        let line = tok.expect("ROOT")?;
        let mut values = 0usize;
        parse_joint(&mut tok, None, &mut joints, &mut values, line)?;
        tok.expect("MOTION")?;
        tok.expect("Frames:")?;
        let (line, w) = tok.next("frame count")?;
        let count: usize = w.parse().map_err(|_| BvhError::Syntax {
            line,
            message: format!("expected a frame count, found '{w}'"),
        })?;
        tok.expect("Frame")?;
        tok.expect("Time:")?;
        let frame_time = tok.number("frame time")?;
        if frame_time <= 0.0 {
            return Err(BvhError::Syntax {
                line,
                message: format!("frame time must be positive, found {frame_time}"),
            });
        }
        let available = tok.words.len() - tok.pos;
        if values == 0 || count.saturating_mul(values) > available {
            return Err(BvhError::Eof(format!(
                "{count} frames of {values} values announced, {available} values present"
            )));
        }
        let mut frames = Vec::with_capacity(count);
        for _ in 0..count {
            let row = (0..values)
                .map(|_| tok.number("channel value"))
                .collect::<Result<Vec<_>, _>>()?;
            frames.push(row);
        }
        Ok(Bvh {
            joints,
            frame_time,
            frames,
        })
    }

    /// Frames per second.
    pub fn fps(&self) -> f64 {
        1.0 / self.frame_time
    }

    /// Index of the joint with this name.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// Local rotation and translation of joint `j` in frame `f`.
    pub fn local_transform(&self, f: usize, j: usize) -> (Quat, Vec3) {
        let joint = &self.joints[j];
        let row = &self.frames[f];
        let mut rot = Quat::IDENTITY;
        let mut pos = joint.offset;
        for (k, ch) in joint.channels.iter().enumerate() {
            let v = row[joint.first_value + k];
            match ch {
                Channel::Xposition => pos[0] = v,
                Channel::Yposition => pos[1] = v,
                Channel::Zposition => pos[2] = v,
                Channel::Xrotation => {
                    rot = rot.mul(Quat::from_axis_angle([1.0, 0.0, 0.0], v.to_radians()))
                }
                Channel::Yrotation => {
                    rot = rot.mul(Quat::from_axis_angle([0.0, 1.0, 0.0], v.to_radians()))
                }
                Channel::Zrotation => {
                    rot = rot.mul(Quat::from_axis_angle([0.0, 0.0, 1.0], v.to_radians()))
                }
            }
        }
        (rot, pos)
    }

    /// World rotation and position of every joint in frame `f`, in the file's units.
    pub fn world_transforms(&self, f: usize) -> Vec<(Quat, Vec3)> {
        let mut out: Vec<(Quat, Vec3)> = Vec::with_capacity(self.joints.len());
        for (j, joint) in self.joints.iter().enumerate() {
            let (rot, pos) = self.local_transform(f, j);
            out.push(match joint.parent {
                None => (rot, pos),
                Some(p) => {
                    let (prot, ppos) = out[p];
                    (prot.mul(rot), geom::add(ppos, prot.rotate(pos)))
                }
            });
        }
        out
    }

    /// World positions of every joint in frame `f`, in the file's units.
    pub fn world_positions(&self, f: usize) -> Vec<Vec3> {
        self.world_transforms(f).into_iter().map(|t| t.1).collect()
    }
}

fn parse_joint(
    tok: &mut Tokens,
    parent: Option<usize>,
    joints: &mut Vec<BvhJoint>,
    values: &mut usize,
    line: usize,
) -> Result<(), BvhError> {
    if joints.len() >= MAX_JOINTS {
        return Err(BvhError::Syntax {
            line,
            message: format!("more than {MAX_JOINTS} joints"),
        });
    }
    let (_, name) = tok.next("joint name")?;
    tok.expect("{")?;
    tok.expect("OFFSET")?;
    let offset = tok.vec3("offset")?;
    let mut channels = Vec::new();
    if tok
        .peek()
        .is_some_and(|w| w.eq_ignore_ascii_case("CHANNELS"))
    {
        tok.next("CHANNELS")?;
        let (line, w) = tok.next("channel count")?;
        let n: usize = w
            .parse()
            .ok()
            .filter(|n| *n <= 6)
            .ok_or_else(|| BvhError::Syntax {
                line,
                message: format!("expected a channel count of 0 to 6, found '{w}'"),
            })?;
        for _ in 0..n {
            let (line, w) = tok.next("channel name")?;
            channels.push(Channel::parse(w).ok_or_else(|| BvhError::Syntax {
                line,
                message: format!("unknown channel '{w}'"),
            })?);
        }
    }
    let index = joints.len();
    joints.push(BvhJoint {
        name: name.to_string(),
        parent,
        offset,
        first_value: *values,
        channels,
        end_site: None,
    });
    *values += joints[index].channels.len();
    loop {
        let (line, w) = tok.next("JOINT, End Site or }")?;
        match w.to_ascii_uppercase().as_str() {
            "JOINT" => parse_joint(tok, Some(index), joints, values, line)?,
            "END" => {
                tok.expect("Site")?;
                tok.expect("{")?;
                tok.expect("OFFSET")?;
                joints[index].end_site = Some(tok.vec3("end site offset")?);
                tok.expect("}")?;
            }
            "}" => return Ok(()),
            _ => {
                return Err(BvhError::Syntax {
                    line,
                    message: format!("expected JOINT, End Site or '}}', found '{w}'"),
                })
            }
        }
    }
}

/// Samples world positions at 20 fps by linear interpolation between the file's frames.
/// Returns one row of positions per output frame, in the file's units.
pub fn resample_positions(bvh: &Bvh) -> Vec<Vec<Vec3>> {
    let source: Vec<Vec<Vec3>> = (0..bvh.frames.len())
        .map(|f| bvh.world_positions(f))
        .collect();
    resample(&source, bvh.frame_time, 1.0 / FPS)
}

/// Linear resampling of a sequence of joint positions from `from_dt` to `to_dt` seconds per
/// frame, covering the same duration (the last output frame is at or before the last input).
pub fn resample(source: &[Vec<Vec3>], from_dt: f64, to_dt: f64) -> Vec<Vec<Vec3>> {
    if source.is_empty() {
        return Vec::new();
    }
    let duration = (source.len() - 1) as f64 * from_dt;
    let count = (duration / to_dt + 1e-9).floor() as usize + 1;
    (0..count)
        .map(|k| {
            let x = k as f64 * to_dt / from_dt;
            let i = (x.floor() as usize).min(source.len() - 1);
            let a = x - i as f64;
            let j = (i + 1).min(source.len() - 1);
            source[i]
                .iter()
                .zip(&source[j])
                .map(|(p, q)| geom::lerp(*p, *q, a))
                .collect()
        })
        .collect()
}

/// Reads any BVH we know as a 22-joint motion at 20 fps in metres: files written by
/// [`writer`] (joints named as in [`JOINT_NAMES`], metres) and Bandai-Namco files (see
/// [`bandai`]). Other skeletons are refused with the joint names that were expected.
pub fn to_smpl_motion(bvh: &Bvh) -> Result<Vec<Pose>, BvhError> {
    if bvh.frames.is_empty() {
        return Err(BvhError::Empty);
    }
    if JOINT_NAMES.iter().all(|n| bvh.joint_index(n).is_some()) {
        let index: Vec<usize> = JOINT_NAMES
            .iter()
            .map(|n| bvh.joint_index(n).unwrap())
            .collect();
        let rows = resample_positions(bvh);
        return Ok(rows
            .iter()
            .map(|row| std::array::from_fn(|j| row[index[j]]))
            .collect());
    }
    if bandai::is_bandai(bvh) {
        return bandai::retarget(bvh);
    }
    Err(BvhError::UnknownSkeleton(format!(
        "expected our 22 SMPL joints ({} …) or the Bandai-Namco skeleton (Hips, Spine, Chest, …); found {}",
        JOINT_NAMES[..4].join(", "),
        bvh.joints.iter().take(6).map(|j| j.name.as_str()).collect::<Vec<_>>().join(", ")
    )))
}

/// Number of joints in our skeleton, re-exported for writers of other formats.
pub const SMPL_JOINTS: usize = NUM_JOINTS;

#[cfg(test)]
mod tests {
    use super::*;

    const TWO_BONES: &str = "HIERARCHY
ROOT hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT arm
  {
    OFFSET 0 10 0
    CHANNELS 3 Yrotation Xrotation Zrotation
    End Site
    {
      OFFSET 0 5 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.033333
1 2 3 0 0 0 0 0 0
0 0 0 90 0 0 0 0 90
";

    #[test]
    fn parses_hierarchy_and_frames() {
        let bvh = Bvh::parse(TWO_BONES).unwrap();
        assert_eq!(bvh.joints.len(), 2);
        assert_eq!(bvh.joints[1].parent, Some(0));
        assert_eq!(bvh.joints[1].first_value, 6);
        assert_eq!(bvh.joints[1].end_site, Some([0.0, 5.0, 0.0]));
        assert_eq!(bvh.frames.len(), 2);
        assert!((bvh.fps() - 30.0).abs() < 0.01);
    }

    #[test]
    fn forward_kinematics_applies_rotations_in_channel_order() {
        let bvh = Bvh::parse(TWO_BONES).unwrap();
        let p0 = bvh.world_positions(0);
        assert_eq!(p0[1], [1.0, 12.0, 3.0]);
        // Root turned 90° about Z: the arm's +Y offset points to −X.
        let p1 = bvh.world_positions(1);
        assert!(geom::dist(p1[1], [-10.0, 0.0, 0.0]) < 1e-9, "{:?}", p1[1]);
    }

    #[test]
    fn errors_name_the_line() {
        let bad = TWO_BONES.replace("CHANNELS 3 Yrotation", "CHANNELS 3 Wrotation");
        let err = Bvh::parse(&bad).unwrap_err();
        assert_eq!(
            err,
            BvhError::Syntax {
                line: 9,
                message: "unknown channel 'Wrotation'".into()
            }
        );
        let short = TWO_BONES.replace("0 0 0 90 0 0 0 0 90\n", "");
        assert!(matches!(Bvh::parse(&short), Err(BvhError::Eof(_))));
        assert!(Bvh::parse("").is_err());
        assert!(Bvh::parse(&TWO_BONES.replace("0.033333", "nan")).is_err());
    }

    #[test]
    fn unknown_skeleton_is_refused_with_names() {
        let bvh = Bvh::parse(TWO_BONES).unwrap();
        let err = to_smpl_motion(&bvh).unwrap_err().to_string();
        assert!(err.contains("hips, arm"), "{err}");
    }

    #[test]
    fn resampling_30_to_20_fps_interpolates() {
        let source: Vec<Vec<Vec3>> = (0..31).map(|i| vec![[i as f64, 0.0, 0.0]]).collect();
        let out = resample(&source, 1.0 / 30.0, 1.0 / 20.0);
        assert_eq!(out.len(), 21);
        assert!((out[1][0][0] - 1.5).abs() < 1e-9);
        assert!((out[20][0][0] - 30.0).abs() < 1e-9);
    }
}
