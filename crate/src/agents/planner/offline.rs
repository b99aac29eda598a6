//! The built-in planner: deterministic rules over the prompt's words, no LLM.
//!
//! 1. The prompt is cut into clauses at sentence ends and temporal connectives ("then",
//!    "after that", "finally", "before", "after", a comma or "and" that starts a new verb);
//!    "while" joins two clauses into one, and so does a comma before "holding", "keeping" or
//!    "with" (what the body keeps doing rides on the clause). "Before Y, X" and "X after Y"
//!    are put in time order (the `clauses` module). Context that is no movement (where, when,
//!    why, what the person feels) is dropped with a note (the `context` module).
//! 2. Each clause gets its movements from [`lexicon`]: one whole-body or walking motion as the
//!    base, and arm gestures beside it as part edits ("walks forward waving the left hand").
//!    A clause with no verb inherits the previous clause's gesture ("then the left hand"); a
//!    clause that lowers "it" brings down the arms raised before (the `anaphora` module).
//! 3. Repetitions ("twice") repeat the clause; durations come from "for N seconds", the
//!    action's usual length and tempo words; paths ("in a circle clockwise") from the
//!    trajectory shape library; style words ("angry", "elderly") become the caption phrases
//!    the data uses.
//! 4. A clause with no known movement is mapped, when an embedder is given, onto the training
//!    action or the library posture that means the same movement ([`meaning`]: calibrated
//!    threshold, same side, never the opposite direction; the `substitutes` module), and an
//!    arm phrase onto the gesture or arm posture it means (the `limbs` module); otherwise it
//!    is named in a note.
//! 5. Whatever a clause names that no segment makes is named in a note with the reason
//!    (the `accounting` module): no clause disappears silently. A plan lasts up to
//!    [`MAX_PLAN_SECONDS`]; clauses past it are named in a note.
//! 6. A posture or part instruction that runs over several consecutive segments becomes one
//!    clip on the body-part tracks (the `tracks` module).
//!
//! The actions of dataset v2 (squat, jump, lie down, kicks, throw, …) are planned as the
//! model's own motion only when the model's vocabulary lists them ([`plan_for`]); otherwise,
//! and for poses held ("holds a deep squat"), the posture library makes what it can of them.

use super::lexicon::{self, Action, Direction, Repertoire, Side};
use super::meaning::{self, Matcher};
use super::postures;
use crate::dataset::Vocabulary;
use crate::plan::{
    clamp_seconds, in_time_order, PartEdits, Plan, PlannerKind, Segment, MAX_PLAN_SECONDS,
    MAX_SEGMENTS, MAX_TEXT_CHARS,
};
use crate::posture::library::{Library, NamedPosture};
use crate::posture::track::{PostureTrack, DEFAULT_TRANSITION_SECONDS};
use crate::skeleton::BodyPart;
use crate::trajectory::{Shape, Trajectory};

mod accounting;
mod anaphora;
mod clauses;
mod context;
mod limb_poses;
mod limbs;
mod substitutes;
mod torso_poses;
mod tracks;

use clauses::{clauses, tokens};
use context::without_context;
use substitutes::{nearest_action, nearest_library_entry};

/// Turns a sentence into a unit embedding (MiniLM); the planner uses it to map movements it
/// has no rule for onto the nearest action of the training data.
pub type Embedder<'a> = &'a dyn Fn(&str) -> Vec<f32>;

/// How a note says a clause was planned as a different movement than it asks for.
pub const SUBSTITUTED: &str = "is not a movement the model knows";
/// How a note says a clause was left out of the plan.
pub const LEFT_OUT: &str = "names no movement the model makes; left out";
/// How a note says no rule read a clause at all (a gap in the rules, never expected: the
/// prompt sets' test fails on it).
pub const UNREAD: &str = "was read by no rule of the built-in planner; left out";
/// How a note says a clause was made as a movement the model knows that says it in other
/// words, not plainly the same ("sidesteps to the right" as "a person walks to the right").
pub const MADE_AS: &str = "is made as the nearest movement the model knows";
/// How a note says a part of a clause was left out of the plan (the reason follows).
pub const NOT_PLACED: &str = "was left out of the plan";

/// Whether a plan note says a clause went unplanned: planned as a different movement (the
/// nearest one the model knows) or left out.
pub fn is_unplanned_note(note: &str) -> bool {
    [SUBSTITUTED, LEFT_OUT, NOT_PLACED, UNREAD]
        .iter()
        .any(|said| note.contains(said))
}

/// Longest prompt read, in characters; the rest is ignored with a note.
pub const MAX_PROMPT_CHARS: usize = 2000;

/// Plans `prompt` with the built-in rules for a model that knows the Bandai Namco actions
/// only (as [`plan_for`] with no vocabulary).
pub fn plan(prompt: &str, embed: Option<Embedder>) -> Plan {
    plan_for(prompt, None, embed)
}

/// Plans `prompt` with the built-in rules for the model whose training vocabulary is
/// `vocabulary`: the actions of dataset v2 it lists are made by the model. `embed` (optional)
/// maps unknown movements onto the training actions. Always returns a plan of 1 to
/// [`MAX_SEGMENTS`] segments, [`MAX_PLAN_SECONDS`] at most.
pub fn plan_for(prompt: &str, vocabulary: Option<&Vocabulary>, embed: Option<Embedder>) -> Plan {
    let known = Repertoire::new(vocabulary);
    // One judgement of "the same movement" for the whole prompt, each text embedded once.
    let similarity = embed.map(meaning::embedding_similarity);
    let matcher = similarity
        .as_ref()
        .map(|s| Matcher::new(s, meaning::SAME_MOVEMENT_MIN_SIMILARITY));
    let mut notes = Vec::new();
    let mut text: String = prompt.chars().take(MAX_PROMPT_CHARS).collect();
    if prompt.chars().count() > MAX_PROMPT_CHARS {
        notes.push(format!(
            "the prompt is longer than {MAX_PROMPT_CHARS} characters; the rest was not read"
        ));
    }
    text = text.to_lowercase();
    let style = prompt_style(&text);
    let mut segments: Vec<Segment> = Vec::new();
    let mut previous: Option<Action> = None;
    // The dataset v2 action the last segment made, whose clip ends standing again.
    let mut ends_standing: Option<Action> = None;
    let clauses = clauses(&text, known);
    let clauses = without_context(&clauses, known, &mut notes);
    let readers: Vec<Reader> = (0..clauses.len())
        .map(|k| Reader {
            known,
            pose_kept: clauses
                .get(k + 1)
                .is_some_and(|next| postures::keeps_pose_before(next)),
        })
        .collect();
    // The clause each segment came from.
    let mut clause_of: Vec<usize> = Vec::new();
    // Limb poses read from the words, held over a clause's segments (their indices).
    let mut held: Vec<(std::ops::Range<usize>, NamedPosture)> = Vec::new();
    // The places (indices into `held`) a clause of their own put limbs in, which stay over
    // the next clause if it leaves those limbs alone.
    let mut lasting: Vec<usize> = Vec::new();
    for (k, words) in clauses.iter().enumerate() {
        let words = with_subject_whole(words, readers[k]);
        let words = words.as_slice();
        let reader = readers[k];
        let clause_start = segments.len();
        let notes_start = notes.len();
        let mut lasting_now: Vec<usize> = Vec::new();
        'clause: {
            let only_stands_up =
                || postures::stands_up(words) && movements(words, None, reader).is_none();
            if let Some(action) = ends_standing.filter(|_| only_stands_up()) {
                // "squats down and stands back up": the squat's clips stand back up already.
                notes.push(format!(
                    "\"{}\" is made by the movement before: \"{}\" ends standing",
                    words.join(" "),
                    action.verb_phrase()
                ));
                break 'clause;
            }
            if let Some(across) = segments
                .last()
                .filter(|_| anaphora::goes_back(words))
                .and_then(anaphora::back_across)
            {
                // "steps to the left, then back to the centre": the way back is to the right.
                notes.push(format!(
                    "\"{}\": back the way the movement before went, to the other side",
                    words.join(" ")
                ));
                segments.push(across);
                previous = None;
                ends_standing = None;
                break 'clause;
            }
            let model = movements(words, previous, reader);
            let next_dataset_action = clauses
                .get(k + 1)
                .and_then(|next| movements(next, None, readers[k + 1]))
                .map(|m| m.base)
                .filter(|a| a.label().is_some());
            if let Some(next) = next_dataset_action
                .filter(|next| model.is_none() && postures::leads_into(words, *next))
            {
                // "kneels and then lies down": the model's lying down kneels on the way.
                notes.push(format!(
                    "\"{}\" is made by the movement after: \"{}\" passes through it",
                    words.join(" "),
                    next.verb_phrase()
                ));
                break 'clause;
            }
            let model_segment = || match &model {
                Some(found) => segment(words, found, style.as_deref()),
                None => segment(
                    words,
                    &Movements::only(Action::Walk(Direction::Forward)),
                    style.as_deref(),
                ),
            };
            // "steps forward with the left foot", "leans to the left": key poses of the
            // whole body the rules write themselves.
            let own_track = super::sided::single_step(words).or_else(|| {
                model
                    .is_none()
                    .then(|| torso_poses::torso_pose(words))
                    .flatten()
                    .map(|pose| PostureTrack::holding(pose.parts, pose.script))
            });
            if let Some(track) = own_track {
                let text = format!("a person {}", lexicon::without_subject(words).join(" "));
                segments.push(standing_segment(text, Some(track)));
                previous = None;
                ends_standing = None;
                // "sidesteps to the right with both arms crossed": what rides on the step.
                // The foot a step names is the step's own ("steps to the left with the left
                // foot").
                let named: Vec<usize> = super::sided::leg_words(words).collect();
                let made = &mut segments[clause_start..];
                let poses = place_limb_phrases(words, &named, matcher.as_ref(), made, &mut notes);
                let span = clause_start..segments.len();
                held.extend(poses.into_iter().map(|p| (span.clone(), p)));
                break 'clause;
            }
            if let Some(held) = segments
                .last()
                .filter(|last| postures::holds_by_name(words, last))
                .and_then(|last| postures::hold_segment(words, last))
            {
                segments.push(held);
                break 'clause;
            }
            let model_parts = model.as_ref().map(|m| (m.base, m.gestures.as_slice()));
            if let Some(planned) = postures::plan_clause(words, model_parts, &model_segment) {
                notes.extend(planned.notes);
                postures::land_in(words, segments.last_mut(), &planned.segment);
                previous = None;
                ends_standing = None;
                // A dataset action with a posture held on its arms is still the model's movement,
                // counted as one ("does two squats in a T-pose").
                let times = match &model {
                    Some(found) if planned.over_model && found.base.label().is_some() => {
                        ends_standing = Some(found.base).filter(|a| *a != Action::LieDown);
                        repetitions(words, found, &mut notes)
                    }
                    _ => 1,
                };
                for _ in 0..times {
                    segments.push(planned.segment.clone());
                }
                if let Some(found) = model.as_ref().filter(|_| planned.over_model) {
                    // "from a walk to a run, holding the T-pose": the run holds it too.
                    let held = model_segment();
                    for (_, mut next) in moves_on(words, found, style.as_deref(), &mut notes) {
                        next.text = planned.segment.text.replacen(&held.text, &next.text, 1);
                        next.postures = planned.segment.postures.clone();
                        next.parts = planned.segment.parts.clone();
                        segments.push(next);
                    }
                }
                // A clause that moves on ("from a walk to a run") is said by all its segments,
                // not by the first.
                let moved_on = model
                    .as_ref()
                    .is_some_and(|m| moves_on_in_sequence(words, m));
                if planned.over_model && !moved_on {
                    notes.extend(said_otherwise(words, &model_segment(), matcher.as_ref()));
                }
                let made = &mut segments[clause_start..];
                let poses =
                    place_limb_phrases(words, &planned.named, matcher.as_ref(), made, &mut notes);
                let span = clause_start..segments.len();
                held.extend(poses.into_iter().map(|p| (span.clone(), p)));
                break 'clause;
            }
            if let Some((stance, poses)) = model.is_none().then(|| standing_poses(words)).flatten()
            {
                // "stands on the left leg while stretching the right leg out behind her". After
                // a pose of the whole body ("drops to one knee, spreads both arms wide") the
                // body stays in that pose.
                let kept = segments
                    .last()
                    .filter(|_| stance.postures.is_none())
                    .filter(|last| last.postures.as_ref().is_some_and(|t| t.whole_body()))
                    .and_then(|last| postures::hold_segment(words, last))
                    .map(|mut kept| {
                        for key in kept.postures.iter_mut().flat_map(|t| t.keys.iter_mut()) {
                            key.script.name = key.script.name.as_deref().map(anaphora::held_name);
                        }
                        kept
                    });
                segments.push(kept.unwrap_or(stance));
                let span = clause_start..segments.len();
                lasting_now.extend(held.len()..held.len() + poses.len());
                held.extend(poses.into_iter().map(|p| (span.clone(), p)));
                previous = None;
                ends_standing = None;
                break 'clause;
            }
            // "lifts the right knee, holds it": the places the clause before reached, kept
            // over a clip of their own; "raises both hands, holds them up": the arms up.
            if let Some(poses) = model
                .is_none()
                .then(|| anaphora::holds_back(words))
                .filter(|holds| *holds)
                .and_then(|_| kept_places(&held, clause_start, segments.last()))
            {
                let names: Vec<&str> = poses.iter().map(|p| p.name.as_str()).collect();
                let text = format!("a person holds still, {}", names.join(", "));
                let body = segments
                    .last()
                    .filter(|last| last.postures.as_ref().is_some_and(|t| t.whole_body()))
                    .and_then(|last| postures::hold_segment(words, last))
                    .unwrap_or_else(|| standing_segment(text, None));
                segments.push(body);
                let span = clause_start..segments.len();
                held.extend(poses.into_iter().map(|mut p| {
                    p.name = anaphora::held_name(&p.name);
                    p.script.name = Some(p.name.clone());
                    (span.clone(), p)
                }));
                previous = None;
                break 'clause;
            }
            if let (None, Some(stay)) = (&model, postures::stay(words)) {
                let held = match (stay, segments.last()) {
                    (postures::Stay::Hold, Some(last)) => postures::hold_segment(words, last),
                    _ => None,
                };
                let said = words.join(" ");
                match (held, segments.last_mut()) {
                    (Some(held), _) => segments.push(held),
                    (None, Some(last)) if stay != postures::Stay::Passing => {
                        // Staying as one is: the movement before lasts longer.
                        last.seconds = clamp_seconds(last.seconds + postures::HOLD_EXTRA_SECONDS)
                            .unwrap_or(last.seconds);
                        notes.push(format!("\"{said}\": the movement before lasts longer"));
                    }
                    (None, _) if stay == postures::Stay::Passing => notes.push(format!(
                        "\"{said}\" happens on the way from one movement to the next; no \
                         movement of its own"
                    )),
                    (None, _) => notes.push(format!(
                        "\"{said}\" {NOT_PLACED}: there is no movement before it to last longer"
                    )),
                }
                break 'clause;
            }
            // "stretches her left arm to the side, and then the right one": the places held
            // over the clause before, on the side asked, over its movement once more.
            let held_before = held
                .last()
                .map(|(span, _)| span.clone())
                .filter(|span| span.end == clause_start && !span.is_empty());
            if let Some((span, poses)) = model
                .is_none()
                .then(|| anaphora::again(words))
                .flatten()
                .zip(held_before)
                .and_then(|(a, span)| {
                    let poses: Vec<NamedPosture> = held
                        .iter()
                        .filter(|(s, _)| *s == span)
                        .map(|(_, p)| p.clone())
                        .collect();
                    Some((span, anaphora::repeated_poses(&poses, a)?))
                })
            {
                segments.extend(segments[span].to_vec());
                let again = clause_start..segments.len();
                held.extend(poses.into_iter().map(|p| (again.clone(), p)));
                break 'clause;
            }
            if let Some(once_more) = model
                .is_none()
                .then(|| anaphora::again(words))
                .flatten()
                .and_then(|a| {
                    let last = segments.iter().rposition(|s| !anaphora::is_lowering(s))?;
                    let one = anaphora::repeated(&segments[last], a)?;
                    // "sits down, then gets up and does the same thing again": getting up
                    // ends what is done again, so the movement before it comes back too.
                    Some(match last.checked_sub(1) {
                        Some(before) if a == anaphora::Again::Same && gets_up(&segments[last]) => {
                            vec![segments[before].clone(), one]
                        }
                        _ => vec![one],
                    })
                })
            {
                // "waves with the left hand, then with the right"; "repeats it twice more".
                for _ in 0..lexicon::repetitions(words) {
                    segments.extend(once_more.iter().cloned());
                }
                break 'clause;
            }
            // After a raise, "puts it back down" lowers the arm; after anything else (picking
            // a box up) it is the model's putting down.
            let after_raise = segments.last().is_some_and(|s| {
                let said_raise = s
                    .text
                    .split(' ')
                    .any(|w| matches!(w, "raise" | "raises" | "lift" | "lifts"));
                said_raise && !anaphora::raised_arms(s).is_empty()
            });
            // "lifts the right knee, holds it, and then puts it down": the limbs held just
            // before.
            let held_before: Vec<BodyPart> = held
                .iter()
                .filter(|(span, _)| span.end == clause_start && !span.is_empty())
                .flat_map(|(_, p)| p.parts.clone())
                .collect();
            if let Some(lowered) = (model.is_none() || after_raise || !held_before.is_empty())
                .then(|| lowered_back(words, segments.last(), &held_before))
                .flatten()
            {
                segments.push(lowered);
                previous = None;
                break 'clause;
            }
            let action = model
                .is_none()
                .then(|| nearest_action(words, matcher.as_ref(), known));
            if let Some((name, similarity)) = model
                .is_none()
                .then(|| nearest_library_entry(words, matcher.as_ref()))
                .flatten()
                .filter(|(_, s)| action.flatten().is_none_or(|(_, a)| *s > a))
            {
                // "sits" is the library's "sit on a chair": planned as if the clause named it.
                let named: Vec<&str> = name.split(' ').collect();
                if let Some(planned) = postures::plan_clause(&named, None, &model_segment) {
                    notes.push(format!(
                        "\"{}\" {SUBSTITUTED}; used the posture library's \"{name}\" \
                         (similarity {similarity:.2})",
                        words.join(" ")
                    ));
                    notes.extend(planned.notes);
                    segments.push(planned.segment);
                    previous = None;
                    ends_standing = None;
                    break 'clause;
                }
            }
            let from_rules = model.is_some();
            let found = match model {
                Some(found) => found,
                None => match action.flatten() {
                    Some((action, similarity)) => {
                        notes.push(format!(
                            "\"{}\" {SUBSTITUTED}; used the nearest one, \"{}\" \
                             (similarity {similarity:.2})",
                            words.join(" "),
                            action.verb_phrase()
                        ));
                        Movements::only(action)
                    }
                    None => {
                        if !words.is_empty() {
                            notes.push(format!("\"{}\" {LEFT_OUT}", words.join(" ")));
                        }
                        break 'clause;
                    }
                },
            };
            let made = segment(words, &found, style.as_deref());
            if from_rules && !moves_on_in_sequence(words, &found) {
                notes.extend(said_otherwise(words, &made, matcher.as_ref()));
            }
            for _ in 0..repetitions(words, &found, &mut notes) {
                segments.push(made.clone());
            }
            let mut last = found.base;
            for (action, next) in moves_on(words, &found, style.as_deref(), &mut notes) {
                segments.push(next);
                last = action;
            }
            // A substitute or an inherited gesture stands for the whole clause.
            if !found.named.is_empty() {
                let made = &mut segments[clause_start..];
                let poses =
                    place_limb_phrases(words, &found.named, matcher.as_ref(), made, &mut notes);
                let span = clause_start..segments.len();
                held.extend(poses.into_iter().map(|p| (span.clone(), p)));
            }
            previous = Some(found.gestures.last().copied().unwrap_or(last));
            ends_standing = Some(last).filter(|a| a.label().is_some() && *a != Action::LieDown);
        }
        // What the clause says of a limb that nothing moves or holds is named too.
        let held_parts: Vec<BodyPart> = held
            .iter()
            .filter(|(span, _)| span.start == clause_start)
            .flat_map(|(_, p)| p.parts.clone())
            .collect();
        for (phrase, limb) in
            accounting::limbs_left_unplaced(words, &segments[clause_start..], &held_parts, &notes)
        {
            notes.push(format!(
                "\"{phrase}\" {NOT_PLACED}: the built-in planner has no rule for this movement \
                 of the {limb}"
            ));
        }
        // A phrase of a clause that made something, which left no trace in it, is named too
        // ("hops forward on the right foot, arms flapping like wings").
        if segments.len() > clause_start {
            let made = accounting::made_words(
                &segments[clause_start..],
                held.iter()
                    .filter(|(span, _)| span.start == clause_start)
                    .map(|(_, p)| p.name.clone()),
                &notes[notes_start..],
            );
            for phrase in accounting::phrases_without_trace(words, &made) {
                notes.push(format!(
                    "\"{phrase}\" {NOT_PLACED}: the built-in planner made nothing of it"
                ));
            }
        }
        // A safety net under the rules: a clause that neither made a segment nor left a note
        // is named now. The prompt sets' test checks the rules never need it.
        if segments.len() == clause_start && notes.len() == notes_start && !words.is_empty() {
            notes.push(format!("\"{}\" {UNREAD}", words.join(" ")));
        }
        // "puts her left hand on her hip and waves with the right": a limb a clause of its
        // own placed stays there over the next clause, unless that clause moves it or only
        // does the same on another limb ("…, and then the right one": one after the other).
        let repeats = anaphora::again(words).is_some();
        for i in std::mem::replace(&mut lasting, lasting_now)
            .into_iter()
            .filter(|_| !repeats)
        {
            let parts = held[i].1.parts.clone();
            let moved_now = held.iter().any(|(span, p)| {
                span.start == clause_start && p.parts.iter().any(|x| parts.contains(x))
            });
            let free = segments[clause_start..].iter().all(|s| {
                busy(s, &parts).is_none() && !s.postures.as_ref().is_some_and(|t| t.whole_body())
            });
            if held[i].0.end == clause_start && segments.len() > clause_start && free && !moved_now
            {
                held[i].0.end = segments.len();
            }
        }
        clause_of.resize(segments.len(), k);
    }
    if segments.is_empty() {
        let fallback =
            crate::plan::clean_text(prompt).unwrap_or_else(|_| "a person walks forward".into());
        let fallback: String = fallback.chars().take(MAX_TEXT_CHARS).collect();
        notes.push("no known movement in the prompt; the model gets the prompt as it is".into());
        segments.push(Segment {
            text: fallback.clone(),
            seconds: 4.0,
            base: fallback,
            parts: PartEdits::default(),
            trajectory: None,
            postures: None,
        });
    }
    // The segments that fit in the longest plan; the rest are named in a note.
    let mut total = 0.0;
    let fit = segments
        .iter()
        .take_while(|s| {
            total += s.seconds;
            total <= MAX_PLAN_SECONDS + 1e-6
        })
        .count()
        .clamp(1, MAX_SEGMENTS);
    if fit < segments.len() {
        let dropped: Vec<String> = segments[fit..].iter().map(|s| s.text.clone()).collect();
        notes.push(format!(
            "a plan lasts at most {MAX_PLAN_SECONDS} s; left out: {}",
            dropped.join("; ")
        ));
        segments.truncate(fit);
    }
    let mut clips = tracks::clips_across_segments(&mut segments, &clause_of);
    clips.extend(tracks::held_clips(&segments, &held));
    in_time_order(&mut clips);
    Plan {
        prompt: prompt.to_string(),
        rewritten: rewrite(&segments),
        segments,
        clips,
        planner: PlannerKind::Offline,
        notes,
    }
}

/// A clause with the words that name the person read as one name: a word between the
/// article and the noun for the person that would read as a movement ("a **basketball**
/// player") says who, not what the body does, and is dropped. Other words there ("an **old**
/// man") stay: they are the person's style.
fn with_subject_whole<'a>(words: &[&'a str], reader: Reader) -> Vec<&'a str> {
    let Some(article) = words
        .iter()
        .position(|w| matches!(*w, "a" | "an" | "the"))
        .filter(|&i| words[..i].iter().all(|w| lexicon::is_subject_word(w)))
    else {
        return words.to_vec();
    };
    let Some(noun) =
        (article + 1..(article + 4).min(words.len())).find(|&i| lexicon::is_subject_noun(words[i]))
    else {
        return words.to_vec();
    };
    words
        .iter()
        .enumerate()
        .filter(|&(i, w)| {
            !((article + 1..noun).contains(&i) && movements(&[*w], None, reader).is_some())
        })
        .map(|(_, w)| *w)
        .collect()
}

/// Whether a segment gets the body up to standing (the library's "stand up").
fn gets_up(segment: &Segment) -> bool {
    segment.postures.as_ref().is_some_and(|t| {
        t.keys
            .iter()
            .any(|k| k.script.name.as_deref() == Some("stand up"))
    }) || postures::stands_up(&segment.text.split(' ').collect::<Vec<_>>())
}

/// The limb places a clause that holds what came before keeps: those held over the clause
/// just before (`held`, ending at `clause_start`), else the arms the segment before raised,
/// up; `None` when there are none.
fn kept_places(
    held: &[(std::ops::Range<usize>, NamedPosture)],
    clause_start: usize,
    before: Option<&Segment>,
) -> Option<Vec<NamedPosture>> {
    let kept: Vec<NamedPosture> = held
        .iter()
        .filter(|(span, _)| span.end == clause_start && !span.is_empty())
        .map(|(_, p)| p.clone())
        .collect();
    if !kept.is_empty() {
        return Some(kept);
    }
    let which = match anaphora::raised_arms(before?).as_slice() {
        [BodyPart::LeftArm] => "left arm up",
        [BodyPart::RightArm] => "right arm up",
        [] => return None,
        _ => "both arms up",
    };
    let words: Vec<&str> = which.split(' ').collect();
    limb_poses::limb_pose(&words).map(|p| vec![p])
}

/// The segment of a clause that lowers the arms the segment before raised ("raises her right
/// arm and then lowers it"): the arms go down to the library's standing posture while the
/// body stands; `None` when the clause is no such thing or nothing before was raised.
fn lowered_back(
    words: &[&str],
    before: Option<&Segment>,
    held_before: &[BodyPart],
) -> Option<Segment> {
    if !anaphora::lowers_back(words) {
        return None;
    }
    let before = before?;
    let mut arms = anaphora::raised_arms(before);
    if arms.is_empty() {
        // "waves with the left hand, lowers it": the arm the movement before used.
        arms = anaphora::moved_arms(before);
    }
    let is_arm = |p: &&BodyPart| matches!(p, BodyPart::LeftArm | BodyPart::RightArm);
    if arms.is_empty() {
        // "raises both hands, holds them up, then lets them drop": the arms held just before.
        arms = held_before.iter().filter(is_arm).copied().collect();
    }
    let stand = Library::builtin().get("stand")?;
    let legs: Vec<BodyPart> = held_before.iter().filter(|p| !is_arm(p)).copied().collect();
    let (parts, which, name) = match (arms.as_slice(), legs.as_slice()) {
        ([BodyPart::LeftArm], _) => (arms, "lowers the left arm", anaphora::ARMS_DOWN),
        ([BodyPart::RightArm], _) => (arms, "lowers the right arm", anaphora::ARMS_DOWN),
        ([], []) => return None,
        // "lifts the right knee, holds it, then puts it down": the foot back on the ground.
        ([], [BodyPart::LeftLeg]) => (legs, "puts the left foot down", "left foot down"),
        ([], [BodyPart::RightLeg]) => (legs, "puts the right foot down", "right foot down"),
        ([], _) => (legs, "puts both feet down", "feet down"),
        _ => (arms, "lowers both arms", anaphora::ARMS_DOWN),
    };
    let mut script = stand.script.clone();
    script.name = Some(name.into());
    let arms = parts;
    Some(Segment {
        text: format!("a person {which}"),
        seconds: 2.0,
        base: "a person stands still".into(),
        parts: PartEdits::default(),
        trajectory: None,
        postures: Some(PostureTrack::holding(arms, script)),
    })
}

/// Whether a clause moves on from its first whole-body movement to another ("from a walk to
/// a run"): see [`moves_on`].
fn moves_on_in_sequence(words: &[&str], found: &Movements) -> bool {
    found
        .left
        .iter()
        .any(|&(at, action)| !action.is_gesture() && accounting::in_sequence(words, found.at, at))
}

/// The segments of the whole-body movements a clause moves on to after its first ("from a
/// walk to a run"), each with the action it makes and carrying the clause's gestures; what
/// else the clause names that its movement does not make is named in a note with the reason.
fn moves_on(
    words: &[&str],
    found: &Movements,
    style: Option<&str>,
    notes: &mut Vec<String>,
) -> Vec<(Action, Segment)> {
    let mut out = Vec::new();
    for &(at, action) in &found.left {
        if !action.is_gesture() && accounting::in_sequence(words, found.at, at) {
            let next = Movements {
                base: action,
                gestures: found.gestures.clone(),
                at,
                left: Vec::new(),
                named: Vec::new(),
            };
            out.push((action, segment(words, &next, style)));
            continue;
        }
        let why = if action.is_gesture() {
            "the arm it needs already does another movement in this clause"
        } else {
            "it happens at the same time as another whole-body movement of this clause, and \
             the body makes one at a time"
        };
        notes.push(format!(
            "\"{}\" {NOT_PLACED}: {why}",
            accounting::phrase_from(words, at)
        ));
    }
    out
}

/// The hand's place in a clause that touches a body point with it or holds a thing ("touches
/// the right knee with the left hand", "taps his head with his left hand", "holding a phone
/// to the right ear"): the point comes before the hand that goes there, across the "with"
/// that parts the clause's phrases, or no hand is named at all, so it is read from the verb
/// on.
fn touch_pose(words: &[&str]) -> Option<NamedPosture> {
    let at = words
        .iter()
        .position(|w| limb_poses::TOUCHING.contains(w) || limb_poses::HOLDING.contains(w))?;
    limb_poses::limb_pose(&words[at..])
}

/// Places each phrase of a clause about a limb in which the rules read no movement on the
/// clause's segments (`made`): a place the limb holds ("with his right arm upwards",
/// [`limb_poses`]) is returned, to be held on the limb's track over those segments; an arm
/// phrase that says no place is the gesture or arm posture it means ([`limbs`]), where those
/// arms are free. What cannot be placed is named in a note (`named`: the words that named a
/// movement).
fn place_limb_phrases(
    words: &[&str],
    named: &[usize],
    matcher: Option<&Matcher>,
    made: &mut [Segment],
    notes: &mut Vec<String>,
) -> Vec<NamedPosture> {
    let mut held: Vec<NamedPosture> = Vec::new();
    // "walking, taps his head with his left hand": the hand's words ("with his left hand")
    // say only which hand, the place is before them.
    if let Some(pose) = touch_pose(words).filter(|p| !made_already(made, p)) {
        hold_place(pose, &words.join(" "), made, &mut held, notes);
    }
    for (phrase, limb) in accounting::limb_phrases_without_movement(words, named) {
        let phrase_words: Vec<&str> = phrase.split(' ').collect();
        if let Some(pose) = limb_poses::limb_pose(&phrase_words) {
            if !held.iter().any(|h| h.name == pose.name) && !made_already(made, &pose) {
                hold_place(pose, &phrase, made, &mut held, notes);
            }
            continue;
        }
        let found = matcher
            .filter(|_| limb == "arm")
            .and_then(|m| limbs::nearest_arm_movement(&phrase_words, m));
        let Some((movement, similarity)) = found
            .filter(|(m, _)| !made.is_empty() && made.iter().all(|s| arms_free(s, &m.parts())))
        else {
            notes.push(format!(
                "\"{phrase}\" {NOT_PLACED}: the built-in planner has no rule for this \
                 movement of the {limb}"
            ));
            continue;
        };
        for segment in made.iter_mut() {
            match &movement {
                limbs::LimbMovement::Gesture(g) => {
                    for part in g.arms() {
                        segment.parts.set(*part, Some(g.caption()));
                    }
                }
                limbs::LimbMovement::Posture(p) => {
                    segment.postures =
                        Some(PostureTrack::holding(p.parts.clone(), p.script.clone()));
                }
            }
        }
        notes.push(format!(
            "\"{phrase}\" {SUBSTITUTED} on its own; used \"{}\" on the same arms \
             (similarity {similarity:.2})",
            movement.describe()
        ));
    }
    held
}

/// Whether the clause's own segments already hold `pose` ("…, holding the T-pose": the
/// posture the clause names is on its segments).
fn made_already(made: &[Segment], pose: &NamedPosture) -> bool {
    made.iter().any(|s| {
        s.postures.as_ref().is_some_and(|t| {
            t.keys
                .iter()
                .any(|k| k.script.name.as_deref() == Some(pose.name.as_str()))
        })
    })
}

/// Holds `pose` (a limb's place a phrase says) over the clause's segments, unless the
/// clause's movement or another of its phrases moves that limb, which a note then says.
fn hold_place(
    pose: NamedPosture,
    phrase: &str,
    made: &[Segment],
    held: &mut Vec<NamedPosture>,
    notes: &mut Vec<String>,
) {
    let taken = held
        .iter()
        .any(|h| h.parts.iter().any(|p| pose.parts.contains(p)));
    match made
        .iter()
        .find_map(|s| busy(s, &pose.parts))
        .or_else(|| (made.is_empty() || taken).then_some("another phrase of the clause moves it"))
    {
        None => held.push(pose),
        Some(why) => notes.push(format!("\"{phrase}\" {NOT_PLACED}: {why}")),
    }
}

/// A clause that only says where limbs are ([`limb_poses`]): the body stands, on one leg if
/// the clause says so (the segment's own posture), and the other places are held on their
/// limbs over it. `None` when no limb phrase of the clause reads as a place.
fn standing_poses(words: &[&str]) -> Option<(Segment, Vec<NamedPosture>)> {
    let mut poses: Vec<NamedPosture> = Vec::new();
    for (phrase, _) in accounting::limb_phrases_without_movement(words, &[]) {
        let phrase: Vec<&str> = phrase.split(' ').collect();
        if let Some(pose) = limb_poses::limb_pose(&phrase) {
            poses.push(pose);
        }
    }
    if poses.is_empty() {
        poses.extend(touch_pose(words));
    }
    if poses.is_empty() {
        return None;
    }
    let legs = [BodyPart::LeftLeg, BodyPart::RightLeg];
    let stance = poses
        .iter()
        .position(|p| legs.iter().all(|l| p.parts.contains(l)))
        .map(|k| poses.remove(k));
    // Each limb held once: the first place a phrase gives it.
    let mut kept: Vec<NamedPosture> = Vec::new();
    for pose in poses {
        if kept
            .iter()
            .all(|k| k.parts.iter().all(|p| !pose.parts.contains(p)))
        {
            kept.push(pose);
        }
    }
    let (text, postures) = match &stance {
        Some(s) => (
            format!("a person {}", s.name.replacen("standing", "stands", 1)),
            Some(PostureTrack::holding(s.parts.clone(), s.script.clone())),
        ),
        None => ("a person stands still".to_string(), None),
    };
    Some((standing_segment(text, postures), kept))
}

/// A segment over the model's standing, made by key poses the rules write (`postures`, if
/// any): as long as the poses take at their own pace with the way into them, 2 s at least.
fn standing_segment(text: String, postures: Option<PostureTrack>) -> Segment {
    let seconds = postures
        .as_ref()
        .and_then(|t| clamp_seconds(t.natural_seconds() + DEFAULT_TRANSITION_SECONDS))
        .unwrap_or(2.0)
        .max(2.0);
    Segment {
        text,
        seconds,
        base: "a person stands still".into(),
        parts: PartEdits::default(),
        trajectory: None,
        postures,
    }
}

/// Why a segment cannot have a pose held on `parts` over it, if it cannot: an instruction or
/// a held posture of its own moves them, or (for a leg) the body travels or jumps on its legs.
/// A posture of the whole body (a spin of key poses) carries a held arm.
fn busy(segment: &Segment, parts: &[BodyPart]) -> Option<&'static str> {
    if parts.iter().any(|p| segment.parts.get(*p).is_some()) {
        return Some("another instruction of the clause moves that limb");
    }
    let legs = parts
        .iter()
        .any(|p| matches!(p, BodyPart::LeftLeg | BodyPart::RightLeg));
    match &segment.postures {
        Some(track) if track.whole_body() && legs => {
            Some("a posture of the whole body already holds the legs")
        }
        Some(track) if !track.whole_body() && track.parts.iter().any(|p| parts.contains(p)) => {
            Some("a posture of the clause already holds that limb")
        }
        _ if legs && !stands(segment) => {
            Some("the legs carry the movement of the clause and cannot also hold a pose")
        }
        _ => None,
    }
}

/// Whether a segment's base motion stands in place (the legs are free to hold a pose).
fn stands(segment: &Segment) -> bool {
    let base = segment.base.as_str();
    base.contains("stands") && !base.contains("up")
}

/// Whether a segment leaves `arms` to a movement of their own: no instruction and no posture
/// on them.
fn arms_free(segment: &Segment, arms: &[BodyPart]) -> bool {
    arms.iter().all(|a| segment.parts.get(*a).is_none()) && segment.postures.is_none()
}

/// The segments' texts as one description ("a person walks forward, then a person bows").
pub fn rewrite(segments: &[Segment]) -> String {
    segments
        .iter()
        .map(|s| s.text.as_str())
        .collect::<Vec<_>>()
        .join(", then ")
}

/// What a clause asks for: a base motion and the gestures that ride on it.
#[derive(Clone, Debug, PartialEq)]
struct Movements {
    base: Action,
    gestures: Vec<Action>,
    /// The index of the word that names the base.
    at: usize,
    /// What else the clause names, with the index of its word, that the base and gestures do
    /// not make: a second whole-body movement, a gesture on an arm already busy. The
    /// planner places or names each ([`accounting`]).
    left: Vec<(usize, Action)>,
    /// The indices of every word that named a movement, made or left.
    named: Vec<usize>,
}

impl Movements {
    /// One action alone, named nowhere in particular (a substitute, a fallback).
    fn only(base: Action) -> Movements {
        Movements {
            base,
            gestures: Vec::new(),
            at: 0,
            left: Vec::new(),
            named: Vec::new(),
        }
    }
}

/// What reading a clause depends on besides its words.
#[derive(Clone, Copy, Debug)]
struct Reader<'a> {
    /// The actions of dataset v2 the model makes.
    known: Repertoire<'a>,
    /// The clause after this one holds its pose or lands it in a named posture ("squats and
    /// holds it", "jumps up and lands in a superhero landing"), which the posture library
    /// makes.
    pose_kept: bool,
}

impl Reader<'_> {
    /// A clause read on its own, for splitting the prompt into clauses.
    fn alone(known: Repertoire) -> Reader {
        Reader {
            known,
            pose_kept: false,
        }
    }
}

/// How many segments a clause's movement takes: "twice", "three times"; for an action of
/// dataset v2 also a count before its noun ("three squats", "3 kicks"), at most
/// [`MAX_SEGMENTS`] (with a note when more were asked).
fn repetitions(words: &[&str], found: &Movements, notes: &mut Vec<String>) -> usize {
    let said = lexicon::repetitions(words);
    let dataset = found.base.label().is_some();
    let asked = if said > 1 {
        said
    } else {
        // "does three squats", "throws two punches", "does squats three times".
        lexicon::count_before(words, found.at)
            .filter(|n| dataset || *n > 1)
            .or_else(|| lexicon::count_after(words, found.at))
            .unwrap_or(1)
    };
    if !dataset && said > 1 {
        return said;
    }
    if asked > MAX_SEGMENTS {
        notes.push(format!(
            "\"{}\" asks for {asked}; a plan has at most {MAX_SEGMENTS} segments, so it makes \
             {MAX_SEGMENTS}",
            words.join(" ")
        ));
    }
    asked.clamp(1, MAX_SEGMENTS)
}

/// The movements of one clause; `previous` lends its gesture to a clause with no verb ("then
/// the left hand").
fn movements(words: &[&str], previous: Option<Action>, reader: Reader) -> Option<Movements> {
    let mut actions: Vec<(usize, Action)> = Vec::new();
    for (i, w) in words.iter().enumerate() {
        let next = &words[i + 1..];
        let prev = &words[..i];
        let prev_rev: Vec<&str> = prev.iter().rev().copied().collect();
        let Some(mut action) =
            dataset_action(words, i, reader).or_else(|| lexicon::action_word(w, next, &prev_rev))
        else {
            continue;
        };
        if *w == "sword" && actions.iter().any(|(_, a)| *a == Action::Slash) {
            continue;
        }
        action = match action {
            Action::Walk(Direction::Forward) => Action::Walk(direction(next)),
            a if a.is_gesture() => {
                a.with_side(side(words, i).unwrap_or(if lexicon::both_by_default(w) {
                    Side::Both
                } else {
                    Side::Right
                }))
            }
            a => a,
        };
        // "waves goodbye with his left hand" is a wave of that hand.
        if action == Action::Goodbye {
            if let Some(s) = side(words, i) {
                action = Action::Wave(s);
            }
        }
        if actions.iter().any(|(_, a)| same_kind(*a, action)) {
            continue;
        }
        actions.push((i, action));
    }
    if actions.is_empty() {
        let side = words.iter().find_map(|w| side_word(w))?;
        let previous = previous.filter(|a| a.is_gesture())?;
        return Some(Movements::only(previous.with_side(side)));
    }
    let named = actions.iter().map(|(i, _)| *i).collect();
    // A walk turning and walking is one turn.
    if let Some(turn) = actions.iter().position(|(_, a)| {
        matches!(
            a,
            Action::Walk(Direction::TurnLeft) | Action::Walk(Direction::TurnRight)
        )
    }) {
        let turn = actions[turn].1;
        actions.retain(|(_, a)| !matches!(a, Action::Walk(_)) || *a == turn);
    }
    let base_index = actions
        .iter()
        .position(|(_, a)| !a.is_gesture())
        .unwrap_or(0);
    let base = actions[base_index].1;
    let mut used: Vec<BodyPart> = base.arms().to_vec();
    let mut gestures = Vec::new();
    let mut left = Vec::new();
    for (k, (i, a)) in actions.iter().enumerate() {
        if k == base_index {
            continue;
        }
        if !a.is_gesture() || a.arms().iter().any(|p| used.contains(p)) {
            left.push((*i, *a));
            continue;
        }
        used.extend_from_slice(a.arms());
        gestures.push(*a);
    }
    Some(Movements {
        base,
        gestures,
        at: actions[base_index].0,
        left,
        named,
    })
}

/// The action of dataset v2 that word `i` names, where the model makes it and the posture
/// library does not keep the clause (a pose held, a movement it names otherwise such as
/// "jumping jacks", or a whole-body pose beside it).
fn dataset_action(words: &[&str], i: usize, reader: Reader) -> Option<Action> {
    let action = lexicon::dataset_action(words, i).or_else(|| jog_circle(words, i))?;
    (reader.known.knows(action) && !postures::keeps(words, i, action, reader.pose_kept))
        .then_some(action)
}

/// A jog or run round a circle or an arc of one ("jogs in a circle to the left", "jogs
/// around, curving to the right"), the way it turns.
fn jog_circle(words: &[&str], i: usize) -> Option<Action> {
    if lexicon::action_word(words[i], &[], &[]) != Some(Action::Run) {
        return None;
    }
    let Trajectory::Shape {
        shape: Shape::Circle(side) | Shape::Arc(side),
    } = path(words)?
    else {
        return None;
    };
    Some(Action::JogCircle(match side {
        crate::trajectory::Side::Left => Side::Left,
        crate::trajectory::Side::Right => Side::Right,
    }))
}

fn same_kind(a: Action, b: Action) -> bool {
    std::mem::discriminant(&a) == std::mem::discriminant(&b) && a == b
        || matches!((a, b), (Action::Walk(_), Action::Walk(_)))
            && !matches!(
                b,
                Action::Walk(Direction::TurnLeft) | Action::Walk(Direction::TurnRight)
            )
}

fn side_word(word: &str) -> Option<Side> {
    match word {
        "left" => Some(Side::Left),
        "right" => Some(Side::Right),
        "both" | "hands" | "arms" => Some(Side::Both),
        _ => None,
    }
}

/// The side a gesture at `i` names: a few words after it ("waves the left hand"), or before
/// ("with the left arm raised").
fn side(words: &[&str], i: usize) -> Option<Side> {
    let stop = |w: &str| {
        lexicon::action_word(w, &[], &[]).is_some_and(|a| !a.is_gesture())
            || matches!(w, "while" | "then" | "and")
    };
    // Up to the end of the gesture's phrase: "waves to his friends with his left hand".
    for w in words.iter().skip(i + 1).take(8) {
        if stop(w) || lexicon::action_word(w, &[], &[]).is_some() {
            break;
        }
        if let Some(s) = side_word(w) {
            return Some(s);
        }
    }
    for w in words[..i].iter().rev().take(4) {
        if stop(w) {
            break;
        }
        if let Some(s) = side_word(w) {
            return Some(s);
        }
    }
    None
}

/// Where a walk goes, from the words after the verb up to the next movement.
fn direction(next: &[&str]) -> Direction {
    for (k, w) in next.iter().take(4).enumerate() {
        match *w {
            "backward" | "backwards" | "back" => return Direction::Backward,
            "left" | "leftward" | "leftwards" => return Direction::Left,
            "right" | "rightward" | "rightwards" => return Direction::Right,
            "forward" | "forwards" | "ahead" | "straight" => return Direction::Forward,
            "sideways" => {
                if next[k..].iter().take(4).any(|w| *w == "right") {
                    return Direction::Right;
                }
                return Direction::Left;
            }
            w if matches!(w, "with" | "while" | "and" | "then" | ",")
                || lexicon::action_word(w, &[], &[]).is_some() =>
            {
                break
            }
            _ => {}
        }
    }
    Direction::Forward
}

/// The style the whole prompt asks for ("an angry person walks …"), as caption words.
fn prompt_style(text: &str) -> Option<String> {
    tokens(text)
        .iter()
        .find_map(|w| lexicon::style_word(w).map(String::from))
}

/// Verbs of standing still or of no movement at all: a clause of only these is no segment.
const NOT_MOVEMENT: &[&str] = &[
    "stop", "stops", "stopping", "stand", "stands", "standing", "still", "pause", "pauses", "wait",
    "waits", "rest", "rests", "laugh", "laughs", "laughing", "smile", "smiles", "smiling", "look",
    "looks", "looking", "talk", "talks", "talking", "freeze", "freezes",
];

fn is_filler(word: &str) -> bool {
    lexicon::is_subject_word(word)
        || matches!(
            word,
            "man"
                | "woman"
                | "he"
                | "his"
                | "her"
                | "their"
                | "for"
                | "of"
                | "at"
                | "on"
                | "in"
                | "to"
                | "end"
                | "ceremony"
                | "moment"
                | "while"
                | "there"
                | "and"
        )
}

/// The actions the model was trained on, as candidates for unknown movements.
const TRAINING_ACTIONS: [Action; 16] = [
    Action::Walk(Direction::Forward),
    Action::Walk(Direction::Backward),
    Action::Walk(Direction::TurnLeft),
    Action::Walk(Direction::TurnRight),
    Action::Run,
    Action::Dash,
    Action::Bow,
    Action::Kick,
    Action::Punch,
    Action::Slash,
    Action::Dance,
    Action::Beckon,
    Action::Guide,
    Action::Wave(Side::Both),
    Action::Goodbye,
    Action::Raise(Side::Both),
];

/// The segment of one clause.
fn segment(words: &[&str], found: &Movements, style: Option<&str>) -> Segment {
    let own_style = words.iter().find_map(|w| lexicon::style_word(w));
    let style = own_style.or(style);
    let with_style = |caption: String| match style {
        Some(s) => format!("{caption} {s}"),
        None => caption,
    };
    let base = with_style(found.base.caption());
    let mut parts = PartEdits::default();
    let mut text = found.base.caption();
    for g in &found.gestures {
        for part in g.arms() {
            parts.set(*part, Some(with_style(g.caption())));
        }
        text = format!("{text} {}", g.participle());
    }
    let text = with_style(text);
    let trajectory = if found.base.is_locomotion()
        && !matches!(
            found.base,
            Action::Walk(Direction::TurnLeft | Direction::TurnRight)
        ) {
        path(words)
    } else {
        None
    };
    let usual = match &trajectory {
        Some(Trajectory::Shape { shape }) => path_seconds(*shape),
        _ => found.base.seconds(),
    };
    let seconds = duration(words).unwrap_or_else(|| {
        let tempo: f64 = words
            .iter()
            .filter_map(|w| lexicon::tempo_word(w))
            .product();
        let few = words.windows(2).any(|w| w == ["few", "steps"]);
        let long = words.windows(2).any(|w| w == ["a", "while"]);
        usual * tempo * if few { 0.75 } else { 1.0 } * if long { 1.5 } else { 1.0 }
    });
    Segment {
        text,
        seconds: clamp_seconds(seconds).unwrap_or(usual),
        base,
        parts,
        trajectory,
        postures: None,
    }
}

/// The note for a clause whose segment does not plainly mean what its words say, by the same
/// judgement the timeline set's scorer uses ([`meaning`]): the rules read the clause's verb
/// and its direction, and drop what they have no word for ("jogs **in place**", "walks **to
/// the door**"), so the person is told what stands for their words. Only the clause's head
/// is compared (up to the first phrase that rides on it: "…, holding the T-pose" is placed on
/// its own).
fn said_otherwise(words: &[&str], made: &Segment, matcher: Option<&Matcher>) -> Option<String> {
    let matcher = matcher?;
    let head = accounting::head_phrase(&lexicon::without_subject(words));
    // The path is part of what the segment says ("walks forward" along "a circle, clockwise").
    let said = match &made.trajectory {
        Some(path) => format!("{} along {}", made.text, path.describe()),
        None => made.text.clone(),
    };
    if head.is_empty() || matcher.same(&head, &said).is_some() {
        return None;
    }
    Some(format!(
        "\"{}\" {MADE_AS}: \"{}\"",
        words.join(" "),
        made.text
    ))
}

/// "for 3 seconds", "for 2.5 s", "for five seconds".
fn duration(words: &[&str]) -> Option<f64> {
    words.windows(3).find_map(|w| {
        let unit = matches!(w[2], "seconds" | "second" | "secs" | "sec" | "s");
        (w[0] == "for" && unit)
            .then(|| lexicon::number(w[1]))
            .flatten()
    })
}

/// The root path a clause names ("in a circle clockwise", "zigzag", "s shaped").
fn path(words: &[&str]) -> Option<Trajectory> {
    let trajectory = Trajectory::from_text(&words.join(" "))?;
    // A turn is in the training data as a motion of its own; the planner asks for that.
    match trajectory {
        Trajectory::Shape {
            shape: Shape::Turn(_),
        } => None,
        t => Some(t),
    }
}

/// A usual length in seconds for walking a shape at about 1.2 m/s: long enough to make a
/// closed shape recognisable, within one generation.
fn path_seconds(shape: Shape) -> f64 {
    match shape {
        Shape::Line => 4.0,
        Shape::Arc(_) | Shape::Turn(_) => 5.0,
        Shape::Zigzag(_) | Shape::SCurve(_) => 6.0,
        _ => 9.0,
    }
}

#[cfg(test)]
mod tests;
