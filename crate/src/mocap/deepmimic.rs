//! Reader of the DeepMimic motion clips (Xue Bin Peng, 2018, MIT licence) and their retarget
//! onto our 22 SMPL joints.
//!
//! ## The source
//!
//! `humanoid3d.txt` is JSON: `{"Skeleton": {"Joints": [...]}, "BodyDefs": [...],
//! "DrawShapeDefs": [...]}`. Each joint has an `ID` (its index), a `Name`, a `Type` (`none` for
//! the root, `spherical`, `revolute` or `fixed`), a `Parent` (`-1` for the root) and an attach
//! offset `AttachX/Y/Z`: where the joint sits in its parent's frame, metres. The world is Y up
//! and, in the rest pose (every rotation the identity), the humanoid stands upright facing +X
//! with its right side at +Z (`right_hip` is attached at `Z = +0.085`); that is a proper,
//! unmirrored human (facing × up = right), so `left_*` is the performer's left. The 15 joints:
//! `root` → `chest` → `neck`; `root` → `*_hip` → `*_knee` → `*_ankle`; `chest` →
//! `*_shoulder` → `*_elbow` → `*_wrist` (the wrist is fixed: a hand, not a joint).
//!
//! Each motion file `motions/humanoid3d_<action>.txt` is JSON `{"Loop": "wrap" | "none",
//! "Frames": [[...], ...]}` and each frame is: its duration in seconds (the time to the next
//! frame; the last frame's is unused and often 0), the root's world position (3, metres), the
//! root's world rotation (quaternion `w, x, y, z`), then for every other joint in skeleton order
//! its rotation relative to its parent: a quaternion `w, x, y, z` for spherical joints, one
//! angle in radians for revolute joints, nothing for fixed joints (44 values per frame).
//!
//! Forward kinematics: a joint's world rotation is its parent's world rotation times its local
//! rotation; its world position is its parent's world position plus the parent's world rotation
//! applied to the attach offset. Revolute joints (knees, elbows) turn about their local **Z**
//! axis, as in DeepMimic's kinematic tree; the data agree: the knees' angles lie in −π…0 and
//! the elbows' in 0…π (the joint limits in `humanoid3d.txt`), and about Z a negative knee angle
//! swings the shin to −X (behind the thigh) while a positive elbow angle swings the forearm to
//! +X (in front of the upper arm); the tests check this geometrically on the walk.
//!
//! ## The mapping
//!
//! DeepMimic has 15 joints and no toes, collars, spine segments or head joint, so 9 of our 22
//! joints are synthesised as points fixed to a DeepMimic body, placed where HumanML3D's
//! reference skeleton (`skeleton_example_h3d.npy`) has them relative to its neighbours and
//! where DeepMimic's own body shapes (`BodyDefs`, `DrawShapeDefs` in `humanoid3d.txt`) put
//! the body part. Offsets are metres along the named DeepMimic joint's own axes (at rest: +X
//! forward, +Y up, +Z the performer's right). Bone lengths do not matter (they are made
//! uniform when features are computed); bone directions do.
//!
//! | SMPL joint          | from                                  | why |
//! |---------------------|---------------------------------------|-----|
//! | pelvis              | `root` + (0, 0.07, 0) in `root`'s frame | SMPL's pelvis joint sits about 9 cm above the hip joints (reference skeleton), DeepMimic's root is level with its hips; 0.07 m is the centre of DeepMimic's pelvis body (`BodyDefs` root sphere) |
//! | l_hip / r_hip       | `left_hip` / `right_hip`              | same joint |
//! | spine1              | `chest`                               | DeepMimic's chest joint is its lumbar bend, 0.24 m above the hips; SMPL's spine1 is 0.21 m above them |
//! | spine2              | 40 % of the way `chest` → `neck`      | SMPL's spine2 is about 40 % of the way from spine1 to the shoulder line, which is where DeepMimic's neck joint is |
//! | spine3              | 65 % of the way `chest` → `neck`      | likewise 65 % for spine3 (0.11 m below the collars in the reference) |
//! | neck                | `neck` + (0, 0.07, 0) in `neck`'s frame | DeepMimic's neck joint is the base of the neck, level with the shoulders; SMPL's neck joint is up the neck, 0.1 m above the shoulders. 0.07 m is just below DeepMimic's head sphere (centre 0.175, radius 0.1025, so its bottom is at 0.0725): the neck may not go into the head |
//! | head                | `neck` + (0.06, 0.14, 0) in `neck`'s frame | SMPL's head joint is above and in front of its neck joint (about 45° forward in the reference skeleton); the head sphere has no face, so the neck's rotation carries the facing and this offset gives the bone SMPL's forward lean |
//! | l_collar / r_collar | `chest` + (−0.011, 0.24, ∓0.095) in `chest`'s frame | the centre of the clavicle capsule that `DrawShapeDefs` draws on the chest (`left_clavicle` / `right_clavicle`); DeepMimic has no clavicle joint, so shrugs are lost |
//! | l_shoulder / r_shoulder | `left_shoulder` / `right_shoulder` | same joint |
//! | l_elbow / r_elbow   | `left_elbow` / `right_elbow`          | same joint |
//! | l_wrist / r_wrist   | `left_wrist` / `right_wrist`          | DeepMimic's fixed wrist joint sits at the end of the forearm (0.259 m from the elbow), where SMPL's wrist is |
//! | l_knee / r_knee     | `left_knee` / `right_knee`            | same joint |
//! | l_ankle / r_ankle   | `left_ankle` / `right_ankle`          | same joint |
//! | l_foot / r_foot     | `*_ankle` + (0.12, −0.035, 0) in the ankle's frame | SMPL's foot joint is the ball of the foot: 0.12 m ahead of the ankle and a third of the ankle's height above the sole in the reference skeleton. DeepMimic's foot box spans x −0.0435…0.1335 and y −0.05…0.005 in the ankle's frame, so the point is near its front, 1.5 cm above its sole |
//!
//! ## Timing
//!
//! Frame `i` is at the sum of the durations of frames `0..i`. Durations differ between clips
//! (1/120 s to 1/16 s) and sometimes within one (`roll`), so clips are resampled at 20 fps
//! ([`crate::timing::FPS`]) with a variable step: each output instant interpolates the two
//! source frames around it, the root position linearly and every rotation by slerp, and only
//! then runs the forward kinematics. Interpolating rotations rather than positions keeps
//! every bone rigid through the fast turns of the flips, which are stored at only 16 fps.
//! Looping clips (`"Loop": "wrap"`) are returned as one pass, as stored, not repeated.

use super::{read_files, Source, Take};
use crate::geom::{self, Quat, Vec3};
use crate::skeleton::{Pose, NUM_JOINTS};
use crate::timing::FPS;
use anyhow::{bail, Context, Result};
use std::path::Path;

/// File name of the skeleton in the `deepmimic` folder.
pub const SKELETON_FILE: &str = "humanoid3d.txt";
/// Folder of the motion files in the `deepmimic` folder.
pub const MOTIONS_DIR: &str = "motions";
/// Prefix of the humanoid's motion files (`humanoid3d_walk.txt`); the rest of the stem is the
/// action label.
pub const MOTION_PREFIX: &str = "humanoid3d_";
/// The performer recorded for every take: the source does not say who performed the clips.
pub const ACTOR: &str = "deepmimic";
/// The longest clip accepted, seconds (DeepMimic's are under 5 s).
pub const MAX_SECONDS: f64 = 3600.0;
/// The local axis revolute joints (knees, elbows) turn about, in the joint's own frame.
pub const REVOLUTE_AXIS: Vec3 = [0.0, 0.0, 1.0];

/// How a DeepMimic joint moves, which decides how many values it takes in a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// The root (`none`): world position and rotation, 7 values.
    Root,
    /// A ball joint: a quaternion `w, x, y, z` relative to the parent, 4 values.
    Spherical,
    /// A hinge about [`REVOLUTE_AXIS`]: one angle in radians, 1 value.
    Revolute,
    /// Rigidly attached to its parent: no values.
    Fixed,
}

impl JointKind {
    /// Values this joint takes in a frame.
    pub fn values(self) -> usize {
        match self {
            JointKind::Root => 7,
            JointKind::Spherical => 4,
            JointKind::Revolute => 1,
            JointKind::Fixed => 0,
        }
    }
}

/// One joint of a DeepMimic skeleton.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// The joint's name (`root`, `chest`, `left_knee`, …).
    pub name: String,
    /// How it moves.
    pub kind: JointKind,
    /// Index of the parent joint, always lower than this joint's; `None` for the root.
    pub parent: Option<usize>,
    /// Where the joint sits in its parent's frame, metres (Y up, +X forward, +Z right at rest).
    pub attach: Vec3,
}

/// A DeepMimic skeleton: joints in file order, the root first and parents before children
/// (which [`Skeleton::parse`] checks, so the joints are private).
#[derive(Clone, Debug, PartialEq)]
pub struct Skeleton {
    joints: Vec<Joint>,
}

#[derive(serde::Deserialize)]
struct SkeletonFile {
    #[serde(rename = "Skeleton")]
    skeleton: SkeletonJoints,
}

#[derive(serde::Deserialize)]
struct SkeletonJoints {
    #[serde(rename = "Joints")]
    joints: Vec<RawJoint>,
}

#[derive(serde::Deserialize)]
#[serde(rename_all = "PascalCase")]
struct RawJoint {
    #[serde(rename = "ID")]
    id: i64,
    name: String,
    #[serde(rename = "Type")]
    kind: String,
    parent: i64,
    attach_x: f64,
    attach_y: f64,
    attach_z: f64,
    #[serde(default)]
    attach_theta_x: f64,
    #[serde(default)]
    attach_theta_y: f64,
    #[serde(default)]
    attach_theta_z: f64,
}

impl Skeleton {
    /// Parses a DeepMimic character file (`humanoid3d.txt`). Only the `Skeleton` section is
    /// read; the body shapes are not needed at run time (see the mapping table).
    pub fn parse(text: &str) -> Result<Skeleton> {
        let file: SkeletonFile = serde_json::from_str(text).context(
            "not a DeepMimic skeleton (expected JSON {\"Skeleton\": {\"Joints\": [...]}})",
        )?;
        let mut joints: Vec<Joint> = Vec::with_capacity(file.skeleton.joints.len());
        for (i, raw) in file.skeleton.joints.into_iter().enumerate() {
            let name = raw.name;
            if raw.id != i as i64 {
                bail!(
                    "joint {i} ('{name}') has ID {}; IDs must count 0, 1, 2, … in file order",
                    raw.id
                );
            }
            if joints.iter().any(|j| j.name == name) {
                bail!("joint name '{name}' appears twice");
            }
            let kind = match raw.kind.as_str() {
                "none" => JointKind::Root,
                "spherical" => JointKind::Spherical,
                "revolute" => JointKind::Revolute,
                "fixed" => JointKind::Fixed,
                other => bail!(
                    "joint '{name}' has type '{other}'; expected none, spherical, revolute or fixed"
                ),
            };
            let parent = match (i, raw.parent, kind) {
                (0, -1, JointKind::Root) => None,
                (0, _, _) => {
                    bail!("the first joint ('{name}') must be the root: type none, parent -1")
                }
                (_, _, JointKind::Root) => {
                    bail!("joint '{name}' has type none but is not the first joint")
                }
                (_, p, _) if (0..i as i64).contains(&p) => Some(p as usize),
                (_, p, _) => bail!(
                    "joint '{name}' has parent {p}; a parent must be an earlier joint (0 to {})",
                    i - 1
                ),
            };
            let attach = [raw.attach_x, raw.attach_y, raw.attach_z];
            let theta = [raw.attach_theta_x, raw.attach_theta_y, raw.attach_theta_z];
            if attach.iter().chain(&theta).any(|v| !v.is_finite()) {
                bail!("joint '{name}' has a non-finite attach offset or angle");
            }
            // humanoid3d has none; a rotated joint frame would need DeepMimic's Euler order,
            // which nothing here could check, so it is refused rather than guessed.
            if theta.iter().any(|v| *v != 0.0) {
                bail!(
                    "joint '{name}' has a non-zero AttachTheta, which this reader does not support"
                );
            }
            joints.push(Joint {
                name,
                kind,
                parent,
                attach,
            });
        }
        if joints.is_empty() {
            bail!("the skeleton has no joints");
        }
        Ok(Skeleton { joints })
    }

    /// The joints in file order; index 0 is the root.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// Index of the joint called `name`.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// Values per frame: the duration, then every joint's values (the root's 7 first).
    pub fn frame_len(&self) -> usize {
        1 + self.joints.iter().map(|j| j.kind.values()).sum::<usize>()
    }

    /// World rotation and position (metres, Y up) of every joint in one frame, in joint order
    /// (only as many as the frame has rotations).
    pub fn forward_kinematics(&self, frame: &Frame) -> Vec<(Quat, Vec3)> {
        let mut world: Vec<(Quat, Vec3)> = Vec::with_capacity(self.joints.len());
        for (joint, &local) in self.joints.iter().zip(&frame.rotations) {
            world.push(match joint.parent {
                None => (local, frame.root),
                Some(p) => {
                    let (rotation, position) = world[p];
                    (
                        rotation.mul(local),
                        geom::add(position, rotation.rotate(joint.attach)),
                    )
                }
            });
        }
        world
    }
}

/// One frame of a DeepMimic motion.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Seconds from this frame to the next (unused for the last frame).
    pub duration: f64,
    /// World position of the root, metres, Y up.
    pub root: Vec3,
    /// Per skeleton joint, a unit quaternion: the root's world rotation, every other joint's
    /// rotation relative to its parent (a revolute angle turned into a rotation about
    /// [`REVOLUTE_AXIS`], the identity for fixed joints).
    pub rotations: Vec<Quat>,
}

/// A DeepMimic motion clip, frames as stored (variable durations, any place and facing).
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    /// DeepMimic's loop mode (`wrap` for cycles, `none` for one-off clips); informative only.
    pub loop_mode: String,
    /// The frames.
    pub frames: Vec<Frame>,
}

#[derive(serde::Deserialize)]
struct MotionFile {
    #[serde(rename = "Loop", default)]
    loop_mode: Option<String>,
    #[serde(rename = "Frames")]
    frames: Vec<Vec<serde_json::Value>>,
}

impl Motion {
    /// Parses a DeepMimic motion file for `skeleton`. Errors name the frame (counted from 0)
    /// and the joint: a frame of the wrong length, a value that is not a finite number, a
    /// negative duration or a zero quaternion.
    pub fn parse(text: &str, skeleton: &Skeleton) -> Result<Motion> {
        let file: MotionFile = serde_json::from_str(text).context(
            "not a DeepMimic motion (expected JSON {\"Loop\": ..., \"Frames\": [[...], ...]})",
        )?;
        if file.frames.is_empty() {
            bail!("the motion has no frames");
        }
        let expected = skeleton.frame_len();
        let mut frames = Vec::with_capacity(file.frames.len());
        for (f, raw) in file.frames.iter().enumerate() {
            if raw.len() != expected {
                bail!(
                    "frame {f} has {} values; the skeleton needs {expected} (duration, root \
                     position 3, root rotation 4, then 4 per spherical and 1 per revolute joint)",
                    raw.len()
                );
            }
            let values = raw
                .iter()
                .enumerate()
                .map(|(k, v)| match v.as_f64() {
                    Some(x) if x.is_finite() => Ok(x),
                    _ => bail!("frame {f}: value {k} is not a finite number ({v})"),
                })
                .collect::<Result<Vec<f64>>>()?;
            let duration = values[0];
            if duration < 0.0 {
                bail!("frame {f} has a negative duration ({duration} s)");
            }
            let mut at = 1;
            let mut root = [0.0; 3];
            let mut rotations = Vec::with_capacity(skeleton.joints.len());
            for joint in skeleton.joints() {
                let v = &values[at..at + joint.kind.values()];
                at += v.len();
                let quat = |q: &[f64]| {
                    let q = Quat([q[0], q[1], q[2], q[3]]);
                    if q.0.iter().map(|x| x * x).sum::<f64>() < 1e-12 {
                        bail!("frame {f}: joint '{}' has a zero quaternion", joint.name);
                    }
                    Ok(q.normalized())
                };
                rotations.push(match joint.kind {
                    JointKind::Root => {
                        root = [v[0], v[1], v[2]];
                        quat(&v[3..7])?
                    }
                    JointKind::Spherical => quat(v)?,
                    JointKind::Revolute => Quat::from_axis_angle(REVOLUTE_AXIS, v[0]),
                    JointKind::Fixed => Quat::IDENTITY,
                });
            }
            frames.push(Frame {
                duration,
                root,
                rotations,
            });
        }
        Ok(Motion {
            loop_mode: file.loop_mode.unwrap_or_else(|| "none".into()),
            frames,
        })
    }

    /// Length in seconds: the sum of every frame's duration but the last.
    pub fn duration(&self) -> f64 {
        let n = self.frames.len().saturating_sub(1);
        self.frames[..n].iter().map(|f| f.duration).sum()
    }

    /// The motion sampled every `step` seconds from its first frame to its last (the last
    /// sample at or before the last frame): root positions interpolated linearly, rotations by
    /// slerp. Each sample's duration is `step`.
    pub fn resample(&self, step: f64) -> Vec<Frame> {
        let durations: Vec<f64> = self.frames.iter().map(|f| f.duration).collect();
        sample_plan(&durations, step)
            .into_iter()
            .map(|(i, j, t)| {
                let (a, b) = (&self.frames[i], &self.frames[j]);
                Frame {
                    duration: step,
                    root: geom::lerp(a.root, b.root, t),
                    rotations: a
                        .rotations
                        .iter()
                        .zip(&b.rotations)
                        .map(|(p, q)| p.slerp(*q, t))
                        .collect(),
                }
            })
            .collect()
    }
}

/// For each sample at `k * step` seconds (k = 0, 1, …, up to the last frame's time), the
/// frames `(i, j)` around it and the weight `t` of `j`, where frame `n` is at the sum of
/// `durations[..n]`. Zero durations (repeated instants) are skipped over; a clip whose
/// frames all share one instant gives one sample.
fn sample_plan(durations: &[f64], step: f64) -> Vec<(usize, usize, f64)> {
    if durations.is_empty() || step.is_nan() || step <= 0.0 {
        return Vec::new();
    }
    let mut times = Vec::with_capacity(durations.len());
    let mut now = 0.0;
    for d in durations {
        times.push(now);
        now += d;
    }
    let last = times.len() - 1;
    let end = times[last];
    let count = (end / step + 1e-9).floor() as usize + 1;
    let mut i = 0;
    (0..count)
        .map(|k| {
            let at = (k as f64 * step).min(end);
            // The last frame at or before `at` (allowing rounding), so repeated instants
            // resolve to the later frame and the span to the next frame is never zero.
            while i < last && times[i + 1] <= at + 1e-9 {
                i += 1;
            }
            if i == last {
                (last, last, 0.0)
            } else {
                let t = ((at - times[i]) / (times[i + 1] - times[i])).clamp(0.0, 1.0);
                (i, i + 1, t)
            }
        })
        .collect()
}

/// Where one of our joints comes from on the DeepMimic skeleton.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Landmark {
    /// The position of one DeepMimic joint.
    Joint(&'static str),
    /// A point fixed to a DeepMimic joint's body: the offset (metres) along that joint's own
    /// axes (at rest +X forward, +Y up, +Z the performer's right), from the joint.
    Fixed(&'static str, Vec3),
    /// The point `t` of the way from the first joint to the second.
    Between(&'static str, &'static str, f64),
}

/// The source of each of our joints, in SMPL joint order (see the table in the module doc).
pub const MAPPING: [Landmark; NUM_JOINTS] = [
    Landmark::Fixed("root", [0.0, 0.07, 0.0]),
    Landmark::Joint("left_hip"),
    Landmark::Joint("right_hip"),
    Landmark::Joint("chest"),
    Landmark::Joint("left_knee"),
    Landmark::Joint("right_knee"),
    Landmark::Between("chest", "neck", 0.40),
    Landmark::Joint("left_ankle"),
    Landmark::Joint("right_ankle"),
    Landmark::Between("chest", "neck", 0.65),
    Landmark::Fixed("left_ankle", [0.12, -0.035, 0.0]),
    Landmark::Fixed("right_ankle", [0.12, -0.035, 0.0]),
    Landmark::Fixed("neck", [0.0, 0.07, 0.0]),
    Landmark::Fixed("chest", [-0.011, 0.24, -0.095]),
    Landmark::Fixed("chest", [-0.011, 0.24, 0.095]),
    Landmark::Fixed("neck", [0.06, 0.14, 0.0]),
    Landmark::Joint("left_shoulder"),
    Landmark::Joint("right_shoulder"),
    Landmark::Joint("left_elbow"),
    Landmark::Joint("right_elbow"),
    Landmark::Joint("left_wrist"),
    Landmark::Joint("right_wrist"),
];

/// A landmark with its joint names resolved to skeleton indices.
#[derive(Clone, Copy)]
enum Resolved {
    Fixed(usize, Vec3),
    Between(usize, usize, f64),
}

fn resolve(skeleton: &Skeleton) -> Result<[Resolved; NUM_JOINTS]> {
    let index = |name: &str| {
        skeleton
            .index(name)
            .with_context(|| format!("the DeepMimic skeleton has no joint '{name}'"))
    };
    let mut out = [Resolved::Fixed(0, [0.0; 3]); NUM_JOINTS];
    for (slot, landmark) in out.iter_mut().zip(&MAPPING) {
        *slot = match *landmark {
            Landmark::Joint(a) => Resolved::Fixed(index(a)?, [0.0; 3]),
            Landmark::Fixed(a, offset) => Resolved::Fixed(index(a)?, offset),
            Landmark::Between(a, b, t) => Resolved::Between(index(a)?, index(b)?, t),
        };
    }
    Ok(out)
}

/// Our 22 joints from one frame's DeepMimic world transforms.
fn pose(world: &[(Quat, Vec3)], sources: &[Resolved; NUM_JOINTS]) -> Pose {
    std::array::from_fn(|j| match sources[j] {
        Resolved::Fixed(a, offset) => geom::add(world[a].1, world[a].0.rotate(offset)),
        Resolved::Between(a, b, t) => geom::lerp(world[a].1, world[b].1, t),
    })
}

/// The motion on our 22 joints at 20 fps ([`crate::timing::FPS`]), metres, Y up, place and
/// facing as captured (DeepMimic's gaits head along +X).
pub fn retarget(skeleton: &Skeleton, motion: &Motion) -> Result<Vec<Pose>> {
    let sources = resolve(skeleton)?;
    if motion.frames.is_empty() {
        bail!("the motion has no frames");
    }
    // Guards the allocation of the resampled frames against an absurd duration.
    let seconds = motion.duration();
    if !(0.0..=MAX_SECONDS).contains(&seconds) {
        bail!("the motion lasts {seconds} s; a clip of 0 to {MAX_SECONDS} s was expected");
    }
    if let Some(f) = motion
        .frames
        .iter()
        .position(|f| f.rotations.len() != skeleton.joints.len())
    {
        bail!(
            "frame {f} has {} joint rotations; the skeleton has {} joints",
            motion.frames[f].rotations.len(),
            skeleton.joints.len()
        );
    }
    Ok(motion
        .resample(1.0 / FPS)
        .iter()
        .map(|frame| pose(&skeleton.forward_kinematics(frame), &sources))
        .collect())
}

/// Reads the DeepMimic humanoid clips from `source`, the `deepmimic` folder (`humanoid3d.txt`
/// and `motions/humanoid3d_*.txt`) or a `.tar.xz` of it, as [`Take`]s on our 22 joints: 20 fps,
/// metres, Y up, place and facing as captured, one pass of each clip. Stems are
/// `deepmimic_<action>`, labels the action (`kick`, `getup_facedown`, …), the actor
/// [`ACTOR`]; sorted by stem. Motion files of other characters are ignored.
pub fn read_deepmimic(source: &Path) -> Result<Vec<Take>> {
    let file_name = |path: &str| path.rsplit('/').next().unwrap_or(path).to_string();
    let is_motion = |path: &str| {
        let mut parts = path.rsplit('/');
        let name = parts.next().unwrap_or("");
        parts.next() == Some(MOTIONS_DIR)
            && name.starts_with(MOTION_PREFIX)
            && name.ends_with(".txt")
    };
    let files = read_files(source, &|path| {
        file_name(path) == SKELETON_FILE || is_motion(path)
    })?;
    let shown = |path: &str| source.join(path).display().to_string();

    let skeletons: Vec<&String> = files
        .keys()
        .filter(|p| file_name(p) == SKELETON_FILE)
        .collect();
    let skeleton_path = match skeletons.as_slice() {
        [one] => *one,
        [] => bail!("{}: no {SKELETON_FILE} found", source.display()),
        many => bail!(
            "{}: several {SKELETON_FILE} found ({}); expected one",
            source.display(),
            many.iter()
                .map(|p| p.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let skeleton = Skeleton::parse(&String::from_utf8_lossy(&files[skeleton_path]))
        .with_context(|| format!("reading the DeepMimic skeleton {}", shown(skeleton_path)))?;
    resolve(&skeleton).with_context(|| shown(skeleton_path))?;

    let mut takes = Vec::new();
    for (path, bytes) in files.iter().filter(|(p, _)| is_motion(p)) {
        let name = file_name(path);
        let label = name[MOTION_PREFIX.len()..name.len() - ".txt".len()].to_string();
        if label.is_empty() {
            bail!("{}: the motion file names no action", shown(path));
        }
        let poses = Motion::parse(&String::from_utf8_lossy(bytes), &skeleton)
            .and_then(|motion| retarget(&skeleton, &motion))
            .with_context(|| format!("reading the DeepMimic motion {}", shown(path)))?;
        takes.push(Take {
            source: Source::DeepMimic,
            stem: format!("deepmimic_{label}"),
            actor: ACTOR.to_string(),
            label,
            poses,
        });
    }
    if takes.is_empty() {
        bail!(
            "{}: no {MOTIONS_DIR}/{MOTION_PREFIX}*.txt motion files found",
            source.display()
        );
    }
    takes.sort_by(|a, b| a.stem.cmp(&b.stem));
    if let Some(pair) = takes.windows(2).find(|w| w[0].stem == w[1].stem) {
        bail!(
            "{}: two motion files give the take '{}'",
            source.display(),
            pair[0].stem
        );
    }
    Ok(takes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::joints_to_features;
    use crate::skeleton::{joint, Offsets};
    use std::path::PathBuf;
    use std::sync::OnceLock;

    const ACTIONS: [&str; 22] = [
        "backflip",
        "cartwheel",
        "crawl",
        "dance_a",
        "dance_b",
        "dance_spin",
        "getup_facedown",
        "getup_faceup",
        "jog",
        "jump",
        "kick",
        "punch",
        "ready_to_walk_mirror",
        "roll",
        "run",
        "sideflip",
        "spin",
        "spinkick",
        "stealthy_walk",
        "walk",
        "walk_to_ready_mirror",
        "zombie_walk",
    ];

    fn folder() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/deepmimic")
    }

    fn takes() -> &'static [Take] {
        static TAKES: OnceLock<Vec<Take>> = OnceLock::new();
        TAKES.get_or_init(|| read_deepmimic(&folder()).expect("the DeepMimic folder reads"))
    }

    fn take(label: &str) -> &'static Take {
        takes()
            .iter()
            .find(|t| t.label == label)
            .unwrap_or_else(|| panic!("no take '{label}'"))
    }

    fn skeleton() -> Skeleton {
        Skeleton::parse(&std::fs::read_to_string(folder().join(SKELETON_FILE)).unwrap()).unwrap()
    }

    fn motion(label: &str) -> Motion {
        let path = folder()
            .join(MOTIONS_DIR)
            .join(format!("{MOTION_PREFIX}{label}.txt"));
        Motion::parse(&std::fs::read_to_string(path).unwrap(), &skeleton()).unwrap()
    }

    /// On the reference bones, on the floor, first frame at the origin facing +Z.
    fn canonical(poses: &[Pose]) -> Vec<Pose> {
        joints_to_features(poses, &Offsets::reference()).unwrap().1
    }

    /// Mean speed of the pelvis on the ground plane from the first frame to the last, m/s.
    fn ground_speed(poses: &[Pose]) -> f64 {
        let (a, b) = (
            poses[0][joint::PELVIS],
            poses[poses.len() - 1][joint::PELVIS],
        );
        let d = geom::sub(b, a);
        (d[0] * d[0] + d[2] * d[2]).sqrt() / ((poses.len() - 1) as f64 / FPS)
    }

    fn max_height(poses: &[Pose], j: usize) -> f64 {
        poses
            .iter()
            .map(|p| p[j][1])
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// The part of `child − joint` perpendicular to the line `joint → end`: how far and which
    /// way a limb's middle joint sticks out of the line through its ends.
    fn bend(start: Vec3, middle: Vec3, end: Vec3) -> Vec3 {
        let u = geom::normalize(geom::sub(end, start));
        let d = geom::sub(middle, start);
        geom::sub(d, geom::scale(u, geom::dot(d, u)))
    }

    #[test]
    fn reads_all_22_clips_at_20_fps() {
        let takes = takes();
        let labels: Vec<&str> = takes.iter().map(|t| t.label.as_str()).collect();
        assert_eq!(labels, ACTIONS);
        for t in takes {
            assert_eq!(t.stem, format!("deepmimic_{}", t.label));
            assert_eq!(t.actor, "deepmimic");
            assert_eq!(t.source, Source::DeepMimic);
            assert!(t.poses.iter().flatten().flatten().all(|v| v.is_finite()));
            // One pass at 20 fps on the clip's own clock (durations vary, e.g. in `roll`).
            let seconds = motion(&t.label).duration();
            assert_eq!(
                t.poses.len(),
                (seconds * FPS + 1e-9).floor() as usize + 1,
                "{}",
                t.stem
            );
            assert!(
                t.poses.len() >= 16,
                "{} has {} frames",
                t.stem,
                t.poses.len()
            );
        }
        assert!(takes.windows(2).all(|w| w[0].stem < w[1].stem));
    }

    #[test]
    fn bones_are_human_and_rigid() {
        // (joint, parent, DeepMimic's length, a plausible adult range), metres.
        let bones = [
            (joint::L_KNEE, joint::L_HIP, 0.421546, 0.35..0.50),
            (joint::R_KNEE, joint::R_HIP, 0.421546, 0.35..0.50),
            (joint::L_ANKLE, joint::L_KNEE, 0.40987, 0.35..0.50),
            (joint::R_ANKLE, joint::R_KNEE, 0.40987, 0.35..0.50),
            (joint::L_ELBOW, joint::L_SHOULDER, 0.274788, 0.22..0.36),
            (joint::R_ELBOW, joint::R_SHOULDER, 0.274788, 0.22..0.36),
            (joint::L_WRIST, joint::L_ELBOW, 0.258947, 0.20..0.32),
            (joint::R_WRIST, joint::R_ELBOW, 0.258947, 0.20..0.32),
        ];
        for t in takes() {
            for (f, p) in t.poses.iter().enumerate() {
                for &(j, parent, length, ref range) in &bones {
                    let d = geom::dist(p[j], p[parent]);
                    // Rotations are interpolated, not positions, so bones stay rigid even in
                    // the 16 fps flips.
                    assert!(
                        (d - length).abs() < 1e-6,
                        "{} frame {f} joint {j}: {d}",
                        t.stem
                    );
                    assert!(range.contains(&d));
                }
                let hips = geom::dist(p[joint::L_HIP], p[joint::R_HIP]);
                let shoulders = geom::dist(p[joint::L_SHOULDER], p[joint::R_SHOULDER]);
                assert!((0.15..0.25).contains(&hips) && (0.3..0.45).contains(&shoulders));
            }
        }
    }

    #[test]
    fn walk_jog_run_speeds_are_plausible_and_increasing() {
        let walk = ground_speed(&take("walk").poses);
        let jog = ground_speed(&take("jog").poses);
        let run = ground_speed(&take("run").poses);
        assert!((0.8..1.6).contains(&walk), "walk {walk} m/s");
        assert!((1.8..3.3).contains(&jog), "jog {jog} m/s");
        assert!((2.8..5.0).contains(&run), "run {run} m/s");
        assert!(walk < jog && jog < run);
    }

    #[test]
    fn walk_keeps_a_foot_on_the_floor() {
        let walk = &take("walk").poses;
        // DeepMimic's floor is y = 0: the synthesised toes reach it and go no deeper.
        let lowest = crate::skeleton::lowest_joint(walk);
        assert!(lowest.abs() < 0.03, "lowest joint {lowest} m");
        for (f, p) in canonical(walk).iter().enumerate() {
            let (j, y) = p
                .iter()
                .enumerate()
                .map(|(j, v)| (j, v[1]))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            assert!(y < 0.04, "frame {f}: lowest joint {j} at {y} m");
            let feet = [joint::L_ANKLE, joint::R_ANKLE, joint::L_FOOT, joint::R_FOOT];
            assert!(feet.contains(&j), "frame {f}: lowest joint is {j}");
        }
    }

    #[test]
    fn upright_clips_face_plus_z_with_the_left_hip_at_plus_x() {
        for label in [
            "walk",
            "jog",
            "run",
            "kick",
            "punch",
            "jump",
            "zombie_walk",
            "dance_a",
        ] {
            let poses = canonical(&take(label).poses);
            let p = poses[0];
            // The foot bearing the weight points ahead; a foot swinging behind may point down.
            let (ankle, toe) = if p[joint::L_ANKLE][1] < p[joint::R_ANKLE][1] {
                (joint::L_ANKLE, joint::L_FOOT)
            } else {
                (joint::R_ANKLE, joint::R_FOOT)
            };
            assert!(
                p[toe][2] > p[ankle][2] + 0.08,
                "{label}: toes behind the ankle"
            );
            assert!(
                p[joint::L_HIP][0] > p[joint::PELVIS][0] + 0.03,
                "{label}: left hip at -X"
            );
            assert!(p[joint::R_HIP][0] < p[joint::PELVIS][0] - 0.03, "{label}");
            assert!(
                p[joint::L_SHOULDER][0] > p[joint::R_SHOULDER][0] + 0.2,
                "{label}"
            );
            assert!(
                p[joint::HEAD][2] > p[joint::NECK][2],
                "{label}: head leans back"
            );
            assert!(
                p[joint::HEAD][1] > p[joint::NECK][1] && p[joint::NECK][1] > p[joint::SPINE3][1]
            );
        }
        // Forward is where the gaits go.
        for label in ["walk", "jog", "run"] {
            let poses = canonical(&take(label).poses);
            let d = geom::sub(poses[poses.len() - 1][0], poses[0][0]);
            assert!(d[2] > 0.5 && d[0].abs() < 0.2 * d[2], "{label} goes {d:?}");
        }
    }

    #[test]
    fn knees_bend_backwards_and_elbows_forwards() {
        // The walk goes straight ahead (+Z after canonicalising), so +Z is forward throughout.
        let poses = canonical(&take("walk").poses);
        let legs = [
            (joint::L_HIP, joint::L_KNEE, joint::L_ANKLE),
            (joint::R_HIP, joint::R_KNEE, joint::R_ANKLE),
        ];
        let arms = [
            (joint::L_SHOULDER, joint::L_ELBOW, joint::L_WRIST),
            (joint::R_SHOULDER, joint::R_ELBOW, joint::R_WRIST),
        ];
        for (limbs, sign, what) in [(legs, 1.0, "knee"), (arms, -1.0, "elbow")] {
            for (a, b, c) in limbs {
                // A knee sticks out forward of the hip-ankle line; an elbow sticks out
                // backward of the shoulder-wrist line (the forearm folds forward).
                let out: Vec<f64> = poses
                    .iter()
                    .map(|p| sign * bend(p[a], p[b], p[c])[2])
                    .collect();
                let min = out.iter().cloned().fold(f64::INFINITY, f64::min);
                let max = out.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
                assert!(min > -0.01, "{what} {b} bends the wrong way by {min} m");
                assert!(max > 0.03, "{what} {b} never bends ({max} m)");
            }
        }
    }

    #[test]
    fn revolute_angles_keep_to_the_human_side() {
        // About +Z a knee folds for negative angles and an elbow for positive ones; the data
        // keep to that side (the skeleton's limits: knees −π…0, elbows 0…π), the knees
        // overstretching by at most 0.22 rad (spinkick), which the geometric test confirms.
        let skeleton = skeleton();
        for label in ACTIONS {
            for (f, frame) in motion(label).frames.iter().enumerate() {
                for (joint, q) in skeleton.joints().iter().zip(&frame.rotations) {
                    let angle = 2.0 * q.0[3].atan2(q.0[0]);
                    let ok = match (joint.kind, joint.name.ends_with("knee")) {
                        (JointKind::Revolute, true) => (-3.0..0.25).contains(&angle),
                        (JointKind::Revolute, false) => (-0.01..3.0).contains(&angle),
                        _ => true,
                    };
                    assert!(ok, "{label} frame {f} {}: {angle} rad", joint.name);
                }
            }
        }
    }

    #[test]
    fn jump_rises() {
        let poses = canonical(&take("jump").poses);
        let rise = max_height(&poses, joint::PELVIS) - poses[0][joint::PELVIS][1];
        assert!(rise > 0.2, "the pelvis rises {rise} m");
        let lowest_foot = poses
            .iter()
            .map(|p| p[joint::L_ANKLE][1].min(p[joint::R_ANKLE][1]))
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(
            lowest_foot > 0.2,
            "both feet off the floor by at most {lowest_foot} m"
        );
    }

    #[test]
    fn the_right_foot_kicks() {
        let kick = canonical(&take("kick").poses);
        let (right, left) = (
            max_height(&kick, joint::R_ANKLE),
            max_height(&kick, joint::L_ANKLE),
        );
        assert!(
            right > 1.0 && left < 0.25,
            "kick: right ankle {right} m, left {left} m"
        );
        // The spin kick takes off with the left knee high and kicks with the right foot.
        let spin = canonical(&take("spinkick").poses);
        let (right, left) = (
            max_height(&spin, joint::R_ANKLE),
            max_height(&spin, joint::L_ANKLE),
        );
        assert!(
            right > 1.4 && right > left + 0.3,
            "spinkick: right {right} m, left {left} m"
        );
    }

    #[test]
    fn getups_start_low_and_end_standing() {
        for label in ["getup_facedown", "getup_faceup"] {
            let poses = canonical(&take(label).poses);
            let (first, last) = (poses[0][0][1], poses[poses.len() - 1][0][1]);
            assert!(
                first < 0.3 && last > 0.8,
                "{label}: pelvis from {first} m to {last} m"
            );
        }
    }

    #[test]
    fn sample_plan_follows_variable_durations() {
        // Frames at 0, 0.05, 0.15 s.
        let plan = sample_plan(&[0.05, 0.1, 0.0], 0.05);
        let expected = [(0, 1, 0.0), (1, 2, 0.0), (1, 2, 0.5), (2, 2, 0.0)];
        assert_eq!(plan.len(), expected.len());
        for (got, want) in plan.iter().zip(&expected) {
            assert_eq!((got.0, got.1), (want.0, want.1));
            assert!((got.2 - want.2).abs() < 1e-9, "{plan:?}");
        }
        // A repeated instant (zero duration mid-clip) resolves to the later frame.
        let plan = sample_plan(&[0.1, 0.0, 0.1, 0.0], 0.05);
        let pairs: Vec<(usize, usize)> = plan.iter().map(|p| (p.0, p.1)).collect();
        assert_eq!(pairs, [(0, 1), (0, 1), (2, 3), (2, 3), (3, 3)]);
        // The last frame's duration is not part of the clip.
        assert_eq!(sample_plan(&[0.05, 0.05, 7.0], 0.05).len(), 3);
        assert_eq!(sample_plan(&[0.0], 0.05), [(0, 0, 0.0)]);
        assert!(sample_plan(&[], 0.05).is_empty());
    }

    #[test]
    fn resampling_interpolates_the_root_and_rotations() {
        let skeleton = skeleton();
        let mut a = motion("walk").frames[0].clone();
        let mut b = a.clone();
        a.duration = 0.1;
        a.root = [0.0, 1.0, 0.0];
        b.root = [1.0, 1.0, 0.0];
        a.rotations[0] = Quat::IDENTITY;
        b.rotations[0] = Quat::from_yaw(1.0);
        let m = Motion {
            loop_mode: "none".into(),
            frames: vec![a, b],
        };
        let frames = m.resample(0.05);
        assert_eq!(frames.len(), 3);
        assert!((frames[1].root[0] - 0.5).abs() < 1e-12);
        let yaw = 2.0 * frames[1].rotations[0].0[2].atan2(frames[1].rotations[0].0[0]);
        assert!((yaw - 0.5).abs() < 1e-9);
        assert_eq!(retarget(&skeleton, &m).unwrap().len(), 3);
    }

    #[test]
    fn mapping_offsets_match_the_body_shapes() {
        let text = std::fs::read_to_string(folder().join(SKELETON_FILE)).unwrap();
        let json: serde_json::Value = serde_json::from_str(&text).unwrap();
        let shape = |section: &str, name: &str| {
            let s = json[section]
                .as_array()
                .unwrap()
                .iter()
                .find(|s| s["Name"] == name)
                .unwrap_or_else(|| panic!("no {name} in {section}"));
            let get = |k: &str| s[k].as_f64().unwrap();
            (
                [get("AttachX"), get("AttachY"), get("AttachZ")],
                [get("Param0"), get("Param1"), get("Param2")],
            )
        };
        let (pelvis, _) = shape("BodyDefs", "root");
        assert_eq!(MAPPING[joint::PELVIS], Landmark::Fixed("root", pelvis));
        for (j, name) in [
            (joint::L_COLLAR, "left_clavicle"),
            (joint::R_COLLAR, "right_clavicle"),
        ] {
            let (at, _) = shape("DrawShapeDefs", name);
            assert_eq!(MAPPING[j], Landmark::Fixed("chest", at));
        }
        // The toe point lies inside the front of the foot box, nearer the sole than the top.
        for (j, name) in [
            (joint::L_FOOT, "left_ankle"),
            (joint::R_FOOT, "right_ankle"),
        ] {
            let (centre, size) = shape("BodyDefs", name);
            let Landmark::Fixed(parent, toe) = MAPPING[j] else {
                panic!()
            };
            assert_eq!(parent, name);
            let front = centre[0] + size[0] / 2.0;
            assert!(toe[0] < front && toe[0] > front - 0.03);
            let (sole, top) = (centre[1] - size[1] / 2.0, centre[1] + size[1] / 2.0);
            assert!(toe[1] > sole && toe[1] < (sole + top) / 2.0);
        }
        // The synthesised neck stays below the head sphere.
        let (head, size) = shape("BodyDefs", "neck");
        let Landmark::Fixed("neck", neck) = MAPPING[joint::NECK] else {
            panic!()
        };
        assert!(neck[1] <= head[1] - size[0] / 2.0);
        // Every mapped name exists.
        resolve(&skeleton()).unwrap();
    }

    #[test]
    fn malformed_input_is_an_error_not_a_panic() {
        let skeleton = skeleton();
        let message = |r: Result<Motion>| format!("{:#}", r.unwrap_err());
        // A standing frame of `n` values: identity rotations, straight limbs.
        let frame = |n: usize| {
            let mut v: Vec<String> = ["0.1", "0", "0.9", "0"].map(String::from).to_vec();
            for joint in skeleton.joints() {
                let values: &[&str] = match joint.kind {
                    JointKind::Root | JointKind::Spherical => &["1", "0", "0", "0"],
                    JointKind::Revolute => &["0"],
                    JointKind::Fixed => &[],
                };
                v.extend(values.iter().map(|s| s.to_string()));
            }
            v.truncate(n);
            format!("[{}]", v.join(","))
        };
        let good = frame(skeleton.frame_len());
        // A valid file parses, so the failures below are the ones intended.
        let ok = format!("{{\"Loop\": \"none\", \"Frames\": [{good}, {good}]}}");
        Motion::parse(&ok, &skeleton).unwrap();

        assert!(message(Motion::parse("{\"Frames\": [[1, 2", &skeleton))
            .contains("not a DeepMimic motion"));
        assert!(message(Motion::parse("[]", &skeleton)).contains("not a DeepMimic motion"));
        assert!(message(Motion::parse("{\"Frames\": []}", &skeleton)).contains("no frames"));
        let short = format!("{{\"Frames\": [{good}, {}]}}", frame(40));
        let e = message(Motion::parse(&short, &skeleton));
        assert!(
            e.contains("frame 1 has 40 values") && e.contains("44"),
            "{e}"
        );
        let text = format!("{{\"Frames\": [{}]}}", good.replacen("0.9", "\"x\"", 1));
        assert!(message(Motion::parse(&text, &skeleton)).contains("frame 0: value 2"));
        let text = format!("{{\"Frames\": [{}]}}", good.replacen("0.1", "-0.1", 1));
        assert!(message(Motion::parse(&text, &skeleton)).contains("negative duration"));
        let text = format!("{{\"Frames\": [{}]}}", good.replacen(",1,", ",0,", 1));
        assert!(message(Motion::parse(&text, &skeleton)).contains("'root' has a zero quaternion"));
        assert!(Motion::parse("{\"Frames\": [[1e999]]}", &skeleton).is_err());

        for bad in [
            "",
            "{}",
            "{\"Skeleton\": {\"Joints\": []}}",
            r#"{"Skeleton": {"Joints": [{"ID": 0, "Name": "root", "Type": "none", "Parent": 3,
                "AttachX": 0, "AttachY": 0, "AttachZ": 0}]}}"#,
            r#"{"Skeleton": {"Joints": [{"ID": 0, "Name": "root", "Type": "none", "Parent": -1,
                "AttachX": 0, "AttachY": 0, "AttachZ": 0}, {"ID": 1, "Name": "a",
                "Type": "planar", "Parent": 0, "AttachX": 0, "AttachY": 0, "AttachZ": 0}]}}"#,
        ] {
            assert!(Skeleton::parse(bad).is_err(), "{bad}");
        }
        // A skeleton without the joints the mapping needs parses but cannot be retargeted.
        let lone = Skeleton::parse(
            r#"{"Skeleton": {"Joints": [{"ID": 0, "Name": "root", "Type": "none", "Parent": -1,
                "AttachX": 0, "AttachY": 0, "AttachZ": 0}]}}"#,
        )
        .unwrap();
        let m = Motion::parse("{\"Frames\": [[0, 0, 1, 0, 1, 0, 0, 0]]}", &lone).unwrap();
        assert!(format!("{:#}", retarget(&lone, &m).unwrap_err()).contains("no joint 'left_hip'"));
    }

    #[test]
    fn a_bad_file_in_the_folder_is_named_in_the_error() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::copy(folder().join(SKELETON_FILE), dir.path().join(SKELETON_FILE)).unwrap();
        std::fs::create_dir(dir.path().join(MOTIONS_DIR)).unwrap();
        let walk = std::fs::read_to_string(folder().join("motions/humanoid3d_walk.txt")).unwrap();
        let motions = dir.path().join(MOTIONS_DIR);
        std::fs::write(motions.join("humanoid3d_walk.txt"), &walk).unwrap();
        // Another character's clip is not ours to read.
        std::fs::write(motions.join("dog3d_pace.txt"), "not json").unwrap();
        let takes = read_deepmimic(dir.path()).unwrap();
        assert_eq!(takes.len(), 1);
        assert_eq!(takes[0].poses, take("walk").poses);

        // Drop the last value of the second frame.
        let mut value: serde_json::Value = serde_json::from_str(&walk).unwrap();
        value["Frames"][1].as_array_mut().unwrap().pop();
        std::fs::write(motions.join("humanoid3d_bad.txt"), value.to_string()).unwrap();
        let e = format!("{:#}", read_deepmimic(dir.path()).unwrap_err());
        assert!(
            e.contains("humanoid3d_bad.txt") && e.contains("frame 1 has 43 values"),
            "{e}"
        );

        std::fs::remove_file(dir.path().join(SKELETON_FILE)).unwrap();
        let e = format!("{:#}", read_deepmimic(dir.path()).unwrap_err());
        assert!(e.contains("no humanoid3d.txt"), "{e}");
        assert!(read_deepmimic(&dir.path().join("missing.tar.xz")).is_err());
    }

    /// Figures for the report: `cargo test --release -p coma --lib mocap::deepmimic::tests::figures -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn figures() {
        for t in takes() {
            let c = canonical(&t.poses);
            println!(
                "{:<24} {:>4} frames {:>5.2} s  ground speed {:>4.2} m/s  pelvis first {:.2} max {:.2} m  max ankle L {:.2} R {:.2} m  lowest raw {:+.3} m",
                t.stem,
                t.poses.len(),
                (t.poses.len() - 1) as f64 / FPS,
                ground_speed(&t.poses),
                c[0][0][1],
                max_height(&c, joint::PELVIS),
                max_height(&c, joint::L_ANKLE),
                max_height(&c, joint::R_ANKLE),
                crate::skeleton::lowest_joint(&t.poses),
            );
        }
    }

    /// Filmstrips to look at: `... mocap::deepmimic::tests::filmstrips -- --ignored`, written
    /// to the system's temporary folder as `deepmimic_<action>.png`.
    #[test]
    #[ignore]
    fn filmstrips() {
        use crate::render::{write_filmstrip, FilmstripOptions, View};
        for t in takes() {
            for view in [View::Side, View::ThreeQuarter] {
                let options = FilmstripOptions {
                    title: Some(t.stem.clone()),
                    view,
                    ..FilmstripOptions::default()
                };
                let path = std::env::temp_dir().join(format!("{}_{}.png", t.stem, view.name()));
                write_filmstrip(&path, &canonical(&t.poses), &options).unwrap();
            }
        }
    }
}
