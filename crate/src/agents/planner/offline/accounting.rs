//! Every clause accounted for: what a clause names that the built-in planner's rules do not
//! make is found here, so the planner either places it (a second whole-body movement the
//! clause moves on to) or names it in a note with the reason, and never drops it silently.
//!
//! The rules read a clause as one whole-body movement with gestures riding on it; what falls
//! outside that reading is
//! - a second whole-body movement ("picks up speed from a walk **to a run**"): placed after
//!   the first when the words between say one follows the other, named in a note when they
//!   happen at once (one whole-body motion at a time);
//! - a gesture on an arm another gesture already moves ("waves the right hand while pointing
//!   with it"): named in a note;
//! - a phrase about an arm, a hand, a leg or a foot in which the rules found no movement at
//!   all ("spins with **his right arm upwards**"): named in a note.

use super::super::lexicon;
use crate::plan::Segment;
use crate::skeleton::{BodyPart, Side};

/// Words that end a phrase inside a clause.
const BOUNDARIES: &[&str] = &[",", "and", "while", "whilst", "then", "as", "but"];

/// Words that open a phrase riding on the clause's movement ("holding both hands up").
const OPENERS: &[&str] = &[
    "with", "holding", "keeping", "having", "using", "while", "whilst",
];

/// Words between two movements of one clause that put the second after the first.
const SEQUENCE_WORDS: &[&str] = &[
    "to", "into", "then", "until", "before", "after", "becoming", "turning",
];

/// Limb nouns and the limb they name, for the notes.
pub(super) fn limb(word: &str) -> Option<&'static str> {
    Some(match word {
        "arm" | "arms" | "hand" | "hands" | "fist" | "fists" | "elbow" | "elbows" | "palm"
        | "palms" | "finger" | "fingers" | "wrist" | "wrists" => "arm",
        "leg" | "legs" | "foot" | "feet" | "knee" | "knees" | "toe" | "toes" | "heel" | "heels"
        | "ankle" | "ankles" => "leg",
        _ => return None,
    })
}

/// Words that name no movement of their own in a limb phrase: determiners, pronouns, sides,
/// the limbs themselves and the prepositions that attach them ("with his left hand").
fn is_instrument_word(word: &str) -> bool {
    lexicon::is_subject_word(word)
        || limb(word).is_some()
        || matches!(
            word,
            "with"
                | "using"
                | "by"
                | "his"
                | "her"
                | "their"
                | "its"
                | "one"
                | "left"
                | "right"
                | "both"
                | "each"
                | "other"
                | "of"
        )
}

/// The phrase that starts at word `at`: up to the next boundary, at most eight words.
pub(super) fn phrase_from(words: &[&str], at: usize) -> String {
    let end = (at + 1..words.len())
        .find(|&k| BOUNDARIES.contains(&words[k]))
        .unwrap_or(words.len())
        .min(at + 8);
    words[at.min(words.len())..end].join(" ")
}

/// The words of a clause up to the first boundary or opener, the movement it names before
/// what rides on it ("walks calmly" of "walks calmly with the right hand raised").
pub(super) fn head_phrase(words: &[&str]) -> String {
    let end = (1..words.len())
        .find(|&k| BOUNDARIES.contains(&words[k]) || OPENERS.contains(&words[k]))
        .unwrap_or(words.len());
    words[..end].join(" ")
}

/// Whether the words between the movement named at `first` and the one at `second` put the
/// second after the first ("from a walk to a run", "walks until he breaks into a run").
pub(super) fn in_sequence(words: &[&str], first: usize, second: usize) -> bool {
    let (a, b) = (first.min(second), first.max(second));
    words[a + 1..b].iter().any(|w| SEQUENCE_WORDS.contains(w))
        && !words[a + 1..b]
            .iter()
            .any(|w| matches!(*w, "while" | "whilst" | "as"))
}

/// The phrases of a clause about a limb in which no movement was found: the words from the
/// phrase's start (the clause's start, a boundary or an opener such as "holding") to its end,
/// with the limb they name. `found` are the indices of the words that named a movement the
/// rules read (placed or not). A phrase that only says which limb does a movement named
/// before it ("kicks with the right leg") is not one.
pub(super) fn limb_phrases_without_movement(
    words: &[&str],
    found: &[usize],
) -> Vec<(String, &'static str)> {
    let mut out: Vec<(String, &'static str)> = Vec::new();
    let mut covered_to = 0;
    for (i, w) in words.iter().enumerate() {
        let Some(limb) = limb(w) else { continue };
        if i < covered_to {
            continue;
        }
        // The phrase starts after the movement named before it ("marches in place swinging
        // both arms") or at a boundary or an opener, whichever comes last.
        let opened = (0..i)
            .rev()
            .find(|&k| BOUNDARIES.contains(&words[k]) || OPENERS.contains(&words[k]))
            .map_or(0, |k| {
                if BOUNDARIES.contains(&words[k]) {
                    k + 1
                } else {
                    k
                }
            });
        let after_movement = found.iter().filter(|k| **k < i).max().map_or(0, |k| k + 1);
        let start = opened.max(after_movement);
        let end = (i + 1..words.len())
            .find(|&k| BOUNDARIES.contains(&words[k]) || OPENERS.contains(&words[k]))
            .unwrap_or(words.len());
        covered_to = end;
        if found.iter().any(|k| (start..end).contains(k)) {
            continue;
        }
        let phrase = &words[start..end];
        if phrase.iter().all(|w| is_instrument_word(w)) && found.iter().any(|k| *k < start) {
            continue;
        }
        out.push((phrase.join(" "), limb));
    }
    out
}

/// The phrases of a clause about a limb that nothing in the plan moves or holds, for a note:
/// a limb of a side the clause names ("tapping **his right foot**") with no part
/// instruction, held posture or held pose (`held`) on it over the clause's segments (`made`),
/// and no note quoting the phrase yet. A base motion moves the limbs its own way ("kicks
/// with the right leg"), so it accounts for them, except standing (no limb) and a walk or a
/// run (the legs only: "walking, taps his head **with his left hand**").
pub(super) fn limbs_left_unplaced(
    words: &[&str],
    made: &[Segment],
    held: &[BodyPart],
    notes: &[String],
) -> Vec<(String, &'static str)> {
    if made.is_empty() {
        return Vec::new();
    }
    // A base motion moves the limbs its own way, except standing (none) and walking or
    // running (only the legs: arms swing whatever the clause asked of them).
    let base_moves = |s: &Segment, part: BodyPart| {
        let arm = matches!(part, BodyPart::LeftArm | BodyPart::RightArm);
        let gait = ["walks", "runs", "jogs"]
            .iter()
            .any(|g| s.base.split(' ').any(|w| w == *g));
        !(s.base.ends_with("stands still") || arm && gait)
    };
    let covered = |part: BodyPart| {
        held.contains(&part)
            || made.iter().all(|s| {
                base_moves(s, part)
                    || s.parts.get(part).is_some()
                    || s.postures.as_ref().is_some_and(|t| t.parts.contains(&part))
            })
    };
    let mut out = Vec::new();
    for (i, w) in words.iter().enumerate() {
        let Some(limb) = limb(w) else { continue };
        // "touches the right knee", "on his left foot" after a hand: where a hand goes.
        let touched = words[i.saturating_sub(3)..i].iter().any(|w| {
            matches!(
                *w,
                "touches" | "touching" | "touch" | "on" | "onto" | "to" | "against" | "over"
            )
        }) && words
            .iter()
            .any(|w| matches!(*w, "hand" | "hands" | "fingers" | "palm"));
        if touched && limb == "leg" {
            continue;
        }
        let side = words[i.saturating_sub(2)..i]
            .iter()
            .rev()
            .find_map(|w| Side::of_word(w));
        let parts: Vec<BodyPart> = match (limb, side) {
            ("arm", Some(Side::Left)) => vec![BodyPart::LeftArm],
            ("arm", Some(Side::Right)) => vec![BodyPart::RightArm],
            ("leg", Some(Side::Left)) => vec![BodyPart::LeftLeg],
            ("leg", Some(Side::Right)) => vec![BodyPart::RightLeg],
            _ => continue,
        };
        if parts.iter().all(|p| covered(*p)) {
            continue;
        }
        // From a boundary, or from the opener or participle that begins the phrase
        // ("…, **tapping** his right foot": the comma before a rider is gone by now).
        let start = (0..i)
            .rev()
            .find_map(|k| {
                if BOUNDARIES.contains(&words[k]) {
                    Some(k + 1)
                } else if OPENERS.contains(&words[k]) || words[k].ends_with("ing") {
                    Some(k)
                } else {
                    None
                }
            })
            .unwrap_or(0);
        let end = (i + 1..words.len())
            .find(|&k| BOUNDARIES.contains(&words[k]) || OPENERS.contains(&words[k]))
            .unwrap_or(words.len());
        let phrase = words[start..end].join(" ");
        if !notes.iter().any(|n| n.contains(&phrase)) && !out.iter().any(|(p, _)| *p == phrase) {
            out.push((phrase, limb));
        }
    }
    out
}

/// Words of a phrase that do not say how the body moves: function words, the anaphora and
/// counts the rules read on their own ("does it again", "twice"), manner words the timing
/// reads ("slowly"), and the instrument words of [`is_instrument_word`].
fn is_movement_content(word: &str) -> bool {
    word.len() >= 4
        && word.chars().all(char::is_alphabetic)
        && !is_instrument_word(word)
        && !lexicon::is_subject_noun(word)
        && !matches!(
            word,
            "from"
                | "into"
                | "onto"
                | "over"
                | "under"
                | "like"
                | "then"
                | "when"
                | "while"
                | "whilst"
                | "again"
                | "same"
                | "thing"
                | "once"
                | "twice"
                | "more"
                | "times"
                | "also"
                | "just"
                | "very"
                | "still"
                | "slowly"
                | "quickly"
                | "gently"
                | "forth"
                | "little"
                | "each"
                | "other"
                | "there"
                | "that"
                | "this"
                | "what"
                | "does"
                | "doing"
                | "keeps"
                | "keeping"
                | "holds"
                | "holding"
        )
}

/// A word without its inflection, enough to match its other forms ("raised", "raises" and
/// "raise"; "hops" and "hopping"). Written here because the planner needs this one
/// comparison, not a language's stemmer.
fn stem(word: &str) -> &str {
    let mut w = word;
    for suffix in ["ing", "ed", "es", "s"] {
        if let Some(rest) = w.strip_suffix(suffix).filter(|r| r.len() >= 3) {
            w = rest;
            break;
        }
    }
    let b = w.as_bytes();
    if b.len() >= 4 && b[b.len() - 1] == b[b.len() - 2] && !b"aeiou".contains(&b[b.len() - 1]) {
        w = &w[..w.len() - 1];
    }
    let w = w.strip_suffix('e').filter(|r| r.len() >= 3).unwrap_or(w);
    // A limb raised is a limb up: the names of held places say "up" ("right arm up").
    match w {
        "rais" | "lift" | "upward" => "up",
        other => other,
    }
}

/// What the planner made of a clause, in words: the segments' base texts, part
/// instructions and key-pose names, the names of the limb poses `held` over them, the
/// clause's `notes`, and the library's other words for every movement or posture among them.
pub(super) fn made_words(
    made: &[Segment],
    held: impl Iterator<Item = String>,
    notes: &[String],
) -> Vec<String> {
    let mut out: Vec<String> = notes.to_vec();
    for s in made {
        out.push(s.base.clone());
        out.extend(
            BodyPart::ALL
                .iter()
                .filter_map(|p| s.parts.get(*p).map(str::to_string)),
        );
        if let Some(track) = &s.postures {
            out.extend(track.keys.iter().filter_map(|k| k.script.name.clone()));
        }
    }
    out.extend(held);
    let library = crate::posture::library::Library::builtin();
    let synonyms: Vec<String> = out
        .iter()
        .flat_map(|t| library.mentions(t))
        .flat_map(|(_, named)| named.phrases())
        .collect();
    out.extend(synonyms);
    out
}

/// The phrases riding on a clause that left no trace in what the planner made of it (`made`:
/// the segments' base texts, part instructions and key-pose names, and the clause's notes):
/// the clause cut at its boundaries and openers, and where a limb noun follows another one
/// ("on the right foot, arms flapping like wings"); the first phrase is the one the clause's
/// movement came from, so only the others are read. A phrase with words about the movement
/// ([`is_movement_content`]) none of which, nor of its limbs ("touches the right **knee**"),
/// shares a stem with a word of `made` is one. The rules make most phrases into something or
/// name them; this names the rest, so nothing a person asked for disappears without a word.
pub(super) fn phrases_without_trace(words: &[&str], made: &[String]) -> Vec<String> {
    let made_stems: Vec<&str> = made
        .iter()
        .flat_map(|t| t.split(|c: char| !c.is_alphanumeric()))
        .filter(|w| !w.is_empty())
        .map(stem)
        .collect();
    let mut phrases: Vec<Vec<&str>> = vec![Vec::new()];
    for (i, w) in words.iter().enumerate() {
        let after_limb = i > 0 && limb(words[i - 1]).is_some() && limb(w).is_some();
        if BOUNDARIES.contains(w) {
            phrases.push(Vec::new());
            continue;
        }
        if OPENERS.contains(w) || after_limb {
            phrases.push(Vec::new());
        }
        phrases.last_mut().expect("one phrase at least").push(w);
    }
    phrases
        .into_iter()
        .skip_while(Vec::is_empty)
        .skip(1)
        .filter(|phrase| {
            phrase.iter().any(|w| is_movement_content(w))
                && !phrase
                    .iter()
                    .filter(|w| is_movement_content(w) || limb(w).is_some())
                    .any(|w| made_stems.contains(&stem(w)))
        })
        .map(|phrase| phrase.join(" "))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(text: &str) -> Vec<&str> {
        text.split(' ').collect()
    }

    #[test]
    fn a_limb_phrase_without_a_movement_is_found_and_an_instrument_is_not() {
        let w = words("he spins while having his right arm upwards");
        assert_eq!(
            limb_phrases_without_movement(&w, &[1]),
            [("having his right arm upwards".to_string(), "arm")]
        );
        let w = words("a person kicks with the right leg");
        assert!(limb_phrases_without_movement(&w, &[2]).is_empty());
        // A movement found inside the phrase places it.
        let w = words("a person walks with both arms raised");
        assert!(limb_phrases_without_movement(&w, &[2, 6]).is_empty());
        let w = words("she marches in place swinging both arms high");
        assert_eq!(
            limb_phrases_without_movement(&w, &[1]),
            [("in place swinging both arms high".to_string(), "arm")]
        );
        let w = words("the child hops , arms flapping like wings");
        assert_eq!(
            limb_phrases_without_movement(&w, &[2]),
            [("arms flapping like wings".to_string(), "arm")]
        );
    }

    #[test]
    fn a_limb_nothing_moves_on_a_standing_segment_is_found() {
        let stand = Segment {
            text: "a person stands still".into(),
            seconds: 2.0,
            base: "a person stands still".into(),
            parts: Default::default(),
            trajectory: None,
            postures: None,
        };
        let w = words("a man stands still with his arms folded tapping his right foot");
        let found = limbs_left_unplaced(&w, std::slice::from_ref(&stand), &[], &[]);
        assert_eq!(found, [("tapping his right foot".to_string(), "leg")]);
        // Held, or named in a note already, or on a segment that moves: accounted for.
        assert!(
            limbs_left_unplaced(&w, std::slice::from_ref(&stand), &[BodyPart::RightLeg], &[])
                .is_empty()
        );
        let noted = ["\"tapping his right foot\" was left out".to_string()];
        assert!(limbs_left_unplaced(&w, std::slice::from_ref(&stand), &[], &noted).is_empty());
        let kick = Segment {
            base: "a person kicks with the right leg".into(),
            ..stand
        };
        assert!(limbs_left_unplaced(&w, &[kick], &[], &[]).is_empty());
    }

    #[test]
    fn a_phrase_that_left_no_trace_is_found_and_one_that_did_is_not() {
        let clause = words("the child hops forward on the right foot arms flapping like wings");
        let made = ["hopping on the right foot".to_string()];
        assert_eq!(
            phrases_without_trace(&clause, &made),
            ["arms flapping like wings"]
        );
        // A raise read from "raised", a walk from "strolls forward": forms of the same words.
        let clause = words("a man strolls forward with arms raised");
        let made = [
            "a person walks forward".to_string(),
            "a person raises both arms".to_string(),
        ];
        assert!(phrases_without_trace(&clause, &made).is_empty());
        for (a, b) in [
            ("hops", "hopping"),
            ("raised", "raise"),
            ("dances", "dancing"),
        ] {
            assert_eq!(stem(a), stem(b), "{a} / {b}");
        }
        // A hand put on a knee: the knee is in what was made.
        let clause = words("a person touches the right knee with the left hand");
        assert!(phrases_without_trace(&clause, &["left hand on the right knee".into()]).is_empty());
        // Anaphora and counts are read by their own rules.
        assert!(phrases_without_trace(&words("does it again twice"), &[]).is_empty());
    }

    #[test]
    fn sequence_words_put_the_second_movement_after_the_first() {
        let w = words("a woman picks up speed from a walk to a run");
        assert!(in_sequence(&w, 7, 10));
        let w = words("a person dances while walking");
        assert!(!in_sequence(&w, 2, 4));
        assert_eq!(phrase_from(&w, 4), "walking");
        assert_eq!(phrase_from(&words("to a run , holding"), 0), "to a run");
    }
}
