//! Reading the Bandai-Namco Research motion datasets 1 and 2, either from the release archive
//! (`bandai-namco-bvh.tar.xz`) or from a folder it was extracted into.
//!
//! Each clip is `dataset-N_{content}_{style}_{id}.bvh` with a `.json` beside it holding
//! `{"content": i, "style": j}`, indices into `cfg/content_label.txt` and
//! `cfg/style_label.txt` of the same dataset (lines like `dataset-2_walk`).

use anyhow::{anyhow, bail, Context, Result};
use std::collections::BTreeMap;
use std::path::Path;

/// One source clip with its labels.
#[derive(Clone, Debug)]
pub struct SourceClip {
    /// File stem, e.g. `dataset-2_wave-left-hand_normal_001`.
    pub stem: String,
    /// Which release: 1 or 2.
    pub dataset: u8,
    /// Content label without the dataset prefix, e.g. `wave-left-hand`.
    pub content: String,
    /// Style label without the dataset prefix, e.g. `normal`.
    pub style: String,
    /// The BVH text.
    pub bvh: String,
}

#[derive(Default)]
struct Collected {
    bvh: BTreeMap<String, String>,
    json: BTreeMap<String, String>,
    labels: BTreeMap<(u8, &'static str), Vec<String>>,
}

impl Collected {
    fn add(&mut self, path: &str, text: String) {
        let file = path.rsplit('/').next().unwrap_or(path);
        let dataset = if path.contains("Motiondataset-1") || file.starts_with("dataset-1") {
            1
        } else {
            2
        };
        if let Some(stem) = file.strip_suffix(".bvh") {
            self.bvh.insert(stem.to_string(), text);
        } else if let Some(stem) = file.strip_suffix(".json") {
            self.json.insert(stem.to_string(), text);
        } else if file == "content_label.txt" || file == "style_label.txt" {
            let kind = if file.starts_with("content") {
                "content"
            } else {
                "style"
            };
            let prefix = format!("dataset-{dataset}_");
            let lines = text
                .lines()
                .map(str::trim)
                .filter(|l| !l.is_empty())
                .map(|l| l.strip_prefix(&prefix).unwrap_or(l).to_string())
                .collect();
            self.labels.insert((dataset, kind), lines);
        }
    }

    fn finish(self, selection: &Selection) -> Result<Vec<SourceClip>> {
        let mut clips = Vec::new();
        for (stem, bvh) in self.bvh {
            if let Selection::Stems(stems) = selection {
                if !stems.contains(&stem) {
                    continue;
                }
            }
            let dataset = if stem.starts_with("dataset-1") { 1 } else { 2 };
            let json = self
                .json
                .get(&stem)
                .ok_or_else(|| anyhow!("{stem}.bvh has no {stem}.json with its labels"))?;
            let v: serde_json::Value = serde_json::from_str(json)
                .with_context(|| format!("{stem}.json is not valid JSON"))?;
            let label = |kind: &'static str| -> Result<String> {
                let i = v[kind]
                    .as_u64()
                    .ok_or_else(|| anyhow!("{stem}.json has no integer '{kind}'"))?
                    as usize;
                self.labels
                    .get(&(dataset, kind))
                    .ok_or_else(|| anyhow!("cfg/{kind}_label.txt of dataset-{dataset} is missing"))?
                    .get(i)
                    .cloned()
                    .ok_or_else(|| {
                        anyhow!("{stem}.json: {kind} {i} is not in cfg/{kind}_label.txt")
                    })
            };
            clips.push(SourceClip {
                content: label("content")?,
                style: label("style")?,
                stem,
                dataset,
                bvh,
            });
        }
        if clips.is_empty() {
            bail!("no BVH clips found");
        }
        if let Selection::Spread(n) = selection {
            clips = super::spread(clips, *n);
        }
        Ok(clips)
    }
}

fn wanted(path: &str) -> bool {
    path.ends_with(".bvh") || path.ends_with(".json") || path.ends_with("_label.txt")
}

/// Which clips to keep.
#[derive(Clone, Debug, PartialEq)]
pub enum Selection {
    /// Every clip.
    All,
    /// This many clips spread evenly over the sorted list.
    Spread(usize),
    /// The clips with these file stems.
    Stems(Vec<String>),
}

/// Reads the selected clips of a `.tar.xz` archive or of an extracted folder, sorted by stem.
pub fn read_clips(source: &Path, selection: &Selection) -> Result<Vec<SourceClip>> {
    let mut collected = Collected::default();
    for (path, bytes) in crate::mocap::read_files(source, &wanted)? {
        let text = String::from_utf8(bytes)
            .map_err(|_| anyhow!("{path} in {} is not UTF-8 text", source.display()))?;
        collected.add(&path, text);
    }
    collected.finish(selection)
}
