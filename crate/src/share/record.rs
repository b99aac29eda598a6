//! What a link says besides the tokens, as types: the plan the motion followed (the planner's
//! plan, or an older link's segments) and the record of the run that made it (its step lines,
//! review scores and notes). The link stores both as JSON text; they are read here once, when
//! the link is decoded, and what does not read is dropped with a note: the motion itself opens
//! whole without them.

use crate::plan::Plan;
use serde::{Deserialize, Serialize};

/// Most lines a record keeps of each kind, and characters a line: what one run writes is far
/// below both, so only a doctored link is cut.
pub const RECORD_LINES: usize = 200;
pub const RECORD_LINE_CHARS: usize = 500;
/// Longest text of an older link's segment, in characters.
const SEGMENT_TEXT_CHARS: usize = 500;

/// How the reviewer scored one segment: the evaluator's 0–100 similarity of its text with its
/// motion before and after review (none without an evaluator), and the rounds it took.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SegmentScores {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub before: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub after: Option<f64>,
    #[serde(default)]
    pub rounds: usize,
    /// Rounds whose corrections were kept.
    #[serde(default)]
    pub kept: usize,
}

/// How the run of a motion went, as its link keeps it: the page shows the same steps, scores
/// and notes when the link is opened.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub steps: Vec<String>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub scores: Vec<SegmentScores>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
}

impl RunRecord {
    /// True when there is nothing to record.
    pub fn is_empty(&self) -> bool {
        self == &RunRecord::default()
    }

    /// The record with at most [`RECORD_LINES`] lines of each kind of at most
    /// [`RECORD_LINE_CHARS`] characters.
    pub fn capped(self) -> RunRecord {
        let lines = |lines: Vec<String>| -> Vec<String> {
            lines
                .into_iter()
                .take(RECORD_LINES)
                .map(|l| l.chars().take(RECORD_LINE_CHARS).collect())
                .collect()
        };
        RunRecord {
            steps: lines(self.steps),
            scores: self.scores.into_iter().take(RECORD_LINES).collect(),
            notes: lines(self.notes),
        }
    }
}

/// A segment of an older link: a stretch of frames (20 fps) with its text, without the
/// planner's base motion, part edits or path.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinkSegment {
    pub text: String,
    pub from: usize,
    pub to: usize,
}

/// The plan a link carries.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum LinkPlan {
    /// None: an edited motion without a plan, or a plan that did not read.
    #[default]
    None,
    /// The planner's plan: the link rebuilds the motion with its paths.
    Planned(Plan),
    /// An older link's segments (text and frames only).
    Segments(Vec<LinkSegment>),
}

#[derive(Serialize, Deserialize)]
struct SegmentsJson {
    segments: Vec<LinkSegment>,
}

impl LinkPlan {
    /// The planner's plan, if the link has one.
    pub fn plan(&self) -> Option<&Plan> {
        match self {
            LinkPlan::Planned(plan) => Some(plan),
            _ => None,
        }
    }

    /// The JSON text a link stores ("" for none).
    pub(super) fn to_json(&self) -> String {
        match self {
            LinkPlan::None => String::new(),
            LinkPlan::Planned(plan) => serde_json::to_string(plan).unwrap_or_default(),
            LinkPlan::Segments(segments) => serde_json::to_string(&SegmentsJson {
                segments: segments.clone(),
            })
            .unwrap_or_default(),
        }
    }

    /// Reads a link's plan text for a motion of `frames` frames: the planner's plan, else an
    /// older link's segments (each a non-empty range inside the motion), else none with the
    /// reason.
    pub(super) fn from_json(text: &str, frames: usize) -> Result<LinkPlan, String> {
        if text.is_empty() {
            return Ok(LinkPlan::None);
        }
        let plan_error = match serde_json::from_str::<Plan>(text) {
            Ok(plan) => return Ok(LinkPlan::Planned(plan)),
            Err(e) => e.to_string(),
        };
        match serde_json::from_str::<SegmentsJson>(text) {
            Ok(SegmentsJson { segments })
                if !segments.is_empty()
                    && segments.iter().all(|s| s.from < s.to && s.to <= frames) =>
            {
                Ok(LinkPlan::Segments(
                    segments
                        .into_iter()
                        .map(|s| LinkSegment {
                            text: s.text.chars().take(SEGMENT_TEXT_CHARS).collect(),
                            ..s
                        })
                        .collect(),
                ))
            }
            _ => Err(plan_error),
        }
    }
}

/// Reads a link's record text ("" for none).
pub(super) fn record_from_json(text: &str) -> Result<Option<RunRecord>, String> {
    if text.is_empty() {
        return Ok(None);
    }
    serde_json::from_str::<RunRecord>(text)
        .map(|r| Some(r.capped()))
        .map_err(|e| e.to_string())
}

/// The JSON text a link stores for a record ("" for none or an empty one).
pub(super) fn record_to_json(record: &Option<RunRecord>) -> String {
    match record {
        Some(r) if !r.is_empty() => serde_json::to_string(r).unwrap_or_default(),
        _ => String::new(),
    }
}
