//! Motion capture sources besides Bandai-Namco's BVH, read onto our 22 SMPL joints.
//!
//! Each reader turns one source's files into [`Take`]s: joint world positions at 20 fps
//! ([`crate::timing::FPS`]), metres, Y up, with the place and facing as captured. Bone lengths,
//! floor, origin and facing are made canonical later, when features are computed
//! ([`crate::features::joints_to_features`]), exactly as for Bandai-Namco.
//!
//! | module          | source                                   | format                         |
//! |-----------------|------------------------------------------|--------------------------------|
//! | [`asf_amc`]     | HDM05 subset (11 classes, 5 actors)      | Acclaim ASF skeleton + AMC, 120 Hz |
//! | [`cmu_expmap`]  | CMU 8-action subset                      | CSV of exponential maps, 120 Hz |
//! | [`deepmimic`]   | DeepMimic clips (22 single actions)      | JSON quaternions, per-frame durations |

pub mod asf_amc;
pub mod cmu_expmap;
pub mod deepmimic;

use crate::skeleton::Pose;
use anyhow::{Context, Result};
use std::collections::BTreeMap;
use std::path::Path;

/// A motion capture source, with the terms its derived files and weights carry; a take's
/// source decides its licence and attribution.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Source {
    Bandai,
    Hdm05,
    Cmu,
    DeepMimic,
}

impl Source {
    /// The licence of the source data, which every derived file inherits.
    pub fn licence(self) -> &'static str {
        match self {
            Source::Bandai => "CC BY-NC 4.0",
            Source::Hdm05 => "CC BY-SA 3.0",
            Source::Cmu => {
                "CMU Graphics Lab Motion Capture Database terms (free to use, not to resell)"
            }
            Source::DeepMimic => "MIT",
        }
    }

    /// The attribution the licence asks for.
    pub fn attribution(self) -> &'static str {
        match self {
            Source::Bandai => "Bandai Namco Research Motion Datasets 1 and 2 (Kobayashi et al. 2023, \"Motion Capture Dataset for Practical Use of AI-based Motion Editing and Stylization\", arXiv:2306.08861)",
            Source::Hdm05 => "The data used in this project was obtained from HDM05 (Müller, Röder, Clausen, Eberhardt, Krüger, Weber, \"Documentation Mocap Database HDM05\", Tech. Rep. CG-2007-2, Universität Bonn, 2007). Converted motion files are CC BY-SA 3.0 (ShareAlike).",
            Source::Cmu => "The data used in this project was obtained from mocap.cs.cmu.edu, created with funding from NSF EIA-0196217; exponential-map conversion by Li et al. (CVPR 2018, MIT) as distributed by DMGNN (MIT)",
            Source::DeepMimic => "DeepMimic motion clips, Copyright (c) 2018 Xue Bin Peng (MIT licence)",
        }
    }
}

/// One clip of a source on our 22 joints.
#[derive(Clone, Debug)]
pub struct Take {
    pub source: Source,
    /// A name unique within the source, usable as a file stem (e.g. `HDM_bd_squat1Reps_001`).
    pub stem: String,
    /// Who performed it (`bd` … `tr` for HDM05); the split keeps each test actor out of training.
    pub actor: String,
    /// The source's own action label (`squat1Reps`, `soccer`, `cartwheel`).
    pub label: String,
    /// Joint positions at 20 fps, metres, Y up, as captured (any place and facing).
    pub poses: Vec<Pose>,
}

/// Reads the files of a `.tar.xz` archive or of a folder (recursively) whose path passes
/// `wanted`, as raw bytes keyed by their path inside the archive or folder (`/`-separated).
/// Bytes, not text: HDM05's AMC headers carry a Latin-1 byte.
pub fn read_files(
    source: &Path,
    wanted: &dyn Fn(&str) -> bool,
) -> Result<BTreeMap<String, Vec<u8>>> {
    let mut out = BTreeMap::new();
    if source.is_dir() {
        visit(source, source, wanted, &mut out)?;
    } else {
        read_archive(source, wanted, &mut out)?;
    }
    Ok(out)
}

fn visit(
    root: &Path,
    dir: &Path,
    wanted: &dyn Fn(&str) -> bool,
    out: &mut BTreeMap<String, Vec<u8>>,
) -> Result<()> {
    for entry in std::fs::read_dir(dir).with_context(|| format!("cannot read {}", dir.display()))? {
        let path = entry?.path();
        if path.is_dir() {
            visit(root, &path, wanted, out)?;
        } else {
            let name = path
                .strip_prefix(root)
                .unwrap_or(&path)
                .to_string_lossy()
                .replace('\\', "/");
            if wanted(&name) {
                let bytes = std::fs::read(&path)
                    .with_context(|| format!("cannot read {}", path.display()))?;
                out.insert(name, bytes);
            }
        }
    }
    Ok(())
}

#[cfg(feature = "native")]
fn read_archive(
    source: &Path,
    wanted: &dyn Fn(&str) -> bool,
    out: &mut BTreeMap<String, Vec<u8>>,
) -> Result<()> {
    use std::io::Read;
    let file =
        std::fs::File::open(source).with_context(|| format!("cannot open {}", source.display()))?;
    let mut archive =
        tar::Archive::new(liblzma::read::XzDecoder::new(std::io::BufReader::new(file)));
    for entry in archive
        .entries()
        .with_context(|| format!("{} is not a tar.xz archive", source.display()))?
    {
        let mut entry = entry.with_context(|| format!("reading {}", source.display()))?;
        let path = entry.path()?.to_string_lossy().to_string();
        if wanted(&path) {
            let mut bytes = Vec::new();
            entry
                .read_to_end(&mut bytes)
                .with_context(|| format!("reading {path} in {}", source.display()))?;
            out.insert(path, bytes);
        }
    }
    Ok(())
}

#[cfg(not(feature = "native"))]
fn read_archive(
    source: &Path,
    _: &dyn Fn(&str) -> bool,
    _: &mut BTreeMap<String, Vec<u8>>,
) -> Result<()> {
    anyhow::bail!(
        "{}: reading .tar.xz archives needs the native build (feature `native`)",
        source.display()
    )
}
