//! Named postures and movements made of them: two data files built into the library (so the
//! page needs no extra download). `static/postures/library.json` holds key poses with their
//! names and synonyms, for the built-in planner ("does a T-pose") and the page's posture
//! picker; `static/postures/actions.json` holds movements of several key poses the motion
//! model does not know (jump, spin, crawl, fall, push-ups, standing up).

use super::script::{PostureScript, ScriptError};
use super::solver::solve;
use super::track::{Bridges, PostureTrack, TrackKey, MAX_KEYS, MAX_REPEAT};
use crate::skeleton::BodyPart;
use serde::Deserialize;
use std::sync::OnceLock;

/// The named postures shipped with the app.
pub const LIBRARY_JSON: &str = include_str!("../../../static/postures/library.json");
/// The movements of key poses shipped with the app.
pub const ACTIONS_JSON: &str = include_str!("../../../static/postures/actions.json");

/// Default ground travel of a key marked `travels` when the prompt says the movement goes
/// somewhere ("jumps forward"), metres.
pub const TRAVEL_STEP_M: f64 = 0.5;

/// One key of a movement.
#[derive(Clone, Debug, PartialEq)]
pub struct ActionKey {
    /// The pose, with its hold.
    pub script: PostureScript,
    /// Seconds to move into it.
    pub transition: f64,
    /// Turn reached at this key, degrees, + to the left.
    pub turn_deg: f64,
    /// A jump into this key: the pelvis's rise in metres.
    pub jump_m: Option<f64>,
    /// Forward travel this key always makes (crawling), metres.
    pub travel_forward_m: f64,
    /// Whether this key moves [`TRAVEL_STEP_M`] when the prompt gives a direction.
    pub travels: bool,
}

/// A movement made of key poses (a jump, a spin, crawling).
#[derive(Clone, Debug, PartialEq)]
pub struct Action {
    /// The name shown to people ("jump").
    pub name: String,
    /// Phrases that name it, lower case.
    pub synonyms: Vec<String>,
    /// Whether it ends back in the pose it started from.
    pub returns: bool,
    /// How many times its keys play when the prompt gives no count (crawling: a few strides).
    pub repeat: u32,
    /// How many of its first keys get into the movement and are played once, before the keys
    /// that repeat (push-ups: into the plank once).
    pub lead_in: u32,
    /// The key poses.
    pub keys: Vec<ActionKey>,
}

impl Action {
    /// Every phrase that names the movement, lower case, the name first.
    pub fn phrases(&self) -> impl Iterator<Item = String> + '_ {
        std::iter::once(self.name.to_lowercase())
            .chain(self.synonyms.iter().map(|s| s.to_lowercase()))
    }

    /// The movement as a whole-body track: played `count` times (once when none is given),
    /// travelling `direction` (`[left, forward]`, unit or zero) on its
    /// travelling keys.
    pub fn track(&self, count: Option<u32>, direction: [f64; 2]) -> PostureTrack {
        // The movement's own cycle (a few crawling strides) is one movement: its keys are
        // written out, and the track's repeat is what the prompt counts.
        let lead = (self.lead_in as usize).min(self.keys.len() - 1);
        let (lead_keys, cycle) = self.keys.split_at(lead);
        let own = (self.repeat as usize).min(((MAX_KEYS - lead) / cycle.len()).max(1));
        let keys = lead_keys
            .iter()
            .chain(std::iter::repeat_n(cycle, own).flatten())
            .map(|k| {
                let step = if k.travels { TRAVEL_STEP_M } else { 0.0 };
                TrackKey {
                    script: k.script.clone(),
                    transition: k.transition,
                    turn_deg: k.turn_deg,
                    travel: [
                        direction[0] * step,
                        direction[1] * step + k.travel_forward_m,
                    ],
                    jump_m: k.jump_m,
                }
            })
            .collect();
        PostureTrack {
            parts: BodyPart::ALL.to_vec(),
            keys,
            repeat: count.unwrap_or(1).clamp(1, MAX_REPEAT),
            lead_in: lead as u32,
            returns: self.returns,
            within: None,
        }
    }
}

/// One named posture.
#[derive(Clone, Debug, PartialEq)]
pub struct NamedPosture {
    /// The name shown to people ("T-pose").
    pub name: String,
    /// Other ways to say it, lower case ("t pose", "arms out to the sides").
    pub synonyms: Vec<String>,
    /// The body parts the posture is about: held on these parts when it is laid over a
    /// generated motion (a T-pose on the arms of a walk).
    pub parts: Vec<BodyPart>,
    /// The key pose.
    pub script: PostureScript,
}

impl NamedPosture {
    /// Every phrase that names the posture, lower case, the name first.
    pub fn phrases(&self) -> impl Iterator<Item = String> + '_ {
        std::iter::once(self.name.to_lowercase())
            .chain(self.synonyms.iter().map(|s| s.to_lowercase()))
    }
}

/// The named postures and the movements made of key poses.
#[derive(Clone, Debug, PartialEq)]
pub struct Library {
    /// The postures in file order.
    pub postures: Vec<NamedPosture>,
    /// The movements in file order.
    pub actions: Vec<Action>,
    /// Every phrase of every posture and movement, normalised once ([`normalise`]), with
    /// the index in [`Library::all`] of what it names: [`Library::mentions`] reads every
    /// clause of every prompt against all of them.
    phrases: Vec<(String, usize)>,
}

/// Something the library names in a text.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Named<'a> {
    /// A key pose.
    Posture(&'a NamedPosture),
    /// A movement of key poses.
    Action(&'a Action),
}

impl<'a> Named<'a> {
    /// Every phrase that names it, lower case, the name first.
    pub fn phrases(&self) -> Vec<String> {
        match self {
            Named::Posture(p) => p.phrases().collect(),
            Named::Action(a) => a.phrases().collect(),
        }
    }

    /// Its name.
    pub fn name(&self) -> &'a str {
        match self {
            Named::Posture(p) => &p.name,
            Named::Action(a) => &a.name,
        }
    }
}

/// Why a library file was refused: which entry, and why.
#[derive(Debug, thiserror::Error)]
pub enum LibraryError {
    #[error("the posture library is not JSON of the expected shape: {0}")]
    Shape(String),
    #[error("posture {index} ({name}): {source}")]
    Script {
        index: usize,
        name: String,
        #[source]
        source: ScriptError,
    },
    #[error("posture {index} ({name}) has no body parts; list some of left_arm, right_arm, left_leg, right_leg")]
    NoParts { index: usize, name: String },
    #[error("movement {index} ({name}): {reason}")]
    Action {
        index: usize,
        name: String,
        reason: String,
    },
    #[error("the phrase '{phrase}' names both '{first}' and '{second}'")]
    Ambiguous {
        phrase: String,
        first: String,
        second: String,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LibraryFile {
    #[serde(default, rename = "about")]
    _about: String,
    postures: Vec<EntryFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EntryFile {
    name: String,
    #[serde(default)]
    synonyms: Vec<String>,
    parts: Vec<BodyPart>,
    #[serde(default = "default_hold")]
    hold: f64,
    constraints: Vec<serde_json::Value>,
}

fn default_hold() -> f64 {
    super::script::DEFAULT_HOLD_SECONDS
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ActionsFile {
    #[serde(default, rename = "about")]
    _about: String,
    actions: Vec<ActionFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ActionFile {
    name: String,
    #[serde(default)]
    synonyms: Vec<String>,
    #[serde(default)]
    returns: bool,
    #[serde(default = "one")]
    repeat: u32,
    #[serde(default)]
    lead_in: u32,
    keys: Vec<ActionKeyFile>,
}

fn one() -> u32 {
    1
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ActionKeyFile {
    #[serde(default)]
    name: Option<String>,
    /// A named posture of the library, or
    #[serde(default)]
    posture: Option<String>,
    /// a script of the key's own.
    #[serde(default)]
    constraints: Option<Vec<serde_json::Value>>,
    #[serde(default)]
    hold: Option<f64>,
    #[serde(default = "default_transition")]
    transition: f64,
    #[serde(default)]
    turn_deg: f64,
    #[serde(default)]
    jump_m: Option<f64>,
    #[serde(default)]
    travel_forward_m: f64,
    #[serde(default)]
    travels: bool,
}

fn default_transition() -> f64 {
    super::track::DEFAULT_TRANSITION_SECONDS
}

impl Library {
    /// Reads and checks a library: every script parses, every posture has parts, and no
    /// phrase names two postures.
    pub fn parse(text: &str) -> Result<Library, LibraryError> {
        let file: LibraryFile =
            serde_json::from_str(text).map_err(|e| LibraryError::Shape(e.to_string()))?;
        let mut postures = Vec::with_capacity(file.postures.len());
        for (i, entry) in file.postures.into_iter().enumerate() {
            if entry.parts.is_empty() {
                return Err(LibraryError::NoParts {
                    index: i + 1,
                    name: entry.name,
                });
            }
            let script = PostureScript::from_value(serde_json::json!({
                "name": entry.name,
                "hold": entry.hold,
                "constraints": entry.constraints,
            }))
            .map_err(|source| LibraryError::Script {
                index: i + 1,
                name: entry.name.clone(),
                source,
            })?;
            postures.push(NamedPosture {
                name: entry.name,
                synonyms: entry.synonyms,
                parts: entry.parts,
                script,
            });
        }
        let mut library = Library {
            postures,
            actions: Vec::new(),
            phrases: Vec::new(),
        };
        library.index_phrases()?;
        Ok(library)
    }

    /// Adds the movements of an actions file; their keys may name the library's postures.
    pub fn with_actions(mut self, text: &str) -> Result<Library, LibraryError> {
        let file: ActionsFile =
            serde_json::from_str(text).map_err(|e| LibraryError::Shape(e.to_string()))?;
        for (i, a) in file.actions.into_iter().enumerate() {
            let fail = |reason: String| LibraryError::Action {
                index: i + 1,
                name: a.name.clone(),
                reason,
            };
            if a.keys.is_empty() || a.keys.len() > MAX_KEYS {
                return Err(fail(format!("a movement has 1 to {MAX_KEYS} keys")));
            }
            if !(1..=MAX_REPEAT).contains(&a.repeat) {
                return Err(fail(format!("repeat is 1 to {MAX_REPEAT}")));
            }
            if a.lead_in as usize >= a.keys.len() {
                return Err(fail(
                    "the lead-in must leave at least one key to repeat".into(),
                ));
            }
            let mut keys = Vec::with_capacity(a.keys.len());
            for (k, key) in a.keys.iter().enumerate() {
                let mut script = match (&key.posture, &key.constraints) {
                    (Some(name), None) => {
                        self.get(name).map(|p| p.script.clone()).ok_or_else(|| {
                            fail(format!("key {}: no posture is called '{name}'", k + 1))
                        })?
                    }
                    (None, Some(constraints)) => PostureScript::from_value(serde_json::json!({
                        "name": key.name.clone().unwrap_or_else(|| a.name.clone()),
                        "constraints": constraints,
                    }))
                    .map_err(|e| fail(format!("key {}: {e}", k + 1)))?,
                    _ => {
                        return Err(fail(format!(
                            "key {}: give either \"posture\" or \"constraints\"",
                            k + 1
                        )))
                    }
                };
                if let Some(hold) = key.hold {
                    script.hold = hold;
                }
                if let Some(name) = &key.name {
                    script.name = Some(name.clone());
                }
                let script = script
                    .check()
                    .map_err(|e| fail(format!("key {}: {e}", k + 1)))?;
                keys.push(ActionKey {
                    script,
                    transition: key.transition,
                    turn_deg: key.turn_deg,
                    jump_m: key.jump_m,
                    travel_forward_m: key.travel_forward_m,
                    travels: key.travels,
                });
            }
            let action = Action {
                name: a.name.clone(),
                synonyms: a.synonyms.clone(),
                returns: a.returns,
                repeat: a.repeat,
                lead_in: a.lead_in,
                keys,
            };
            // The track checks the numbers (times, turns, jumps) once, as a plan would.
            action.track(None, [0.0, 1.0]).checked().map_err(fail)?;
            self.actions.push(action);
        }
        self.index_phrases()?;
        Ok(self)
    }

    /// Normalises every phrase once, refusing a phrase that names two things: the planner
    /// could not tell which was meant.
    fn index_phrases(&mut self) -> Result<(), LibraryError> {
        let mut phrases: Vec<(String, usize)> = Vec::new();
        for (i, named) in self.all().enumerate() {
            for phrase in named.phrases() {
                let phrase = normalise(&phrase);
                match phrases.iter().find(|(s, _)| *s == phrase) {
                    Some(&(_, first)) if first != i => {
                        let first = self.named(first).name().to_string();
                        if first != named.name() {
                            return Err(LibraryError::Ambiguous {
                                phrase,
                                first,
                                second: named.name().to_string(),
                            });
                        }
                    }
                    Some(_) => {}
                    None if phrase.is_empty() => {}
                    None => phrases.push((phrase, i)),
                }
            }
        }
        self.phrases = phrases;
        Ok(())
    }

    /// The `i`-th of [`Library::all`].
    fn named(&self, i: usize) -> Named<'_> {
        match self.postures.get(i) {
            Some(p) => Named::Posture(p),
            None => Named::Action(&self.actions[i - self.postures.len()]),
        }
    }

    /// Every posture, then every movement.
    pub fn all(&self) -> impl Iterator<Item = Named<'_>> {
        self.postures
            .iter()
            .map(Named::Posture)
            .chain(self.actions.iter().map(Named::Action))
    }

    /// The poses a posture segment passes through between standing and lying (see
    /// [`Bridges`]): the library's "sit on the floor" and "crawling position", solved; `None`
    /// when the library lacks either.
    pub fn bridges(&self) -> Option<Bridges> {
        let pose = |name: &str| Some(solve(&self.get(name)?.script, None).pose);
        Some(Bridges {
            back: pose("sit on the floor")?,
            front: pose("crawling position")?,
        })
    }

    /// The built-in library's [`Library::bridges`], solved once.
    pub fn builtin_bridges() -> Option<&'static Bridges> {
        static BRIDGES: OnceLock<Option<Bridges>> = OnceLock::new();
        BRIDGES
            .get_or_init(|| Library::builtin().bridges())
            .as_ref()
    }

    /// The library shipped with the app, read once.
    pub fn builtin() -> &'static Library {
        static LIBRARY: OnceLock<Library> = OnceLock::new();
        LIBRARY.get_or_init(|| {
            // The file is part of the build and a test reads it, so a broken file never ships.
            Library::parse(LIBRARY_JSON)
                .and_then(|l| l.with_actions(ACTIONS_JSON))
                .expect("static/postures/{library,actions}.json are checked by a test")
        })
    }

    /// The posture a name or synonym denotes exactly (case, spaces, hyphens ignored).
    pub fn get(&self, name: &str) -> Option<&NamedPosture> {
        let wanted = normalise(name);
        self.phrases
            .iter()
            .find(|(phrase, _)| *phrase == wanted)
            .and_then(|&(_, i)| self.postures.get(i))
    }

    /// Postures and movements named in a text, with the byte range of the longest phrase that
    /// names each, in the order they appear; overlapping mentions keep the longer phrase.
    pub fn mentions(&self, text: &str) -> Vec<(std::ops::Range<usize>, Named<'_>)> {
        let (flat, map) = normalise_with_map(text);
        let mut found: Vec<(std::ops::Range<usize>, Named<'_>)> = Vec::new();
        for (phrase, i) in &self.phrases {
            let mut from = 0;
            while let Some(at) = flat[from..].find(phrase.as_str()) {
                let start = from + at;
                let end = start + phrase.len();
                let bounded = (start == 0 || flat.as_bytes()[start - 1] == b' ')
                    && (end == flat.len() || flat.as_bytes()[end] == b' ');
                if bounded {
                    let last = map[end - 1];
                    let stop = last + text[last..].chars().next().map_or(1, char::len_utf8);
                    found.push((map[start]..stop, self.named(*i)));
                }
                from = start + 1;
            }
        }
        // Longer phrases first, then keep those that overlap nothing kept.
        found.sort_by_key(|(r, _)| (std::cmp::Reverse(r.len()), r.start));
        let mut kept: Vec<(std::ops::Range<usize>, Named<'_>)> = Vec::new();
        for (r, n) in found {
            if kept
                .iter()
                .all(|(k, _)| r.end <= k.start || r.start >= k.end)
            {
                kept.push((r, n));
            }
        }
        kept.sort_by_key(|(r, _)| r.start);
        kept
    }

    /// Postures whose name or a synonym contains every word of `query`, best first (name
    /// matches before synonym matches): the page's searchable list.
    pub fn search(&self, query: &str) -> Vec<&NamedPosture> {
        let words: Vec<String> = normalise(query).split(' ').map(str::to_string).collect();
        let mut hits: Vec<(usize, &NamedPosture)> = self
            .postures
            .iter()
            .filter_map(|p| {
                p.phrases().enumerate().find_map(|(rank, ph)| {
                    let ph = normalise(&ph);
                    words
                        .iter()
                        .all(|w| ph.contains(w.as_str()))
                        .then_some((rank.min(1), p))
                })
            })
            .collect();
        hits.sort_by_key(|(rank, _)| *rank);
        hits.into_iter().map(|(_, p)| p).collect()
    }
}

/// Lower case, letters and digits kept, everything else one space, possessives as "the":
/// "T-Pose!" → "t pose", "on his knees" → "on the knees".
fn normalise(text: &str) -> String {
    normalise_with_map(text).0
}

/// [`normalise`], with the byte offset in `text` of every byte of the result.
fn normalise_with_map(text: &str) -> (String, Vec<usize>) {
    let mut out = String::with_capacity(text.len());
    let mut map = Vec::with_capacity(text.len());
    let mut space = true;
    for (i, c) in text.char_indices() {
        if c.is_alphanumeric() {
            for l in c.to_lowercase() {
                let mut buf = [0u8; 4];
                for _ in l.encode_utf8(&mut buf).bytes() {
                    map.push(i);
                }
                out.push(l);
            }
            space = false;
        } else if !space {
            out.push(' ');
            map.push(i);
            space = true;
        }
    }
    if out.ends_with(' ') {
        out.pop();
        map.pop();
    }
    // "on his right knee" is "on the right knee": a possessive says whose body, never which
    // posture, so one synonym serves every subject.
    let mut plain = String::with_capacity(out.len());
    let mut plain_map = Vec::with_capacity(map.len());
    let mut at = 0;
    for (n, word) in out.split(' ').enumerate() {
        if n > 0 {
            plain.push(' ');
            plain_map.push(map[at - 1]);
        }
        let said = match word {
            "his" | "her" | "their" | "its" => "the",
            w => w,
        };
        plain.push_str(said);
        plain_map.extend_from_slice(&map[at..at + said.len()]);
        at += word.len() + 1;
    }
    (plain, plain_map)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_library_reads() {
        let library = Library::parse(LIBRARY_JSON).unwrap();
        assert!(library.get("T pose").is_some());
        assert_eq!(library.get("tpose").unwrap().name, "T-pose");
    }

    #[test]
    fn mentions_find_the_longest_phrase_in_order() {
        let library = Library::builtin();
        let text = "The girl squats while striking a T-pose, then kneels down";
        let names: Vec<&str> = library
            .mentions(text)
            .iter()
            .map(|(_, n)| n.name())
            .collect();
        assert_eq!(names, ["squat", "T-pose", "kneel on both knees"]);
        let (range, _) = &library.mentions(text)[1];
        assert_eq!(&text[range.clone()], "T-pose");
        assert!(library.mentions("he squatted").is_empty() || library.get("squatted").is_some());
        // A possessive names whose body, not which posture; the range is still the text's own.
        let text = "A man kneels on his right knee.";
        let found = library.mentions(text);
        assert_eq!(found.len(), 1);
        assert_eq!(found[0].1.name(), "kneel on one knee");
        assert_eq!(&text[found[0].0.clone()], "kneels on his right knee");
        let text = "she drops to their knees";
        assert_eq!(
            &text[library.mentions(text)[0].0.clone()],
            "drops to their knees"
        );
    }

    #[test]
    fn a_bad_entry_is_named() {
        let e = Library::parse(
            r#"{"postures":[{"name":"x","parts":["left_arm"],"constraints":[{"kind":"bend","joint":"left_elbow","is":"bent"}]}]}"#,
        )
        .unwrap_err();
        assert!(
            e.to_string().starts_with("posture 1 (x): constraint 1"),
            "{e}"
        );
    }
}
