//! Cutting a prompt into clauses: at sentence ends, temporal connectives ("then", "after
//! that", "before", "while") and "and" between verbs, each clause put in the order it happens
//! ("before Y, X" is Y then X); a walk and a gesture joined by "and" stay one clause, and what
//! rides after a comma ("…, holding the T-pose") stays with the clause before.

use super::super::lexicon::{self, Repertoire};
use super::super::postures;
use super::{accounting, anaphora, context, movements, Reader};

/// How a clause starts: a marker that changes its order or merges it with the next one.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Marker {
    None,
    /// "before ...": happens after the clause it is attached to, when it leads the sentence.
    Before,
    /// "after ...": happens before the clause it follows.
    After,
    /// "while ...": at the same time as the next clause.
    While,
}

/// A clause and how it joins the one before.
struct Chunk {
    words: Vec<String>,
    marker: Marker,
    /// Split at "and" with no other connective: undone when the clauses are a walk and a
    /// gesture ("walks forward and waves"), which happen together.
    soft: bool,
}

/// Words and punctuation of the prompt, lower case; hyphens and apostrophes split words.
pub(super) fn tokens(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut word = String::new();
    let chars: Vec<char> = text.chars().collect();
    for (i, &c) in chars.iter().enumerate() {
        let decimal_point = c == '.'
            && i > 0
            && chars[i - 1].is_ascii_digit()
            && chars.get(i + 1).is_some_and(|n| n.is_ascii_digit());
        if c.is_alphanumeric() || decimal_point {
            word.push(c);
            continue;
        }
        if !word.is_empty() {
            out.push(std::mem::take(&mut word));
        }
        match c {
            ',' | ':' => out.push(",".into()),
            '.' | ';' | '!' | '?' | '\n' => out.push(".".into()),
            _ => {}
        }
    }
    if !word.is_empty() {
        out.push(word);
    }
    out
}

/// True when the words start a new verb phrase, after an optional subject.
fn starts_verb(words: &[String], known: Repertoire) -> bool {
    let mut i = 0;
    // Determiners take a noun, and the noun an adjective or two: "the old man bows".
    while i < words.len() && i < 4 {
        let w = words[i].as_str();
        let next: Vec<&str> = words[i + 1..].iter().take(3).map(String::as_str).collect();
        let dataset_verb = known.knows_any() && lexicon::is_dataset_verb(w);
        if (lexicon::is_finite_verb(w) || postures::is_posture_verb(w) || dataset_verb)
            && !(w == "turn" && next.first() == Some(&"to"))
        {
            // "left" after "turn" is part of the verb; a bare side word is not a verb.
            return action_or_other(w, &next);
        }
        if unknown_verb(w, next.first().copied()) {
            return true;
        }
        if !lexicon::is_subject_word(w) && i > 0 && !lexicon::is_subject_word(&words[i - 1]) {
            return false;
        }
        i += 1;
    }
    false
}

/// A word that is a verb wherever it stands ("turns" in "turns his head").
fn is_verb(word: &str, known: Repertoire) -> bool {
    lexicon::is_finite_verb(word)
        || postures::is_posture_verb(word)
        || (known.knows_any() && lexicon::is_dataset_verb(word))
}

/// After a comma, a verb the lists do not hold followed by its object's determiner ("…, ties
/// her right shoe", "…, grabs the rail"): a clause of its own. After "and" the same words
/// more often finish the clause before ("dribbles and shoots a basketball").
fn verb_with_object(words: &[String]) -> bool {
    let determiner = |w: &str| matches!(w, "his" | "her" | "their" | "its" | "the" | "a" | "an");
    match words {
        [verb, next, ..] if determiner(next) => verb_form(verb),
        // "…, drinks from the cup", "…, leans on the wall".
        [verb, preposition, next, ..] => {
            matches!(
                preposition.as_str(),
                "from" | "at" | "on" | "with" | "into" | "onto" | "through" | "over"
            ) && determiner(next)
                && verb_form(verb)
        }
        _ => false,
    }
}

/// A word that may be a verb by its form: in "-s", not a limb, a person or a word the
/// prompts use as a plural noun.
fn verb_form(word: &str) -> bool {
    word.len() > 3
        && word.ends_with('s')
        && !word.ends_with("ss")
        && accounting::limb(word).is_none()
        && !matches!(word, "shoulders" | "hips" | "eyes" | "heads" | "others")
        && !lexicon::is_subject_noun(word)
        && !lexicon::is_subject_word(word)
}

/// A verb the lists do not hold, read from its form: a word in "-s" followed by a particle
/// of direction ("ducks down", "scoots back", "drops to one knee"). Limbs and people in "-s"
/// ("arms up", "the twins forward") are nouns.
fn unknown_verb(word: &str, next: Option<&str>) -> bool {
    const PARTICLES: &[&str] = &[
        "down",
        "up",
        "back",
        "forward",
        "forwards",
        "backward",
        "backwards",
        "away",
        "off",
        "over",
        "sideways",
        "aside",
        "around",
        "out",
        "onto",
        "into",
        "to",
    ];
    next.is_some_and(|n| PARTICLES.contains(&n)) && verb_form(word)
}

/// True when the words up to the next comma or "and" only point back at the movement before
/// ("… and one with the right", "…, then the other hand") or name it again on one side ("…, a
/// right hook"): a clause of their own, made from the one before.
fn points_back(words: &[String]) -> bool {
    let end = words
        .iter()
        .position(|w| matches!(w.as_str(), "," | "and" | "then"))
        .unwrap_or(words.len());
    let chunk: Vec<&str> = words[..end].iter().map(String::as_str).collect();
    let sided_noun = matches!(
        chunk.as_slice(),
        ["a" | "an" | "one", "left" | "right", _, ..]
    );
    !chunk.is_empty() && (anaphora::again(&chunk).is_some() || sided_noun)
}

fn action_or_other(word: &str, next: &[&str]) -> bool {
    match word {
        // "turns left", "turns around": a turn of the body ("takes turns" is none).
        "turn" | "turns" => matches!(
            next.first(),
            Some(
                &("left"
                    | "right"
                    | "around"
                    | "round"
                    | "back"
                    | "to"
                    | "in"
                    | "toward"
                    | "towards"
                    | "sideways"
                    | "away")
            )
        ),
        _ => true,
    }
}

/// Cuts the prompt into clauses in time order.
pub(super) fn clauses(text: &str, known: Repertoire) -> Vec<Vec<String>> {
    let tokens = tokens(text);
    let mut out = Vec::new();
    for sentence in tokens.split(|t| t == ".") {
        out.extend(sentence_clauses(sentence, known));
    }
    with_gaps_filled(out, known)
}

/// Words that open a clause that says only where the movement before goes next ("walks to
/// the left, **then to the right**", "jumps forward, then backward").
const WAYS: &[&str] = &[
    "to",
    "toward",
    "towards",
    "forward",
    "forwards",
    "backward",
    "backwards",
    "back",
    "sideways",
    "left",
    "right",
];

/// Clauses that leave out their verb take the one before's ("turns his head to the left,
/// then to the right" is "turns his head to the right"): the words of the clause before from
/// its verb up to where its own way begins go in front.
fn with_gaps_filled(clauses: Vec<Vec<String>>, known: Repertoire) -> Vec<Vec<String>> {
    let mut out: Vec<Vec<String>> = Vec::with_capacity(clauses.len());
    for clause in clauses {
        // Up to what rides on it ("then to the right **with the left hand on the head**").
        let own = clause
            .iter()
            .take_while(|w| {
                !matches!(
                    w.as_str(),
                    "with" | "holding" | "keeping" | "while" | "and" | ","
                )
            })
            .count();
        // "hops on the right foot, then on the left foot": a side given by "on".
        let on_a_side = clause.first().is_some_and(|w| w == "on")
            && clause
                .iter()
                .take(3)
                .any(|w| crate::skeleton::Side::of_word(w).is_some());
        let opener = clause.first().map(String::as_str).unwrap_or("");
        let gapped = (WAYS.contains(&opener) || on_a_side)
            && !clause[..own].iter().any(|w| is_verb(w, known));
        let head = out.last().filter(|_| gapped).and_then(|before| {
            let verb = before.iter().position(|w| is_verb(w, known))?;
            let way = (verb + 1..before.len())
                .find(|&i| {
                    WAYS.contains(&before[i].as_str()) || before[i] == "," || before[i] == opener
                })
                .unwrap_or(before.len());
            Some(before[verb..way].to_vec())
        });
        match head {
            Some(mut head) => {
                head.extend(clause);
                out.push(head);
            }
            None => out.push(clause),
        }
    }
    out
}

/// How many words after "after" say only a pause ("a moment", "a while", "a few seconds",
/// "some time"); 0 when they name an event ("after the jump").
fn pause_after(rest: &[String]) -> usize {
    let word = |k: usize| rest.get(k).map(String::as_str).unwrap_or("");
    const PAUSES: &[&str] = &[
        "moment", "while", "pause", "second", "seconds", "beat", "bit", "moments", "time",
    ];
    match (word(0), word(1), word(2)) {
        ("a", "few", w) if PAUSES.contains(&w) => 3,
        ("a" | "some", w, _) if PAUSES.contains(&w) => 2,
        _ => 0,
    }
}

fn sentence_clauses(sentence: &[String], known: Repertoire) -> Vec<Vec<String>> {
    let mut chunks: Vec<Chunk> = vec![Chunk {
        words: Vec::new(),
        marker: Marker::None,
        soft: false,
    }];
    let mut i = 0;
    let word = |k: usize| sentence.get(k).map(String::as_str).unwrap_or("");
    let new_chunk = |chunks: &mut Vec<Chunk>, marker: Marker, soft: bool| {
        if chunks.last().is_some_and(|c| c.words.is_empty()) {
            let last = chunks.last_mut().unwrap();
            if last.marker == Marker::None {
                last.marker = marker;
            }
            last.soft &= soft;
        } else {
            chunks.push(Chunk {
                words: Vec::new(),
                marker,
                soft,
            });
        }
    };
    while i < sentence.len() {
        let w = word(i);
        let rest = &sentence[i + 1..];
        match w {
            "," => {
                let after = rest
                    .iter()
                    .position(|t| !matches!(t.as_str(), "and" | "then" | "finally" | ","))
                    .unwrap_or(rest.len());
                let connective = rest[..after].iter().any(|t| t == "then" || t == "finally");
                // "In the rain, a woman hurries …": a sentence that opens with context ends it
                // at its first comma, whatever the verb after it.
                let opening: Vec<&str> = sentence[..i].iter().map(String::as_str).collect();
                let opening = chunks.len() == 1 && context::opens_context(&opening);
                // "…, holding the T-pose": what the body keeps doing rides on the clause.
                let rider =
                    !connective && rest.first().is_some_and(|w| RIDERS.contains(&w.as_str()));
                if rider {
                    i += 1;
                    continue;
                }
                if connective
                    || opening
                    || starts_verb(&rest[after..], known)
                    || verb_with_object(&rest[after..])
                    || starts_connective(rest)
                    || points_back(&rest[after..])
                {
                    new_chunk(&mut chunks, Marker::None, false);
                }
                i += 1;
                continue;
            }
            "then" | "finally" | "afterwards" | "afterward" | "later" | "eventually" => {
                new_chunk(&mut chunks, Marker::None, false);
                i += 1;
                continue;
            }
            "next" if starts_verb(rest, known) || rest.first().is_some_and(|t| t == ",") => {
                new_chunk(&mut chunks, Marker::None, false);
                i += 1;
                continue;
            }
            "and" => {
                let skip = rest
                    .iter()
                    .take_while(|t| matches!(t.as_str(), "then" | "finally"))
                    .count();
                if skip > 0 {
                    new_chunk(&mut chunks, Marker::None, false);
                } else if starts_verb(rest, known) {
                    new_chunk(&mut chunks, Marker::None, true);
                } else if points_back(rest) {
                    new_chunk(&mut chunks, Marker::None, false);
                } else {
                    chunks.last_mut().unwrap().words.push(w.to_string());
                }
                i += 1;
                continue;
            }
            // "and after a moment puts it back down": a pause, then what follows.
            "after" if pause_after(rest) > 0 => {
                new_chunk(&mut chunks, Marker::None, false);
                i += 1 + pause_after(rest);
                continue;
            }
            "after" if word(i + 1) == "that" || word(i + 1) == "this" => {
                new_chunk(&mut chunks, Marker::None, false);
                i += 2;
                continue;
            }
            "followed" if word(i + 1) == "by" => {
                new_chunk(&mut chunks, Marker::None, false);
                i += 2;
                continue;
            }
            "before" => {
                new_chunk(&mut chunks, Marker::Before, false);
                i += 1;
                continue;
            }
            "after" => {
                new_chunk(&mut chunks, Marker::After, false);
                i += 1;
                continue;
            }
            "while" | "whilst" if chunks.last().is_some_and(|c| c.words.is_empty()) => {
                chunks.last_mut().unwrap().marker = Marker::While;
                i += 1;
                continue;
            }
            "first" | "firstly" | "initially" => {
                i += 1;
                continue;
            }
            _ => {}
        }
        chunks.last_mut().unwrap().words.push(w.to_string());
        i += 1;
    }
    chunks.retain(|c| !c.words.is_empty());
    order(chunks, known)
}

/// Words that open a phrase of what the body keeps doing during a clause ("…, holding the
/// T-pose", "…, with both arms raised"): after a comma they ride on the clause before.
const RIDERS: &[&str] = &["holding", "keeping", "with"];

fn starts_connective(rest: &[String]) -> bool {
    matches!(
        rest.first().map(String::as_str),
        Some("before" | "after" | "afterwards" | "later" | "next")
    )
}

/// Puts "before" and "after" clauses in time order, joins "while" clauses and the soft "and"
/// splits that are one movement.
fn order(chunks: Vec<Chunk>, known: Repertoire) -> Vec<Vec<String>> {
    let mut out: Vec<Chunk> = Vec::new();
    let mut pending_before: Option<Chunk> = None;
    let mut pending_while: Option<Chunk> = None;
    for (k, mut chunk) in chunks.into_iter().enumerate() {
        if let Some(w) = pending_while.take() {
            let mut words = w.words;
            words.append(&mut chunk.words);
            chunk.words = words;
        }
        match chunk.marker {
            Marker::While => {
                pending_while = Some(chunk);
                continue;
            }
            Marker::Before if k == 0 => {
                pending_before = Some(chunk);
                continue;
            }
            Marker::After if !out.is_empty() => {
                let last = out.len() - 1;
                out.insert(last, chunk);
                continue;
            }
            _ => {}
        }
        if chunk.soft {
            if let Some(last) = out.last_mut() {
                if soft_join(&last.words, &chunk.words, known) {
                    last.words.push("and".into());
                    last.words.append(&mut chunk.words);
                    continue;
                }
            }
        }
        out.push(chunk);
        if let Some(b) = pending_before.take() {
            out.push(b);
        }
    }
    out.extend(pending_while);
    out.extend(pending_before);
    out.into_iter().map(|c| c.words).collect()
}

/// "walks forward and waves the left hand" is one movement: a walk carrying a gesture.
fn soft_join(left: &[String], right: &[String], known: Repertoire) -> bool {
    let l: Vec<&str> = left.iter().map(String::as_str).collect();
    let r: Vec<&str> = right.iter().map(String::as_str).collect();
    let reader = Reader::alone(known);
    let Some(b) = movements(&r, None, reader) else {
        return false;
    };
    let gesture = b.base.is_gesture() && b.gestures.is_empty();
    // A gesture rides on a walk, or on a posture the model does not know ("kneels and raises
    // the right hand").
    let carries = movements(&l, None, reader).is_some_and(|a| a.base.is_locomotion())
        || postures::names_posture(&l);
    gesture && carries
}
