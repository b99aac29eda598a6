//! The timeline prompt set (`eval/timeline_prompts.json`, issue 38) and how a planner places
//! each of its clauses.
//!
//! Every prompt of the set is annotated clause by clause: the track the clause belongs on
//! (whole body, an arm, both arms, a leg, the torso, or none for context), its step in time,
//! the clauses it overlaps, its side and how many times it happens. Scoring a planner plans
//! each prompt and matches each clause to what the plan holds ([`plan_elements`]: a segment's
//! base motion, each body-part edit, each posture track, with their times in seconds). A
//! clause is **placed correctly** when its element
//! - is on the right track: the whole body for a whole-body clause, the right part for a part
//!   clause; a part or torso clause may also be a whole-body clip of its own when no
//!   whole-body clause is meant to happen at the same time ("raises the right arm, then
//!   lowers it" made as two whole-body clips of the arm moving is right; "jumps with both arms
//!   raised" needs the arms on their own track);
//! - is in the right order against the other placed clauses: a clause of an earlier step
//!   starts earlier, and clauses of overlapping steps (the same step, or one riding `over` the
//!   other) overlap in time. A conflict between two clauses otherwise right is blamed on the
//!   fewest clauses that explain every conflict ("the bow comes too early", not "everything
//!   is out of order");
//! - is on the right side (left, right, or the way a path turns: clockwise is right);
//! - happens as many times as asked (repeated identical clips, a posture track's repeat, or
//!   "twice" / "N times" in the element's text; walking or running in two clips in a row is
//!   one longer walk, not two), and walks the path asked for.
//!
//! A clause is **silently lost** when no plan element is matched to it and no plan note names
//! it (quotes its words, in part or whole, or names in its own words a movement it left out
//! that means the clause; the substitute a note says it used for a clause does not count); a
//! **side swap** when its element is on the opposite side. A context clause (track `none`) is
//! right when a note names it and no movement stands in its place (neither an element that
//! means it nor the substitute the note says it used), and silently lost when nothing names
//! it.
//!
//! **Matching by meaning.** A clause's words (or its `means`, for anaphora) and an element's
//! text (with its path, if it walks one; for a posture of the library, also the library's
//! other words for it: "T-pose" is "arms out to the sides") are matched as [`super::meaning`]
//! decides whether two texts are the same movement: MiniLM similarity at least
//! [`SAME_MOVEMENT_MIN_SIMILARITY`](super::meaning::SAME_MOVEMENT_MIN_SIMILARITY) (calibrated
//! on hand-labelled pairs, as that module says), sides aside, and no opposite directions or
//! gaits.
//!
//! Each plan element accounts for one clause. Among all ways to match clauses to elements
//! above the threshold, the scorer keeps the one with the most clauses placed correctly, then
//! the most placed, then the highest total similarity: it is read as favourably as it allows,
//! what else the plan holds is found (a clause out of order is misplaced, not lost), and a
//! plan that says something once is not counted for two clauses.

use super::meaning::{words, Matcher, OPPOSITES};
use crate::plan::Plan;
use crate::posture::library::Library;
use crate::posture::script::PostureScript;
use crate::skeleton::BodyPart;
pub use crate::skeleton::Side;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The root paths a clause may ask for, as [`crate::trajectory::Shape::describe`] names them.
pub const PATHS: [&str; 9] = [
    "line",
    "circle",
    "arc",
    "zigzag",
    "s curve",
    "figure eight",
    "square",
    "heart",
    "spiral",
];

/// Seconds two elements must share to overlap, and one must start before another to come
/// first: less than a frame is the same instant.
const TIME_EPS: f64 = 0.05;

/// How much closer an element must be to another clause of the prompt than to this one to be
/// read as that clause's only (MiniLM cosine similarity).
const CLEARLY_OTHER: f32 = 0.15;

/// Candidate elements kept per clause (the most similar), to bound the search.
const MAX_CANDIDATES: usize = 4;

/// Longest run of identical consecutive elements one clause takes ("jumps five times").
const MAX_RUN: usize = 8;

/// Where a clause belongs on a timeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Track {
    /// The whole-body track: base motions, whole-body postures, paths.
    #[serde(rename = "body")]
    Body,
    #[serde(rename = "left arm")]
    LeftArm,
    #[serde(rename = "right arm")]
    RightArm,
    #[serde(rename = "both arms")]
    BothArms,
    #[serde(rename = "left leg")]
    LeftLeg,
    #[serde(rename = "right leg")]
    RightLeg,
    /// Torso and head.
    #[serde(rename = "torso")]
    Torso,
    /// Context that is no movement, to be dropped with a note.
    #[serde(rename = "none")]
    None,
}

impl Track {
    /// The name the set uses.
    pub fn name(self) -> &'static str {
        match self {
            Track::Body => "body",
            Track::LeftArm => "left arm",
            Track::RightArm => "right arm",
            Track::BothArms => "both arms",
            Track::LeftLeg => "left leg",
            Track::RightLeg => "right leg",
            Track::Torso => "torso",
            Track::None => "none",
        }
    }

    /// The body parts of a part track.
    fn parts(self) -> Option<&'static [BodyPart]> {
        match self {
            Track::LeftArm => Some(&[BodyPart::LeftArm]),
            Track::RightArm => Some(&[BodyPart::RightArm]),
            Track::BothArms => Some(&[BodyPart::LeftArm, BodyPart::RightArm]),
            Track::LeftLeg => Some(&[BodyPart::LeftLeg]),
            Track::RightLeg => Some(&[BodyPart::RightLeg]),
            Track::Body | Track::Torso | Track::None => None,
        }
    }

    /// The side a one-sided part track implies.
    fn side(self) -> Option<Side> {
        match self {
            Track::LeftArm | Track::LeftLeg => Some(Side::Left),
            Track::RightArm | Track::RightLeg => Some(Side::Right),
            _ => None,
        }
    }
}

/// A speed word of the clause ("slowly", "quickly"); annotated for a later check of timing,
/// not scored here.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Speed {
    Slow,
    Fast,
}

fn one() -> u32 {
    1
}

/// One annotated clause of a prompt.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Clause {
    /// The clause's words as they stand in the prompt.
    pub text: String,
    pub track: Track,
    /// Step in time from 1; clauses at the same step overlap. Absent for context.
    #[serde(default)]
    pub order: Option<u32>,
    /// Indices of the clauses this one rides over (it spans their steps too).
    #[serde(default)]
    pub over: Vec<usize>,
    #[serde(default)]
    pub side: Option<Side>,
    /// How many times the movement happens.
    #[serde(default = "one")]
    pub count: u32,
    /// The clause an anaphora points to.
    #[serde(default)]
    pub refers_to: Option<usize>,
    /// The movement in full words where the clause's own words do not say it ("lowers it").
    #[serde(default)]
    pub means: Option<String>,
    /// The root path asked for, one of [`PATHS`].
    #[serde(default)]
    pub path: Option<String>,
    #[serde(default)]
    pub speed: Option<Speed>,
    /// Why a context clause is dropped.
    #[serde(default)]
    pub note: Option<String>,
}

impl Clause {
    /// The words matched against the plan: `means` where the clause's words do not say it.
    pub fn meaning(&self) -> &str {
        self.means.as_deref().unwrap_or(&self.text)
    }
}

/// One prompt of the set with its clauses.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SetPrompt {
    pub id: String,
    pub prompt: String,
    pub clauses: Vec<Clause>,
}

/// The whole set as committed.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimelineSet {
    /// What the set is and how it is annotated.
    pub about: String,
    pub prompts: Vec<SetPrompt>,
}

/// Reads and checks a timeline prompt set.
pub fn load(path: &Path) -> anyhow::Result<TimelineSet> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?;
    parse(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

/// Parses and checks a timeline prompt set; the error names the prompt and clause at fault.
pub fn parse(text: &str) -> Result<TimelineSet, String> {
    let set: TimelineSet = serde_json::from_str(text)
        .map_err(|e| format!("not a timeline prompt set (see eval/timeline_prompts.json): {e}"))?;
    validate(&set)?;
    Ok(set)
}

fn validate(set: &TimelineSet) -> Result<(), String> {
    if set.prompts.is_empty() {
        return Err("the set has no prompts".into());
    }
    let mut ids = std::collections::HashSet::new();
    for p in &set.prompts {
        if p.id.trim().is_empty() {
            return Err(format!("the prompt \"{}\" has no id", p.prompt));
        }
        if !ids.insert(p.id.as_str()) {
            return Err(format!("two prompts have the id \"{}\"", p.id));
        }
        if p.prompt.trim().is_empty() {
            return Err(format!("prompt \"{}\" is empty", p.id));
        }
        if p.clauses.is_empty() {
            return Err(format!("prompt \"{}\" has no clauses", p.id));
        }
        let prompt = squeeze(&p.prompt);
        for (i, c) in p.clauses.iter().enumerate() {
            let at =
                |why: String| format!("prompt \"{}\", clause {i} (\"{}\"): {why}", p.id, c.text);
            if c.text.trim().is_empty() {
                return Err(at("the clause has no text".into()));
            }
            if !prompt.contains(&squeeze(&c.text)) {
                return Err(at("its text is not in the prompt".into()));
            }
            if c.count == 0 {
                return Err(at("`count` is at least 1".into()));
            }
            if c.track == Track::None {
                if c.order.is_some() || !c.over.is_empty() || c.side.is_some() {
                    return Err(at(
                        "a context clause (track \"none\") has no `order`, `over` or `side`".into(),
                    ));
                }
                if c.note.as_deref().is_none_or(|n| n.trim().is_empty()) {
                    return Err(at(
                        "a context clause (track \"none\") says why in `note`".into()
                    ));
                }
            } else if c.order.is_none_or(|o| o == 0) {
                return Err(at("`order` (a step from 1) is missing".into()));
            }
            if let (Some(implied), Some(side)) = (c.track.side(), c.side) {
                if implied != side {
                    return Err(at(format!(
                        "side \"{}\" on the {} track",
                        side.name(),
                        c.track.name()
                    )));
                }
            }
            for &j in &c.over {
                if j >= p.clauses.len() || j == i {
                    return Err(at(format!(
                        "`over` names clause {j}; the prompt has clauses 0 to {} and a clause \
                         does not ride over itself",
                        p.clauses.len() - 1
                    )));
                }
                if p.clauses[j].track == Track::None {
                    return Err(at(format!("`over` names clause {j}, which is context")));
                }
            }
            if let Some(j) = c.refers_to {
                if j >= p.clauses.len() || j == i {
                    return Err(at(format!(
                        "`refers_to` names clause {j}; the prompt has clauses 0 to {}",
                        p.clauses.len() - 1
                    )));
                }
            }
            if let Some(path) = &c.path {
                if !PATHS.contains(&path.as_str()) {
                    return Err(at(format!(
                        "unknown path \"{path}\" (one of {})",
                        PATHS.join(", ")
                    )));
                }
            }
        }
    }
    Ok(())
}

/// Lower case, single spaces.
fn squeeze(text: &str) -> String {
    text.to_lowercase()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

/// Where a plan element is: the whole body or some parts.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum On {
    Body,
    Parts(Vec<BodyPart>),
}

impl On {
    fn describe(&self) -> String {
        match self {
            On::Body => "body".into(),
            On::Parts(parts) if parts == &[BodyPart::LeftArm, BodyPart::RightArm] => {
                "both arms".into()
            }
            On::Parts(parts) => parts
                .iter()
                .map(|p| p.name())
                .collect::<Vec<_>>()
                .join(" + "),
        }
    }

    fn side(&self) -> Option<Side> {
        match self {
            On::Parts(parts) if parts.len() == 1 => match parts[0] {
                BodyPart::LeftArm | BodyPart::LeftLeg => Some(Side::Left),
                BodyPart::RightArm | BodyPart::RightLeg => Some(Side::Right),
            },
            _ => None,
        }
    }
}

/// One thing a plan does, on one track over a span of time.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Element {
    pub on: On,
    /// What it does, in the plan's words (a base motion, a part's instruction, the names of a
    /// posture track's key poses).
    pub text: String,
    /// Seconds from the start of the plan.
    pub start: f64,
    pub end: f64,
    /// How many times it happens (a posture track's repeat, "twice" in the text).
    pub count: u32,
    /// The path the root walks, in [`crate::trajectory::Trajectory::describe`]'s words.
    pub path: Option<String>,
    /// The segment it belongs to (identical elements of consecutive segments repeat a
    /// movement).
    pub segment: usize,
    /// The posture library's other words for what a posture track holds ("arms out to the
    /// sides" for its "T-pose"): a person reading the plan knows the name means them, so the
    /// meaning match reads them too.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub aliases: Vec<String>,
}

impl Element {
    /// The side it moves: its part's, else the side its words name (a path turning clockwise
    /// goes right); `None` when it names none or both.
    pub fn side(&self) -> Option<Side> {
        self.on.side().or_else(|| text_side(&self.said()))
    }

    /// What it does in words, with the path it walks: the text the meaning match reads.
    pub fn said(&self) -> String {
        match &self.path {
            Some(p) => format!("{}, along {p}", self.text),
            None => self.text.clone(),
        }
    }

    /// How much it means `clause`'s movement, by its words or the library's other words for
    /// it; `None` below the matcher's threshold.
    pub fn means(&self, clause: &str, matcher: &Matcher) -> Option<f32> {
        std::iter::once(self.said())
            .chain(self.aliases.iter().cloned())
            .filter_map(|t| matcher.same(clause, &t))
            .max_by(f32::total_cmp)
    }

    fn describe(&self) -> String {
        let path = self
            .path
            .as_ref()
            .map(|p| format!(", path {p}"))
            .unwrap_or_default();
        let times = if self.count > 1 {
            format!(" ×{}", self.count)
        } else {
            String::new()
        };
        format!(
            "[{:.1}–{:.1} s {}] {}{times}{path}",
            self.start,
            self.end,
            self.on.describe(),
            self.text
        )
    }
}

/// The side a text names ("turning to the left", "a circle, clockwise"), if one only.
fn text_side(text: &str) -> Option<Side> {
    let w = words(text);
    let has = |x: &str| w.iter().any(|v| v == x);
    let counter = w
        .windows(2)
        .any(|p| matches!(p[0].as_str(), "counter" | "anti") && p[1] == "clockwise")
        || has("counterclockwise")
        || has("anticlockwise");
    let left = has("left") || counter;
    let right = has("right") || (has("clockwise") && !counter);
    match (left, right) {
        (true, false) => Some(Side::Left),
        (false, true) => Some(Side::Right),
        _ => None,
    }
}

/// How many times a text says ("twice", "three times").
fn text_count(text: &str) -> u32 {
    let w = words(text);
    for (i, x) in w.iter().enumerate() {
        match x.as_str() {
            "twice" => return 2,
            "thrice" => return 3,
            _ => {}
        }
        if w.get(i + 1).is_some_and(|n| n == "times") {
            if let Some(n) = super::lexicon::number(x).filter(|n| *n >= 1.0) {
                return n.round() as u32;
            }
        }
    }
    1
}

/// What a plan holds, element by element, with times from the segments' lengths: each
/// segment's base motion (with its path), each body-part instruction (parts with the same
/// instruction as one element: "both arms"), each clip of the body-part tracks, and each
/// posture track (the library movement it
/// plays, else the names of its key poses; a track that holds both legs carries the whole
/// body and its path, and the base motion under it is replaced).
pub fn plan_elements(plan: &Plan) -> Vec<Element> {
    // Every part instruction as a clip, the segments' own included.
    let plan = &plan.lifted();
    let mut out = Vec::new();
    let mut t = 0.0;
    for (k, s) in plan.segments.iter().enumerate() {
        let (start, end) = (t, t + s.seconds);
        t = end;
        let posture_body = s.postures.as_ref().is_some_and(|p| {
            p.parts.contains(&BodyPart::LeftLeg) && p.parts.contains(&BodyPart::RightLeg)
        });
        if !posture_body {
            out.push(Element {
                on: On::Body,
                text: s.base.clone(),
                start,
                end,
                count: text_count(&s.base),
                path: s.trajectory.as_ref().map(|t| t.describe()),
                segment: k,
                aliases: Vec::new(),
            });
        }
        if let Some(track) = &s.postures {
            let (from, to) = match track.within {
                Some([a, b]) => ((start + a).min(end), (start + b).min(end)),
                None => (start, end),
            };
            let names = distinct_names(track.keys.iter().map(|k| &k.script));
            // Arms held in a posture through a whole-body movement are on the arms' tracks.
            let held = held_arms(&names).filter(|_| posture_body);
            let names = held.as_ref().map_or(names, |(names, _, _)| names.clone());
            if let Some((_, arms_text, arms)) = held {
                let (from, to) = match track.within {
                    Some([a, b]) => ((start + a).min(end), (start + b).min(end)),
                    None => (start, end),
                };
                out.push(Element {
                    on: On::Parts(arms),
                    aliases: library_words(&arms_text, std::slice::from_ref(&arms_text)),
                    text: arms_text,
                    start: from,
                    end: to,
                    count: 1,
                    path: None,
                    segment: k,
                });
            }
            let text = library_movement(&names).unwrap_or_else(|| names.join(", "));
            let aliases = library_words(&text, &names);
            // The way a track goes, unless its names say it already ("side step to the left").
            let way = way(track);
            let text = if way.is_empty() || text.ends_with(way.trim_start_matches(", ")) {
                text
            } else {
                format!("{text}{way}")
            };
            let mut parts = track.parts.clone();
            parts.sort();
            out.push(Element {
                on: if posture_body {
                    On::Body
                } else {
                    On::Parts(parts)
                },
                text,
                start: from,
                end: to,
                count: track.repeat.max(1),
                // The root's path is the body's: a track on the arms does not walk it.
                path: s
                    .trajectory
                    .as_ref()
                    .filter(|_| posture_body)
                    .map(|t| t.describe()),
                segment: k,
                aliases,
            });
        }
    }
    for clip in &plan.clips {
        let (text, count, aliases) = match &clip.postures {
            Some(track) => {
                let names = distinct_names(track.keys.iter().map(|k| &k.script));
                let text = library_movement(&names).unwrap_or_else(|| names.join(", "));
                let aliases = library_words(&text, &names);
                (text, track.repeat.max(1), aliases)
            }
            None => (clip.text.clone(), text_count(&clip.text), Vec::new()),
        };
        out.push(Element {
            on: On::Parts(clip.parts.clone()),
            text,
            start: clip.start,
            end: clip.end,
            count,
            path: None,
            segment: plan.segment_at(clip.start),
            aliases,
        });
    }
    // In time order, the whole body first: as a person reads a timeline.
    out.sort_by(|a, b| {
        a.start
            .total_cmp(&b.start)
            .then((a.on != On::Body).cmp(&(b.on != On::Body)))
    });
    out
}

/// Which way a track turns or travels sideways, as its numbers say (", turning to the
/// right"), so the side is read from what the plan does; empty when it does neither.
fn way(track: &crate::posture::track::PostureTrack) -> String {
    let turn: f64 = track.keys.iter().map(|k| k.turn_deg).sum();
    let left: f64 = track.keys.iter().map(|k| k.travel[0]).sum();
    let mut out = String::new();
    if turn.abs() > 1.0 {
        out += if turn > 0.0 {
            ", turning to the left"
        } else {
            ", turning to the right"
        };
    }
    if left.abs() > 1e-3 {
        out += if left > 0.0 {
            ", to the left"
        } else {
            ", to the right"
        };
    }
    out
}

/// The names of key poses in order, each once (a pose without a name in words).
fn distinct_names<'a>(scripts: impl Iterator<Item = &'a PostureScript>) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for script in scripts {
        let name = script.name.clone().unwrap_or_else(|| script.in_words());
        if !names.contains(&name) {
            names.push(name);
        }
    }
    names
}

/// The arms' posture a planner laid into every key pose of a track ("left knee up with
/// T-pose", "right knee up with T-pose": a jog in place with the arms in a T-pose), read from
/// the key names: the names without it, its name, and the arms it holds (the library's, else
/// the arm its words name, else both). `None` when the keys share no such posture, or what
/// they share is not of the arms.
fn held_arms(names: &[String]) -> Option<(Vec<String>, String, Vec<BodyPart>)> {
    let split: Vec<(&str, &str)> = names
        .iter()
        .map(|n| n.split_once(" with "))
        .collect::<Option<_>>()?;
    let held = split[0].1;
    if split.iter().any(|(_, h)| *h != held) {
        return None;
    }
    let named = |word: &str| held.split(' ').any(|w| w == word);
    let arm_words = [
        "arm", "arms", "hand", "hands", "fist", "fists", "elbow", "elbows",
    ];
    let leg_words = [
        "leg", "legs", "foot", "feet", "knee", "knees", "toe", "toes",
    ];
    let arms = match Library::builtin().get(held) {
        Some(p) => p.parts.clone(),
        // What the words hold must be an arm ("step forward with the left foot" is a step).
        None if !arm_words.iter().any(|w| named(w)) || leg_words.iter().any(|w| named(w)) => {
            return None
        }
        None if named("left") && !named("right") => vec![BodyPart::LeftArm],
        None if named("right") && !named("left") => vec![BodyPart::RightArm],
        None => vec![BodyPart::LeftArm, BodyPart::RightArm],
    };
    if arms.is_empty()
        || arms
            .iter()
            .any(|p| !matches!(p, BodyPart::LeftArm | BodyPart::RightArm))
    {
        return None;
    }
    let mut bases: Vec<String> = Vec::new();
    for (base, _) in &split {
        if !bases.iter().any(|b| b == base) {
            bases.push(base.to_string());
        }
    }
    Some((bases, held.to_string(), arms))
}

/// The posture library's movement whose key poses a track plays, by their names: a track of
/// "crouch to jump, landing, standing" is the library's "jump", and that is what the plan
/// does (the key names alone do not say it).
fn library_movement(names: &[String]) -> Option<String> {
    Library::builtin()
        .actions
        .iter()
        .find(|a| distinct_names(a.keys.iter().map(|k| &k.script)) == names)
        .map(|a| a.name.clone())
}

/// The library's other words for a posture track named `text` (a library movement) or
/// holding the key poses `names`: the movement's phrases, or, for a track of one key pose,
/// the posture's (a track of several poses is the sequence, which no one phrase says).
fn library_words(text: &str, names: &[String]) -> Vec<String> {
    let library = Library::builtin();
    if let Some(action) = library.actions.iter().find(|a| a.name == text) {
        return action.phrases().skip(1).collect();
    }
    match names {
        [one] => library
            .get(one)
            .map(|p| p.phrases().skip(1).collect())
            .unwrap_or_default(),
        _ => Vec::new(),
    }
}

/// Why a clause is not placed correctly.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Miss {
    /// Nothing in the plan nor any note accounts for it.
    Lost,
    /// Not placed, but a note names it.
    OnlyInANote {
        note: String,
    },
    /// Context placed as a movement.
    ContextPlaced,
    /// Placed on another track.
    Track {
        expected: Track,
        got: String,
    },
    /// Placed on the opposite side.
    SideSwapped {
        expected: Side,
    },
    /// Placed with no side, or both, where one is asked.
    SideMissing {
        expected: Side,
    },
    Count {
        expected: u32,
        got: u32,
    },
    Path {
        expected: String,
        got: Option<String>,
    },
    /// Should start before clause `other` (an earlier step).
    NotBefore {
        other: usize,
    },
    /// Should start after clause `other`.
    NotAfter {
        other: usize,
    },
    /// Should overlap clause `other` in time.
    NoOverlap {
        other: usize,
    },
}

impl std::fmt::Display for Miss {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Miss::Lost => write!(f, "silently lost: nothing in the plan nor any note"),
            Miss::OnlyInANote { note } => write!(f, "not placed; a note says: {note}"),
            Miss::ContextPlaced => write!(f, "context placed as a movement"),
            Miss::Track { expected, got } => {
                write!(f, "on the {got} track, not {}", expected.name())
            }
            Miss::SideSwapped { expected } => {
                write!(f, "side swapped: {} expected", expected.name())
            }
            Miss::SideMissing { expected } => {
                write!(f, "side not kept: {} expected", expected.name())
            }
            Miss::Count { expected, got } => write!(f, "{got} times, not {expected}"),
            Miss::Path { expected, got } => match got {
                Some(g) => write!(f, "path {g}, not {expected}"),
                None => write!(f, "no path, {expected} expected"),
            },
            Miss::NotBefore { other } => write!(f, "does not come before clause {other}"),
            Miss::NotAfter { other } => write!(f, "does not come after clause {other}"),
            Miss::NoOverlap { other } => write!(f, "does not overlap clause {other}"),
        }
    }
}

/// How one clause was placed.
#[derive(Clone, Debug, Serialize)]
pub struct ClauseOutcome {
    pub text: String,
    pub track: Track,
    /// The plan elements matched to it, described.
    pub placed_as: Vec<String>,
    /// The similarity of the first of them.
    pub similarity: Option<f32>,
    pub correct: bool,
    pub misses: Vec<Miss>,
}

impl ClauseOutcome {
    /// Nothing in the plan nor any note accounts for it.
    pub fn lost(&self) -> bool {
        self.misses.contains(&Miss::Lost)
    }

    /// Placed on the opposite side.
    pub fn side_swap(&self) -> bool {
        self.misses
            .iter()
            .any(|m| matches!(m, Miss::SideSwapped { .. }))
    }
}

/// How one prompt was planned.
#[derive(Clone, Debug, Serialize)]
pub struct PromptOutcome {
    pub id: String,
    pub prompt: String,
    pub clauses: Vec<ClauseOutcome>,
    /// Every plan element, described.
    pub plan: Vec<String>,
    /// The plan elements no clause accounts for (a substitute nobody asked for, a movement
    /// said twice).
    pub extra: Vec<String>,
    /// The plan's notes.
    pub notes: Vec<String>,
}

impl PromptOutcome {
    /// Whether every clause is placed correctly.
    pub fn all_correct(&self) -> bool {
        self.clauses.iter().all(|c| c.correct)
    }
}

/// A planner over the whole set.
#[derive(Clone, Debug, Serialize)]
pub struct TimelineReport {
    #[serde(flatten)]
    pub figures: TimelineFigures,
    /// Plan elements no clause accounts for.
    pub extra_elements: usize,
    /// The similarity threshold of the meaning match.
    pub threshold: f32,
    /// Seconds the planner took over the whole set, when the caller timed it.
    pub planner_seconds: Option<f64>,
    pub results: Vec<PromptOutcome>,
}

/// The counts of a report, as the evaluation keeps them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TimelineFigures {
    pub prompts: usize,
    pub clauses: usize,
    /// Clauses placed correctly (track, order, overlap, side, count, path).
    pub correct: usize,
    /// Clauses nothing in the plan nor any note accounts for.
    pub silently_lost: usize,
    /// Clauses placed on the opposite side.
    pub side_swaps: usize,
    /// Prompts whose every clause is placed correctly.
    pub prompts_correct: usize,
    /// Context clauses (track `none`), and those dropped with a note.
    pub context_clauses: usize,
    pub context_dropped_with_note: usize,
}

impl TimelineFigures {
    /// The figures as a paragraph of `EVAL.md`'s agents section, for the set at `set`.
    pub fn markdown(&self, set: &str) -> String {
        format!(
            "Built-in planner on the {} prompts ({} clauses) of `{set}`, each clause annotated \
             with its track, order, overlap, side and count before the planner's timeline \
             changes, scored by `coma plan --timeline-set {set}`: **{}/{} clauses placed \
             correctly ({:.1} %)**, {} silently lost (neither in the plan nor in a note), {} \
             side swap(s), **{}/{} prompts with every clause placed correctly ({:.1} %)**; {}/{} \
             context clauses dropped with a note. Issue 38's targets are 85 %, 0, 0 and 70 %; \
             the misses and their reasons are in `docs/timeline_set_misses.txt`.\n\n",
            self.prompts,
            self.clauses,
            self.correct,
            self.clauses,
            percent(self.correct, self.clauses),
            self.silently_lost,
            self.side_swaps,
            self.prompts_correct,
            self.prompts,
            percent(self.prompts_correct, self.prompts),
            self.context_dropped_with_note,
            self.context_clauses,
        )
    }
}

fn percent(n: usize, of: usize) -> f64 {
    100.0 * n as f64 / of.max(1) as f64
}

impl TimelineReport {
    /// The figures in a few lines.
    pub fn figures(&self) -> String {
        let f = &self.figures;
        let mut out = format!(
            "clauses placed correctly: {}/{} ({:.1} %)\n\
             clauses silently lost: {}\n\
             side swaps: {}\n\
             prompts with every clause placed correctly: {}/{} ({:.1} %)\n\
             context clauses dropped with a note: {}/{}\n\
             plan elements no clause accounts for: {}\n",
            f.correct,
            f.clauses,
            percent(f.correct, f.clauses),
            f.silently_lost,
            f.side_swaps,
            f.prompts_correct,
            f.prompts,
            percent(f.prompts_correct, f.prompts),
            f.context_dropped_with_note,
            f.context_clauses,
            self.extra_elements,
        );
        if let Some(s) = self.planner_seconds {
            out += &format!(
                "planner time: {s:.2} s for {} prompts ({:.1} ms a prompt)\n",
                f.prompts,
                1000.0 * s / f.prompts.max(1) as f64
            );
        }
        out
    }

    /// Every prompt with a miss, its misses with the reason and what the plan holds, then the
    /// figures.
    pub fn table(&self) -> String {
        let mut out = String::new();
        for r in self.results.iter().filter(|r| !r.all_correct()) {
            out += &format!("✗ {}  {}\n", r.id, r.prompt);
            for (i, c) in r.clauses.iter().enumerate().filter(|(_, c)| !c.correct) {
                let reasons: Vec<String> = c.misses.iter().map(|m| m.to_string()).collect();
                let placed = if c.placed_as.is_empty() {
                    String::new()
                } else {
                    format!(" — placed as {}", c.placed_as.join(" + "))
                };
                out += &format!(
                    "    clause {i} \"{}\" ({}): {}{placed}\n",
                    c.text,
                    c.track.name(),
                    reasons.join("; ")
                );
            }
            for e in &r.plan {
                let extra = if r.extra.contains(e) {
                    "  (no clause)"
                } else {
                    ""
                };
                out += &format!("    plan: {e}{extra}\n");
            }
            for n in &r.notes {
                out += &format!("    note: {n}\n");
            }
        }
        out += &self.figures();
        out
    }
}

/// Plans every prompt of `set` with `planner` and scores the placement of its clauses.
pub fn score(
    set: &TimelineSet,
    planner: &mut dyn FnMut(&str) -> Plan,
    matcher: &Matcher,
) -> TimelineReport {
    let results: Vec<PromptOutcome> = set
        .prompts
        .iter()
        .map(|p| score_prompt(p, &planner(&p.prompt), matcher))
        .collect();
    let all = || results.iter().flat_map(|r| r.clauses.iter());
    let context = || all().filter(|c| c.track == Track::None);
    TimelineReport {
        figures: TimelineFigures {
            prompts: results.len(),
            clauses: all().count(),
            correct: all().filter(|c| c.correct).count(),
            silently_lost: all().filter(|c| c.lost()).count(),
            side_swaps: all().filter(|c| c.side_swap()).count(),
            prompts_correct: results.iter().filter(|r| r.all_correct()).count(),
            context_clauses: context().count(),
            context_dropped_with_note: context().filter(|c| c.correct).count(),
        },
        extra_elements: results.iter().map(|r| r.extra.len()).sum(),
        threshold: matcher.threshold(),
        planner_seconds: None,
        results,
    }
}

/// One way a clause may be placed: a run of identical consecutive elements.
#[derive(Clone, Debug)]
struct Choice {
    elements: Vec<usize>,
    similarity: f32,
}

/// What the expected steps say about two clauses.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Relation {
    Before,
    After,
    Overlap,
}

/// The steps a clause spans: its own and those of the clauses it rides over.
fn span(clauses: &[Clause], i: usize) -> (u32, u32) {
    let own = clauses[i].order.unwrap_or(0);
    clauses[i]
        .over
        .iter()
        .filter_map(|&j| clauses[j].order)
        .fold((own, own), |(lo, hi), o| (lo.min(o), hi.max(o)))
}

fn relation(clauses: &[Clause], i: usize, j: usize) -> Relation {
    let (a, b) = (span(clauses, i), span(clauses, j));
    if a.1 < b.0 {
        Relation::Before
    } else if b.1 < a.0 {
        Relation::After
    } else {
        Relation::Overlap
    }
}

/// The time a run of elements covers.
fn interval(elements: &[Element], run: &[usize]) -> (f64, f64) {
    run.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(s, e), &k| {
            (s.min(elements[k].start), e.max(elements[k].end))
        })
}

/// Movements that go on rather than happen a number of times: gaits (walking, running,
/// crawling, …). Two identical elements of these in a row are one longer movement.
fn continuous(text: &str) -> bool {
    const MORE: [&str; 10] = [
        "crawl", "crawls", "crawling", "march", "marches", "marching", "sneak", "sneaks",
        "shuffle", "shuffles",
    ];
    let gaits = &OPPOSITES[3];
    words(text).iter().any(|w| {
        let w = w.as_str();
        gaits.0.contains(&w) || gaits.1.contains(&w) || MORE.contains(&w)
    })
}

/// Whether two elements are the same movement said again in the next segment.
fn repeats(a: &Element, b: &Element) -> bool {
    b.segment == a.segment + 1 && a.text == b.text && a.on == b.on && a.path == b.path
}

/// Everything the scorer reads about one prompt, fixed before the search.
struct Problem<'a> {
    clauses: &'a [Clause],
    elements: &'a [Element],
    /// The movement clauses, in the order the search places them.
    movement: Vec<usize>,
    choices: Vec<Vec<Choice>>,
}

impl Problem<'_> {
    /// What is wrong with clause `i` placed as `choice`, on its own.
    fn own_misses(&self, i: usize, choice: &Choice) -> Vec<Miss> {
        let c = &self.clauses[i];
        let first = &self.elements[choice.elements[0]];
        let mut misses = Vec::new();
        let track_ok = match (c.track, &first.on) {
            (Track::Body, on) => *on == On::Body,
            (_, On::Parts(parts)) => Some(parts.as_slice()) == c.track.parts(),
            // A part or torso movement made as a whole-body clip of its own, with no
            // whole-body movement meant to happen beside it.
            (_, On::Body) => self.alone_on_the_body(i),
        };
        if !track_ok {
            misses.push(Miss::Track {
                expected: c.track,
                got: first.on.describe(),
            });
        }
        if let Some(want) = c.side {
            match first.side() {
                Some(got) if got == want => {}
                Some(_) => misses.push(Miss::SideSwapped { expected: want }),
                None => misses.push(Miss::SideMissing { expected: want }),
            }
        }
        if let Some(path) = &c.path {
            let got = choice
                .elements
                .iter()
                .find_map(|&k| self.elements[k].path.clone());
            let walked = got
                .as_ref()
                .is_some_and(|g| squeeze(g).contains(path.as_str()));
            if !walked {
                misses.push(Miss::Path {
                    expected: path.clone(),
                    got,
                });
            }
        }
        misses
    }

    /// Whether no whole-body clause is meant to overlap clause `i`.
    fn alone_on_the_body(&self, i: usize) -> bool {
        self.movement.iter().all(|&j| {
            j == i
                || self.clauses[j].track != Track::Body
                || relation(self.clauses, i, j) != Relation::Overlap
        })
    }

    /// The miss of clause `i` against clause `j`, both placed.
    fn pair_miss(&self, i: usize, ci: &Choice, j: usize, cj: &Choice) -> Option<Miss> {
        let (si, ei) = interval(self.elements, &ci.elements);
        let (sj, ej) = interval(self.elements, &cj.elements);
        match relation(self.clauses, i, j) {
            Relation::Before => (si + TIME_EPS >= sj).then_some(Miss::NotBefore { other: j }),
            Relation::After => (sj + TIME_EPS >= si).then_some(Miss::NotAfter { other: j }),
            Relation::Overlap => {
                (ei.min(ej) - si.max(sj) <= TIME_EPS).then_some(Miss::NoOverlap { other: j })
            }
        }
    }

    /// How many times clause `i` happens placed as `choice`, given every element claimed:
    /// identical elements right before or after the run that no clause claims repeat it too.
    /// A clause that rides over others is one clip held across segments, and walking or
    /// running in two segments in a row is one longer walk or run: neither is repeated.
    fn count(&self, i: usize, choice: &Choice, claimed: &[bool]) -> u32 {
        let counts = choice.elements.iter().map(|&k| self.elements[k].count);
        let first = &self.elements[choice.elements[0]];
        if !self.clauses[i].over.is_empty() || continuous(&first.text) {
            return counts.max().unwrap_or(1);
        }
        let mut n: u32 = counts.sum();
        let (first, last) = (
            choice.elements[0],
            choice.elements[choice.elements.len() - 1],
        );
        let mut at = last;
        while let Some(k) = (at + 1..self.elements.len())
            .find(|&k| repeats(&self.elements[at], &self.elements[k]))
            .filter(|&k| !claimed[k])
        {
            n += self.elements[k].count;
            at = k;
        }
        at = first;
        while let Some(k) = (0..at)
            .rev()
            .find(|&k| repeats(&self.elements[k], &self.elements[at]))
            .filter(|&k| !claimed[k])
        {
            n += self.elements[k].count;
            at = k;
        }
        n
    }
}

/// The search for the best matching.
struct Search<'p, 'a> {
    problem: &'p Problem<'a>,
    /// Per movement clause (in `problem.movement` order), the choice taken.
    taken: Vec<Option<usize>>,
    claimed: Vec<bool>,
    /// Per clause: decided and wrong on its own (lost, or a track, side or path miss).
    own_bad: Vec<bool>,
    /// A greedy matching of the order conflicts found so far: each conflict needs one of its
    /// two clauses blamed, so its size bounds the blame from below.
    matched: Vec<bool>,
    matching: usize,
    best: Option<(Score, Vec<Option<usize>>)>,
}

/// What the search maximises, in order: as many clauses right as the plan allows (as a
/// person reads it: "raise the right fist" is the clause that says so, even where another
/// clause could also be read into it), then every other clause the plan holds placed, then the
/// closest meaning, then the whole of a repeated run taken.
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd)]
struct Score {
    correct: usize,
    placed: usize,
    similarity: f32,
    elements: usize,
}

impl Search<'_, '_> {
    fn run(&mut self, depth: usize) {
        let p = self.problem;
        // Bounds: every clause still to place is placed, and right unless it is already wrong
        // or must take the blame of a conflict.
        let placed_bound = self.taken[..depth].iter().flatten().count() + p.movement.len() - depth;
        let bad = self.own_bad.iter().filter(|b| **b).count();
        let correct_bound = p.movement.len() - bad - self.matching;
        if let Some((best, _)) = &self.best {
            if correct_bound < best.correct
                || (correct_bound == best.correct && placed_bound < best.placed)
            {
                return;
            }
        }
        if depth == p.movement.len() {
            self.leaf();
            return;
        }
        let i = p.movement[depth];
        for (ci, choice) in p.choices[i].iter().enumerate() {
            if choice.elements.iter().any(|&k| self.claimed[k]) {
                continue;
            }
            self.own_bad[i] = !p.own_misses(i, choice).is_empty();
            let mut newly = Vec::new();
            for (d, &j) in p.movement[..depth].iter().enumerate() {
                let Some(cj) = self.taken[d] else { continue };
                let free = !self.own_bad[i] && !self.own_bad[j] && !self.matched[i];
                if free
                    && !self.matched[j]
                    && p.pair_miss(i, choice, j, &p.choices[j][cj]).is_some()
                {
                    self.matched[i] = true;
                    self.matched[j] = true;
                    self.matching += 1;
                    newly.push(j);
                }
            }
            for &k in &choice.elements {
                self.claimed[k] = true;
            }
            self.taken[depth] = Some(ci);
            self.run(depth + 1);
            self.taken[depth] = None;
            for &k in &choice.elements {
                self.claimed[k] = false;
            }
            for j in newly {
                self.matched[i] = false;
                self.matched[j] = false;
                self.matching -= 1;
            }
            self.own_bad[i] = false;
        }
        // Or not placed at all.
        self.own_bad[i] = true;
        self.run(depth + 1);
        self.own_bad[i] = false;
    }

    fn leaf(&mut self) {
        let p = self.problem;
        let judged = p.judge(&self.taken);
        let mut score = Score {
            placed: 0,
            correct: 0,
            similarity: 0.0,
            elements: 0,
        };
        for (d, &i) in p.movement.iter().enumerate() {
            let Some(ci) = self.taken[d] else { continue };
            let choice = &p.choices[i][ci];
            score.placed += 1;
            score.similarity += choice.similarity;
            score.elements += choice.elements.len();
            if judged[i].is_empty() {
                score.correct += 1;
            }
        }
        if self.best.as_ref().is_none_or(|(b, _)| score > *b) {
            self.best = Some((score, self.taken.clone()));
        }
    }
}

impl Problem<'_> {
    /// The misses of every clause under a full matching (`taken`, per movement clause); an
    /// unplaced clause gets [`Miss::Lost`] (the caller looks for a note). An order conflict
    /// between two clauses otherwise right is blamed on the fewest clauses that resolve every
    /// conflict (ties: fewer whole-body clauses, then the earliest in the prompt), as a
    /// reader says "the bow comes too early" rather than "everything is out of order"; a
    /// clause wrong on its own also lists its conflicts.
    fn judge(&self, taken: &[Option<usize>]) -> Vec<Vec<Miss>> {
        let n = self.clauses.len();
        let mut placed: Vec<Option<&Choice>> = vec![None; n];
        let mut claimed = vec![false; self.elements.len()];
        for (d, &i) in self.movement.iter().enumerate() {
            if let Some(ci) = taken[d] {
                let choice = &self.choices[i][ci];
                for &k in &choice.elements {
                    claimed[k] = true;
                }
                placed[i] = Some(choice);
            }
        }
        let mut misses: Vec<Vec<Miss>> = vec![Vec::new(); n];
        for &i in &self.movement {
            let Some(choice) = placed[i] else {
                misses[i].push(Miss::Lost);
                continue;
            };
            misses[i] = self.own_misses(i, choice);
            let got = self.count(i, choice, &claimed);
            if got != self.clauses[i].count {
                misses[i].push(Miss::Count {
                    expected: self.clauses[i].count,
                    got,
                });
            }
        }
        let own_ok: Vec<bool> = misses.iter().map(Vec::is_empty).collect();
        let mut conflicts: Vec<(usize, usize, Miss, Miss)> = Vec::new();
        for (a, &i) in self.movement.iter().enumerate() {
            for &j in &self.movement[a + 1..] {
                if let (Some(ci), Some(cj)) = (placed[i], placed[j]) {
                    if let Some(m) = self.pair_miss(i, ci, j, cj) {
                        let back = self
                            .pair_miss(j, cj, i, ci)
                            .expect("an order conflict goes both ways");
                        conflicts.push((i, j, m, back));
                    }
                }
            }
        }
        // The clauses to blame among those otherwise right: the smallest set that meets every
        // conflict between two of them (conflicts with a clause already wrong are its own).
        let open: Vec<&(usize, usize, Miss, Miss)> = conflicts
            .iter()
            .filter(|(i, j, ..)| own_ok[*i] && own_ok[*j])
            .collect();
        let mut nodes: Vec<usize> = open.iter().flat_map(|(i, j, ..)| [*i, *j]).collect();
        nodes.sort();
        nodes.dedup();
        let mut blamed: Vec<bool> = vec![false; n];
        if !open.is_empty() {
            let cost = |mask: u32| {
                let picked = nodes
                    .iter()
                    .enumerate()
                    .filter(|(b, _)| mask & (1 << b) != 0);
                let body = picked
                    .clone()
                    .filter(|(_, &i)| self.clauses[i].track == Track::Body)
                    .count();
                (mask.count_ones(), body)
            };
            let covers = |mask: u32| {
                open.iter().all(|(i, j, ..)| {
                    let at = |c: &usize| nodes.iter().position(|x| x == c).expect("a node");
                    mask & (1 << at(i)) != 0 || mask & (1 << at(j)) != 0
                })
            };
            // Lower masks blame earlier clauses: the first best is kept.
            let best = (0..1u32 << nodes.len())
                .filter(|m| covers(*m))
                .min_by_key(|m| cost(*m))
                .expect("all nodes cover every conflict");
            for (b, &i) in nodes.iter().enumerate() {
                blamed[i] = best & (1 << b) != 0;
            }
        }
        for (i, j, m, back) in conflicts {
            if !own_ok[i] || blamed[i] {
                misses[i].push(m);
            }
            if !own_ok[j] || blamed[j] {
                misses[j].push(back);
            }
        }
        misses
    }
}

/// Scores one prompt against its plan.
pub fn score_prompt(p: &SetPrompt, plan: &Plan, matcher: &Matcher) -> PromptOutcome {
    let elements = plan_elements(plan);
    let clauses = &p.clauses;
    let mut movement: Vec<usize> = (0..clauses.len())
        .filter(|&i| clauses[i].track != Track::None)
        .collect();
    movement.sort_by_key(|&i| (clauses[i].order, i));
    // How well each element means the clause it means best: an element that plainly says one
    // clause is not read as another it only resembles (a T-pose is no "run").
    let best_of: Vec<f32> = elements
        .iter()
        .map(|e| {
            clauses
                .iter()
                .filter(|c| c.track != Track::None)
                .filter_map(|c| e.means(c.meaning(), matcher))
                .fold(f32::MIN, f32::max)
        })
        .collect();
    let choices: Vec<Vec<Choice>> = clauses
        .iter()
        .map(|c| {
            if c.track == Track::None {
                return Vec::new();
            }
            let mut starts: Vec<(usize, f32)> = elements
                .iter()
                .enumerate()
                .filter_map(|(k, e)| e.means(c.meaning(), matcher).map(|s| (k, s)))
                .filter(|(k, s)| *s >= best_of[*k] - CLEARLY_OTHER)
                .collect();
            starts.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
            starts.truncate(MAX_CANDIDATES);
            let mut out = Vec::new();
            for (k, s) in starts {
                let mut run = vec![k];
                loop {
                    let last = *run.last().expect("a run has elements");
                    out.push(Choice {
                        elements: run.clone(),
                        similarity: s,
                    });
                    let next = (last + 1..elements.len())
                        .find(|&n| repeats(&elements[last], &elements[n]));
                    match next {
                        Some(n) if run.len() < MAX_RUN => run.push(n),
                        _ => break,
                    }
                }
            }
            out
        })
        .collect();
    let problem = Problem {
        clauses,
        elements: &elements,
        movement,
        choices,
    };
    let mut search = Search {
        problem: &problem,
        taken: vec![None; problem.movement.len()],
        claimed: vec![false; elements.len()],
        own_bad: vec![false; clauses.len()],
        matched: vec![false; clauses.len()],
        matching: 0,
        best: None,
    };
    search.run(0);
    let taken = search
        .best
        .map(|(_, t)| t)
        .unwrap_or_else(|| vec![None; problem.movement.len()]);
    let mut judged = problem.judge(&taken);
    let mut claimed = vec![false; elements.len()];
    let mut placed: Vec<Option<&Choice>> = vec![None; clauses.len()];
    for (d, &i) in problem.movement.iter().enumerate() {
        if let Some(ci) = taken[d] {
            let choice = &problem.choices[i][ci];
            for &k in &choice.elements {
                claimed[k] = true;
            }
            placed[i] = Some(choice);
        }
    }
    let named = |c: &Clause| {
        plan.notes
            .iter()
            .find(|n| note_names(n, c, &p.prompt, &elements, matcher))
            .cloned()
    };
    let mut extra: Vec<String> = elements
        .iter()
        .enumerate()
        .filter(|(k, _)| !claimed[*k])
        .map(|(_, e)| e.describe())
        .collect();
    let outcomes: Vec<ClauseOutcome> = clauses
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let mut misses = std::mem::take(&mut judged[i]);
            let mut placed_as = Vec::new();
            let mut similarity = None;
            if c.track == Track::None {
                // Context placed as a movement: an element no clause claimed that means it,
                // or the movement a note says was used in its place.
                let note = named(c);
                let as_movement = elements
                    .iter()
                    .enumerate()
                    .filter(|(k, _)| !claimed[*k])
                    .find_map(|(_, e)| e.means(c.meaning(), matcher).map(|s| (e, Some(s))))
                    .or_else(|| {
                        let note = note.as_deref()?;
                        note_pieces(note)
                            .find_map(|piece| in_plan(piece, &elements).map(|e| (e, None)))
                    });
                match (as_movement, note) {
                    (Some((e, s)), _) => {
                        extra.retain(|x| *x != e.describe());
                        placed_as.push(e.describe());
                        similarity = s;
                        misses.push(Miss::ContextPlaced);
                    }
                    (None, Some(_)) => {}
                    (None, None) => misses.push(Miss::Lost),
                }
            } else if let Some(choice) = placed[i] {
                placed_as = choice
                    .elements
                    .iter()
                    .map(|&k| elements[k].describe())
                    .collect();
                similarity = Some(choice.similarity);
            } else if let Some(note) = named(c) {
                misses = vec![Miss::OnlyInANote { note }];
            }
            ClauseOutcome {
                text: c.text.clone(),
                track: c.track,
                placed_as,
                similarity,
                correct: misses.is_empty(),
                misses,
            }
        })
        .collect();
    PromptOutcome {
        id: p.id.clone(),
        prompt: p.prompt.clone(),
        clauses: outcomes,
        plan: elements.iter().map(Element::describe).collect(),
        extra,
        notes: plan.notes.clone(),
    }
}

/// A note cut at quotes, colons and semicolons: notes quote the clauses they drop and list
/// what they leave out.
fn note_pieces(note: &str) -> impl Iterator<Item = &str> {
    note.split(['"', ':', ';'])
        .map(str::trim)
        .filter(|piece| !piece.is_empty())
}

/// Where the words of `piece` stand in `text` in a row: the word positions of every place.
fn places(piece: &str, text: &str) -> Vec<std::ops::Range<usize>> {
    let (p, t) = (words(piece), words(text));
    if p.is_empty() || p.len() > t.len() {
        return Vec::new();
    }
    (0..=t.len() - p.len())
        .filter(|&k| t[k..k + p.len()] == p[..])
        .map(|k| k..k + p.len())
        .collect()
}

/// The element a note piece names, if the plan holds it: the piece's words begin the
/// element's text, after "a person" (the nearest movement the planner used instead of a
/// clause, as its notes name it: "kicks with the right leg").
fn in_plan<'e>(piece: &str, elements: &'e [Element]) -> Option<&'e Element> {
    let p = words(piece);
    elements.iter().find(|e| {
        let said = words(&e.said());
        let said = match said.as_slice() {
            [a, person, rest @ ..] if a == "a" && person == "person" => rest,
            all => all,
        };
        !p.is_empty() && said.starts_with(&p)
    })
}

/// Whether a plan note names a clause. A piece that is a movement the plan holds (the
/// substitute the planner used for some clause) names none; a piece that quotes the prompt
/// names the clauses whose words it covers, in part or whole (the planner quotes the words it
/// could not plan, cut as it cut them); a piece in the note's own words (a segment it left
/// out) names a clause when it holds all of the clause's words or means the same movement.
fn note_names(
    note: &str,
    clause: &Clause,
    prompt: &str,
    elements: &[Element],
    matcher: &Matcher,
) -> bool {
    let own = words(&clause.text);
    let at = places(&clause.text, prompt);
    note_pieces(note).any(|piece| {
        if in_plan(piece, elements).is_some() {
            return false;
        }
        let quoted = places(piece, prompt);
        if !quoted.is_empty() {
            return quoted
                .iter()
                .any(|q| at.iter().any(|c| q.start < c.end && c.start < q.end));
        }
        let have = words(piece);
        own.iter().all(|w| have.contains(w)) || matcher.same(clause.meaning(), piece).is_some()
    })
}

#[cfg(test)]
mod tests;
