//! Reader of the CMU 8-action subset in exponential maps (the files DMGNN and Li et al. 2018
//! forecast on), retargeted onto our 22 SMPL joints.
//!
//! The source (`cmu-8action-expmap.tar.xz`, or the folder it unpacks to) holds
//! `{train,test}/<action>/<action>_<n>.txt` and `skeleton-38.json`. Each text file is a CSV of
//! 117 numbers per row at 120 Hz: the root position (columns 0–2, CMU ASF length units, 1 unit =
//! 0.0254 / 0.45 m) and then one exponential map per joint of a 38-joint skeleton (radians,
//! joint 0 = root orientation). Y is up and +x is the performer's left, as in our skeleton, so
//! no axis is flipped. **Row 0 of every file is a rest pose, not motion, and is dropped.**
//!
//! Forward kinematics are DMGNN's, kept in its row-vector convention so that they can be
//! compared with `cmu-short/processor/data_tools.py` line by line:
//! `R_i = expmap(r_i) · R_parent`, `p_i = offset_i · R_parent + p_parent`, and
//! `p_0 = offset_0 + root position`, `R_0 = expmap(r_0)`. The exp-maps are turned into rotation
//! matrices frame by frame and only positions are ever interpolated: exp-maps wrap near π (steps
//! of up to 9 rad between neighbouring rows), so averaging them would be meaningless.
//!
//! The source does not name its joints; the names below are inferred from the parents and bone
//! lengths (see the data README, `shared/data/README.md`). Which joint (DMGNN index) drives
//! which SMPL joint:
//!
//! | SMPL joint              | from                                                              |
//! |-------------------------|-------------------------------------------------------------------|
//! | pelvis                  | 0 root                                                            |
//! | l_hip / r_hip           | 2 / 8, hip joint centres (ends of `l/rhipjoint`)                  |
//! | l_knee / r_knee         | 3 / 9                                                             |
//! | l_ankle / r_ankle       | 4 / 10                                                            |
//! | l_foot / r_foot         | 5 / 11, ball of the foot (the toe tips 6 / 12 are not used)       |
//! | spine1                  | 14, end of the lower back                                         |
//! | spine2                  | synthesised: midpoint of 14 and 15                                |
//! | spine3                  | 15, end of the upper back (= 16 thorax, which has a zero offset)  |
//! | neck                    | 17, end of the lower neck                                         |
//! | head                    | synthesised: 1.56 units (8.8 cm) ahead of 18 (upper neck), in the head's own frame |
//! | l_collar / r_collar     | synthesised: a third of the way from 17 to 21 / 30                |
//! | l_shoulder / r_shoulder | 21 / 30, ends of the clavicles                                    |
//! | l_elbow / r_elbow       | 22 / 31                                                           |
//! | l_wrist / r_wrist       | 23 / 32 (hands, fingers and thumbs 25–28 / 34–37 are not used)    |
//!
//! Why the synthesised points:
//! - *spine2*: CMU has two spine segments below the clavicles where SMPL has three. The clavicles
//!   leave from 15, as SMPL's collars leave from spine3, so spine3 goes there and spine2 splits
//!   the upper back. Both halves point the same way, so where it splits does not matter once
//!   bone lengths are made uniform (only bone directions survive that step).
//! - *collars*: CMU's clavicle runs from the upper back straight out to the shoulder (20 cm out,
//!   5 cm up), with no joint on the way. SMPL's collar joint sits near the base of the neck:
//!   in HumanML3D's reference skeleton the spine3 → collar bone rises steeply (12 cm up, 7 cm
//!   out) and collar → shoulder runs level. A point a third of the way from the lower neck to
//!   the shoulder (7 cm out, 8 cm up from 15) gives the same bend.
//! - *head*: SMPL's head joint sits in the middle of the skull, ahead of the top of the neck
//!   (the reference skeleton's neck → head bone leans 46° forward), while CMU's chain runs up
//!   the back of the neck to the crown (18 → 19 is vertical in a neutral pose). A point fixed in
//!   the head's frame, as far ahead of the upper neck as the upper neck is long, leans 35°–55°
//!   forward in the walking and soccer takes and turns with the head.
//!
//! Positions are converted to metres and resampled from 120 Hz to 20 fps ([`FPS`]) by linear
//! interpolation (every sixth row, as 120 is a multiple of 20). Bone lengths, floor, origin and
//! facing are made canonical later ([`crate::features::joints_to_features`]).
//!
//! Stems are `cmu_<split>_<file stem>` (`cmu_train_soccer_3`, `cmu_test_soccer_1`): the source
//! numbers its train and test files from 1 each, so the split is part of the name.
//! [`source_split_is_test`] tells which takes the source set aside for testing.

use super::{read_files, Source, Take};
use crate::bvh::resample;
use crate::geom::{self, Vec3};
use crate::skeleton::{Pose, NUM_JOINTS};
use crate::timing::FPS;
use anyhow::{anyhow, bail, Context, Result};
use std::path::Path;

/// Rows per second of the source files.
pub const CAPTURE_FPS: f64 = 120.0;
/// Metres per CMU ASF length unit (the ASF files scale inches by 0.45).
pub const UNIT: f64 = 0.0254 / 0.45;
/// Joints of the source skeleton.
pub const CMU_JOINTS: usize = 38;
/// Numbers per CSV row: root position, then one exponential map per joint.
pub const COLUMNS: usize = 3 + 3 * CMU_JOINTS;

/// Parents of the 38 joints as DMGNN's `_some_variables` lists them (−1 = root). The mapping's
/// joint names are inferred for this exact tree, so another tree is refused.
const EXPECTED_PARENTS: [i64; CMU_JOINTS] = [
    -1, 0, 1, 2, 3, 4, 5, 0, 7, 8, 9, 10, 11, 0, 13, 14, 15, 16, 17, 18, 15, 20, 21, 22, 23, 24,
    25, 23, 27, 15, 29, 30, 31, 32, 33, 34, 32, 36,
];

/// A 3×3 rotation matrix, row-major, used as DMGNN does: row vectors multiplied on the left.
type Mat3 = [[f64; 3]; 3];

/// Where an SMPL joint comes from, in terms of the source's joints (DMGNN indices).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Point {
    /// The position of one source joint.
    Joint(usize),
    /// The point `t` of the way from the first joint to the second.
    Between(usize, usize, f64),
    /// A point fixed to a joint: the offset (ASF units) in the frame the joint's rotation
    /// carries, as a child joint would be placed.
    Attached(usize, Vec3),
}

/// The source of each SMPL joint, in SMPL joint order (see the table in the module docs).
pub const MAPPING: [Point; NUM_JOINTS] = [
    Point::Joint(0),
    Point::Joint(2),
    Point::Joint(8),
    Point::Joint(14),
    Point::Joint(3),
    Point::Joint(9),
    Point::Between(14, 15, 0.5),
    Point::Joint(4),
    Point::Joint(10),
    Point::Joint(15),
    Point::Joint(5),
    Point::Joint(11),
    Point::Joint(17),
    Point::Between(17, 21, 1.0 / 3.0),
    Point::Between(17, 30, 1.0 / 3.0),
    // As far ahead (+z in the rest frame, where the performer faces +z) as the upper neck
    // (offset of joint 18) is long.
    Point::Attached(18, [0.0, 0.0, 1.56]),
    Point::Joint(21),
    Point::Joint(30),
    Point::Joint(22),
    Point::Joint(31),
    Point::Joint(23),
    Point::Joint(32),
];

/// The source skeleton: the parent and rest offset of each of the 38 joints, in ASF units.
/// Only [`Skeleton::from_json`] makes one, so the tree is always DMGNN's.
#[derive(Clone, Debug, PartialEq)]
pub struct Skeleton {
    /// Parent of each joint; `None` for the root. A parent always comes before its children,
    /// which lets forward kinematics run in one pass.
    parents: [Option<usize>; CMU_JOINTS],
    /// Offset of each joint from its parent in the parent's rest frame (ASF units, Y up, +x
    /// the performer's left, +z ahead).
    offsets: [Vec3; CMU_JOINTS],
}

#[derive(serde::Deserialize)]
struct SkeletonFile {
    parent: Vec<i64>,
    offset: Vec<[f64; 3]>,
}

impl Skeleton {
    /// Parses `skeleton-38.json` (`parent`: 38 indices, −1 for the root; `offset`: 38 × 3 ASF
    /// units). Refuses any tree other than DMGNN's, for which the mapping was worked out.
    pub fn from_json(text: &str) -> Result<Skeleton> {
        let file: SkeletonFile =
            serde_json::from_str(text).context("skeleton-38.json is not the expected JSON")?;
        if file.parent.len() != CMU_JOINTS || file.offset.len() != CMU_JOINTS {
            bail!(
                "skeleton-38.json has {} parents and {} offsets, expected {CMU_JOINTS} of each",
                file.parent.len(),
                file.offset.len()
            );
        }
        if file.parent != EXPECTED_PARENTS {
            bail!(
                "skeleton-38.json's parents {:?} differ from DMGNN's CMU tree {:?}",
                file.parent,
                EXPECTED_PARENTS
            );
        }
        if let Some(v) = file.offset.iter().flatten().find(|v| !v.is_finite()) {
            bail!("skeleton-38.json has a non-finite offset ({v})");
        }
        Ok(Skeleton {
            parents: std::array::from_fn(|i| usize::try_from(file.parent[i]).ok()),
            offsets: std::array::from_fn(|i| file.offset[i]),
        })
    }

    /// World positions (ASF units) and accumulated rotations of the 38 joints for one row.
    fn forward_kinematics(&self, row: &[f64; COLUMNS]) -> ([Vec3; CMU_JOINTS], [Mat3; CMU_JOINTS]) {
        let mut positions = [[0.0; 3]; CMU_JOINTS];
        let mut rotations = [[[0.0; 3]; 3]; CMU_JOINTS];
        for i in 0..CMU_JOINTS {
            let local = expmap_to_matrix([row[3 + 3 * i], row[4 + 3 * i], row[5 + 3 * i]]);
            match self.parents[i] {
                None => {
                    positions[i] = geom::add(self.offsets[i], [row[0], row[1], row[2]]);
                    rotations[i] = local;
                }
                Some(p) => {
                    positions[i] =
                        geom::add(row_times(self.offsets[i], &rotations[p]), positions[p]);
                    rotations[i] = mat_mul(&local, &rotations[p]);
                }
            }
        }
        (positions, rotations)
    }

    /// The 22 SMPL joints of one row, in metres, at 120 Hz (no row is dropped here).
    pub fn smpl_pose(&self, row: &[f64; COLUMNS]) -> Pose {
        let (positions, rotations) = self.forward_kinematics(row);
        std::array::from_fn(|j| {
            let p = match MAPPING[j] {
                Point::Joint(a) => positions[a],
                Point::Between(a, b, t) => geom::lerp(positions[a], positions[b], t),
                Point::Attached(a, offset) => {
                    geom::add(row_times(offset, &rotations[a]), positions[a])
                }
            };
            geom::scale(p, UNIT)
        })
    }
}

/// Rodrigues' formula as DMGNN's `expmap2rotmat` writes it: `I + sin θ K + (1 − cos θ) K²`.
fn expmap_to_matrix(r: Vec3) -> Mat3 {
    let theta = geom::norm(r);
    if theta < 1e-12 {
        return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    }
    let [x, y, z] = geom::scale(r, 1.0 / theta);
    let k = [[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]];
    let k2 = mat_mul(&k, &k);
    let (s, c) = theta.sin_cos();
    std::array::from_fn(|i| {
        std::array::from_fn(|j| (i == j) as u8 as f64 + s * k[i][j] + (1.0 - c) * k2[i][j])
    })
}

fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

/// The row vector `v` times `m`.
fn row_times(v: Vec3, m: &Mat3) -> Vec3 {
    std::array::from_fn(|j| (0..3).map(|k| v[k] * m[k][j]).sum())
}

/// Parses one source file: every non-empty line must hold [`COLUMNS`] finite numbers separated
/// by commas. `file` names the file in errors, which give its line (1-based) and column
/// (0-based). Returns every row, the rest row 0 included.
pub fn parse_rows(text: &str, file: &str) -> Result<Vec<[f64; COLUMNS]>> {
    let mut rows = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() != COLUMNS {
            bail!(
                "{file}:{}: expected {COLUMNS} comma-separated numbers, found {}",
                n + 1,
                fields.len()
            );
        }
        let mut row = [0.0; COLUMNS];
        for (c, (slot, field)) in row.iter_mut().zip(&fields).enumerate() {
            let field = field.trim();
            *slot = field
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    anyhow!(
                        "{file}:{}: column {c}: '{field}' is not a finite number",
                        n + 1
                    )
                })?;
        }
        rows.push(row);
    }
    Ok(rows)
}

/// The motion of one file's rows on our 22 joints: metres, Y up, +X the performer's left,
/// place and facing as captured, 20 fps ([`FPS`]). Drops the rest row 0 first. `file` names
/// the file in errors; a file too short to make two frames at 20 fps is an error.
pub fn retarget(skeleton: &Skeleton, rows: &[[f64; COLUMNS]], file: &str) -> Result<Vec<Pose>> {
    let motion = rows.get(1..).unwrap_or_default();
    let positions: Vec<Vec<Vec3>> = motion
        .iter()
        .map(|row| skeleton.smpl_pose(row).to_vec())
        .collect();
    let poses: Vec<Pose> = resample(&positions, 1.0 / CAPTURE_FPS, 1.0 / FPS)
        .into_iter()
        .map(|p| std::array::from_fn(|j| p[j]))
        .collect();
    if poses.len() < 2 {
        bail!(
            "{file}: {} rows after the rest row make {} frame(s) at {FPS} fps, need at least 2",
            motion.len(),
            poses.len()
        );
    }
    Ok(poses)
}

/// True for the stem of a take that the source put in its test split (`cmu_test_…`).
///
/// The source's test files are other takes of the same actions, presumably by the same
/// performers, so they are not held-out people: use the flag to compare with results reported
/// on this split, not as a test set of unseen actors.
pub fn source_split_is_test(stem: &str) -> bool {
    stem.starts_with("cmu_test_")
}

/// The split, action folder and file stem of a clip's path (`…/train/soccer/soccer_3.txt`).
fn clip_path(path: &str) -> Option<(&str, &str, &str)> {
    let mut parts = path.rsplit('/');
    let stem = parts.next()?.strip_suffix(".txt")?;
    let action = parts.next()?;
    let split = parts.next()?;
    let known = matches!(split, "train" | "test");
    (known && !stem.is_empty() && !action.is_empty()).then_some((split, action, stem))
}

/// Reads every clip of the CMU 8-action subset from `source`: the `.tar.xz` archive or the
/// folder it unpacks to. Each take is one file, whole (the 25–30 s arm-signal takes too;
/// windows are cut by the dataset builder), as joint positions at 20 fps in metres, Y up, +X
/// the performer's left, placed and facing as captured. Sorted by stem.
///
/// `stem` is `cmu_<split>_<file stem>`, `label` the action folder (`soccer`, `walking`, …) and
/// `actor` `cmu-<action>`: the source does not say who performed what, but each action appears
/// to come from one performer, so takes of one action are kept together.
pub fn read_cmu(source: &Path) -> Result<Vec<Take>> {
    let files = read_files(source, &|p| {
        p.rsplit('/').next() == Some("skeleton-38.json") || clip_path(p).is_some()
    })?;
    // A folder may hold the skeleton both beside and inside the unpacked tree (the data folder
    // ships a copy beside the archive); the copies are the same file, so any one will do.
    let skeleton_bytes = files
        .iter()
        .find(|(p, _)| p.rsplit('/').next() == Some("skeleton-38.json"))
        .map(|(_, b)| b)
        .ok_or_else(|| anyhow!("{}: no skeleton-38.json found", source.display()))?;
    let skeleton = Skeleton::from_json(
        std::str::from_utf8(skeleton_bytes).context("skeleton-38.json is not UTF-8 text")?,
    )?;
    let mut takes = Vec::new();
    for (path, bytes) in &files {
        let Some((split, action, stem)) = clip_path(path) else {
            continue;
        };
        let text =
            std::str::from_utf8(bytes).with_context(|| format!("{path} is not UTF-8 text"))?;
        let rows = parse_rows(text, path)?;
        takes.push(Take {
            source: Source::Cmu,
            stem: format!("cmu_{split}_{stem}"),
            actor: format!("cmu-{action}"),
            label: action.to_string(),
            poses: retarget(&skeleton, &rows, path)?,
        });
    }
    if takes.is_empty() {
        bail!(
            "{}: no clips found (expected {{train,test}}/<action>/<action>_<n>.txt in the archive \
             or folder)",
            source.display()
        );
    }
    takes.sort_by(|a, b| a.stem.cmp(&b.stem));
    if let Some(w) = takes.windows(2).find(|w| w[0].stem == w[1].stem) {
        bail!(
            "{}: two clips make the stem {} (is the tree unpacked twice?)",
            source.display(),
            w[0].stem
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

    fn archive() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../shared/data/cmu-8action-expmap/cmu-8action-expmap.tar.xz")
    }

    /// The archive is read once for all tests (decompressing it takes a second or two).
    fn takes() -> &'static [Take] {
        static TAKES: OnceLock<Vec<Take>> = OnceLock::new();
        TAKES.get_or_init(|| read_cmu(&archive()).expect("the CMU archive reads"))
    }

    fn take(stem: &str) -> &'static Take {
        takes()
            .iter()
            .find(|t| t.stem == stem)
            .unwrap_or_else(|| panic!("no take {stem}"))
    }

    fn of_label(label: &str) -> impl Iterator<Item = &'static Take> + '_ {
        takes().iter().filter(move |t| t.label == label)
    }

    fn median(mut xs: Vec<f64>) -> f64 {
        xs.sort_by(f64::total_cmp);
        xs[xs.len() / 2]
    }

    /// The take as `joints_to_features` leaves it: reference bone lengths, on the floor, first
    /// frame at the origin facing +Z.
    fn processed(take: &Take) -> Vec<Pose> {
        joints_to_features(&take.poses, &Offsets::reference())
            .unwrap_or_else(|e| panic!("{}: {e}", take.stem))
            .1
    }

    #[test]
    fn every_clip_reads_with_the_frame_count_of_its_duration() {
        let takes = takes();
        assert_eq!(takes.len(), 38);
        assert!(takes.windows(2).all(|w| w[0].stem < w[1].stem));
        let tests: Vec<&str> = takes
            .iter()
            .filter(|t| source_split_is_test(&t.stem))
            .map(|t| t.stem.as_str())
            .collect();
        assert_eq!(
            tests,
            [
                "cmu_test_basketball_1",
                "cmu_test_jumping_1",
                "cmu_test_running_1",
                "cmu_test_soccer_1",
                "cmu_test_walking_1",
                "cmu_test_washwindow_1",
            ]
        );
        assert!(takes.iter().all(|t| t.source == Source::Cmu));
        assert_eq!(take("cmu_train_soccer_3").label, "soccer");
        assert_eq!(take("cmu_train_soccer_3").actor, "cmu-soccer");

        // clips.tsv: file, action, split, rows at 120 Hz (the rest row included), seconds.
        let tsv = read_files(&archive(), &|p| p.ends_with("/clips.tsv")).unwrap();
        let tsv = std::str::from_utf8(tsv.values().next().unwrap()).unwrap();
        let mut listed = 0;
        for line in tsv.lines().skip(1) {
            let f: Vec<&str> = line.split('\t').collect();
            let (split, action, stem) = clip_path(f[0]).unwrap();
            let take = take(&format!("cmu_{split}_{stem}"));
            assert_eq!(take.label, action);
            let rows: usize = f[3].parse().unwrap();
            let seconds: f64 = f[4].parse().unwrap();
            // Motion rows are rows − 1; every sixth of them, the first included.
            assert_eq!(take.poses.len(), (rows - 2) / 6 + 1, "{}", take.stem);
            let expected = seconds * FPS;
            assert!(
                (take.poses.len() as f64 - expected).abs() <= 1.5,
                "{}: {} frames for {seconds} s",
                take.stem,
                take.poses.len()
            );
            listed += 1;
        }
        assert_eq!(listed, 38);
        // The long arm-signal takes come whole.
        assert!(take("cmu_train_directing_traffic_4").poses.len() > 600);
    }

    #[test]
    fn root_heights_match_the_readme() {
        // Standing and walking: the pelvis at 0.84–1.02 m by the README; the median of
        // directing_traffic_1 is 1.04 m.
        for label in [
            "walking",
            "basketball_signal",
            "directing_traffic",
            "washwindow",
        ] {
            for t in of_label(label) {
                let h = median(t.poses.iter().map(|p| p[0][1]).collect());
                assert!((0.84..1.06).contains(&h), "{}: pelvis at {h:.3} m", t.stem);
            }
        }
        // jumping_1 rises to 1.31 m.
        let top = take("cmu_train_jumping_1")
            .poses
            .iter()
            .map(|p| p[0][1])
            .fold(f64::MIN, f64::max);
        assert!((1.28..1.35).contains(&top), "jumping_1 peaks at {top:.3} m");
    }

    #[test]
    fn feet_are_on_the_floor() {
        // The lowest joint of a frame is a foot on the ground: near y = 0 in every take (the
        // capture's floor), never metres away.
        for t in takes() {
            let lows: Vec<f64> = t
                .poses
                .iter()
                .map(|p| p.iter().map(|v| v[1]).fold(f64::MAX, f64::min))
                .collect();
            let m = median(lows.clone());
            assert!((-0.08..0.12).contains(&m), "{}: feet at {m:.3} m", t.stem);
            let lowest = lows.iter().copied().fold(f64::MAX, f64::min);
            assert!(
                lowest > -0.1,
                "{}: a joint {lowest:.3} m under the floor",
                t.stem
            );
        }
        // And in jumping_1 the lowest point is about 0.06–0.08 m.
        let t = take("cmu_train_jumping_1");
        let lowest = t
            .poses
            .iter()
            .flatten()
            .map(|v| v[1])
            .fold(f64::MAX, f64::min);
        assert!(
            (0.04..0.1).contains(&lowest),
            "jumping_1 lowest {lowest:.3} m"
        );
        // A standing foot's ankle is a few centimetres above its ball.
        for p in &take("cmu_train_basketball_signal_1").poses {
            for (ankle, ball) in [(7, 10), (8, 11)] {
                let rise = p[ankle][1] - p[ball][1];
                assert!(
                    (0.0..0.12).contains(&rise),
                    "ankle {rise:.3} m above the ball"
                );
            }
        }
    }

    #[test]
    fn the_rest_row_is_gone() {
        // How far the body changes shape between two poses: the largest move of a joint
        // relative to the pelvis (so walking forwards does not count).
        let change = |a: &Pose, b: &Pose| {
            (0..NUM_JOINTS)
                .map(|j| geom::dist(geom::sub(a[j], a[0]), geom::sub(b[j], b[0])))
                .fold(0.0, f64::max)
        };
        // Every file starts with a rest row: from it to the next row, 1/120 s later, a hand or
        // foot moves by half a metre or more relative to the pelvis.
        let skeleton = take_skeleton();
        let files = read_files(&archive(), &|p| clip_path(p).is_some()).unwrap();
        assert_eq!(files.len(), 38);
        for (path, bytes) in &files {
            let rows = parse_rows(std::str::from_utf8(bytes).unwrap(), path).unwrap();
            let jump = change(&skeleton.smpl_pose(&rows[0]), &skeleton.smpl_pose(&rows[1]));
            assert!(
                jump > 0.4,
                "{path}: row 0 differs from row 1 by {jump:.3} m"
            );
        }
        // The takes start with motion: their first step, 1/20 s, changes the shape by less
        // than any rest row does (at most 0.18 m, in running, where 0.5 m is seen in kicks).
        for t in takes() {
            let first = change(&t.poses[0], &t.poses[1]);
            assert!(first < 0.3, "{}: first step {first:.3} m", t.stem);
        }
    }

    #[test]
    fn bone_lengths_are_those_of_a_person() {
        let t = take("cmu_train_walking_1");
        let len = |p: &Pose, a: usize, b: usize| geom::dist(p[a], p[b]);
        let first = &t.poses[0];
        for (name, a, b, range) in [
            ("left thigh", joint::L_HIP, joint::L_KNEE, 0.38..0.48),
            ("right thigh", joint::R_HIP, joint::R_KNEE, 0.38..0.48),
            ("left shin", joint::L_KNEE, joint::L_ANKLE, 0.36..0.46),
            ("right shin", joint::R_KNEE, joint::R_ANKLE, 0.36..0.46),
            (
                "left upper arm",
                joint::L_SHOULDER,
                joint::L_ELBOW,
                0.24..0.32,
            ),
            (
                "right upper arm",
                joint::R_SHOULDER,
                joint::R_ELBOW,
                0.24..0.32,
            ),
            ("left forearm", joint::L_ELBOW, joint::L_WRIST, 0.17..0.3),
            ("right forearm", joint::R_ELBOW, joint::R_WRIST, 0.17..0.3),
            ("hips", joint::L_HIP, joint::R_HIP, 0.15..0.25),
            ("shoulders", joint::L_SHOULDER, joint::R_SHOULDER, 0.3..0.45),
        ] {
            let l = len(first, a, b);
            assert!(range.contains(&l), "{name}: {l:.3} m");
            // Rigid: the same length in every frame (the frames are rows, not interpolations).
            for p in &t.poses {
                assert!((len(p, a, b) - l).abs() < 1e-9, "{name} changes length");
            }
        }
        // Ankle to head: a person's height less the feet and crown, and less the thorax that
        // the source's skeleton lacks (its offset is zero: about 11 cm).
        let tall = first[joint::HEAD][1] - first[joint::L_ANKLE][1].min(first[joint::R_ANKLE][1]);
        assert!((1.2..1.6).contains(&tall), "ankle to head {tall:.3} m");
    }

    #[test]
    fn after_features_the_body_faces_plus_z_with_its_left_at_plus_x() {
        // joints_to_features turns the first frame to face +Z from the hips and shoulders. If
        // left and right were swapped, that would turn the body round: toes and bent knees
        // would point to −Z.
        for t in takes() {
            let p = processed(t);
            let first = &p[0];
            assert!(
                first[joint::L_HIP][0] > first[joint::R_HIP][0] + 0.1,
                "{}: left hip not at +X",
                t.stem
            );
            assert!(first[joint::L_SHOULDER][0] > first[joint::R_SHOULDER][0] + 0.2);
            // Over the take's first second, toes lead the ankles along the first frame's +Z.
            let n = p.len().min(20);
            let ahead: f64 = p[..n]
                .iter()
                .map(|q| {
                    (q[joint::L_FOOT][2] - q[joint::L_ANKLE][2])
                        + (q[joint::R_FOOT][2] - q[joint::R_ANKLE][2])
                })
                .sum::<f64>()
                / (2 * n) as f64;
            assert!(
                ahead > 0.03,
                "{}: toes {ahead:.3} m ahead of the ankles",
                t.stem
            );
        }
        // Standing still, the first frame itself has both feet pointing ahead.
        for stem in ["cmu_train_basketball_signal_1", "cmu_train_walking_1"] {
            let first = &processed(take(stem))[0];
            for (ankle, toe) in [
                (joint::L_ANKLE, joint::L_FOOT),
                (joint::R_ANKLE, joint::R_FOOT),
            ] {
                assert!(
                    first[toe][2] > first[ankle][2] + 0.05,
                    "{stem}: a foot points back"
                );
            }
        }
    }

    #[test]
    fn knees_bend_forwards() {
        // A knee bends with its joint ahead of the line from hip to ankle. The wrong rotation
        // convention (column instead of row vectors) would bend them backwards.
        for label in ["walking", "running", "jumping"] {
            for t in of_label(label) {
                let p = processed(t);
                let mut bent = Vec::new();
                for q in &p {
                    let across = geom::sub(q[joint::L_HIP], q[joint::R_HIP]);
                    let forward = geom::normalize(geom::cross(across, [0.0, 1.0, 0.0]));
                    for (hip, knee, ankle) in [
                        (joint::L_HIP, joint::L_KNEE, joint::L_ANKLE),
                        (joint::R_HIP, joint::R_KNEE, joint::R_ANKLE),
                    ] {
                        let mid = geom::lerp(q[hip], q[ankle], 0.5);
                        bent.push(geom::dot(geom::sub(q[knee], mid), forward));
                    }
                }
                let m = median(bent);
                assert!(
                    m > 0.01,
                    "{}: knees {m:.3} m ahead of the hip-ankle line",
                    t.stem
                );
            }
        }
    }

    #[test]
    fn the_right_foot_kicks_the_ball() {
        // Most people kick with the right foot; in every soccer take the right toe rises far
        // higher than the left, so "l" and "r" are the performer's own sides (not a mirror).
        for t in of_label("soccer") {
            let top = |j: usize| t.poses.iter().map(|p| p[j][1]).fold(f64::MIN, f64::max);
            let (left, right) = (top(joint::L_FOOT), top(joint::R_FOOT));
            assert!(
                right > left + 0.15,
                "{}: left toe {left:.2} m, right {right:.2} m",
                t.stem
            );
        }
    }

    #[test]
    fn walking_and_running_speeds() {
        // Ground distance covered by the pelvis from the first frame to the last, per second.
        let speed = |t: &Take| {
            let (a, b) = (t.poses[0][0], t.poses[t.poses.len() - 1][0]);
            let d = ((b[0] - a[0]).powi(2) + (b[2] - a[2]).powi(2)).sqrt();
            d / ((t.poses.len() - 1) as f64 / FPS)
        };
        let mean = |label: &str| {
            let s: Vec<f64> = of_label(label).map(speed).collect();
            s.iter().sum::<f64>() / s.len() as f64
        };
        let (run, walk) = (mean("running"), mean("walking"));
        assert!((2.7..3.6).contains(&run), "running at {run:.2} m/s");
        assert!((1.0..1.4).contains(&walk), "walking at {walk:.2} m/s");
        for t in of_label("running") {
            assert!((2.3..4.0).contains(&speed(t)), "{}", t.stem);
        }
        for t in of_label("walking") {
            assert!((0.7..1.7).contains(&speed(t)), "{}", t.stem);
        }
    }

    #[test]
    fn row_vector_convention_as_dmgnn() {
        // A quarter turn of the root about +Y: DMGNN's `offset · R` carries +X to +Z, where the
        // column-vector reading `R · offset` would carry it to −Z.
        let mut offsets = [[0.0; 3]; CMU_JOINTS];
        offsets[1] = [1.0, 0.0, 0.0];
        let skeleton = Skeleton {
            parents: std::array::from_fn(|i| usize::try_from(EXPECTED_PARENTS[i]).ok()),
            offsets,
        };
        let mut row = [0.0; COLUMNS];
        row[..3].copy_from_slice(&[1.0, 2.0, 3.0]);
        row[4] = std::f64::consts::FRAC_PI_2;
        let (p, _) = skeleton.forward_kinematics(&row);
        assert!(geom::dist(p[0], [1.0, 2.0, 3.0]) < 1e-12);
        assert!(geom::dist(p[1], [1.0, 2.0, 4.0]) < 1e-12, "{:?}", p[1]);
        // Rotations far past π are the same rotations as their wrapped equivalents.
        let a = expmap_to_matrix([0.0, 0.0, 3.0]);
        let b = expmap_to_matrix([0.0, 0.0, 3.0 - 2.0 * std::f64::consts::PI]);
        assert!((0..3).all(|i| (0..3).all(|j| (a[i][j] - b[i][j]).abs() < 1e-12)));
    }

    #[test]
    fn malformed_input_is_an_error_not_a_panic() {
        let good = vec!["0"; COLUMNS].join(",");
        assert_eq!(
            parse_rows(&format!("{good}\n{good}\n\n"), "x.txt")
                .unwrap()
                .len(),
            2
        );

        let short = vec!["0"; COLUMNS - 1].join(",");
        let e = parse_rows(&format!("{good}\n{short}\n"), "walking_9.txt").unwrap_err();
        assert!(e.to_string().contains("walking_9.txt:2"), "{e}");
        assert!(e.to_string().contains("found 116"), "{e}");

        let mut fields = vec!["0"; COLUMNS];
        fields[7] = "0.3x";
        let e = parse_rows(&fields.join(","), "soccer_1.txt").unwrap_err();
        assert!(
            e.to_string().contains("soccer_1.txt:1: column 7: '0.3x'"),
            "{e}"
        );
        fields[7] = "NaN";
        assert!(parse_rows(&fields.join(","), "a.txt").is_err());

        // Too short for two frames at 20 fps after the rest row.
        let skeleton = take_skeleton();
        let rows = parse_rows(&format!("{good}\n{good}\n{good}\n"), "tiny.txt").unwrap();
        let e = retarget(&skeleton, &rows, "tiny.txt").unwrap_err();
        assert!(e.to_string().starts_with("tiny.txt:"), "{e}");
        assert!(retarget(&skeleton, &[], "empty.txt").is_err());

        assert!(Skeleton::from_json("{").is_err());
        assert!(Skeleton::from_json(r#"{"parent": [-1], "offset": [[0,0,0]]}"#).is_err());
        assert!(read_cmu(Path::new("/nonexistent/cmu.tar.xz")).is_err());
    }

    fn take_skeleton() -> Skeleton {
        let files = read_files(&archive(), &|p| p.ends_with("skeleton-38.json")).unwrap();
        Skeleton::from_json(std::str::from_utf8(files.values().next().unwrap()).unwrap()).unwrap()
    }

    #[test]
    fn an_unpacked_folder_reads_like_the_archive() {
        let files = read_files(&archive(), &|p| {
            p.ends_with("skeleton-38.json")
                || p.ends_with("test/running/running_1.txt")
                || p.ends_with("train/running/running_2.txt")
        })
        .unwrap();
        let dir = tempfile::tempdir().unwrap();
        for (path, bytes) in &files {
            let out = dir.path().join(path);
            std::fs::create_dir_all(out.parent().unwrap()).unwrap();
            std::fs::write(out, bytes).unwrap();
        }
        let from_folder = read_cmu(dir.path()).unwrap();
        let stems: Vec<&str> = from_folder.iter().map(|t| t.stem.as_str()).collect();
        assert_eq!(stems, ["cmu_test_running_1", "cmu_train_running_2"]);
        for t in &from_folder {
            assert_eq!(t.poses, take(&t.stem).poses);
        }
        // A folder without clips is refused with a message, not an empty list.
        let empty = tempfile::tempdir().unwrap();
        assert!(read_cmu(empty.path()).is_err());
    }

    /// Writes filmstrips of a few takes to the system's temporary folder, to look at them:
    /// `cargo test --release -p coma --lib mocap::cmu_expmap -- --ignored`.
    #[test]
    #[ignore]
    fn filmstrips() {
        use crate::render::{write_filmstrip, FilmstripOptions, View};
        for stem in [
            "cmu_train_soccer_1",
            "cmu_train_walking_1",
            "cmu_train_jumping_1",
            "cmu_train_basketball_signal_1",
            "cmu_test_washwindow_1",
        ] {
            let poses = processed(take(stem));
            for view in [View::Front, View::Side] {
                let path = std::env::temp_dir().join(format!("{stem}_{view:?}.png"));
                let options = FilmstripOptions {
                    frames: 12,
                    columns: 6,
                    title: Some(stem.to_string()),
                    view,
                    ..FilmstripOptions::default()
                };
                write_filmstrip(&path, &poses, &options).unwrap();
                eprintln!("{}", path.display());
            }
        }
    }
}
