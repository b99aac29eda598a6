//! Named postures: a data file (`static/postures/library.json`, built into the library so the
//! page needs no extra download) of key poses with their names and synonyms, for the built-in
//! planner ("does a T-pose") and the page's posture picker.

use super::script::{PostureScript, ScriptError};
use crate::skeleton::BodyPart;
use serde::Deserialize;
use std::sync::OnceLock;

/// The library file shipped with the app.
pub const LIBRARY_JSON: &str = include_str!("../../../static/postures/library.json");

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

/// The named postures.
#[derive(Clone, Debug, PartialEq)]
pub struct Library {
    /// The postures in file order.
    pub postures: Vec<NamedPosture>,
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
        let library = Library { postures };
        let mut seen: Vec<(String, &str)> = Vec::new();
        for p in &library.postures {
            for phrase in p.phrases() {
                let phrase = normalise(&phrase);
                match seen.iter().find(|(s, _)| *s == phrase) {
                    Some((_, first)) if *first != p.name => {
                        return Err(LibraryError::Ambiguous {
                            phrase,
                            first: first.to_string(),
                            second: p.name.clone(),
                        })
                    }
                    Some(_) => {}
                    None => seen.push((phrase, &p.name)),
                }
            }
        }
        Ok(library)
    }

    /// The library shipped with the app, read once.
    pub fn builtin() -> &'static Library {
        static LIBRARY: OnceLock<Library> = OnceLock::new();
        LIBRARY.get_or_init(|| {
            // The file is part of the build and a test reads it, so a broken file never ships.
            Library::parse(LIBRARY_JSON).expect("static/postures/library.json is checked by a test")
        })
    }

    /// The posture a name or synonym denotes exactly (case, spaces, hyphens ignored).
    pub fn get(&self, name: &str) -> Option<&NamedPosture> {
        let wanted = normalise(name);
        self.postures
            .iter()
            .find(|p| p.phrases().any(|ph| normalise(&ph) == wanted))
    }

    /// Postures named in a text, with the byte range of the longest phrase that names each,
    /// in the order they appear; overlapping mentions keep the longer phrase.
    pub fn mentions(&self, text: &str) -> Vec<(std::ops::Range<usize>, &NamedPosture)> {
        let (flat, map) = normalise_with_map(text);
        let mut found: Vec<(std::ops::Range<usize>, &NamedPosture)> = Vec::new();
        for p in &self.postures {
            for phrase in p.phrases() {
                let phrase = normalise(&phrase);
                if phrase.is_empty() {
                    continue;
                }
                let mut from = 0;
                while let Some(at) = flat[from..].find(&phrase) {
                    let start = from + at;
                    let end = start + phrase.len();
                    let bounded = (start == 0 || flat.as_bytes()[start - 1] == b' ')
                        && (end == flat.len() || flat.as_bytes()[end] == b' ');
                    if bounded {
                        let last = map[end - 1];
                        let stop = last + text[last..].chars().next().map_or(1, char::len_utf8);
                        found.push((map[start]..stop, p));
                    }
                    from = start + 1;
                }
            }
        }
        // Longer phrases first, then keep those that overlap nothing kept.
        found.sort_by_key(|(r, _)| (std::cmp::Reverse(r.len()), r.start));
        let mut kept: Vec<(std::ops::Range<usize>, &NamedPosture)> = Vec::new();
        for (r, p) in found {
            if kept
                .iter()
                .all(|(k, _)| r.end <= k.start || r.start >= k.end)
            {
                kept.push((r, p));
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

/// Lower case, letters and digits kept, everything else one space: "T-Pose!" → "t pose".
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
    (out, map)
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
            .map(|(_, p)| p.name.as_str())
            .collect();
        assert_eq!(names, ["squat", "T-pose", "kneel on both knees"]);
        let (range, _) = &library.mentions(text)[1];
        assert_eq!(&text[range.clone()], "T-pose");
        assert!(library.mentions("he squatted").is_empty() || library.get("squatted").is_some());
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
